"""End-to-end formation flights: safety, terrain, re-forming, thesis scenario, bad input."""

import numpy as np
import pytest

from fm2uav import FlightLevel, FormationConfig, InputError, PointError, UnreachableError, World
from fm2uav.analysis.flight_level import flight_level_deviation
from fm2uav.missions.formation import (
    fly_formation,
    formation_error,
    inside_terrain,
    min_separation,
)


def _assert_safe(r):
    assert r.completed
    assert r.min_separation >= r.dist / 2
    assert r.min_distance.min() >= r.dist / 2
    # recompute with the independent checker from the raw trajectories
    d, _, _ = min_separation(r.positions)
    assert d == pytest.approx(r.min_separation)
    assert not inside_terrain(r.world, r.positions).any()
    assert np.all(np.diff(r.times) > 0)


def test_fissure_with_flight_level_is_safe_deforms_and_reforms(fissure_level):
    r = fissure_level
    _assert_safe(r)
    assert r.settled
    # the formation narrows inside the fissure ...
    x_cells = r.world.to_index(r.positions[:, 0])[:, 0]
    inside = (x_cells > 50) & (x_cells < 95)
    assert r.grey.min() < 0.6
    assert r.shape_error_norm[inside].max() > 0.3
    # ... and re-forms after it: below 10 % of the nominal spacing once past x = 105 cells
    after = np.flatnonzero(x_cells > 105)
    assert r.shape_error_norm[after].min() < 0.1
    assert r.shape_error_norm[-1] < 0.05
    # every UAV keeps its level (thesis Fig. 6.8); the leader's transitions excluded
    for i in range(r.n_uav):
        rep = flight_level_deviation(r.world, r.positions[:, i], 105.0)
        assert rep.within > 0.9, (r.names[i], rep.within)


def test_fissure_without_flight_level(fissure_free):
    r = fissure_free
    _assert_safe(r)
    assert r.settled
    # the followers stay at the leader's height
    np.testing.assert_allclose(r.partial_goals[:, 1:, 2], r.partial_goals[:, :1, 2].repeat(2, 1))
    assert r.shape_error_norm[-1] < 0.05


def test_shape_error_is_what_the_metric_says(fissure_free):
    r = fissure_free
    np.testing.assert_allclose(
        formation_error(r.leader_plan.path, r.positions, r.shape, r.dist), r.shape_error)


def test_cycles_cost_milliseconds_and_use_windows(fissure_free):
    """Not a timing assertion: the local windows keep every FMM small, which we check
    through the number of cycles and that every re-plan reached its goal or was projected."""
    r = fissure_free
    assert len(r.cycle_start) == r.summary()["cycles"]
    assert r.held.sum() == 0


def test_corridor_narrows_the_formation_then_it_reforms(corridor):
    r = fly_formation(corridor, (50.0, 200.0, 60.0), (550.0, 200.0, 60.0),
                      config=FormationConfig(dist=20.0, leader_speed=8.0, clearance=20.0))
    _assert_safe(r)
    x = r.positions[:, 0, 0]
    in_corridor = (x > 260) & (x < 380)
    # walls 50 m from the axis: B = 50 / (4·dist) = 0.625 (test_local), lateral 25 m
    assert r.grey.min() == pytest.approx(0.625, abs=0.03)
    lateral = np.abs(r.positions[in_corridor, 1:, 1] - 200.0)
    assert lateral.max() < 30.0  # nominal: 2·dist = 40 m
    assert r.shape_error_norm[-1] < 0.05


@pytest.mark.parametrize("shape,n", [("v", 4), ("line", 3), ("triangle", 3)])
def test_other_shapes_on_the_fissure(fissure, shape, n):
    r = fly_formation(fissure.world, fissure.start, fissure.goal,
                      config=FormationConfig(shape=shape, n_followers=n, dist=45.0),
                      level=FlightLevel(agl=105.0, p2=1.5))
    _assert_safe(r)
    assert r.positions.shape[1] == n + 1


def test_literal_grey_mode_is_safe_too(fissure):
    r = fly_formation(fissure.world, fissure.start, fissure.goal,
                      config=FormationConfig(grey="follower"), level=FlightLevel(agl=105.0, p2=1.5))
    _assert_safe(r)


