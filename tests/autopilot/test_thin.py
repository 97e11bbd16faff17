"""3D Douglas–Peucker waypoint thinning: exact tiny cases and a seeded property."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from fm2uav.errors import InputError
from fm2uav.autopilot.thin import segment_distances, thin_indices, thin_path


def test_straight_line_keeps_the_ends():
    line = np.column_stack([np.linspace(0, 100, 201), np.linspace(0, 50, 201), np.zeros(201)])
    assert thin_indices(line, 0.01).tolist() == [0, 200]


def test_exact_corner_and_tolerance():
    # an L: (0,0) → (10,0) → (10,10), 1 m steps; the corner is 7.07 m off the chord
    p = np.array([[i, 0.0] for i in range(11)] + [[10.0, j] for j in range(1, 11)])
    assert thin_indices(p, 1.0).tolist() == [0, 10, 20]
    assert thin_indices(p, 7.0).tolist() == [0, 10, 20]
    assert thin_indices(p, 7.1).tolist() == [0, 20]


def test_climb_is_kept_in_3d_although_flat_in_plan_view():
    # straight in x/y, but a 20 m climb and descent: a 2D thinning would drop it
    x = np.linspace(0, 400, 81)
    z = np.where(x < 200, x / 10, (400 - x) / 10) + 50
    p = np.column_stack([x, np.zeros_like(x), z])
    kept = thin_indices(p, 1.0)
    assert kept.tolist() == [0, 40, 80]
    assert thin_indices(p[:, :2], 1.0).tolist() == [0, 80]


def test_max_points_keeps_the_worst_first():
    p = np.array([[0, 0, 0], [1, 5, 0], [2, 0, 0], [3, 1, 0], [4, 0, 0]], float)
    assert thin_indices(p, 0.0, max_points=3).tolist() == [0, 1, 4]


def test_short_and_bad_inputs():
    assert thin_indices(np.zeros((1, 3)), 1.0).tolist() == [0]
    assert thin_indices(np.zeros((2, 3)), 1.0).tolist() == [0, 1]
    for bad in (-1.0, np.nan):
        with pytest.raises(InputError, match="tolerance"):
            thin_indices(np.zeros((3, 3)), bad)
    with pytest.raises(InputError, match="shape"):
        thin_indices(np.zeros((3, 4)), 1.0)


@settings(max_examples=40, deadline=None, derandomize=True)
@given(seed=st.integers(0, 10_000), tol=st.floats(0.1, 20.0), dim=st.sampled_from([2, 3]))
def test_every_dropped_point_is_within_tolerance(seed, tol, dim):
    rng = np.random.default_rng(seed)
    p = np.cumsum(rng.normal(size=(200, dim)) * 5.0, axis=0)
    kept = thin_indices(p, tol)
    assert kept[0] == 0 and kept[-1] == len(p) - 1 and np.all(np.diff(kept) > 0)
    for a, b in zip(kept[:-1], kept[1:]):
        if b - a > 1:
            d = segment_distances(p[a + 1 : b], p[a], p[b])
            assert d.max() <= tol + 1e-9
    np.testing.assert_array_equal(thin_path(p, tol), p[kept])
