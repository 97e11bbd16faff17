"""plan(): end-to-end on tiny maps and the open field, errors, determinism."""

import numpy as np
import pytest

import fm2uav
from fm2uav import (
    InputError,
    Plan,
    PlanningError,
    PlanOptions,
    PointError,
    Shaping,
    UnreachableError,
    World,
    plan,
)
from fm2uav.world import clearance_profile
from fm2uav.world.clearance import surface_clearance


@pytest.fixture(scope="module")
def wall_world():
    # 2D, 1 m cells: a wall along x = 20 m from y = 0 to y = 24 m, gap above
    occ = np.zeros((41, 31), bool)
    occ[19:22, 0:25] = True
    return World(occ, spacing=1.0)


def _nearest_nodes(world, path):
    return np.floor(world.to_index(path) + 0.5).astype(int)


def test_path_goes_around_wall_and_ends_exactly(wall_world):
    p = plan(wall_world, (5.0, 5.0), (35.0, 5.0))
    assert isinstance(p, Plan)
    np.testing.assert_array_equal(p.path[0], [5.0, 5.0])
    np.testing.assert_array_equal(p.path[-1], [35.0, 5.0])
    # must pass above the wall's end (y > 24 m) while crossing x = 20 m
    crossing = p.path[np.abs(p.path[:, 0] - 20.0) < 1.0]
    assert crossing[:, 1].min() > 24.0
    nodes = _nearest_nodes(wall_world, p.path)
    assert not wall_world.occupancy[tuple(nodes.T)].any()
    # length: at least the straight detour through the gap corner (24.5, 20) m
    detour = np.hypot(15, 20) * 2
    assert detour * 0.98 <= p.length <= detour * 1.6
    assert p.length == pytest.approx(np.sum(np.linalg.norm(np.diff(p.path, axis=0), axis=1)))


def test_clearance_and_speed_are_consistent(wall_world):
    p = plan(wall_world, (5.0, 5.0), (35.0, 5.0))
    # clearance is to the obstacles' cells (continuous), never more than to their nodes
    assert p.clearance == pytest.approx(surface_clearance(wall_world, p.path).min())
    assert 0 < p.clearance <= clearance_profile(wall_world, p.path).min()
    assert p.w.shape == (len(p.path),)
    assert np.all((p.w > 0) & (p.w <= 1))
    assert set(p.timings) == {"velocity_map", "fast_marching", "geodesic", "metrics", "total"}


def test_stop_at_start_leaves_later_nodes_unreached(wall_world):
    p = plan(wall_world, (30.0, 5.0), (35.0, 5.0))
    start_node = tuple(_nearest_nodes(wall_world, p.path[:1])[0])
    assert np.isfinite(p.T[start_node])
    finite = np.isfinite(p.T)
    assert not finite.all()  # the march stopped before covering the map
    # nodes freeze in increasing T, so every frozen node is not later than the start
    # (1e-9 relative slack for the order-2 scheme's rare non-monotone updates)
    assert np.all(p.T[finite] <= p.T[start_node] * (1 + 1e-9))


def test_exponent_trades_clearance_for_length():
    # thesis §2.3: a greater exponent darkens W -> paths further from obstacles
    # (longer); a smaller one clarifies it -> shorter paths closer to obstacles
    occ = np.zeros((60, 40), bool)
    occ[25:35, 0:22] = True
    occ[25:35, 30:40] = True
    w = World(occ, spacing=1.0)
    lo = plan(w, (5.0, 5.0), (55.0, 5.0), shaping=Shaping(exponent=0.25))
    hi = plan(w, (5.0, 5.0), (55.0, 5.0), shaping=Shaping(exponent=4.0))
    assert lo.length < hi.length
    gap_lo = lo.path[(lo.path[:, 0] > 26) & (lo.path[:, 0] < 34)]
    gap_hi = hi.path[(hi.path[:, 0] > 26) & (hi.path[:, 0] < 34)]
    # through the gap (y in 22..30) the darker map keeps closer to its centre y = 26
    assert np.abs(gap_hi[:, 1] - 26).max() <= np.abs(gap_lo[:, 1] - 26).max() + 1e-9


def test_saturation_shortens_path():
    occ = np.zeros((60, 40), bool)
    occ[25:35, 0:22] = True
    w = World(occ, spacing=1.0)
    full = plan(w, (5.0, 5.0), (55.0, 5.0))
    sat = plan(w, (5.0, 5.0), (55.0, 5.0), shaping=Shaping(saturation=0.2))
    assert sat.length < full.length


def test_deterministic(wall_world):
    a = plan(wall_world, (5.0, 5.0), (35.0, 5.0))
    b = plan(wall_world, (5.0, 5.0), (35.0, 5.0))
    np.testing.assert_array_equal(a.path, b.path)


