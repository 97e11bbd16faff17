"""mission.param: NAME VALUE lines as MAVProxy / Mission Planner load them."""

import io

import pytest
from pymavlink import mavparm

from fm2uav.errors import InputError
from fm2uav.io.params import params_text, read_params, write_params


def test_the_file_parses_with_pymavlink_as_written(returns_mission, tmp_path):
    ps = returns_mission.returns.params
    f = tmp_path / "mission.param"
    with open(f, "w") as fh:
        assert write_params(fh, ps) == len(ps.params)
    d = mavparm.MAVParmDict()
    d.load(str(f))
    assert dict(d) == pytest.approx(ps.as_dict())
    assert read_params(f) == pytest.approx(ps.as_dict())
    text = f.read_text()
    assert text.startswith("# fm2uav return settings")
    assert "\nRTL_ALT_M " in text and "#" not in [ln for ln in text.splitlines()
                                                   if ln.startswith("RTL")][0]


def test_read_params_refuses_a_bad_line(tmp_path):
    f = tmp_path / "x.param"
    f.write_text("RTL_ALT 100\nOOPS\n")
    with pytest.raises(InputError, match="line 2"):
        read_params(f)
    f.write_text("RTL_ALT,100 # comment\n")
    assert read_params(f) == {"RTL_ALT": 100.0}


def test_values_keep_their_precision():
    class P:
        header = ()
        params = [type("p", (), {"name": "A", "value": 2.5, "why": "w"})(),
                  type("p", (), {"name": "B", "value": 3.0, "why": "w"})()]

    assert params_text(P()).splitlines()[1::2] == ["A 2.5", "B 3"]
    assert io.StringIO(params_text(P())).read().count("#") == 2
