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
            answer = _kernels.scan_speed(ro, MIN_SPEED)
            assert _kernels.scan_speed_parallel(nth, ro, MIN_SPEED) == answer, (bad_at, bad)
            if bad_at is None:  # the speeds' span with it (speed_range's, bit for bit)
                assert answer == (-1, int(((v > 0) & (v < MIN_SPEED)).sum()),
                                  *_kernels.speed_range(ro))
                assert answer[2:] == (v[v > 0].min(), v.max())
            else:
                assert answer[0] == bad_at


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


@pytest.mark.parametrize("threads", [1, 2])
@pytest.mark.parametrize("field", ["uniform", "plateau", "tiny"])
def test_the_input_scan_spares_the_march_its_passes_over_the_speeds(monkeypatch, field,
                                                                    threads):
    """``fast_marching`` hands its input scan's speed span to the march: the plateau test
    and the parallel march's first window take no pass of their own over the speeds, a
    pooled result's resident pages no toucher thread, and the times are those of a march
    that finds the span itself, bit for bit."""
    from fm2uav.eikonal import _parallel, _tuning, fmm

    monkeypatch.setattr(_tuning, "PARALLEL_MIN_NODES", 0)
    monkeypatch.setattr(_tuning, "ORDER2_MIN_NODES_2D", 0)
    rng = np.random.default_rng(3)
    v = np.full((90, 70), 2.0)
    if field == "plateau":  # the top speed on most nodes, a slow wall: the mask is built
        v[rng.random(v.shape) < 0.3] = 1.25
        v[40:43, 10:60] = 0.0
    elif field == "tiny":  # speeds under the floor raised to it: the span follows
        v = rng.random(v.shape) + 0.5
        v[:, 30] = 1e-200
    flat, span = fmm._as_speed_span(v)
    assert span == _kernels.speed_range(flat.reshape(-1))
    src = [(5, 6)]
    shape3 = (90, 70, 1)
    expect = {}
    for order in (1, 2):  # the march finding the span itself
        start = fmm._source_start(flat, np.array([[5, 6, 0]]), shape3, (1.0,) * 3, 4.0, 2.0)
        expect[order] = fmm.run_march(flat.reshape(-1), start, (90, 70), (1.0,) * 3, order,
                                      None, threads=threads)

    def forbidding(f):  # the grid's speeds (the cuts' coarse march scans its own)
        def check(speed):
            assert speed.size != v.size, "a pass over the speeds the input scan made already"
            return f(speed)
        return check

    monkeypatch.setattr(_kernels, "speed_range", forbidding(_kernels.speed_range))
    monkeypatch.setattr(_parallel, "_top_speed", forbidding(_parallel._top_speed))
    monkeypatch.setattr(fmm, "SOURCE_INIT_FRACTION", 0.0)  # the ball of 4 cells above
    monkeypatch.setattr(fmm, "SOURCE_INIT_CELLS", 4.0)
    for order in (1, 2):
        T = fast_marching(v, src, order=order, threads=threads)
        np.testing.assert_array_equal(T, expect[order])


@pytest.mark.parametrize("values", [
    [], [0.0], [-0.0, 0.0], [0.0, 3.0, -0.0, 2.5], [5e-324, 1.0], [1e-200, 1e300, 7.0],
    [2.0] * 9, [np.nextafter(1.0, 2.0), 1.0, 0.0],
])
def test_the_speed_span_on_the_bits_is_the_float_span(values):
    """The span of :func:`speed_range` (and the scan's) found on the bits as integers: the
    smallest positive and the largest speed as floats give them, -0.0 not positive,
    subnormals positive, (inf, 0) with none positive."""
    v = np.array(values, dtype=float)
    pos = v[v > 0]
    expect = (pos.min() if pos.size else np.inf, max(v.max(), 0.0) if v.size else 0.0)
    ro = _kernels._readonly(v)
    assert _kernels.speed_range(ro) == expect
    assert _kernels.scan_speed(ro, MIN_SPEED)[2:] == expect
    assert _kernels.scan_speed_parallel(2, ro, MIN_SPEED)[2:] == expect
    assert str(_kernels.speed_range(ro)[1]) != "-0.0"
