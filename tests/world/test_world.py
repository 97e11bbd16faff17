"""Tests of fm2uav.world.World: geometry, conversions, builders, validation."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from fm2uav.errors import InputError, PlanningError, WorldError
from fm2uav.world import World

T, F = True, False


def _world3(shape=(5, 4, 3), spacing=(2.0, 3.0, 5.0), origin=(10.0, -20.0, 1.0)) -> World:
    return World(np.zeros(shape, dtype=bool), spacing=spacing, origin=origin)


# ----------------------------------------------------------------------------- geometry
def test_basic_properties_3d():
    occ = np.zeros((5, 4, 3), dtype=bool)
    occ[1, 2, 0] = True
    w = World(occ, spacing=(2.0, 3.0, 5.0), origin=(10.0, -20.0, 1.0), name="box")
    assert w.ndim == 3
    assert w.shape == (5, 4, 3)
    assert w.spacing == (2.0, 3.0, 5.0)
    assert w.origin == (10.0, -20.0, 1.0)
    np.testing.assert_array_equal(w.bounds, [[10.0, 18.0], [-20.0, -11.0], [1.0, 11.0]])
    np.testing.assert_array_equal(w.free, ~occ)
    assert w.terrain is None and w.crs is None and w.name == "box"
    assert "box" in repr(w) and "(5, 4, 3)" in repr(w)


def test_2d_world_defaults_and_scalar_spacing():
    w = World(np.zeros((3, 2), dtype=bool), spacing=0.5)
    assert w.ndim == 2 and w.shape == (3, 2)
    assert w.spacing == (0.5, 0.5)
    assert w.origin == (0.0, 0.0)
    np.testing.assert_array_equal(w.bounds, [[0.0, 1.0], [0.0, 0.5]])


def test_to_index_and_to_world_exact():
    w = _world3()
    np.testing.assert_array_equal(w.to_index([12.0, -14.0, 11.0]), [1.0, 2.0, 2.0])
    np.testing.assert_array_equal(w.to_index([[10.0, -20.0, 1.0], [11.0, -18.5, 3.5]]),
                                  [[0.0, 0.0, 0.0], [0.5, 0.5, 0.5]])
    np.testing.assert_array_equal(w.to_world([1, 2, 2]), [12.0, -14.0, 11.0])
    np.testing.assert_array_equal(w.to_world(np.zeros((2, 7, 3))).shape, (2, 7, 3))


@settings(max_examples=60, deadline=None, derandomize=True)
@given(
    shape=st.tuples(*[st.integers(1, 12)] * 3),
    spacing=st.tuples(*[st.floats(0.01, 100.0)] * 3),
    origin=st.tuples(*[st.floats(-1e5, 1e5)] * 3),
    frac=st.lists(st.tuples(*[st.floats(-0.5, 1.5)] * 3), min_size=1, max_size=8),
)
def test_round_trip_to_index_to_world(shape, spacing, origin, frac):
    w = World(np.zeros(shape, dtype=bool), spacing=spacing, origin=origin)
    lo, hi = w.bounds[:, 0], w.bounds[:, 1]
    pts = lo + np.asarray(frac) * (hi - lo + np.asarray(spacing))
    back = w.to_world(w.to_index(pts))
    np.testing.assert_allclose(back, pts, rtol=0, atol=1e-9 * (1.0 + np.abs(pts).max()))
    idx = np.asarray(frac) * np.asarray(shape)
    np.testing.assert_allclose(w.to_index(w.to_world(idx)), idx, rtol=0,
                               atol=1e-7 * (1.0 + np.abs(np.asarray(origin)).max()))


@settings(max_examples=40, deadline=None, derandomize=True)
@given(
    shape=st.tuples(*[st.integers(1, 10)] * 2),
    spacing=st.tuples(*[st.floats(0.1, 50.0)] * 2),
    origin=st.tuples(*[st.floats(-1e3, 1e3)] * 2),
    data=st.data(),
)
def test_to_cell_of_node_is_node(shape, spacing, origin, data):
    w = World(np.zeros(shape, dtype=bool), spacing=spacing, origin=origin)
    i = data.draw(st.integers(0, shape[0] - 1))
    j = data.draw(st.integers(0, shape[1] - 1))
    jitter = data.draw(st.tuples(st.floats(-0.49, 0.49), st.floats(-0.49, 0.49)))
    p = w.to_world([i + jitter[0], j + jitter[1]])
    p = np.clip(p, w.bounds[:, 0], w.bounds[:, 1])
    assert w.to_cell(p) == (i, j)


def test_to_cell_single_and_batch():
    w = _world3()
    assert w.to_cell([12.9, -14.2, 11.0]) == (1, 2, 2)
    cell = w.to_cell(np.array([10.0, -20.0, 1.0]))
    assert cell == (0, 0, 0) and all(type(c) is int for c in cell)
    assert w.to_cell([[10.0, -20.0, 1.0], [18.0, -11.0, 11.0]]) == [(0, 0, 0), (4, 3, 2)]
    occ = w.occupancy
    assert occ[w.to_cell([18.0, -11.0, 11.0])] == np.False_


def test_to_cell_outside_raises_planning_error_with_details():
    w = _world3()
    with pytest.raises(PlanningError) as exc:
        w.to_cell([100.0, -15.0, 2.0], what="start")
    msg = str(exc.value)
    assert "start" in msg
    assert "(100, -15, 2)" in msg
    assert "outside the map" in msg
    assert "x in [10, 18]" in msg and "z in [1, 11]" in msg
    assert "move the start inside" in msg
    with pytest.raises(PlanningError, match="goal"):
        w.to_cell([[12.0, -14.0, 2.0], [12.0, -14.0, 11.5]], what="goal")
    assert isinstance(exc.value, ValueError)


def test_to_cell_bad_points():
    w = _world3()
    with pytest.raises(InputError, match="3 coordinates"):
        w.to_cell([1.0, 2.0], what="start")
    with pytest.raises(InputError, match="non-finite"):
        w.to_cell([np.nan, -15.0, 2.0])
    with pytest.raises(InputError, match="3 coordinates"):
        w.to_index([1.0, 2.0, 3.0, 4.0])


def test_contains():
    w = _world3()
    assert w.contains([10.0, -20.0, 1.0]) is True
    assert w.contains([18.0, -11.0, 11.0]) is True  # upper bounds are inclusive
    assert w.contains([18.001, -11.0, 11.0]) is False
    assert w.contains([9.999, -15.0, 5.0]) is False
    np.testing.assert_array_equal(
        w.contains([[12.0, -15.0, 5.0], [12.0, -25.0, 5.0], [np.nan, -15.0, 5.0]]),
        [True, False, False],
    )


# ----------------------------------------------------------------------------- storage
def test_occupancy_is_a_read_only_copy():
    occ = np.zeros((3, 3, 2), dtype=bool)
    w = World(occ, spacing=1.0)
    occ[0, 0, 0] = True
    assert not w.occupancy[0, 0, 0]
    assert not w.occupancy.flags.writeable
    with pytest.raises(ValueError):
        w.occupancy[1, 1, 1] = True
    with pytest.raises(dataclasses.FrozenInstanceError):
        w.name = "other"  # type: ignore[misc]


def test_cache_is_per_instance_and_not_copied_by_replace():
    w = _world3()
    w._cache["dist"] = np.ones(3)
    w2 = dataclasses.replace(w, name="copy")
    assert w2._cache == {}
    assert _world3()._cache == {}
    assert w == w and w != _world3()  # eq=False: identity comparison


# ----------------------------------------------------------------------------- validation
@pytest.mark.parametrize(
    ("occ", "phrase"),
    [
        (np.zeros((3, 3), dtype=np.uint8), "bool"),
        (np.zeros(4, dtype=bool), r"2D \(nx, ny\) or 3D"),
        (np.zeros((2, 2, 2, 2), dtype=bool), "got 4D"),
        (np.zeros((0, 3), dtype=bool), "empty"),
    ],
)
def test_occupancy_validation(occ, phrase):
    with pytest.raises(WorldError, match=phrase):
        World(occ, spacing=1.0)


@pytest.mark.parametrize(
    ("kwargs", "phrase"),
    [
        ({"spacing": (1.0, 1.0)}, "one value per axis"),
        ({"spacing": (1.0, 0.0, 1.0)}, "> 0"),
        ({"spacing": -2.0}, "> 0"),
        ({"spacing": (1.0, np.nan, 1.0)}, "finite"),
        ({"spacing": "abc"}, "number"),
        ({"spacing": 1.0, "origin": (0.0, 0.0)}, "one value per axis"),
        ({"spacing": 1.0, "origin": (0.0, np.inf, 0.0)}, "finite"),
        ({"spacing": 1.0, "terrain": np.zeros((3, 3))}, r"shape \(nx, ny\) = \(2, 3\)"),
        ({"spacing": 1.0, "terrain": np.full((2, 3), np.nan)}, "non-finite"),
        ({"spacing": 1.0, "crs": 4326}, "crs"),
    ],
)
def test_parameter_validation(kwargs, phrase):
    with pytest.raises(WorldError, match=phrase):
        World(np.zeros((2, 3, 4), dtype=bool), **kwargs)


def test_errors_are_value_errors():
    with pytest.raises(ValueError):
        World(np.zeros((2, 3), dtype=bool), spacing=0.0)


# ----------------------------------------------------------------------------- heightmap
def test_from_heightmap_tiny_isotropic():
    heights = np.array([[0.0, 15.0], [30.0, -5.0]])
    w = World.from_heightmap(heights, 15.0, 4, name="tiny")
    expected = np.array(
        [
            [[T, F, F, F], [T, T, F, F]],
            [[T, T, T, F], [F, F, F, F]],
        ]
    )
    np.testing.assert_array_equal(w.occupancy, expected)
    assert w.spacing == (15.0, 15.0, 15.0)
    assert w.origin == (0.0, 0.0, 0.0)
    np.testing.assert_array_equal(w.terrain, heights)
    assert not w.terrain.flags.writeable
    assert w.name == "tiny"
    np.testing.assert_array_equal(w.surface_index(), [[0, 1], [2, -1]])


def test_from_heightmap_anisotropic_with_origin():
    # z nodes: 100, 105, 110, 115 m
    heights = np.array([[107.0, 100.0, 99.9], [112.0, 114.999, 104.0]])
    w = World.from_heightmap(heights, (10.0, 20.0, 5.0), 4, origin=(-50.0, 30.0, 100.0))
    expected = np.array(
        [
            [[T, T, F, F], [T, F, F, F], [F, F, F, F]],
            [[T, T, T, F], [T, T, T, F], [T, F, F, F]],
        ]
    )
    np.testing.assert_array_equal(w.occupancy, expected)
    assert w.spacing == (10.0, 20.0, 5.0)
    np.testing.assert_array_equal(w.bounds, [[-50.0, -40.0], [30.0, 70.0], [100.0, 115.0]])
    np.testing.assert_array_equal(w.surface_index(), [[1, 0, -1], [2, 2, 0]])


def test_surface_index_handles_overhangs_and_is_cached():
    occ = np.zeros((2, 1, 5), dtype=bool)
    occ[0, 0, [0, 3]] = True  # overhang: topmost obstacle is 3
    w = World(occ, spacing=1.0)
    np.testing.assert_array_equal(w.surface_index(), [[3], [-1]])
    assert w.surface_index() is w.surface_index()
    assert not w.surface_index().flags.writeable


def test_surface_index_needs_3d():
    with pytest.raises(WorldError, match="3D"):
        World(np.zeros((2, 2), dtype=bool), spacing=1.0).surface_index()


@pytest.mark.parametrize(
    ("args", "kwargs", "phrase"),
    [
        ((np.array([[np.nan, 0.0]]), 15.0, 4), {}, r"NaN/inf .*column \(0, 0\)"),
        ((np.zeros((2, 2, 2)), 15.0, 4), {}, "2D"),
        ((np.zeros(3), 15.0, 4), {}, "2D"),
        ((np.zeros((0, 2)), 15.0, 4), {}, "empty"),
        ((np.zeros((2, 2)), 0.0, 4), {}, "cell_size must be finite and > 0"),
        ((np.zeros((2, 2)), (1.0, -1.0, 1.0), 4), {}, "cell_size"),
        ((np.zeros((2, 2)), (1.0, 1.0), 4), {}, r"\(dx, dy, dz\)"),
        ((np.zeros((2, 2)), 15.0, 0), {}, "height_cells must be >= 1"),
        ((np.zeros((2, 2)), 15.0, 2.5), {}, "integer"),
        ((np.zeros((2, 2)), 15.0, 4), {"origin": (0.0, 0.0)}, "origin"),
    ],
)
def test_from_heightmap_validation(args, kwargs, phrase):
    with pytest.raises(WorldError, match=phrase):
        World.from_heightmap(*args, **kwargs)


def test_from_heightmap_terrain_above_ceiling_suggests_height_cells():
    heights = np.array([[0.0, 50.0], [10.0, 20.0]])
    with pytest.raises(WorldError) as exc:
        World.from_heightmap(heights, 15.0, 4)  # top node at 45 m
    msg = str(exc.value)
    assert "column (0, 1)" in msg
    assert "no free space" in msg
    assert "height_cells >= 5" in msg
    # the suggestion works
    w = World.from_heightmap(heights, 15.0, 5)
    assert not w.occupancy[0, 1, -1]
    # a column reaching exactly the top node is also rejected
    with pytest.raises(WorldError, match="height_cells"):
        World.from_heightmap(np.array([[45.0]]), 15.0, 4)
