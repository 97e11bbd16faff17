"""The parallel march (issue 27): the serial march's times on slabs of the grid.

``fast_marching(..., threads=k)`` with ``k >= 2`` marches slabs of the grid in time windows
(:mod:`fm2uav.eikonal._parallel`); its arrival times must equal the serial march's to
round-off, at order 1 and 2, on every field, spacing, thread count and with ``stop_at``. The exactness cases of
``test_fmm_exact.py`` also run on it (the ``parallel`` solver of ``fmm_checks``). Speed is
measured in ``benchmarks/bench_core.py`` (the ``threads`` rows), never here.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

import numba
import numpy as np
import pytest

from fm2uav.errors import InputError
from fm2uav.eikonal import _kernels, _parallel, fast_marching
from fm2uav.eikonal.fmm import _as_speed, _source_start

from .fmm_checks import fast_marching_parallel

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))
from benchmarks.fields import fm2_shaped, smooth  # noqa: E402

RTOL = 1e-12


def _fields(shape):
    """Constant speed from a corner, the smooth field, an FM²-shaped map (walls, W -> 0),
    and a plateau: two thirds of the nodes at the top speed across every slab interface,
    the rest slower and varying (the march's plateau mask, not the one-speed register)."""
    yield "constant", np.ones(shape), (0,) * len(shape)
    v, src = smooth(shape)
    yield "smooth", v, src
    v, src = fm2_shaped(shape, seed=1)
    yield "fm2", v, src
    v = np.ones(shape)
    band = (slice(None), slice(0, shape[1] // 3))
    v[band] = np.random.default_rng(3).uniform(0.3, 0.9, v[band].shape)
    yield "plateau", v, tuple(n // 2 for n in shape)


def assert_equal_times(a, b):
    fa, fb = np.isfinite(a), np.isfinite(b)
    assert np.array_equal(fa, fb), f"{int(fa.sum())} vs {int(fb.sum())} nodes reached"
    np.testing.assert_allclose(b[fa], a[fa], rtol=RTOL, atol=0)


@pytest.mark.parametrize("order", [1, 2])
@pytest.mark.parametrize("shape", [(97, 81), (41, 37, 29)])
@pytest.mark.parametrize("threads", [2, 3])
def test_parallel_times_equal_the_serial_march(shape, threads, order):
    for name, v, src in _fields(shape):
        for h in (1.0, (1.0, 0.7, 1.3)[:len(shape)]):
            serial = fast_marching(v, [src], order=order, spacing=h, threads=1)
            par = fast_marching_parallel(v, [src], order=order, spacing=h, threads=threads)
            assert_equal_times(serial, par)
            assert np.isfinite(par).sum() > 0.5 * par.size, name


@pytest.mark.parametrize("order", [1, 2])
@pytest.mark.parametrize("shape", [(97, 81), (41, 37, 29)])
def test_lean_layout_equals_the_serial_lean_march(shape, order, monkeypatch):
    # big grids (over LEAN_NODES padded nodes) keep 1 / speed^2 in float32 in both marches
    layouts = []
    pad = _kernels.pad_grid

    def spy(*args):
        layouts.append(args[-1].dtype)  # the padded 1 / speed^2
        return pad(*args)

    monkeypatch.setattr(_kernels, "pad_grid", spy)
    monkeypatch.setattr(_kernels, "LEAN_NODES", 0)
    for name, v, src in _fields(shape):
        layouts.clear()
        serial = fast_marching(v, [src], order=order, threads=1)
        par = fast_marching_parallel(v, [src], order=order)
        assert set(layouts) == {np.dtype(np.float32)}, name
        assert_equal_times(serial, par)


@pytest.mark.parametrize("order", [1, 2])
@pytest.mark.parametrize("shape", [(97, 81), (41, 37, 29)])
def test_parallel_stop_at_freezes_what_the_serial_march_freezes(shape, order):
    for name, v, src in _fields(shape):
        free = np.argwhere(v > 0)
        for stop in ([tuple(free[-1])], [tuple(free[len(free) // 3]), tuple(free[-7])]):
            serial = fast_marching(v, [src], order=order, stop_at=stop, threads=1)
            par = fast_marching_parallel(v, [src], order=order, stop_at=stop)
            assert all(np.isfinite(par[s]) for s in stop), name
            # nodes tied with the latest stop node may be frozen before it or not, in the
            # serial march too (its queue's order of ties; the plateau field has many):
            # every other node is equal
            last = max(serial[s] for s in stop)
            differ = np.isfinite(serial) != np.isfinite(par)
            assert np.all(np.where(np.isfinite(serial), serial, par)[differ] == last), name
            both = np.isfinite(serial) & np.isfinite(par)
            assert both.sum() > 0.3 * np.isfinite(serial).sum() > 0, name
            np.testing.assert_allclose(par[both], serial[both], rtol=RTOL, atol=0)


@pytest.mark.parametrize("order", [1, 2])
def test_several_sources_and_no_ball_equal_the_serial_march(order):
    v, _ = fm2_shaped((120, 90), seed=2)
    free = np.argwhere(v > 0.3)
    rng = np.random.default_rng(0)
    sources = [tuple(c) for c in free[rng.choice(len(free), 70, replace=False)]]  # > 64: no ball
    assert_equal_times(fast_marching(v, sources, order=order, threads=1),
                       fast_marching_parallel(v, sources, order=order))
    src = [tuple(free[5])]
    assert_equal_times(fast_marching(v, src, order=order, threads=1, source_ball=False),
                       fast_marching_parallel(v, src, order=order, source_ball=False))
    sources = [tuple(c) for c in free[rng.choice(len(free), 5, replace=False)]]  # 5 balls
    assert_equal_times(fast_marching(v, sources, order=order, threads=1),
                       fast_marching_parallel(v, sources, order=order))


def _start(v, src):
    v = _as_speed(v)
    shape3 = v.shape + (1,) * (3 - v.ndim)
    src3 = np.zeros((1, 3), dtype=np.int64)
    src3[0, :v.ndim] = src
    return v.reshape(-1), _source_start(v, src3, shape3, (1.0,) * 3, 2.0, 2.0), shape3


@pytest.mark.parametrize("order", [1, 2])
def test_windows_repair_nodes_the_other_slab_reaches_first(order):
    """The case the repairs exist for: a fast channel along x crossing the slab interface
    lets the wave arrive there from the other slab after this one froze its side; the
    re-opened nodes must end at the serial times."""
    v = np.full((200, 60), 0.2)
    v[:, 28:32] = 5.0  # fast lane across every slab
    flat, start, shape3 = _start(v, (2, 30))
    T, stats = _parallel.march(flat, start, shape3, (1.0,) * 3, 2, order=order)
    serial = fast_marching(v, [(2, 30)], order=order, threads=1, source_ball=False)
    assert stats["slabs"] >= 2 and stats["windows"] > 1
    assert stats["reopened"] > 0
    assert_equal_times(serial.reshape(-1), T)


def _random_case(seed):
    """A random FM²-shaped field (2D or 3D, obstacle share, spacing, source), as a
    property-based test draws them: the seed is the example."""
    rng = np.random.default_rng(seed)
    if seed % 3:
        shape = (int(rng.integers(40, 130)), int(rng.integers(20, 90)))
    else:
        shape = tuple(int(n) for n in rng.integers(14, 34, size=3))
    v, _ = fm2_shaped(shape, seed=seed, share=float(rng.uniform(0.05, 0.35)))
    v = v ** float(rng.uniform(0.5, 2.0))  # W rising faster or slower from the walls
    h = tuple(float(x) for x in rng.uniform(0.6, 1.6, size=len(shape)))
    free = np.argwhere(v > 0.2)
    src = tuple(int(c) for c in free[rng.integers(len(free))])
    return v, src, h, int(rng.integers(2, 4))


@pytest.mark.parametrize("block", range(4))
def test_order_2_on_random_fm2_fields_and_thin_slabs_equals_the_serial_march(block,
                                                                             monkeypatch):
    """Order 2 converges to the serial times however the slabs cut the wave: random
    FM²-shaped fields, 2 or 3 threads, slabs of 2 to 6 rows (every node near a ghost, the
    order-2 stencil reading two slabs' rows); the repairs re-open nodes and raise some
    (the update is not monotone: a lower time two away raises the order-2 term)."""
    monkeypatch.setattr(_parallel, "MIN_SLAB_ROWS", 2)
    monkeypatch.setattr(_parallel, "MIN_SLAB_NODES", 0)
    reopened = raised = 0
    for seed in range(6 * block, 6 * block + 6):
        v, src, h, threads = _random_case(seed)
        rows = 2 + seed % 5
        nth = min(threads, numba.config.NUMBA_NUM_THREADS)  # the march's thread count
        per = max(1, v.shape[0] // rows // nth)
        monkeypatch.setattr(_parallel, "SLABS_PER_THREAD", {2: per, 3: per})
        monkeypatch.setattr(_parallel, "slab_bounds",  # equal slabs of ``rows`` rows
                            lambda speed, start, shape3, h3, k, t=2: np.linspace(
                                0, shape3[0], k + 1).round().astype(np.int64))
        flat, start, shape3 = _start_h(v, src, h)
        T, stats = _parallel.march(flat, start, shape3, h + (1.0,) * (3 - v.ndim), threads,
                                   order=2)
        serial = fast_marching(v, [src], order=2, spacing=h, threads=1)
        assert stats["slabs"] == nth * per, seed
        assert_equal_times(serial.reshape(-1), T)
        reopened += stats["reopened"]
        raised += stats["raised"]
    assert reopened > 0 and raised > 0


def _start_h(v, src, h):
    v = _as_speed(v)
    shape3 = v.shape + (1,) * (3 - v.ndim)
    h3 = tuple(h) + (1.0,) * (3 - v.ndim)
    src3 = np.zeros((1, 3), dtype=np.int64)
    src3[0, :v.ndim] = src
    extent = max((n - 1) * hk for n, hk in zip(v.shape, h))
    radius = max(2.0 * max(h), 0.05 * extent)
    return v.reshape(-1), _source_start(v, src3, shape3, h3, radius, 2.0 * max(h)), shape3


def test_slab_split_follows_the_wave_of_an_off_centre_source():
    """Two slabs are cut where a coarse march balances the windows: near the source when
    it sits off-centre (an even cut would leave one slab idle while the wave crosses the
    other), in the middle for a centred one."""
    n = 512
    v = np.ones((n, 64))
    flat, start, shape3 = _start(v, (40, 32))
    cut = _parallel.slab_bounds(flat, start, shape3, (1.0,) * 3, 2)[1]
    assert cut < n // 3
    flat, start, shape3 = _start(v, (n // 2, 32))
    cut = _parallel.slab_bounds(flat, start, shape3, (1.0,) * 3, 2)[1]
    assert abs(cut - n // 2) <= 16


@pytest.mark.parametrize("shape, gain", [((1024, 1024), 1.01), ((160, 120, 100), 1.02)])
def test_balanced_cuts_of_many_slabs_shorten_the_windows_critical_path(shape, gain,
                                                                        monkeypatch):
    """With several slabs per thread the cuts follow the wave too (the bench's FM²-shaped
    map, source at 0.3 of x): the windows' balance (nodes frozen over the sum of each
    window's busiest thread's share, the speed-up they allow) beats equal slabs, and the
    times stay the serial march's. (2D, 4 slabs per thread: 1.651 against 1.625 for equal
    slabs; 8 per thread gained more balance but no wall time.)"""
    monkeypatch.setattr(_parallel, "MIN_SLAB_NODES", 0)  # slab counts of 2048^2 and 160^3
    v, src = fm2_shaped(shape)
    flat, start, shape3 = _start(v, src)
    k = 2 * _parallel.SLABS_PER_THREAD[len(shape)]
    cuts = _parallel.slab_bounds(flat, start, shape3, (1.0,) * 3, k, 2)
    assert cuts[0] == 0 and cuts[-1] == shape[0] and len(cuts) == k + 1
    assert np.all(np.diff(cuts) >= _parallel.MIN_SLAB_ROWS)
    T, balanced = _parallel.march(flat, start, shape3, (1.0,) * 3, 2)
    serial, _ = _kernels.march(flat, start, shape3, (1.0,) * 3, 1, np.zeros((0, 3), dtype=int))
    assert_equal_times(serial, T)
    even = np.linspace(0, shape[0], k + 1).round().astype(np.int64)
    assert not np.array_equal(cuts, even)
    monkeypatch.setattr(_parallel, "slab_bounds", lambda *a: even)
    T, equal = _parallel.march(flat, start, shape3, (1.0,) * 3, 2)
    assert_equal_times(serial, T)
    assert balanced["slabs"] == equal["slabs"] == k
    assert balanced["balance"] > gain * equal["balance"]


@pytest.mark.parametrize("bad", [0, -2, 1.5, True, "2"])
def test_bad_threads_are_refused(bad):
    with pytest.raises(InputError, match="threads must be an integer >= 1"):
        fast_marching(np.ones((4, 4)), [(0, 0)], threads=bad)


@pytest.mark.parametrize("bad", ["0", "two", "-1"])
def test_bad_environment_variable_is_refused_by_name(monkeypatch, bad):
    monkeypatch.setenv("FM2UAV_THREADS", bad)
    with pytest.raises(InputError, match="FM2UAV_THREADS must be an integer >= 1"):
        fast_marching(np.ones((4, 4)), [(0, 0)])


def test_threads_default_to_the_variable_then_every_core(monkeypatch):
    monkeypatch.setenv("FM2UAV_THREADS", "3")
    assert _parallel.resolve_threads(None) == 3
    assert _parallel.resolve_threads(1) == 1  # the argument wins
    monkeypatch.delenv("FM2UAV_THREADS")
    assert _parallel.resolve_threads(None) == len(os.sched_getaffinity(0))


def _no_parallel(*args, **kwargs):
    raise AssertionError("the parallel march ran")


def test_small_grids_and_one_thread_march_serially(monkeypatch):
    monkeypatch.setattr(_parallel, "march", _no_parallel)
    small = int(np.sqrt(_parallel.PARALLEL_MIN_NODES)) - 1
    fast_marching(np.ones((small, small)), [(0, 0)], order=1, threads=2)
    fast_marching(np.ones((small, small)), [(0, 0)], order=2, threads=2)
    monkeypatch.setattr(_parallel, "PARALLEL_MIN_NODES", 0)
    fast_marching(np.ones((40, 40)), [(0, 0)], order=2, threads=1)
    fast_marching(np.ones((40, 40)), [(0, 0)], order=1, threads=1)
    monkeypatch.setenv("FM2UAV_THREADS", "1")
    fast_marching(np.ones((40, 40)), [(0, 0)], order=1)
    monkeypatch.setenv("FM2UAV_THREADS", "2")
    with pytest.raises(AssertionError, match="parallel march ran"):
        fast_marching(np.ones((40, 40)), [(0, 0)], order=1)
    fast_marching(np.ones((40, 40)), [(0, 0)], order=2)  # order 2: serial unless ORDER2
    monkeypatch.setattr(_parallel, "ORDER2", True)
    with pytest.raises(AssertionError, match="parallel march ran"):
        fast_marching(np.ones((40, 40)), [(0, 0)], order=2)


def test_plan_options_take_threads():
    from fm2uav.planning.params import PlanOptions

    assert PlanOptions(threads=2).threads == 2
    assert PlanOptions().threads is None
    with pytest.raises(InputError, match=r"threads must be an integer >= 1.*planner\.threads"):
        PlanOptions(threads=0)


def test_slab_count_keeps_slabs_of_a_minimum_size():
    v = np.ones((1024, 1024))
    flat, start, shape3 = _start(v, (300, 500))
    _, stats = _parallel.march(flat, start, shape3, (1.0,) * 3, 2)
    assert stats["slabs"] == v.size // _parallel.MIN_SLAB_NODES == 8  # not 2 * 8
    v = np.ones((96, 40))
    flat, start, shape3 = _start(v, (30, 20))
    _, stats = _parallel.march(flat, start, shape3, (1.0,) * 3, 2)
    assert stats["slabs"] == 2  # one per thread however small


def test_queues_that_run_low_grow_and_the_march_resumes(monkeypatch):
    """Tiny entry pools and repair heaps: the start and the windows stop when a slab runs
    low, the queues double, and the march goes on to the serial times."""
    monkeypatch.setattr(_parallel, "POOL_MIN_BLOCKS", 8)
    monkeypatch.setattr(_parallel, "HEAP_START", 8)
    v = np.full((200, 60), 0.2)
    v[:, 28:32] = 5.0
    flat, start, shape3 = _start(v, (2, 30))
    for order in (1, 2):
        T, stats = _parallel.march(flat, start, shape3, (1.0,) * 3, 2, order=order)
        assert stats["reopened"] > 0
        serial = fast_marching(v, [(2, 30)], order=order, threads=1, source_ball=False)
        assert_equal_times(serial.reshape(-1), T)
    for name, v, src in _fields((64, 48, 40)):
        for order in (1, 2):
            assert_equal_times(fast_marching(v, [src], order=order, threads=1),
                               fast_marching_parallel(v, [src], order=order))
