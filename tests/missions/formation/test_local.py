"""Local re-planning: other UAVs as obstacles, goal projection, grey levels."""

import numpy as np
import pytest

from fm2uav import Shaping, World
from fm2uav.missions.formation import StaticMaps, formation_shape, grey_levels, local_path


def _maps(world, clearance=20.0):
    return StaticMaps(world, Shaping(), clearance=clearance)


@pytest.fixture(scope="module")
def flat():
    return World.from_heightmap(np.zeros((40, 30)), 10.0, 12)


def test_path_goes_around_another_uav(flat):
    maps = _maps(flat)
    start, goal = np.array([50.0, 150.0, 60.0]), np.array([250.0, 150.0, 60.0])
    other, r = np.array([[150.0, 150.0, 60.0]]), np.array([45.0])
    lp = local_path(maps, maps.speed(None), start, goal, other, r, margin=6)
    assert not lp.projected and not lp.blocked
    np.testing.assert_allclose(lp.path[0], start)
    np.testing.assert_allclose(lp.path[-1], goal)
    d = np.linalg.norm(lp.path - other[0], axis=1)
    # no point in the cell of a node inside the ball: >= r - half the cell diagonal
    assert d.min() >= r[0] - maps.half_diagonal
    assert lp.path[:, 2].min() >= 20.0  # never into the clearance band over the ground


def test_goal_inside_a_ball_is_projected(flat):
    maps = _maps(flat)
    start, goal = np.array([50.0, 150.0, 60.0]), np.array([150.0, 150.0, 60.0])
    other, r = np.array([[150.0, 150.0, 60.0]]), np.array([35.0])
    lp = local_path(maps, maps.speed(None), start, goal, other, r, margin=4)
    assert lp.projected
    assert np.linalg.norm(lp.goal - other[0]) >= r[0]
    # the projected goal is the nearest reachable node: on the near side of the ball
    assert np.linalg.norm(lp.goal - goal) < r[0] + 10.0


def test_goal_in_the_ground_is_lifted_out_of_the_clearance_band(flat):
    maps = _maps(flat)
    lp = local_path(maps, maps.speed(None), np.array([50.0, 50.0, 60.0]),
                    np.array([100.0, 50.0, 0.0]), np.zeros((0, 3)), np.zeros(0), margin=3)
    assert lp.projected
    np.testing.assert_allclose(lp.goal, [100.0, 50.0, 20.0])


def test_grey_level_in_a_corridor_matches_the_analytic_value(corridor):
    """Walls at |y - 200| >= 50 m: the slot at lateral 2·dist·B has clearance 50 - 2·dist·B
    (for 2·dist·B <= 50 — trilinear is exact on this linear field) and B = min(1, c / (2·dist))
    is consistent for B <= 50 / (4·dist)."""
    maps = _maps(corridor)
    shape = formation_shape()
    for dist in (10.0, 15.0, 20.0):
        B = grey_levels(maps, shape, np.array([300.0, 200.0, 60.0]), np.array([1.0, 0.0]),
                        dist, 2 * dist)
        expected = min(1.0, 50.0 / (4 * dist))
        assert np.all(B <= expected + 1e-9)
        assert np.all(B >= expected - 1.0 / 40 - 1e-9)


def test_grey_level_is_one_in_the_open(corridor):
    maps = _maps(corridor)
    B = grey_levels(maps, formation_shape(), np.array([550.0, 200.0, 60.0]),
                    np.array([1.0, 0.0]), 20.0, 40.0)
    np.testing.assert_array_equal(B, [1.0, 1.0])
