"""Path profiles (exact geometric cases), auto-tuning and the CLI."""

from __future__ import annotations

import json

import numpy as np
import pytest
from typer.testing import CliRunner

import fm2uav
from fm2uav.analysis import flight_level_deviation, path_profiles
from fm2uav.geometry import menger_curvature, resample_path
from fm2uav.errors import InputError
from fm2uav.analysis.tune import as_limits, tune
from fm2uav.vehicles import AirframeLimits, FixedWing
from fm2uav import FlightLevel


def test_resample_keeps_ends_and_step():
    p = np.array([[0.0, 0, 0], [10, 0, 0], [10, 5, 0]])
    q = resample_path(p, 4.0)
    np.testing.assert_allclose(q[0], p[0])
    np.testing.assert_allclose(q[-1], p[-1])
    np.testing.assert_allclose(np.linalg.norm(np.diff(q, axis=0), axis=1)[:2], 4.0)
    # the third point is 12 m along the polyline: (10, 2, 0)
    np.testing.assert_allclose(q[3], [10, 2, 0])


def test_helix_profiles_are_exact():
    # helix radius R, pitch angle g: horizontal curvature 1/R, climb g,
    # 3D curvature cos(g)^2 / R, turn per step ds*cos(g)/R
    R, g, ds = 200.0, np.radians(10.0), 5.0
    t = np.linspace(0, 2 * np.pi, 4000)
    h = R * t * np.tan(g)
    helix = np.stack([R * np.cos(t), R * np.sin(t), h], axis=1)
    pr = path_profiles(helix, ds=ds)
    np.testing.assert_allclose(pr.climb, g, atol=1e-3)
    np.testing.assert_allclose(pr.curvature_h[2:-2], 1 / R, rtol=2e-3)
    np.testing.assert_allclose(pr.curvature[2:-2], np.cos(g) ** 2 / R, rtol=2e-3)
    np.testing.assert_allclose(pr.turn[2:-2], ds * np.cos(g) / R, rtol=2e-3)
    s = pr.summary()
    assert s["min_turn_radius_m"] == pytest.approx(R, rel=5e-3)
    assert s["climb_max_deg"] == pytest.approx(10.0, abs=0.1)


def test_straight_line_and_right_angle():
    line = np.stack([np.linspace(0, 100, 11), np.zeros(11), np.linspace(0, 100, 11)], axis=1)
    pr = path_profiles(line, ds=10.0)
    assert np.allclose(pr.turn, 0) and np.allclose(pr.curvature, 0)
    np.testing.assert_allclose(np.degrees(pr.climb), 45.0)
    assert pr.summary()["min_turn_radius_m"] == np.inf
    corner = np.array([[0.0, 0, 0], [10, 0, 0], [10, 10, 0]])
    pr = path_profiles(corner, ds=10.0)
    np.testing.assert_allclose(np.degrees(pr.turn), [90.0])
    # circle through (0,0), (10,0), (10,10): radius 5 sqrt(2)
    np.testing.assert_allclose(menger_curvature(corner), [1 / (5 * np.sqrt(2))])
    with pytest.raises(InputError):
        path_profiles(np.zeros((1, 3)))


def test_flight_level_deviation_exact():
    w = fm2uav.World.from_heightmap(np.full((10, 4), 10.0), 5.0, 12)
    # ideal z = 10 + 20 = 30; start stretch 2 points, end stretch 1 point
    path = np.array([[0, 5, 50.0], [5, 5, 40.0], [10, 5, 33.0], [15, 5, 28.0],
                     [20, 5, 36.0], [25, 5, 30.0], [30, 5, 45.0]])
    r = flight_level_deviation(w, path, agl=20.0)
    assert r.start_transition_m == pytest.approx(np.hypot(5, 10) + np.hypot(5, 7))
    assert r.end_transition_m == pytest.approx(np.hypot(5, 15))
    assert r.middle_points == 4
    assert r.within == pytest.approx(3 / 4)  # 3, 2, 6, 0 m vs tolerance 5 m
    assert r.within_all == pytest.approx(3 / 7)
    assert r.mean_dev_m == pytest.approx((3 + 2 + 6 + 0) / 4)
    assert r.max_dev_m == pytest.approx(6.0)
    assert r.inside_terrain == 0 and r.min_agl_m == pytest.approx(18.0)
    # layer reference: surface node k=2 (z=10) + round(20/5)=4 -> z = 30
    rl = flight_level_deviation(w, path, agl=20.0, reference="layer")
    np.testing.assert_allclose(rl.deviation, r.deviation)
    inside = path.copy()
    inside[3, 2] = 9.0
    assert flight_level_deviation(w, inside, agl=20.0).inside_terrain == 1


def test_limits_parsing():
    lim = AirframeLimits.from_degrees(20, 50)
    assert lim.max_climb == pytest.approx(np.radians(20)) and lim.min_turn_radius == 50.0
    assert as_limits({"max_climb": np.radians(20), "min_turn_radius": 50}) == lim
    assert as_limits(lim) is lim
    with pytest.raises(InputError):
        AirframeLimits(0, 50)
    with pytest.raises(InputError, match="90 degrees"):
        AirframeLimits(2.0, 50)  # radians, not degrees: 115 degrees
    with pytest.raises(InputError):
        AirframeLimits.from_degrees(95, 50)
    with pytest.raises(InputError):
        AirframeLimits(0.3, -1)
    with pytest.raises(InputError, match="missing"):
        as_limits({"max_climb": 0.3})
    with pytest.raises(InputError, match="AirframeLimits"):
        as_limits((20, 50))
    # an airframe: the smaller of climb and descent, its turn radius at cruise
    wing = FixedWing("w", 14.0, 12.0, 17.0, np.radians(55), np.radians(15), np.radians(12))
    lim = as_limits(wing)
    assert lim.max_climb_deg == pytest.approx(12.0)
    assert lim.min_turn_radius == pytest.approx(wing.turn_radius())
    assert as_limits("disco") == fm2uav.get_airframe("disco").limits()
    assert as_limits("arducopter").max_climb == pytest.approx(np.pi / 2)


