"""The parameter set a mission writes, checked."""

import pytest

from fm2uav.autopilot.firmware.profile import Param
from fm2uav.autopilot.params import param_set
from fm2uav.errors import MissionError


def test_a_param_set_keeps_one_value_per_name():
    ps = param_set([Param("RTL_ALT", 13000, "a"), Param("RTL_ALT", 13000, "again")],
                   header=["x"])
    assert ps.as_dict() == {"RTL_ALT": 13000} and ps.header == ("x",)


@pytest.mark.parametrize("bad, match", [
    ([Param("rtl_alt", 1, "")], "param_id"),
    ([Param("A_VERY_LONG_PARAMETER", 1, "")], "param_id"),
    ([Param("RTL_ALT", float("nan"), "")], "finite"),
    ([Param("RTL_ALT", 1, "a"), Param("RTL_ALT", 2, "b")], "set twice"),
])
def test_bad_parameters_are_refused(bad, match):
    with pytest.raises(MissionError, match=match):
        param_set(bad)


def test_the_ridge_missions_parameters(returns_mission):
    d = returns_mission.returns.params.as_dict()
    assert d["RTL_ALT"] == 100 * d["RTL_ALT_M"]  # cm up to Copter 4.6, m from 4.7
    assert d["RTL_CONE_SLOPE"] == 0 and d["RTL_ALT_TYPE"] == 0
    assert d["RALLY_INCL_HOME"] == 1  # a rally point: home still competes
