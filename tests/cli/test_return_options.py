"""The safe-return flags: --rally, --rally-file, --return-min-agl, --strict, --no-returns."""

import pytest

from fm2uav.autopilot.safe_return import ReturnOptions
from fm2uav.cli._return_options import ReturnFlags
from fm2uav.errors import InputError


@pytest.fixture(scope="module")
def world():
    from fm2uav.scenarios import get_scenario

    return get_scenario("open-field").world


def test_flags_become_return_options(world, tmp_path):
    from fm2uav.world.geo import to_lonlat

    lo, la, _ = to_lonlat(world, [[300.0, 400.0, 0.0]])[0]
    f = ReturnFlags(rally=[f"{lo},{la},45", "auto:2"], return_min_agl=20.0, strict=True)
    ro = f.options(world)
    assert ro.auto_rally == 2 and ro.strict and ro.min_agl == 20.0 and ro.enabled
    (x, y, agl), = ro.rally
    assert (x, y, agl) == (pytest.approx(300.0, abs=1e-3), pytest.approx(400.0, abs=1e-3), 45.0)
    base = ReturnOptions(rally=((1.0, 2.0, None),), auto_rally=1)
    merged = ReturnFlags(enabled=False).options(world, base=base)
    assert merged.rally == base.rally and merged.auto_rally == 1 and not merged.enabled
    (tmp_path / "r.csv").write_text(f"lon,lat\n{lo},{la}\n")
    assert len(ReturnFlags(rally_file=tmp_path / "r.csv").options(world).rally) == 1
    with pytest.raises(InputError, match="--rally"):
        ReturnFlags(rally=["nowhere"]).options(world)


def test_strict_refuses_a_mission_past_its_point_of_no_return(tmp_path):
    from typer.testing import CliRunner

    from fm2uav.cli import app

    out = tmp_path / "p"
    args = ["plan", "--agl", "150", "--export", "plan", "--endurance", "6", "--out", str(out)]
    res = CliRunner().invoke(app, [*args, "--strict"])
    assert res.exit_code == 1, res.output
    assert "point of no return" in res.output and "--strict" in res.output
    assert not out.exists()  # nothing written
    res = CliRunner().invoke(app, [*args, "--rally", "nowhere"])
    assert res.exit_code == 2 and res.output.startswith("error: --rally 'nowhere'")
    assert not out.exists()
    res = CliRunner().invoke(app, [*args, "--no-returns", "--json"])
    assert res.exit_code == 0
    import json

    data = json.loads(res.output)
    assert "returns" not in data and not (out / "mission.param").exists()
