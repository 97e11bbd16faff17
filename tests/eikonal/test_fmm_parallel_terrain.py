"""The parallel march on a terrain's FM² map, as a plan marches it (issue 27).

The 1000 x 1000 x 40 terrain plan marches order 2 from the goal with ``stop_at`` the start,
on two threads in the lean layout (float32 ``1 / speed^2``): a second thread faults the
buffers' pages in while the cuts are placed (``_parallel._PageToucher``) and the nodes after
the stop are set to inf on the threads (``_parallel._inf_after``). Here the same path on a
small terrain, its times bit for bit the serial march's. Speed: docs/performance.md "Both
cores" (never timed here).
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy import ndimage

from fm2uav.eikonal import _kernels, _parallel, _tuning, distance_map, fast_marching

from .fmm_checks import fast_marching_parallel


def _terrain(nx=48, ny=40, nz=14, seed=3):
    """An FM² map over a smooth random relief: W = distance to the ground / its largest
    (0 in the ground, rising into the air), as a plan's base map; the goal high in one corner,
    the start in the opposite one."""
    rng = np.random.default_rng(seed)
    relief = ndimage.gaussian_filter(rng.standard_normal((nx, ny)), 4, mode="wrap")
    ground = 1 + np.round((relief - relief.min()) / np.ptp(relief) * (nz // 2)).astype(int)
    occ = np.arange(nz)[None, None, :] < ground[:, :, None]
    d = distance_map(occ, spacing=(15.0, 15.0, 10.0))
    return d / d.max(), (nx - 3, ny - 3, nz - 2), (2, 2, nz - 2)



def _below_and_at(monkeypatch, threshold, W, goal, start, h):
    """March ``W`` order 2 from ``goal`` to ``start`` on the slabs with the grid below the
    ``_tuning`` size ``threshold``, then at it (set to this grid's size): both the serial
    march's times bit for bit."""
    serial = fast_marching(W, [goal], spacing=h, order=2, stop_at=[start], threads=1)
    below = fast_marching_parallel(W, [goal], spacing=h, order=2, stop_at=[start])
    monkeypatch.setattr(_tuning, threshold, W.size)  # this grid: at it
    at = fast_marching_parallel(W, [goal], spacing=h, order=2, stop_at=[start])
    assert np.array_equal(serial, below) and np.array_equal(serial, at)

@pytest.fixture
def lean(monkeypatch):
    """The lean layout (float32 speeds) of big grids, on a small one."""
    monkeypatch.setattr(_kernels, "LEAN_NODES", 0)


def test_terrain_march_with_a_stop_equals_the_serial_march_bit_for_bit(lean, monkeypatch):
    W, goal, start = _terrain()
    calls = {"touched": 0, "inf_after": 0, "cuts": 0}

    class Toucher(_parallel._PageToucher):
        def __enter__(self):
            calls["touched"] += 1
            return super().__enter__()

    def inf_after(nth, T, t):
        calls["inf_after"] += 1
        return real_inf_after(nth, T, t)

    def bounds(*args, **kw):
        calls["cuts"] += 1
        return real_bounds(*args, **kw)

    real_inf_after, real_bounds = _parallel._inf_after, _parallel.slab_bounds
    monkeypatch.setattr(_parallel, "_PageToucher", Toucher)
    monkeypatch.setattr(_parallel, "_inf_after", inf_after)
    monkeypatch.setattr(_parallel, "slab_bounds", bounds)
    serial = fast_marching(W, [goal], spacing=(15.0, 15.0, 10.0), order=2, stop_at=[start],
                           threads=1)
    par = fast_marching_parallel(W, [goal], spacing=(15.0, 15.0, 10.0), order=2,
                                 stop_at=[start])
    # the plan's path through the slabs: pages touched while the cuts are placed, a stop
    assert calls == {"touched": 1, "inf_after": 1, "cuts": 1}
    assert np.isfinite(par[start])
    assert np.isinf(par).sum() > (W == 0).sum()  # the stop left air nodes unfrozen
    assert np.array_equal(serial, par)  # bit for bit, inf where the serial march stopped


def test_inf_after_equals_numpys_masked_assignment():
    rng = np.random.default_rng(0)
    T = rng.random(10_001)
    T[::7] = np.inf
    T[3::11] = np.nan  # unreachable nodes are inf; a NaN is left alone as numpy leaves it
    want = T.copy()
    want[want > 0.4] = np.inf
    for nth in (1, 2, 3):
        got = T.copy()
        _parallel._inf_after(nth, got, 0.4)
        np.testing.assert_array_equal(got, want)


def test_touch_writes_a_zero_byte_every_step():
    a = np.full(3 * 4096 + 5, 0xAB, dtype=np.uint8)
    _parallel._touch(a, 4096)
    assert np.flatnonzero(a == 0).tolist() == [0, 4096, 8192, 12288]
    assert np.all(np.delete(a, [0, 4096, 8192, 12288]) == 0xAB)


def test_page_toucher_touches_only_page_starts_and_stops_at_the_block_end():
    # two arrays (the lean layout's float64 times and float32 speeds): wherever the thread
    # got to before the block ended, it wrote zero bytes at page starts only
    a = np.full(3 * _tuning.TOUCH_CHUNK + 4096, 0xAB, dtype=np.uint8).view(np.float64)
    b = np.full(5000, 0xCD, dtype=np.uint8).view(np.float32)
    with _parallel._PageToucher(a, b) as toucher:
        pass
    assert not toucher.thread.is_alive()
    for arr, byte in ((a, 0xAB), (b, 0xCD)):
        raw = arr.view(np.uint8)
        zeros = np.flatnonzero(raw == 0)
        assert np.all(zeros % 4096 == 0)
        assert np.all(np.delete(raw, zeros) == byte)


def test_page_toucher_finds_the_top_speed_before_it_touches():
    # the top speed (the first window's width) is found whatever the block's length: the
    # block ends at once here, the pages then stay untouched but the top is there
    speed = np.random.default_rng(1).random(100_003) * 7.0
    a = np.full(3 * _tuning.TOUCH_CHUNK, 0xAB, dtype=np.uint8)
    with _parallel._PageToucher(a, top_of=speed) as toucher:
        pass
    assert toucher.top == speed.max()
    assert _parallel._top_speed(_kernels._readonly(speed)) == speed.max()
    assert _parallel._top_speed(_kernels._readonly(np.zeros(0))) == 1.0  # none: 1
    with _parallel._PageToucher(a) as toucher:  # no speeds, no top
        pass
    assert toucher.top is None


def test_big_3d_grids_cut_the_slabs_for_sharing_bit_for_bit(lean, monkeypatch):
    """From ``SHARED_CUTS_MIN_NODES_3D`` nodes (the terrain plan's 40 M) a 3D march's cuts are
    those placed for the slabs shared before each window, where the coarse march says their
    windows are shorter (the terrain plan's order-2 march: balance 1.881 -> 1.922,
    docs/performance.md); smaller 3D grids keep the interleave's cuts (the bench's 160^3
    FM²-shaped field: other cuts, simulated worse). The times are the serial march's bit
    for bit either way."""
    W, goal, start = _terrain(nx=192, ny=40, nz=14)
    h = (15.0, 15.0, 10.0)
    # the coarse march over every node: on a grid this small, a coarser one leaves a few
    # nodes per time bin, and both descents the same cuts
    monkeypatch.setattr(_tuning, "COARSE_3D", {1: 1, 2: 1})
    monkeypatch.setattr(_tuning, "COARSE_3D_Z", 1)
    monkeypatch.setitem(_tuning.SLABS_PER_THREAD, (3, 2), 4)  # 8 slabs to place
    seen = []
    real = _parallel.slab_bounds

    def spy(*args, **kw):
        seen.append((args, real(*args, **kw)))
        return seen[-1][1]

    monkeypatch.setattr(_parallel, "slab_bounds", spy)
    _below_and_at(monkeypatch, "SHARED_CUTS_MIN_NODES_3D", W, goal, start, h)
    (args, cuts_below), (args_at, cuts_at) = seen
    speed, st, shape3, h3, k, threads, more = args
    assert more < k  # more slabs only where asked for more than k
    assert k == 8 and threads == 2 and shape3 == W.shape
    monkeypatch.setitem(_tuning.SHARED_CUTS, 3, False)
    fixed = real(*args)  # the interleave's cuts
    assert np.array_equal(cuts_below, fixed)
    assert not np.array_equal(cuts_at, fixed)
    # the shared cuts' windows, as _assign shares the slabs, are shorter on the coarse march
    hist, f = _parallel._coarse_histogram(speed, st, shape3, h3)
    cum = np.vstack([np.zeros((1, hist.shape[1]), dtype=np.int64), np.cumsum(hist, axis=0)])
    assert f == 1
    assert _parallel._shared_cost(cum, cuts_at, threads) < _parallel._shared_cost(cum, fixed,
                                                                                 threads)


def test_big_3d_grids_take_their_own_slabs_and_windows_bit_for_bit(lean, monkeypatch):
    """From ``BIG_3D_NODES`` nodes (the terrain plan's march) a 3D march takes
    ``BIG_3D_SLABS_PER_THREAD`` slabs a thread and windows of ``BIG_3D_WINDOW_NODES`` nodes
    (keyed by order), smaller grids ``SLABS_PER_THREAD`` and ``WINDOW_NODES``; the times are the
    serial march's bit for bit either way."""
    W, goal, start = _terrain(nx=192, ny=40, nz=14)
    h = (15.0, 15.0, 10.0)
    monkeypatch.setitem(_tuning.SLABS_PER_THREAD, (3, 2), 2)
    monkeypatch.setitem(_tuning.WINDOW_NODES, (3, 2), 4000)
    monkeypatch.setitem(_tuning.BIG_3D_SLABS_PER_THREAD, 2, 3)
    monkeypatch.setitem(_tuning.BIG_3D_WINDOW_NODES, 2, 1000)
    monkeypatch.setattr(_tuning, "MORE_SLABS_3D", {})  # the slabs asked for, no more
    seen = []
    real = _parallel.march

    def spy(*args, **kwargs):
        T, stats = real(*args, **kwargs)
        seen.append(stats)
        return T, stats

    monkeypatch.setattr(_parallel, "march", spy)
    _below_and_at(monkeypatch, "BIG_3D_NODES", W, goal, start, h)
    small, big = seen
    assert small["slabs"] == 4 and big["slabs"] == 6
    # a window freezes ~its target: a quarter of the target, four times the windows
    assert big["windows"] > 2.5 * small["windows"]
