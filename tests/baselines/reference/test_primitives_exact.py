"""The control set's vectorised steps (swept cells, dominance reduction) against the
per-primitive loops they replaced: the same primitives and cells, bit for bit."""

from __future__ import annotations

import math

import numpy as np
import pytest

from fm2uav.baselines.reference import primitives as P
from fm2uav.baselines.reference.lattice import default_radius


def _reduce_loop(prim, K, r):
    """The dominance test one primitive at a time (the implementation before)."""
    i, j, dx, dy, c = prim["i"], prim["j"], prim["dx"], prim["dy"], prim["cost"]
    n2 = dx * dx + dy * dy
    span, off = 4 * r + 1, 2 * r

    def key(ddx, ddy, jj):
        return ((ddx + off) * span + (ddy + off)) * K + jj

    by_start = [np.flatnonzero(i == h) for h in range(K)]
    keep = np.ones(len(i), dtype=bool)
    for h in range(K):
        for p in by_start[h]:
            for p1 in by_start[h]:
                p2 = by_start[j[p1]]
                hit = ((key(dx[p1] + dx[p2], dy[p1] + dy[p2], j[p2]) == key(dx[p], dy[p], j[p]))
                       & (np.maximum(n2[p1], n2[p2]) < n2[p]) & (c[p1] + c[p2] <= c[p] * (1 + 1e-9)))
                if n2[p] > 0 and hit.any():
                    keep[p] = False
                    break
    return keep


@pytest.mark.parametrize("model, xi, max_int", [("dubins", 3.0, 2), ("elastica", 3.0, 2),
                                                 ("rs", 3.0, 2), ("dubins", 2.0, 3)])
def test_reduction_drops_exactly_the_dominated_primitives(model, xi, max_int):
    th = P.lattice_headings(max_int)
    radius = default_radius(xi, max_int, model)
    r = int(math.floor(radius))
    prim = P._candidates(model, xi, th, radius, r, math.pi / 2, math.radians(70.0))
    if model == "rs":
        prim = P._with_rotations(prim, th, xi)
    want = _reduce_loop(prim, len(th), r)
    assert 0 < want.sum() < len(want)  # some dropped, some kept: the test can fail
    assert np.array_equal(P._reduce(prim, len(th), r), want)


@pytest.mark.parametrize("model", ["dubins", "elastica", "rs"])
def test_swept_cells_are_each_primitives_distinct_nearest_nodes(model):
    pr = P.build_primitives(model, 5.0, max_int=4, radius=default_radius(5.0, 4, model))
    assert pr.cell_x.dtype == pr.cell_y.dtype == np.int64
    assert len(pr.cell_ptr) == pr.count + 1
    for n in range(pr.count):
        a, b = pr.pt_ptr[n], pr.pt_ptr[n + 1]
        pts = np.stack([np.append(pr.pt_x[a:b], 0.0), np.append(pr.pt_y[a:b], 0.0)], 1)
        want = np.unique(np.floor(pts + 0.5).astype(np.int64), axis=0)
        lo, hi = pr.cell_ptr[n], pr.cell_ptr[n + 1]
        got = np.stack([pr.cell_x[lo:hi], pr.cell_y[lo:hi]], 1)
        assert np.array_equal(got, want), n


@pytest.mark.parametrize("model", ["dubins", "elastica", "rs"])
def test_all_primitives_are_sampled_as_one_at_a_time(model):
    """The vectorised sampling gives :func:`_sample`'s points of every primitive (rotations in
    place, straight and curved arcs), bit for bit."""
    th = P.lattice_headings(3)
    radius = default_radius(4.0, 3, model)
    prim = P._candidates(model, 4.0, th, radius, int(radius), math.pi / 2, math.radians(70.0))
    if model == "rs":
        prim = P._with_rotations(prim, th, 4.0)
    ptr, xs, ys, ths = P._sample_all(th[prim["i"]], prim["geom"], prim["dx"].astype(float),
                                     prim["dy"].astype(float))
    for n in range(len(prim["i"])):
        want = P._sample(th[prim["i"][n]], *prim["geom"][n], float(prim["dx"][n]),
                         float(prim["dy"][n]))
        got = (xs[ptr[n]:ptr[n + 1]], ys[ptr[n]:ptr[n + 1]], ths[ptr[n]:ptr[n + 1]])
        for g, w in zip(got, want):
            assert np.array_equal(g, w), n