@pytest.fixture(scope="module")
def open_field():
    return fm2uav.scenarios.open_field()


def test_tune_trade_off(open_field):
    sc = open_field
    grid = {"p1": [0.5], "p2": [0.6, 0.8, 1.3, 2.5]}
    lv = FlightLevel(agl=150.0)
    loose = tune(sc.world, sc.start, sc.goal, AirframeLimits.from_degrees(89.9, 0.0), lv, grid=grid)
    strict = tune(sc.world, sc.start, sc.goal, AirframeLimits.from_degrees(25.0, 200.0), lv,
                  grid=grid)
    assert len(loose.rows) == 4 and all(r["error"] is None for r in loose.rows)
    # with no limits the best is the closest follower; with tight limits a smoother one
    assert loose.best["deviation_m"] == min(r["deviation_m"] for r in loose.rows)
    assert strict.best is not None
    assert strict.best["climb_max_deg"] <= 25.0 and strict.best["min_turn_radius_m"] >= 200.0
    assert strict.best["p2"] < loose.best["p2"]
    assert strict.best["deviation_m"] >= loose.best["deviation_m"]
    # the Pareto front is non-dominated and contains both extremes
    front = strict.pareto
    assert loose.best in loose.pareto
    for a in front:
        for b in front:
            assert not (b["deviation_m"] < a["deviation_m"] and b["climb_max_deg"] < a["climb_max_deg"]
                        and b["min_turn_radius_m"] > a["min_turn_radius_m"])
    assert "| p1 | p2 |" in strict.table()
    with pytest.raises(InputError, match="p2 > p1"):
        tune(sc.world, sc.start, sc.goal, AirframeLimits.from_degrees(30, 10), lv,
             grid={"p1": [1.0], "p2": [0.5]})
    with pytest.raises(InputError, match="grid 'p1'"):
        tune(sc.world, sc.start, sc.goal, AirframeLimits.from_degrees(30, 10), lv,
             grid={"p1": [-1.0]})


def _cli(args):
    from fm2uav.cli import app

    return CliRunner().invoke(app, args)


@pytest.mark.slow
def test_reproduce_tff_cli(cli_once):
    # the same run as tests/cli_reports (one run per session, tests/conftest.py)
    run = cli_once(["reproduce", "tff", "--report", "--json"])
    r, out = run.result, run.out
    assert r.exit_code == 0, r.output
    table = (out / "tff_table.md").read_text()
    assert table.count("\n| ") >= 7
    data = json.loads((out / "tff_summary.json").read_text())
    cases = {c["case"]: c for c in data["cases"]}
    lvl10 = cases["level 10"]
    assert lvl10["within"] >= 0.8 and lvl10["inside_terrain"] == 0
    # the seeds' trends at level 10: bigger p2 - p1 -> sharper turns and climbs,
    # closer to the layer
    s10, s08 = cases["smooth p2=1.0"], cases["smooth p2=0.8"]
    assert lvl10["turn_max_deg"] > s10["turn_max_deg"] > s08["turn_max_deg"]
    assert lvl10["climb_max_deg"] > s10["climb_max_deg"] > s08["climb_max_deg"]
    assert lvl10["mean_dev_layer_m"] < s08["mean_dev_layer_m"]
    for name in ("tff_3d_levels.png", "tff_kinematics.png", "tff_profile_smoothness.png"):
        assert (out / name).stat().st_size > 10_000
    # no overwrite without --force, and nothing written before the check
    r = _cli(["reproduce", "tff", "--out", str(out), "--quiet"])
    assert r.exit_code == 2 and "already exists" in r.output


def test_cli_bad_input_leaves_no_output(tmp_path):
    out = tmp_path / "bad"
    r = _cli(["tune", "--agl", "900", "--out", str(out), "--quiet"])
    assert r.exit_code in (1, 2) and "leaves the map" in r.output
    assert not out.exists() or not any(out.iterdir())
    r = _cli(["tune", "--p1", "0", "--out", str(out), "--quiet"])
    assert r.exit_code == 2
    r = _cli(["reproduce", "tff", "--mode", "nope", "--out", str(out), "--quiet"])
    assert r.exit_code == 2
    assert not out.exists() or not any(out.iterdir())


def test_tune_cli(tmp_path):
    out = tmp_path / "tune"
    r = _cli(["tune", "--p1", "0.5", "--p2", "0.8,1.3", "--max-climb", "60",
              "--min-turn-radius", "50", "--out", str(out), "--json"])
    assert r.exit_code == 0, r.output
    data = json.loads(r.output[r.output.index("{"):])
    assert data["best"]["p2"] == 0.8
    assert (out / "tune_table.md").exists() and (out / "tune_best_path.csv").exists()
