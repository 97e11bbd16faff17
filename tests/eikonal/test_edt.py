"""eikonal._edt: the exact distance transform, bit for bit the first-written transform on
every path (serial, parallel, squared, root, normalised), and exact against brute force."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import ndimage

from fm2uav.eikonal import _edt

from .edt_reference import squared_edt as reference


def _grids():
    rng = np.random.default_rng(27)
    spacings = [(1.0, 1.0, 1.0), (15.0, 15.0, 10.0), (0.7, 2.5, 1 / 3), (1.0, 3.0, 0.1)]
    out = []
    for it in range(24):
        shape = tuple(int(x) for x in rng.integers(1, 23, 3))
        if it % 4 == 0:  # a column world (terrain): solid below a top layer
            top = rng.integers(-1, shape[2], shape[:2])
            occ = np.arange(shape[2])[None, None, :] <= top[:, :, None]
        else:
            occ = rng.random(shape) < rng.choice([0.004, 0.03, 0.2, 0.7])
        out.append((np.ascontiguousarray(occ), spacings[it % len(spacings)]))
    out.append((np.zeros((9, 1, 1), bool), (1.0, 1.0, 1.0)))       # no obstacle
    out.append((np.ones((3, 4, 5), bool), (2.0, 1.0, 1.0)))        # all obstacle
    occ = np.zeros((40, 30, 1), bool)                               # 2D, one node
    occ[17, 3, 0] = True
    out.append((occ, (1.0, 1.0, 1.0)))
    occ = np.zeros((5, 6, 19), bool)                                # lanes: 19 = 2 x 8 + 3
    occ[2, 3, [0, 18]] = True
    out.append((occ, (1.0, 2.0, 0.5)))
    # a terrain: solid ground up to layer 2 at least, so whole y and x lines are obstacle
    # (zeros at once) beside lines with some; the x pass's blocks: 13 x 9 = 3 x 32 + 21
    top = np.maximum(rng.integers(-1, 9, (21, 13)), 2)
    out.append((np.ascontiguousarray(np.arange(9)[None, None, :] <= top[:, :, None]),
                (15.0, 15.0, 10.0)))
    return out


GRIDS = _grids()


@pytest.mark.parametrize("k", range(len(GRIDS)))
@pytest.mark.parametrize("threads", [1, 2, 3])
def test_every_path_gives_the_reference_bytes(k, threads, monkeypatch):
    occ, h = GRIDS[k]
    monkeypatch.setattr(_edt, "EDT_PARALLEL_MIN_NODES", 0 if threads > 1 else 10**12)
    ref = reference(occ, *h)
    np.testing.assert_array_equal(_edt.squared_edt(occ, *h, threads=threads), ref)
    d, top = _edt.edt(occ, *h, threads=threads)
    root = np.sqrt(ref)
    np.testing.assert_array_equal(d, root)
    assert top == root.max()
    w, top2 = _edt.edt(occ, *h, normalise=True, threads=threads)
    assert top2 == top
    if 0.0 < top < np.inf:
        np.testing.assert_array_equal(w, root / root.max())
    else:  # nothing to divide by: left as it is
        np.testing.assert_array_equal(w, root)


def test_the_reference_is_the_exact_distance():
    # brute force over every obstacle node: the reference (hence the transform) is exact
    rng = np.random.default_rng(3)
    occ = rng.random((9, 8, 7)) < 0.05
    occ[0, 0, 0] = True
    h = np.array([1.5, 1.0, 0.5])
    pts = np.argwhere(occ) * h
    nodes = np.indices(occ.shape).reshape(3, -1).T * h
    brute = ((nodes[:, None, :] - pts[None, :, :]) ** 2).sum(-1).min(1).reshape(occ.shape)
    np.testing.assert_allclose(reference(occ, *h), brute, rtol=1e-13, atol=1e-12)
    scipy_d = ndimage.distance_transform_edt(~occ, sampling=h)
    np.testing.assert_allclose(_edt.edt(occ, *h)[0], scipy_d, rtol=1e-13, atol=1e-12)


def test_the_comparison_sees_one_ulp():
    # the bytes compared can differ: a spacing one ulp larger moves the distances
    rng = np.random.default_rng(1)
    occ = np.ascontiguousarray(rng.random((20, 18, 6)) < 0.1)
    a = _edt.squared_edt(occ, 0.7, 1 / 3, 1.0)
    b = _edt.squared_edt(occ, np.nextafter(0.7, 1.0), 1 / 3, 1.0)
    assert not np.array_equal(a, b)
    np.testing.assert_allclose(a, b, rtol=1e-14)
