"""The mission files of fm2uav cover, plan and formation (every format, camera, via points)."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from pymavlink import mavwp
from typer.testing import CliRunner

from fm2uav.cli import app
from fm2uav.autopilot import validate_mission
from fm2uav.io import read_plan, read_wpl

runner = CliRunner()
MISSION_FILES = ("mission.plan", "mission.waypoints", "path.kml", "path.kmz", "path.geojson",
                 "path.csv")


@pytest.mark.parametrize("firmware", ["px4", "ardupilot"])
def test_cover_writes_every_format_with_the_camera_triggered_per_band(firmware, tmp_path):
    out = tmp_path / "c"
    res = runner.invoke(app, ["cover", "--area", "S3", "--camera", "13.2,8.8,8.8,5472,3648",
                              "--side-overlap", "0.6", "--front-overlap", "0.75", "--agl", "100",
                              "--angle", "1.012", "--firmware", firmware, "--out", str(out),
                              "--json"])
    assert res.exit_code == 0, res.output
    for f in MISSION_FILES:
        assert (out / f).stat().st_size > 0, f
    s = json.loads((out / "summary.json").read_text())
    cam = s["autopilot"]["camera"]
    # GSD = 13.2 mm x 100 m / (8.8 mm x 5472 px); D = 150 m x (1 - 0.6): the side overlap 0.6
    assert cam["gsd_cm_per_px"] == pytest.approx(100 * 13.2 * 100 / (8.8 * 5472), abs=1e-3)
    assert cam["side_overlap"] == pytest.approx(0.6, abs=1e-6)
    assert cam["trigger_distance_m"] == pytest.approx(100.0 * 0.25)  # footprint along x 0.25
    plan = read_plan(out / "mission.plan")
    trig = plan["items"]
    on_off = [it.params[0] for it in trig if it.command == 206]
    assert on_off == [cam["trigger_distance_m"], 0.0] * s["bands"]
    assert validate_mission(trig, firmware, home_alt=plan["home"][2]) == []
    frames = set(plan["frame"][plan["command"] == 16])
    assert frames == ({10} if firmware == "ardupilot" else {0})
    loader = mavwp.MAVWPLoader()
    n = loader.load(str(out / "mission.waypoints")) - 1
    assert n == len(trig)
    first = next(k for k in range(1, n + 1) if loader.wp(k).command == 16)
    assert math.isnan(loader.wp(first).param4)


def test_plan_via_and_return_flags(tmp_path):
    out = tmp_path / "p"
    res = runner.invoke(app, ["plan", "--scenario", "open-field", "--agl", "150",
                              "--via", "1400,300,480", "--via", "500,1100,420", "--return",
                              "--export", "plan,wpl", "--firmware", "ardupilot", "--end", "land",
                              "--out", str(out), "--json"])
    assert res.exit_code == 0, res.output
    s = json.loads(res.output)
    assert s["route"]["legs"] == 4
    plan = read_plan(out / "mission.plan")
    assert plan["command"][0] == 22 and plan["command"][-1] == 21
    assert set(plan["frame"][plan["command"] == 16]) == {10}
    wpl = read_wpl(out / "mission.waypoints")
    np.testing.assert_array_equal(wpl["command"], plan["command"])


def test_formation_writes_one_time_consistent_mission_per_uav(tmp_path):
    out = tmp_path / "f"
    res = runner.invoke(app, ["formation", "--no-gif", "--followers", "2", "--firmware",
                              "ardupilot", "--out", str(out), "--json"])
    assert res.exit_code == 0, res.output
    s = json.loads((out / "summary.json").read_text())
    assert set(s["missions"]) == {"leader", "follower 1", "follower 2"}
    for prefix in ("leader", "follower1", "follower2"):
        for f in MISSION_FILES:
            assert (out / f"{prefix}_{f}").stat().st_size > 0
    holds = []
    for name, prefix in (("leader", "leader"), ("follower 1", "follower1"),
                         ("follower 2", "follower2")):
        plan = read_plan(out / f"{prefix}_mission.plan")
        wpl = read_wpl(out / f"{prefix}_mission.waypoints")
        np.testing.assert_array_equal(plan["command"], wpl["command"])
        assert plan["command"][0] == 22 and plan["command"][-1] == 21
        assert (plan["command"] == 178).sum() >= 1  # the simulated speeds
        m = s["missions"][name]
        assert m["timing"]["planned_s"] == pytest.approx(s["mission_time_s"], abs=1.0)
        holds.append(m["timing"]["start_hold_s"])
        # honest timing: the route's time, and a warning if the vehicle's vertical speed
        # cannot follow the simulated climbs
        late = m["timing"]["error_s"] > 0.05 * m["timing"]["planned_s"]
        assert late == any(w.startswith("timing:") for w in m["warnings"])
    assert min(holds) == 0.0  # the one with the most to climb does not wait
