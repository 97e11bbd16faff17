"""Discrete Fréchet distance and area between curves: exact values and a peer."""

import math

import numpy as np
import pytest

from fm2uav.analysis.similarity import area_between_curves, frechet_distance
from fm2uav.errors import InputError


def test_frechet_exact_values():
    assert frechet_distance([[0, 0], [1, 0], [2, 0]], [[0, 1], [2, 1]]) == pytest.approx(math.sqrt(2))
    assert frechet_distance([[0, 0], [1, 0]], [[0, 0], [1, 0]]) == 0.0
    # order matters: a reversed curve is far away
    assert frechet_distance([[0, 0], [10, 0]], [[10, 0], [0, 0]]) == pytest.approx(10.0)
    # single points
    assert frechet_distance([[0, 0]], [[3, 4]]) == pytest.approx(5.0)
    # 3D
    assert frechet_distance([[0, 0, 0], [0, 0, 1]], [[0, 0, 0], [0, 2, 1]]) == pytest.approx(2.0)


def test_frechet_matches_similaritymeasures():
    sm = pytest.importorskip("similaritymeasures")
    rng = np.random.default_rng(11)
    for _ in range(40):
        a = rng.normal(size=(int(rng.integers(1, 40)), 2))
        b = rng.normal(size=(int(rng.integers(1, 40)), 2))
        assert frechet_distance(a, b) == pytest.approx(sm.frechet_dist(a, b), abs=1e-12)


def test_frechet_properties():
    rng = np.random.default_rng(5)
    for _ in range(20):
        a = rng.normal(size=(15, 2))
        b = rng.normal(size=(9, 2))
        d = frechet_distance(a, b)
        assert d == pytest.approx(frechet_distance(b, a))
        # at least the end-point distances, at most the largest pairwise distance
        assert d >= max(np.linalg.norm(a[0] - b[0]), np.linalg.norm(a[-1] - b[-1])) - 1e-12
        assert d <= np.max(np.linalg.norm(a[:, None] - b[None], axis=2)) + 1e-12


def test_area_exact_values():
    assert area_between_curves([[0, 0], [1, 1], [2, 0]], [[0, 0], [2, 0]]) == pytest.approx(1.0)
    # crossing curves: two lobes, both count (a signed shoelace area would give 0)
    assert area_between_curves([[0, 0], [1, 1], [2, -1], [3, 0]], [[0, 0], [3, 0]]) == pytest.approx(1.5)
    assert area_between_curves([[0, 0], [5, 5]], [[0, 0], [2, 2], [5, 5]]) == pytest.approx(0.0)
    # symmetric and independent of sampling
    p = [[0, 0], [0, 2], [4, 2], [4, 0]]
    q = np.c_[np.linspace(0, 4, 17), np.zeros(17)]
    assert area_between_curves(p, q) == pytest.approx(8.0)
    assert area_between_curves(q, p) == pytest.approx(8.0)


def test_area_sine_against_integral():
    x = np.linspace(0, 100, 2001)
    p = np.c_[x, 10 * np.sin(x / 10)]
    q = np.c_[x[::7], np.zeros(len(x[::7]))]
    q[-1] = (100, 0)
    q = np.vstack([q, [[100, 0]]]) if q[-1, 0] != 100 else q
    exact = 100 * (6 + 1 - math.cos(10 - 3 * math.pi))  # ∫0^100 |10 sin(x/10)| dx
    assert area_between_curves(p, q) == pytest.approx(exact, rel=1e-3)


def test_bad_curves():
    with pytest.raises(InputError):
        frechet_distance([[0, 0]], [[0, 0, 0]])
    with pytest.raises(InputError):
        frechet_distance(np.zeros((0, 2)), [[0, 0]])
    with pytest.raises(InputError):
        area_between_curves([[0, 0, 0]], [[1, 1, 1]])
    with pytest.raises(InputError):
        frechet_distance([[0, np.nan]], [[0, 0]])


def _area_face_by_face(P, Q):
    """The former ``area_between_curves``: one face at a time (area, inner point, winding)."""
    import shapely
    from shapely.geometry import LineString

    from fm2uav.analysis.similarity import _winding

    p, q = np.asarray(P, float), np.asarray(Q, float)
    ring = np.concatenate([p, q[::-1], p[:1]])
    keep = np.ones(len(ring), dtype=bool)
    keep[1:] = np.any(np.diff(ring, axis=0) != 0.0, axis=1)
    ring = np.ascontiguousarray(ring[keep])
    if len(ring) < 4:
        return 0.0
    faces = shapely.get_parts(shapely.polygonize(shapely.get_parts(shapely.node(LineString(ring)))))
    total = 0.0
    for face in faces:
        a = face.area
        if a > 0.0:
            pt = face.representative_point()
            if _winding.py_func(ring, pt.x, pt.y) != 0:
                total += a
    return total


def test_area_equals_the_face_by_face_sum_bit_for_bit():
    rng = np.random.default_rng(5)
    for _ in range(60):  # wiggly curves with shared ends: many lobes, some wound twice
        n, m = int(rng.integers(2, 40)), int(rng.integers(2, 40))
        P = np.column_stack([np.linspace(0, 10, n), rng.normal(0, 1, n)])
        Q = np.column_stack([np.linspace(0, 10, m), rng.normal(0, 1, m)])
        Q[0], Q[-1] = P[0], P[-1]
        if rng.random() < 0.3:
            Q = np.round(Q)  # collinear runs and touching vertices
        assert area_between_curves(P, Q) == _area_face_by_face(P, Q)
    assert area_between_curves([[0, 0], [1, 0], [2, 0]], [[0, 0], [2, 0]]) == 0.0
