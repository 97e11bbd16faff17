"""Tests of the built-in scenarios (open field, fissure)."""

from __future__ import annotations

import numpy as np
import pytest

from fm2uav.errors import WorldError
from fm2uav.scenarios import SCENARIOS, Scenario, fissure, get_scenario, open_field
from fm2uav.world import World
from fm2uav.scenarios.field import _open_field_world_uncached
from fm2uav.world.terrain import FISSURE_Y, open_field_heights

CELL = 15.0
SEEDS = range(8)


def _cells(p_m) -> tuple[int, ...]:
    return tuple(int(v) for v in np.rint(np.asarray(p_m) / CELL))


def _free_below(world: World, point_m) -> int:
    i, j, k = world.to_cell(point_m)
    return k - int(world.surface_index()[i, j]) - 1


def test_open_field_geometry():
    sc = open_field()
    w = sc.world
    assert isinstance(sc, Scenario) and isinstance(w, World)
    assert w.shape == (120, 90, 40)
    assert w.spacing == (CELL, CELL, CELL)
    assert w.origin == (0.0, 0.0, 0.0)
    assert w.name == "open-field"
    assert w.terrain is not None and w.terrain.shape == (120, 90)
    np.testing.assert_array_equal(sc.start, [300.0, 300.0, 300.0])
    np.testing.assert_array_equal(sc.goal, [1500.0, 1200.0, 450.0])
    assert "open field" in sc.description.lower()
    assert not sc.start.flags.writeable and not sc.goal.flags.writeable


def test_fissure_start_goal():
    sc = fissure()
    np.testing.assert_array_equal(sc.start, [450.0, 600.0, 375.0])  # cell (30, 40, 25)
    np.testing.assert_array_equal(sc.goal, [1680.0, 600.0, 450.0])  # cell (112, 40, 30)
    assert _cells(sc.start) == (30, 40, 25) and _cells(sc.goal) == (112, 40, 30)
    assert "fissure" in sc.description.lower()


def test_fissure_shares_the_open_field_terrain():
    for seed in (0, 5):
        np.testing.assert_array_equal(fissure(seed).world.occupancy, open_field(seed).world.occupancy)


def test_occupancy_matches_terrain():
    w = open_field().world
    expected_top = np.floor(w.terrain / CELL).astype(int)  # obstacle iff k * dz <= h
    np.testing.assert_array_equal(w.surface_index(), expected_top)
    # columns are solid from the ground up, with no overhangs
    k = np.arange(w.shape[2])
    np.testing.assert_array_equal(w.occupancy, k[None, None, :] <= expected_top[:, :, None])


def test_determinism_same_seed_same_world():
    for seed in (0, 3):
        a = _open_field_world_uncached(seed)
        b = _open_field_world_uncached(seed)
        np.testing.assert_array_equal(a.terrain, b.terrain)
        np.testing.assert_array_equal(a.occupancy, b.occupancy)
        np.testing.assert_array_equal(open_field(seed).world.terrain, a.terrain)
    np.testing.assert_array_equal(open_field_heights(7), open_field_heights(7))
    np.testing.assert_array_equal(
        open_field_heights(np.random.default_rng(7)), open_field_heights(7)
    )


def test_different_seeds_differ():
    assert not np.array_equal(open_field_heights(0), open_field_heights(1))
    assert not np.array_equal(open_field(0).world.occupancy, open_field(1).world.occupancy)


@pytest.mark.parametrize("factory", [open_field, fissure])
@pytest.mark.parametrize("seed", SEEDS)
def test_start_goal_free_with_clearance(factory, seed):
    sc = factory(seed)
    w = sc.world
    for p in (sc.start, sc.goal):
        assert w.contains(p)
        assert not w.occupancy[w.to_cell(p)]
        assert _free_below(w, p) >= 3


