"""Dubins-airplane and multirotor tracking, and the feasibility verdict."""

from __future__ import annotations

import math

import numpy as np
import pytest

from fm2uav import World
from fm2uav.errors import InputError
from fm2uav.vehicles import (
    FixedWing,
    TrackingOptions,
    check_feasibility,
    get_airframe,
    track_dubins,
    track_multirotor,
)

DISCO = get_airframe("disco")
R = DISCO.turn_radius()


def _circle(r: float, turns: float = 0.75, n: int = 600) -> np.ndarray:
    th = np.linspace(0.0, 2 * np.pi * turns, n)
    return np.column_stack([r * np.cos(th), r * np.sin(th), np.full(n, 50.0)])


def _line(length=400.0, n=81, heading=0.4, climb=0.1) -> np.ndarray:
    s = np.linspace(0, length, n)
    return np.column_stack([s * np.cos(heading) * np.cos(climb), s * np.sin(heading) * np.cos(climb),
                            10 + s * np.sin(climb)])


@pytest.mark.parametrize("airframe", ["disco", "crosswind", "plane-jet", "arducopter"])
def test_straight_path_has_zero_separation(airframe):
    p = _line()
    tr = (track_dubins if get_airframe(airframe).kind == "fixed-wing" else track_multirotor)(p, airframe)
    assert tr.reached
    assert tr.max_separation < 1e-6
    assert np.linalg.norm(tr.trajectory[-1] - p[-1]) < get_airframe(airframe).cruise_speed * tr.dt + 0.1
    assert not tr.saturated.get("turn", np.zeros(1, bool)).any()
    rep = check_feasibility(p, airframe)
    assert rep.feasible and "reached the goal" in rep.reason


def test_dubins_flies_at_constant_speed_with_exact_kinematics():
    tr = track_dubins(_circle(3 * R), DISCO, tracking=TrackingOptions(dt=0.02))
    step = np.linalg.norm(np.diff(tr.trajectory, axis=0), axis=1)
    # each step is a chord of an arc of length V dt
    assert np.all(step <= DISCO.cruise_speed * tr.dt + 1e-9)
    assert np.all(step >= DISCO.cruise_speed * tr.dt * (1 - 1e-4))


def test_circle_tighter_than_r_is_infeasible():
    rep = check_feasibility(_circle(0.5 * R), DISCO)
    assert not rep.feasible
    assert not rep.geometric.feasible
    tr = rep.tracking
    assert tr.max_separation > 0.3 * R
    assert tr.saturation_time()["turn"] > 1.0
    # while saturated the aircraft turns at exactly its maximum rate
    sat = tr.saturated["turn"]
    np.testing.assert_allclose(np.abs(tr.states["turn_rate"][sat]), DISCO.max_turn_rate())
    iv = [i for i in tr.saturation_intervals() if i["limit"] == "turn"]
    assert iv and sum(i["duration_s"] for i in iv) == pytest.approx(tr.saturation_time()["turn"])


def test_circle_wider_than_r_is_followed_closely():
    rep = check_feasibility(_circle(3 * R), DISCO)
    assert rep.feasible
    assert rep.tracking.max_separation < 0.1 * R
    assert rep.tracking.saturation_time()["turn"] == 0.0


def test_separation_grows_as_the_circle_tightens():
    seps = [track_dubins(_circle(f * R), DISCO).max_separation for f in (4.0, 2.0, 0.9, 0.5)]
    assert seps == sorted(seps)


def test_steep_climb_saturates_climb_limit():
    p = _line(length=300, climb=math.radians(50))
    rep = check_feasibility(p, DISCO)
    assert rep.tracking.saturation_time()["climb"] > 0
    assert not rep.geometric.feasible
    assert not rep.feasible


def test_lookahead_points_is_a_times_the_step():
    p = _line(length=400, n=81)  # 5 m steps
    tr = track_dubins(p, DISCO, tracking=TrackingOptions(lookahead_points=4))
    assert tr.lookahead == pytest.approx(20.0)
    with pytest.raises(InputError):
        track_dubins(p, DISCO, tracking=TrackingOptions(lookahead=10.0, lookahead_points=2))


def test_multirotor_follows_a_tight_circle():
    tr = track_multirotor(_circle(10.0), "arducopter")
    assert tr.reached
    assert tr.max_separation < 1.0
    assert tr.states["speed"].max() <= get_airframe("arducopter").max_speed + 1e-6


def test_collision_with_world_makes_it_infeasible():
    # an L-shaped path turning 90 deg 2.8 m from the corner of a block inside the
    # turn: the Dubins airplane cuts the corner by ~3 m and clips the block
    from fm2uav.geometry import resample_uniform

    occ = np.zeros((201, 201), bool)
    occ[0:99, 52:201] = True
    w = World(occ, spacing=1.0)
    path, _ = resample_uniform(np.array([[0.0, 50.0], [100.0, 50.0], [100.0, 150.0]]), 1.0)
    rep = check_feasibility(path, DISCO, world=w, tolerance=100.0)
    assert rep.collision["inside_obstacle"] > 0
    assert not rep.feasible and "enters an obstacle" in rep.reason
    # the same turn with the block moved 10 m away is flown safely
    occ2 = np.zeros((201, 201), bool)
    occ2[0:90, 60:201] = True
    ok = check_feasibility(path, DISCO, world=World(occ2, spacing=1.0), tolerance=100.0)
    assert ok.feasible and ok.collision["first"] is None
    with pytest.raises(InputError):
        check_feasibility(np.column_stack([path, np.zeros(len(path))]), DISCO, world=w)


@pytest.mark.parametrize(
    "path",
    [np.array([[0.0, 0.0, 0.0]]), np.array([[0.0, 0.0], [np.nan, 1.0]]), np.zeros((3, 4)),
     np.zeros((3, 3))],
)
def test_bad_paths_raise_input_error(path):
    with pytest.raises(InputError):
        check_feasibility(path, DISCO)


def test_bad_options_raise_input_error():
    p = _line()
    with pytest.raises(InputError):
        check_feasibility(p, "no-such-plane")
    with pytest.raises(InputError):
        check_feasibility(p, DISCO, speed=-3.0)
    with pytest.raises(InputError):
        check_feasibility(p, DISCO, tolerance=0.0)
    with pytest.raises(InputError):
        track_dubins(p, DISCO, tracking=TrackingOptions(dt=-0.1))
    with pytest.raises(InputError):
        track_dubins(p, "arducopter")
    with pytest.raises(InputError):
        FixedWing("x", -1.0, 1.0, 2.0, 0.5, 0.2, 0.2)
