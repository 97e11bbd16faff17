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


# ------------------------------------------------------------------ compiled = numpy, bit for bit
def _thin_in_numpy(p, tol, max_points=None):
    """The numpy Douglas–Peucker as it was before the compiled splits (worst segment first,
    a heap of numpy distances), kept as ``thin._split_in_order`` for the point budget."""
    from fm2uav.autopilot.thin import _split_in_order

    return np.arange(len(p)) if len(p) <= 2 else _split_in_order(p, tol, max_points)


def _polyline(rng, kind):
    n = int(rng.integers(3, 300))
    d = int(rng.choice([2, 3]))
    if kind == "walk":  # a descent-like path: small steps, smooth turns
        p = np.cumsum(rng.normal(0, 1, (n, d)) + rng.normal(0, 1, d), axis=0)
    elif kind == "grid":  # half-cell points: collinear runs, exact ties, duplicates
        p = np.cumsum(rng.integers(-1, 2, (n, d)), axis=0) * 0.5
    elif kind == "zigzag":  # symmetric teeth: equal distances everywhere
        p = np.zeros((n, d))
        p[:, 0] = np.arange(n)
        p[:, 1] = np.where(np.arange(n) % 2, 1.0, -1.0) * rng.choice([1.0, 2.0])
        p[0, 1] = p[-1, 1] = 0.0
    elif kind == "line":  # collinear points, some repeated, in UTM-sized coordinates
        t = np.sort(rng.choice(np.linspace(0, 1, 40), n))
        p = np.array([4.1e6, 6.5e5, 300.0][:d]) + t[:, None] * rng.normal(0, 900, d)
    else:  # "utm": a walk far from the origin (rounding relative to the coordinates)
        p = np.array([6.5e5, 4.1e6, 900.0][:d]) + np.cumsum(rng.normal(0, 20, (n, d)), axis=0)
    return p


@pytest.mark.parametrize("kind", ["walk", "grid", "zigzag", "line", "utm"])
@pytest.mark.parametrize("seed", range(40))
def test_compiled_splits_keep_exactly_the_numpy_indices(kind, seed):
    rng = np.random.default_rng(seed)
    p = _polyline(rng, kind)
    dists = segment_distances(p[1:-1], p[0], p[-1])
    tols = [0.0, 0.5, 1.0, 15.0, float(rng.uniform(0, 5)),
            float(dists.max()) if len(dists) else 1.0,  # a distance exactly at the tolerance
            float(np.median(dists)) if len(dists) else 1.0]
    for tol in tols:
        want = _thin_in_numpy(p, tol)
        assert np.array_equal(thin_indices(p, tol), want), (kind, seed, tol)
        cap = max(2, len(want) - int(rng.integers(0, 3)))
        assert np.array_equal(thin_indices(p, tol, max_points=cap), _thin_in_numpy(p, tol, cap))


def test_near_ties_are_decided_by_numpy_and_the_rest_compiled(monkeypatch):
    """Equal teeth go to numpy (its own rounding picks), a plain walk never does."""
    from fm2uav.autopilot import thin

    p = _polyline(np.random.default_rng(7), "walk")
    z = _polyline(np.random.default_rng(1), "zigzag")
    want_p, want_z = _thin_in_numpy(p, 1.0), _thin_in_numpy(z, 0.1)
    calls = []
    real = thin.segment_distances
    monkeypatch.setattr(thin, "segment_distances", lambda *a: calls.append(1) or real(*a))
    assert np.array_equal(thin_indices(p, 1.0), want_p)
    assert calls == []  # a walk has no near ties: the compiled splits decide everything
    assert np.array_equal(thin_indices(z, 0.1), want_z)
    assert calls  # the zigzag's equal teeth are decided by numpy's own rounding