def test_same_input_same_output(corridor):
    kw = dict(config=FormationConfig(dist=20.0, leader_speed=8.0, clearance=20.0))
    a = fly_formation(corridor, (50.0, 200.0, 60.0), (550.0, 200.0, 60.0), **kw)
    b = fly_formation(corridor, (50.0, 200.0, 60.0), (550.0, 200.0, 60.0), **kw)
    np.testing.assert_array_equal(a.positions, b.positions)


# ------------------------------------------------------------------ bad input
def test_follower_start_inside_terrain(fissure):
    starts = [[450.0, 480.0, 375.0], [450.0, 720.0, 30.0]]  # the second is underground
    with pytest.raises(PointError, match="follower 2 start .* inside the terrain"):
        fly_formation(fissure.world, fissure.start, fissure.goal, follower_starts=starts)


def test_follower_start_in_the_clearance_band(fissure):
    w = fissure.world
    ground = float(w.terrain[30, 48])
    starts = [[450.0, 480.0, 375.0], [450.0, 720.0, ground + 10.0]]
    with pytest.raises(PointError, match="clearance"):
        fly_formation(w, fissure.start, fissure.goal, follower_starts=starts)


def test_overlapping_starts(fissure):
    s = np.asarray(fissure.start)
    starts = [s + [-10.0, 0.0, 0.0], s + [-120.0, 0.0, 0.0]]
    with pytest.raises(InputError, match="overlap"):
        fly_formation(fissure.world, fissure.start, fissure.goal, follower_starts=starts)


def test_unreachable_goal():
    # a ring of walls just below the ceiling closes the goal in (clearance band on top)
    h = np.zeros((30, 30))
    h[18:27, 18:27] = 95.0
    h[20:25, 20:25] = 0.0
    w = World.from_heightmap(h, 10.0, 11)
    with pytest.raises(UnreachableError):
        fly_formation(w, (50.0, 50.0, 50.0), (220.0, 220.0, 50.0),
                      config=FormationConfig(dist=20.0, clearance=20.0))


def test_goal_inside_terrain(fissure):
    g = np.asarray(fissure.goal).copy()
    g[2] = 30.0
    with pytest.raises(PointError, match="goal"):
        fly_formation(fissure.world, fissure.start, g)


@pytest.mark.parametrize("make,match", [
    (lambda: dict(config=FormationConfig(dist=0.0)), "dist"),
    (lambda: dict(config=FormationConfig(cycle=-1.0)), "cycle"),
    (lambda: dict(config=FormationConfig(shape="circle")), "shape"),
    (lambda: dict(config=FormationConfig(window=0)), "window"),
    (lambda: dict(config=FormationConfig(n_followers=0)), "n_followers"),
    (lambda: dict(follower_starts=[[1.0, 2.0, 3.0]]), "follower_starts"),
    (lambda: dict(config=FormationConfig(grey="average")), "grey"),
    (lambda: dict(level=FlightLevel(agl=10.0)), "clearance"),
    (lambda: dict(level=105.0), "FlightLevel"),
    (lambda: dict(follower_levels=[FlightLevel(agl=105.0)]), "follower_levels"),
    (lambda: dict(config={"dist": 20.0}), "FormationConfig"),
])
def test_bad_parameters(fissure, make, match):
    with pytest.raises(InputError, match=match):
        fly_formation(fissure.world, fissure.start, fissure.goal, **make())


def test_follower_levels_one_per_follower():
    """A follower without a level flies at the leader's height, one with a level at its own."""
    flat = World.from_heightmap(np.zeros((40, 30)), 10.0, 12)
    cfg = FormationConfig(dist=20.0, leader_speed=8.0, clearance=20.0)
    r = fly_formation(flat, (50.0, 150.0, 70.0), (350.0, 150.0, 70.0), config=cfg,
                      follower_levels=[None, FlightLevel(agl=40.0, p2=1.5)])
    _assert_safe(r)
    assert r.agl == (None, None, 40.0)
    np.testing.assert_allclose(r.partial_goals[:, 1, 2], r.partial_goals[:, 0, 2])
    np.testing.assert_allclose(r.partial_goals[:, 2, 2], 40.0)
    assert r.config.follower_speed == 12.0 and r.config.max_cycles is not None


def test_2d_world_is_refused():
    w = World(np.zeros((10, 10), bool), spacing=1.0)
    with pytest.raises(InputError, match="3D"):
        fly_formation(w, (1.0, 1.0), (8.0, 8.0))
