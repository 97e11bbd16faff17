"""Planner sessions: re-plan from a new position and after world changes, same as plan()."""

from __future__ import annotations

import numpy as np
import pytest

from fm2uav import FlightLevel, Shaping, World, plan
from fm2uav.errors import InputError, PlanningError, PointError, UnreachableError
from fm2uav.planning.session import Planner


@pytest.fixture
def room():
    occ = np.zeros((80, 50), bool)
    occ[40, 0:30] = True
    return World(occ, spacing=1.0)


def _same_plan(a, b, tol=0.05):
    assert a.length == pytest.approx(b.length, rel=1e-3)
    assert np.abs(a.path[-1] - b.path[-1]).max() < 1e-9
    # same route: every point of one within a small distance of the other
    d = np.linalg.norm(a.path[:, None, :] - b.path[None, :, :], axis=2)
    assert d.min(axis=1).max() < tol + 0.5


def test_session_matches_plan_and_replans_from_new_positions(room):
    s = Planner(room, goal=(75.0, 5.0), shaping=Shaping(exponent=0.5))
    for start in [(5.0, 5.0), (20.0, 40.0), (60.0, 45.0)]:
        _same_plan(s.plan(start), plan(room, start, (75.0, 5.0), shaping=Shaping(exponent=0.5)))


def test_session_obstacles_added_and_removed(room):
    sh = Shaping(saturation_distance=6.0)
    s = Planner(room, goal=(75.0, 5.0), shaping=sh)
    wall = np.zeros(room.shape, bool)
    wall[60, 10:50] = True
    s.add_obstacles(wall)
    assert s.last_update["reused"] > 0.0 and not s.last_update["full"]
    ref_world = World(room.occupancy | wall, spacing=1.0)
    _same_plan(s.plan((5.0, 5.0)), plan(ref_world, (5.0, 5.0), (75.0, 5.0), shaping=sh))
    # the arrival times equal a fresh full march
    fresh = Planner(ref_world, goal=(75.0, 5.0), shaping=sh)
    fresh.plan((5.0, 5.0))
    fin = np.isfinite(fresh._T) & np.isfinite(s._T)
    assert fin.sum() > 0.5 * fin.size
    np.testing.assert_allclose(s._T[fin], fresh._T[fin], rtol=1e-12)
    s.remove_obstacles(wall)
    _same_plan(s.plan((5.0, 5.0)), plan(room, (5.0, 5.0), (75.0, 5.0), shaping=sh))
    # closing the last gap makes the goal unreachable
    gap = np.zeros(room.shape, bool)
    gap[40, 30:50] = True
    s.add_obstacles(gap)
    with pytest.raises(UnreachableError):
        s.plan((5.0, 5.0))
    with pytest.raises(PointError, match="blocks the goal"):
        g = np.zeros(room.shape, bool)
        g[75, 5] = True
        s.add_obstacles(g)


def test_session_zones(room):
    from fm2uav.world.zones import Zone
    from shapely.geometry import box

    s = Planner(room, goal=(75.0, 45.0))
    p0 = s.plan((5.0, 45.0))
    z = Zone(geometry=box(30, 35, 50, 50), name="stadium")
    s.add_zones([z])
    p1 = s.plan((5.0, 45.0))
    assert not any(box(30, 35, 50, 50).contains(__import__("shapely").Point(x, y)) for x, y in p1.path)
    assert p1.length > p0.length
    with pytest.raises(PlanningError, match="stadium"):
        s.plan((40.0, 45.0))
    s.remove_zones("stadium")
    assert s.plan((5.0, 45.0)).length == pytest.approx(p0.length, rel=1e-9)
    with pytest.raises(InputError, match="no zone named"):
        s.remove_zones("nothere")


def test_session_terrain_following():
    from fm2uav.scenarios import open_field

    sc = open_field()
    lvl = FlightLevel(agl=150.0, p1=0.5, p2=1.3)
    s = Planner(sc.world, sc.goal, level=lvl)
    p = s.plan(sc.start)
    q = plan(sc.world, sc.start, sc.goal, level=lvl)
    assert p.length == pytest.approx(q.length, rel=1e-3)


def test_session_bad_input(room):
    with pytest.raises(InputError, match="fm2uav.World"):
        Planner("map", goal=(1, 1))
    s = Planner(room, goal=(75.0, 5.0))
    with pytest.raises(InputError, match="bool mask"):
        s.add_obstacles(np.zeros((3, 3), bool))
    with pytest.raises(InputError, match="Zone objects"):
        s.add_zones(["zone"])
    with pytest.raises(PointError):
        s.plan((40.0, 10.0))  # inside the wall


@pytest.mark.parametrize("terrain", [False, True])
def test_local_velocity_update_is_exact(terrain):
    """With a saturation distance, W is rebuilt only around the change: equal to a full rebuild."""
    from fm2uav.scenarios import open_field

    sc = open_field()
    world = sc.world
    level = FlightLevel(agl=150.0) if terrain else None
    sh = Shaping(saturation_distance=100.0, exponent=0.7)
    s = Planner(world, sc.goal, shaping=sh, level=level)
    tower = np.zeros(world.shape, bool)
    tower[40:45, 40:45, :20] = True  # 300 m high, under the ceiling
    tower &= ~world.occupancy  # removing it later must not dig into the terrain
    s.add_obstacles(tower)
    from fm2uav.planning.planner import plan_velocity
    from fm2uav import PlanOptions

    full = plan_velocity(s.world, sh, level, PlanOptions())
    np.testing.assert_allclose(s._W, full, rtol=1e-12, atol=1e-15)  # round-off of d/max(d)*max(d)
    s.remove_obstacles(tower)
    np.testing.assert_allclose(s._W, plan_velocity(world, sh, level, PlanOptions()), rtol=1e-12,
                               atol=1e-15)