@pytest.mark.parametrize("order", [1, 2])
def test_open_field_path_is_safe(order):
    sc = fm2uav.scenarios.open_field()
    p = plan(sc.world, sc.start, sc.goal, options=PlanOptions(order=order))
    np.testing.assert_allclose(p.path[0], sc.start)
    np.testing.assert_allclose(p.path[-1], sc.goal)
    nodes = _nearest_nodes(sc.world, p.path)
    assert not sc.world.occupancy[tuple(nodes.T)].any()
    # every point is above the terrain
    assert np.all(p.path[:, 2] > sc.world.ground_height(p.path[:, 0], p.path[:, 1]))
    assert p.clearance > 15.0  # at least one cell away from the ground
    straight = np.linalg.norm(sc.goal - sc.start)
    assert straight <= p.length <= 1.5 * straight


def test_custom_speed_map_is_used(wall_world):
    W = np.ones(wall_world.shape)
    W[wall_world.occupancy] = 0
    p = plan(wall_world, (5.0, 5.0), (35.0, 5.0), options=PlanOptions(speed_map=W))
    assert p.params["custom_speed_map"]
    with pytest.raises(InputError, match="speed_map has shape"):
        plan(wall_world, (5.0, 5.0), (35.0, 5.0), options=PlanOptions(speed_map=np.ones((3, 3))))


def test_start_outside_map(wall_world):
    with pytest.raises(PointError) as exc:
        plan(wall_world, (-5.0, 5.0), (35.0, 5.0))
    msg = str(exc.value)
    assert "start" in msg and "outside the map" in msg and "bounds" in msg


def test_goal_inside_obstacle(wall_world):
    with pytest.raises(PointError) as exc:
        plan(wall_world, (5.0, 5.0), (20.0, 5.0))
    assert "goal" in str(exc.value) and "inside an obstacle" in str(exc.value)


def test_start_below_terrain_mentions_ground():
    sc = fm2uav.scenarios.open_field()
    with pytest.raises(PointError, match="ground there is at z"):
        plan(sc.world, [300.0, 300.0, 15.0], sc.goal)


def test_unreachable_goal():
    occ = np.zeros((30, 30), bool)
    occ[10:20, 10] = occ[10:20, 19] = True
    occ[10, 10:20] = occ[19, 10:20] = True  # closed box
    with pytest.raises(UnreachableError) as exc:
        plan(World(occ, spacing=1.0), (2.0, 2.0), (15.0, 15.0))
    assert "cannot be reached" in str(exc.value)
    assert isinstance(exc.value, PlanningError)


@pytest.mark.parametrize(
    "start, phrase",
    [((1.0, 2.0, 3.0), "must have 2 coordinates"), ((np.nan, 2.0), "finite"), ("ab", "coordinates")],
)
def test_bad_points(wall_world, start, phrase):
    with pytest.raises(InputError, match=phrase):
        plan(wall_world, start, (35.0, 5.0))


def test_world_type_checked():
    with pytest.raises(InputError, match="fm2uav.World"):
        plan(np.zeros((3, 3), bool), (0, 0), (1, 1))


def test_objects_are_type_checked(wall_world):
    with pytest.raises(InputError, match="shaping must be a fm2uav.Shaping"):
        plan(wall_world, (5.0, 5.0), (35.0, 5.0), shaping={"exponent": 2.0})
    with pytest.raises(InputError, match="level must be a fm2uav.FlightLevel"):
        plan(wall_world, (5.0, 5.0), (35.0, 5.0), level=150.0)
    with pytest.raises(InputError, match="options must be a fm2uav.PlanOptions"):
        plan(wall_world, (5.0, 5.0), (35.0, 5.0), options=None)


def test_plan_records_its_objects_and_w(wall_world):
    s = Shaping(exponent=2.0)
    p = plan(wall_world, (5.0, 5.0), (35.0, 5.0), shaping=s)
    assert p.shaping is s and p.level is None
    assert p.params["exponent"] == 2.0 and "agl" not in p.params
    assert p.summary()["min_w"] == round(float(p.w.min()), 6)


def test_saturation_distance_is_the_share_of_the_largest_distance(wall_world):
    """W = min(d / d_sat, 1): d_sat = alpha * max(d) gives the same map as alpha."""
    from fm2uav.planning import max_distance, shaped_velocity

    top = max_distance(wall_world)
    a = shaped_velocity(wall_world, Shaping(saturation=0.5, exponent=2.0))
    b = shaped_velocity(wall_world, Shaping(saturation_distance=0.5 * top, exponent=2.0))
    np.testing.assert_allclose(a, b, rtol=1e-12, atol=1e-15)
    p = plan(wall_world, (5.0, 5.0), (35.0, 5.0), shaping=Shaping(saturation_distance=3.0))
    q = plan(wall_world, (5.0, 5.0), (35.0, 5.0), shaping=Shaping(saturation=3.0 / top))
    np.testing.assert_allclose(p.path, q.path, atol=1e-9)
    assert p.params["saturation_distance"] == 3.0
