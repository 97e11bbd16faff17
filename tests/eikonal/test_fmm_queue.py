"""The march's monotone radix queue at its limits: exact ties, a band larger
than the initial entry pool (pool growth and resume), huge key spreads.

Expected values are exact (derived in the comments); ``rtol = 1e-12``.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from numba import njit

from .fmm_checks import assert_same_field, fast_marching_parallel
from fm2uav.eikonal import _kernels, fast_marching
from fm2uav.eikonal._reference import fast_marching_reference

RTOL = 1e-12


@pytest.fixture
def grow_calls(monkeypatch):
    """Count the pool doublings of the march."""
    calls = []
    original = _kernels._grow

    def spy(pool, nxt, st):
        calls.append(nxt.size)
        return original(pool, nxt, st)

    monkeypatch.setattr(_kernels, "_grow", spy)
    return calls


@pytest.mark.parametrize("order", [1, 2])
def test_checkerboard_sources_overflow_the_initial_pool(grow_calls, order):
    # Sources on every node with i + j even (more than 64: plain T = 0 nodes),
    # speed 2, h = 1. Every other node has a source on both sides along both
    # axes, so its update is the two-axis one from T1 = T2 = 0:
    # 2 T^2 = (h/v)^2 -> T = 1 / (2 sqrt 2); order 2 cannot apply (the nodes two
    # steps away are not frozen before it). The band holds half the grid,
    # far more than the initial pool (1/16 of the nodes, at least two reserves
    # of RESERVE_BLOCKS): the march must grow the pool and resume.
    n = 1100
    assert n * n // 2 > 2 * 2 * _kernels.RESERVE_BLOCKS * _kernels.BLOCK  # two doublings
    i, j = np.indices((n, n))
    src = np.argwhere((i + j) % 2 == 0)
    T = fast_marching(np.full((n, n), 2.0), src, order=order, threads=1)  # the serial queue
    expected = np.where((i + j) % 2 == 0, 0.0, 1.0 / (2.0 * math.sqrt(2.0)))
    assert_same_field(T, expected, RTOL)
    assert len(grow_calls) >= 2


def test_band_given_on_entry_larger_than_the_pool(grow_calls):
    # Every node starts in the band with a time far above its arrival time
    # (1e6 + anything); each is lowered by the march long before that key could
    # be popped, so the result is the plain march from the source. Seeding the
    # band overflows the initial pool (phase 0 resumes after growing).
    n = 500
    speed = np.random.default_rng(7).uniform(0.5, 2.0, (n, n))
    plain = fast_marching(speed, [(n // 2, n // 3)], order=1, source_ball=False)
    T = np.full(n * n, 1e6) + np.arange(n * n)
    state = np.full(n * n, _kernels.BAND, dtype=np.uint8)
    c = (n // 2) * n + n // 3
    T[c] = 0.0
    state[c] = _kernels.FROZEN
    T, _ = _kernels.march(speed.reshape(-1), _kernels.Start.whole(T, state, (n, n, 1)),
                          (n, n, 1), (1.0, 1.0, 1.0), 1, np.zeros((0, 3), np.int64))
    assert grow_calls
    assert_same_field(T.reshape(n, n), plain, RTOL)


@pytest.mark.parametrize("order", [1, 2])
@pytest.mark.parametrize("shape", [(300, 200), (20, 30, 40)])
def test_plane_wave_has_many_exact_ties(shape, order):
    # Sources on the whole face x = 0, speed 1, h = 1: a plane wave, T = i
    # exactly (a linear T is exact for both stencils). All nodes of a plane
    # share one key, hundreds of exact ties in one bucket (several blocks).
    src = np.argwhere(np.indices(shape)[0] == 0)
    T = fast_marching(np.ones(shape), src, order=order)
    expected = np.broadcast_to(
        np.arange(shape[0], dtype=float).reshape((-1,) + (1,) * (len(shape) - 1)), shape
    )
    assert_same_field(T, expected, RTOL)


@pytest.mark.parametrize("order", [1, 2])
def test_keys_spanning_many_binary_orders_match_the_reference(order):
    # Speeds from 1e-6 to 1e3 (seeded): keys differ by up to ~12 orders of
    # magnitude, so entries live on many radix levels at once.
    rng = np.random.default_rng(3)
    speed = 10.0 ** rng.uniform(-6, 3, (14, 13))
    T = fast_marching(speed, [(0, 0), (13, 12)], order=order)
    R = fast_marching_reference(speed, [(0, 0), (13, 12)], order=order)
    assert_same_field(T, R, 1e-9)


@pytest.mark.parametrize("order", [1, 2])
@pytest.mark.parametrize("shape, sources", [((31, 31), [(5, 5), (25, 20)]),
                                            ((9, 8, 7), [(1, 1, 1), (7, 6, 2)])])
def test_deferred_nodes_are_frozen_once_their_neighbour_does_not_lower_them(shape, sources,
                                                                            order):
    # A far node reached while a band neighbour across another axis is earlier gets its
    # time but no queue entry (deferred): that neighbour, frozen first, updates it again.
    # At order 2 that update can come out above the deferred time (the order-2 term is
    # not monotone), two fronts meet here, and the speeds vary: the node must then be
    # queued at the time it has, or it is never frozen (inf). Every node is reached, at
    # the reference march's times, in the serial march and on slabs (two threads).
    rng = np.random.default_rng(11)
    for speed in (np.ones(shape), 0.5 + rng.random(shape)):
        R = fast_marching_reference(speed, sources, order=order)
        assert np.isfinite(R).all()
        for T in (fast_marching(speed, sources, order=order),
                  fast_marching_parallel(speed, sources, order=order, threads=2)):
            assert np.isfinite(T).all()
            assert_same_field(T, R, RTOL)


def test_stop_at_after_pool_growth(grow_calls):
    # Checkerboard sources as above plus stop_at: the march stops once the stop
    # node is frozen, after at least one resume; the stop node has its value.
    n = 600
    i, j = np.indices((n, n))
    src = np.argwhere((i + j) % 2 == 0)
    stop = (n - 1, n - 2)  # i + j odd: not a source
    T = fast_marching(np.full((n, n), 2.0), src, order=1, stop_at=[stop])
    assert math.isclose(T[stop], 1.0 / (2.0 * math.sqrt(2.0)), rel_tol=RTOL)
    assert grow_calls


@pytest.mark.parametrize("shape", [(61, 47), (17, 19, 13)])
def test_kept_work_buffers_leave_no_trace(shape):
    # The march keeps its work buffers for the thread's next call (stale data in
    # them): a march after a larger one with walls, a band and another order gives
    # the same times, bit for bit, as the same march on fresh buffers.
    rng = np.random.default_rng(5)
    speed = 0.5 + rng.random(shape)
    src = [tuple(n // 3 for n in shape)]
    _kernels._KEPT.bufs = {}  # fresh buffers
    first = fast_marching(speed, src, order=2)
    big = tuple(n + 9 for n in shape)
    walls = np.where(rng.random(big) < 0.2, 0.0, 1.0 + rng.random(big))
    walls[tuple(n // 2 for n in big)] = 1.0
    fast_marching(walls, [tuple(n // 2 for n in big)], order=1)
    assert set(_kernels._KEPT.bufs) == {"pair", "pool"}
    again = fast_marching(speed, src, order=2)
    np.testing.assert_array_equal(again, first)


@njit(cache=False)
def _drain(ahead, T, V, nodes, seed, s1, s2, steps):
    """A march's queue workload on the band times ``-T[nodes]``: pop the smallest entry,
    skip it if its node is frozen, freeze it, then lower a few pseudo-random band nodes
    to the popped time plus 0 (exact ties) to 1/8 (new entries; the old ones stay behind,
    outdated). ``ahead``: pop with ``_pop_ahead`` (strides ``s1``, ``s2``; 2: ``scans`` False, the
    3D order-1 windows' pop), else ``_pop``.
    Returns the popped nodes (outdated entries as ``-1``) in order."""
    nblk = 8 * nodes.size // _kernels.BLOCK + 2 * _kernels.RESERVE_BLOCKS
    pool = np.empty(2 * nblk * _kernels.BLOCK, dtype=np.uint64)
    nxt = np.empty(nblk, dtype=np.uint32)
    bk = np.empty(2 * int(_kernels._NB), dtype=np.uint32)
    mw = np.empty(_kernels._NW, dtype=np.uint64)
    st = np.zeros(_kernels.ST_SIZE, dtype=np.uint64)
    _kernels.init_queue(nxt, bk, mw, st)
    nfree, fh, cur, last = np.uint64(st[2]), np.uint64(st[3]), np.uint64(st[4]), np.uint64(0)
    for c in nodes:
        k = _kernels._bits(-T[c])
        nfree, fh, cur = _kernels._push(_kernels._bucket(k, last), k, np.uint64(c), pool, nxt,
                                        bk, mw, nfree, fh, cur)
    out = np.full(steps, -2, dtype=np.int64)
    x = np.uint64(seed)
    for i in range(steps):
        if ahead:  # 1: every prefetch (the serial 3D march), 2: the level-0 one only
            c, nfree, fh, cur, last = _kernels._pop_ahead(T, V, pool, nxt, bk, mw, nfree, fh,
                                                          cur, last, s1, s2, True, ahead == 1)
        else:
            c, nfree, fh, cur, last = _kernels._pop(T, pool, nxt, bk, mw, nfree, fh, cur, last)
        if c == np.uint64(0xFFFFFFFF):
            break
        if not T[c] < 0.0:
            out[i] = -1
            continue
        t = -T[c]
        T[c] = t
        out[i] = c
        for _ in range(3):
            x = x * np.uint64(6364136223846793005) + np.uint64(1442695040888963407)
            nb = nodes[(x >> np.uint64(33)) % np.uint64(nodes.size)]
            new = t + float((x >> np.uint64(20)) & np.uint64(7)) / 64.0
            if T[nb] < 0.0 and new < -T[nb]:
                T[nb] = -new
                k = _kernels._bits(new)
                nfree, fh, cur = _kernels._push(_kernels._bucket(k, last), k, nb, pool, nxt,
                                                bk, mw, nfree, fh, cur)
    return out


@pytest.mark.parametrize("s1, s2", [(64, 8), (40, 0)])
def test_pop_ahead_pops_the_same_nodes_as_pop(s1, s2):
    # The 3D march pops with _pop_ahead (prefetching the lines of the next pops); the
    # prefetches must not change the queue: the same nodes in the same order as _pop,
    # on a workload with exact ties, outdated entries and keys spread over many radix
    # levels (splits, scans, multi-block buckets). The nodes sit where the prefetch's
    # strides stay inside T, as inner nodes of a padded grid do.
    rng = np.random.default_rng(11)
    m = 3000
    margin = 2 * (s1 + s2)
    nodes = np.arange(margin, margin + m, dtype=np.uint64)
    T0 = np.full(m + 2 * margin, np.nan)
    times = (np.round(rng.uniform(0.0, 50.0, m) * 16.0) + 1.0) / 16.0  # many exact ties
    times[::7] *= 10.0 ** rng.uniform(-9, 3, times[::7].size)  # many binary orders
    T0[margin:margin + m] = -times
    V = np.ones(T0.size)
    seqs = [_drain(ahead, T0.copy(), V, nodes, 3, np.uint64(s1), np.uint64(s2), 6 * m)
            for ahead in (0, 1, 2)]
    np.testing.assert_array_equal(seqs[1], seqs[0])
    np.testing.assert_array_equal(seqs[2], seqs[0])
    popped = seqs[0][seqs[0] >= 0]
    assert np.array_equal(np.sort(popped), nodes.astype(np.int64))  # each node once
    assert (seqs[0] == -1).any() and (seqs[0] == -2).any()  # outdated entries; drained