def test_start_goal_ground_heights_match_the_papers_profiles():
    # Paper 000 §5.1: at flight level 2 the path descends after the start and climbs
    # before the goal; at flight level 10 it barely changes altitude there.
    sc = open_field(0)
    s = sc.world.surface_index()
    assert 5 <= s[20, 20] <= 10  # start at z = 20: ~FL10 above the ground
    assert 13 <= s[100, 80] <= 19  # goal at z = 30: ~FL10-15 above the ground


@pytest.mark.parametrize("seed", SEEDS)
def test_room_for_flight_levels_up_to_10_cells(seed):
    w = open_field(seed).world
    top = w.surface_index()
    assert top.min() >= 0  # the ground is everywhere
    assert top.max() <= 28  # highest peak well below the 40-node ceiling
    assert top.max() + 10 <= w.shape[2] - 2  # FL10 fits over every column


@pytest.mark.parametrize("seed", SEEDS)
def test_fissure_between_two_lateral_mountains(seed):
    h = open_field(seed).world.terrain / CELL  # [cells]
    y0 = int(FISSURE_Y)
    assert y0 == 40
    xs = slice(40, 101)
    floor = h[xs, y0]
    south = h[xs, 10:33].max(axis=1)
    north = h[xs, 48:72].max(axis=1)
    # along the whole fissure both sides are higher than its floor...
    assert np.all(south - floor >= 2.0)
    assert np.all(north - floor >= 2.0)
    # ...and clearly so on average (the mountains rise ~10 cells above it)
    assert np.mean(south - floor) >= 5.0
    assert np.mean(north - floor) >= 5.0
    # the two mountains, seen from the front (max over x), stand either side of y = 40
    front = h[xs].max(axis=0)
    assert front[y0] < front[15:30].max() - 5.0
    assert front[y0] < front[50:65].max() - 5.0


@pytest.mark.parametrize("seed", SEEDS)
def test_fissure_corridor_is_free_at_formation_altitude(seed):
    w = fissure(seed).world
    # the thesis' formation flies at ~25-30 cells through the fissure
    assert not w.occupancy[30:113, 40, 25:].any()


def test_central_mountain_is_the_highest_and_central():
    for seed in SEEDS:
        h = open_field_heights(seed)
        i, j = np.unravel_index(np.argmax(h), h.shape)
        assert 40 <= i <= 95 and 15 <= j <= 70
    h = open_field_heights(0)
    i, j = np.unravel_index(np.argmax(h), h.shape)
    assert 55 <= i <= 75 and 50 <= j <= 70  # the central mountain (66, 60)
    # the lateral areas (corners) are lower and gentler than the middle
    assert h[:25, 70:].max() < h[50:80, 50:70].max() - 8
    assert h[100:, :15].max() < h[50:80, 50:70].max() - 8


def test_get_scenario_and_registry():
    # other issues register more scenarios; these two are the foundation's
    assert {"open-field", "fissure"} <= set(SCENARIOS)
    sc = get_scenario("open-field")
    np.testing.assert_array_equal(sc.goal, open_field().goal)
    np.testing.assert_array_equal(get_scenario("Open_Field", seed=2).world.terrain,
                                  open_field(2).world.terrain)
    np.testing.assert_array_equal(get_scenario("fissure").start, fissure().start)


def test_get_scenario_unknown_lists_valid_names():
    with pytest.raises(WorldError) as exc:
        get_scenario("atlantis")
    msg = str(exc.value)
    assert "'atlantis'" in msg and "open-field" in msg and "fissure" in msg


def test_scenario_validates_points():
    w = open_field().world
    with pytest.raises(WorldError, match="3 coordinates"):
        Scenario(world=w, start=np.zeros(2), goal=np.zeros(3), description="bad")


def test_open_field_heights_other_shape_keeps_the_layout():
    h = open_field_heights(0, shape=(60, 45))
    assert h.shape == (60, 45) and np.all(np.isfinite(h)) and h.min() >= 1.0
    i, j = np.unravel_index(np.argmax(h), h.shape)
    assert 25 <= i <= 40 and 22 <= j <= 35  # central mountain near (33, 30)
