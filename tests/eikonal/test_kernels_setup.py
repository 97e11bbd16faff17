"""The march's set-up on several threads (issue 27): the padding and the input scan give
the bytes and answers of their one-thread forms."""

from __future__ import annotations

import numpy as np
import pytest

from fm2uav import InputError
from fm2uav.eikonal import _kernels, fast_marching
from fm2uav.eikonal.fmm import MIN_SPEED


def _padded(speed, start, shape3, vdtype, nth):
    nx, ny, nz = shape3
    npad = (nx + 2) * (ny + 2) * (1 if nz == 1 else nz + 2)
    Tp = np.full(npad, 7.0)  # not NaN: every node the padding sets is seen to be set
    Vp = np.full(npad, 7.0, dtype=vdtype)
    args = (_kernels._readonly(speed.reshape(-1)), start.T, start.state, *start.lo,
            *start.shape, nx, ny, nz, Tp, Vp)
    if nth == 0:
        _kernels.pad_grid(*args)
    else:
        _kernels.pad_grid_parallel(nth, *args)
    return Tp.view(np.uint64), Vp  # NaN against NaN: the bits


def _start(shape3, lo, bshape, rng):
    n = int(np.prod(bshape))
    T = rng.random(n) * 3.0
    state = rng.integers(0, 3, n).astype(np.uint8)
    T[state == 0] = np.inf
    return _kernels.Start(lo, bshape, T, state)


@pytest.mark.parametrize("shape3, lo, bshape", [
    ((13, 11, 1), (3, 2, 0), (4, 5, 1)),
    ((9, 8, 7), (2, 1, 3), (3, 4, 2)),
    ((5, 17, 6), (0, 0, 0), (5, 17, 6)),
    ((2, 3, 4), (1, 1, 1), (1, 1, 1)),
])
@pytest.mark.parametrize("vdtype", [np.float64, np.float32])
@pytest.mark.parametrize("nth", [1, 2, 3])
def test_parallel_padding_writes_the_serial_bytes(shape3, lo, bshape, vdtype, nth):
    rng = np.random.default_rng(sum(shape3) + nth)
    speed = rng.random(shape3) + 0.1
    speed[rng.random(shape3) < 0.2] = 0.0
    start = _start(shape3, lo, bshape, rng)
    T1, V1 = _padded(speed, start, shape3, vdtype, 0)
    Tn, Vn = _padded(speed, start, shape3, vdtype, nth)
    np.testing.assert_array_equal(Tn, T1)
    np.testing.assert_array_equal(Vn.view(np.uint8), V1.view(np.uint8))
    assert np.isnan(T1.view(np.float64)).any() and (T1.view(np.float64) == -np.inf).any()


@pytest.mark.parametrize("nth", [1, 2, 3, 4])
def test_parallel_scan_answers_as_the_serial_scan(nth):
    rng = np.random.default_rng(nth)
    n = 1001
    for bad_at in [None, 0, 250, 500, 501, 1000]:
        for bad in [np.nan, -1.0, np.inf]:
            v = rng.random(n)
            v[rng.random(n) < 0.05] = 1e-200  # tiny speeds on both sides of the bad one
            v[rng.random(n) < 0.05] = 0.0
            if bad_at is not None:
                v[bad_at] = bad
                v[min(bad_at + 7, n - 1)] = -3.0  # a second bad value later: not reported
            ro = _kernels._readonly(v)
            assert _kernels.scan_speed_parallel(nth, ro, MIN_SPEED) == \
                _kernels.scan_speed(ro, MIN_SPEED), (bad_at, bad)


def test_fast_marching_names_the_same_bad_node_on_two_threads(monkeypatch):
    monkeypatch.setattr(_kernels, "SETUP_PARALLEL_MIN_NODES", 0)
    v = np.ones((30, 20, 6))
    v[22, 3, 4] = -2.0
    v[25, 0, 0] = np.nan
    msgs = []
    for threads in (1, 2):
        with pytest.raises(InputError) as e:
            fast_marching(v, [(0, 0, 0)], threads=threads)
        msgs.append(str(e.value))
    assert msgs[0] == msgs[1] and "[22, 3, 4]" in msgs[0]
    # tiny speeds raised to the floor on both
    v = np.ones((30, 20, 6))
    v[5:9] = 1e-200
    a = fast_marching(v, [(0, 0, 0)], order=1, threads=1)
    b = fast_marching(v, [(0, 0, 0)], order=1, threads=2)
    np.testing.assert_array_equal(a, b)
    assert np.isfinite(a[20, 0, 0])
