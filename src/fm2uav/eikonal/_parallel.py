"""The parallel Fast Marching (order 1): slabs, time windows, ghost exchange, repair.

Private module: :func:`fm2uav.eikonal.fast_marching` calls :func:`march` for
grids of at least :data:`PARALLEL_MIN_NODES` nodes when more than one thread is
allowed (``threads``, ``FM2UAV_THREADS``) and the order is 1 (``stop_at`` too).
Order 2 marches serially: its stencil reads two nodes upwind, so the ghosts and
the repairs would have to reach two rows, which is not built (nor tested) yet.

Design (Yang & Stern 2017, domain-decomposition FMM)
----------------------------------------------------
* The grid is cut along x (the slowest-varying axis of the C layout) into
  ``K`` slabs, :data:`SLABS_PER_THREAD` per thread, thread ``t`` marching slabs
  ``t, t + threads, ...`` (interleaved strips keep both threads busy when the
  wave starts off-centre, and a coarse march places the cuts, :func:`slab_bounds`; in 2D
  for the slabs shared before each window where that shortens the windows,
  :data:`SHARED_CUTS`),
  unless sharing them longest first by the last window's freezes promises a shorter
  window (:func:`_assign`, before every window). The set-up pads the slabs in parallel
  (:func:`_pad_slabs`) and the result is unpadded so (:func:`_unpad_slabs`).
  Each slab is a padded grid of its own, laid out exactly as the
  serial march's (:func:`fm2uav.eikonal._kernels.pad_grid`), one after the other
  in one buffer (the serial march's kept huge-page buffers, chosen by its
  :func:`~fm2uav.eikonal._kernels._buffers`; in the lean layout of big grids float32 ``V``
  and the times compacted in place, as there): its two ghost x-slabs hold, between
  windows, the *frozen* times of the neighbouring slab's boundary rows (``NaN`` where not
  frozen), so the serial kernels' update (``_solve_iso``, ``_axis_term``, ``_combine``,
  the plateau register ``_rhs``) and radix queue (``_push``, ``_pop``) run unchanged on a
  slab.
* **2D interleaved**, as the serial march: a 2D map (outside the lean layout) whose
  passable nodes do not all have one speed keeps each node's time and ``1 / speed^2``
  side by side in one array (node ``c``'s time at element ``2 c``, its speed term at
  ``2 c + 1``; the kernels take the buffer and the buffer shifted by one, and every node
  index in the kernels, the queues, the boundary lists, the start rows and the stop
  nodes is an element index: strides ``sx = 2 (ny + 2)``, ``sy = 2``); the frozen-on-entry
  and plateau masks keep a bit per node (element index halved). An update reads a
  neighbour's time and speed from one cache line. A uniform map keeps the separate arrays
  and reads no speed (the plateau register). ``march(..., interleave=False)`` forces the
  separate arrays (the tests: the same times bit for bit).
* **Far neighbours** (2D): a window freezing a node gives its far neighbours the one-axis
  update along their axis, as the serial march (:data:`FAR_ONE_AXIS`). Valid in a slab
  because a far node never has a frozen neighbour: a pop, a node frozen on entry (the
  start) and a ghost (the exchange, its one own neighbour) each update their band and far
  own neighbours when they become frozen, and a re-opened node had done so when it was
  frozen first; so the full update of that node reads one frozen neighbour and gives the
  same bits (the tests run with the rule on and off, one-row slabs included, and compare
  the times and statistics bit for bit).
* Time windows: every slab pops, with its own queue and in parallel, the nodes
  whose time is below ``t_w``, and lists the nodes it froze in its two boundary rows;
  then (barrier) every slab copies those of its neighbours into its ghosts (not the
  whole rows, e.g. 162x162 planes per slab and window on 160^3). A node next to a
  ghost whose value changed is
  updated again; if that lowers a node frozen already, it is **re-opened**
  (band again, queued). When a node is frozen, each frozen neighbour later
  than it is updated again too and re-opened if that lowers it, so the
  corrections cascade in time order (through the same queues, never a stack).
  ``t_w`` then advances to the smallest queued time plus a width that adapts
  so a window freezes ~``WINDOW_NODES`` nodes.
* Queued times below the radix queue's lower bound (re-opened nodes) go to a
  small binary heap (:mod:`._heap`) that is emptied first: its keys are all
  below the radix queue's, so the slab still pops its exact minimum.
* Nodes frozen on entry (sources, their balls) are never lowered, as in the
  serial march. With stop nodes, the march ends once they are all frozen no
  later than every queued time (nothing queued can lower them), and nodes
  later than the latest of them are ``inf``, as the serial march leaves them.
* It ends when every queue is empty after an exchange. The result is the fixed
  point of the upwind scheme, which is what the serial march computes: the
  times agree to round-off (tests/eikonal/test_fmm_parallel.py).
"""

from __future__ import annotations

import contextlib
import math
import os

import numpy as np
from numba import njit, prange

from . import _kernels
from ._heap import sift_down, sift_up
from ._kernels import (_INF, _NB, _NIL, _NW, _ONE, _U, _ZERO, RESERVE_BLOCKS, BLOCK,
                       _at_plateau, _axis_term, _bits, _bucket, _prefetch, _combine, _pop, _push,
                       _rhs, _side_min, _solve_iso, pad_grid, unpad_grid)

#: The windows meet at a barrier several hundred times per march: a thread that waits
#: there sleeps instead of spinning (OpenMP's default spins), or on a busy machine the
#: spinning thread takes the core its partner needs (measured on 2048^2 with 10 runnable
#: processes on 2 cores: 3.4 CPU-s spinning, 0.56 s passive, serial 0.53 s). Read by
#: libgomp when numba first starts its thread pool; a value set by the user stays.
os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")

__all__ = ["march", "resolve_threads", "PARALLEL_MIN_NODES", "THREADS_ENV"]

#: Environment variable with the default thread count of the march (an integer >= 1).
THREADS_ENV = "FM2UAV_THREADS"
#: Grids of fewer nodes march serially whatever the thread count. Measured
#: (benchmarks/bench_core.py, "threads" rows, a machine at load 9 on 2 cores):
#: on 1024^2 the busiest thread takes 0.06 s of the serial 0.099 CPU-s (1.65x on
#: an idle machine) and the wall time is equal; below, a window holds fewer nodes
#: per barrier and the wall time on a busy machine decides: kept serial.
PARALLEL_MIN_NODES = 1_000_000
#: Each slab gets at least this many x-slabs (rows), else fewer slabs are used.
MIN_SLAB_ROWS = 16
#: ... and at least this many nodes (but every thread one slab): thin slabs cost repairs.
#: Measured on 1024^2 smooth (2 threads, CPU over the serial march's, loaded machine):
#: 2/4/8 slabs per thread 1.05x/1.08x/1.24x at the same windows' balance (1.94-1.96).
MIN_SLAB_NODES = 2**17
#: Slabs per thread, thread ``t`` marching slabs ``t, t + threads, ...``: strips
#: interleaved across the grid keep both threads busy when the wave starts off-centre
#: (and :func:`slab_bounds` places the cuts). Measured on the FM²-shaped fields (source
#: at 0.3 of x), 2 threads, windows of 32768 nodes, balanced cuts: the windows' balance
#: (``stats["balance"]``, the speed-up they allow) 2D 4/8 slabs per thread 1.69/1.76,
#: 3D 2/4 1.65/1.84, process CPU the same within noise (0.88-0.96x the serial march's;
#: the exchange reads only the nodes frozen in the boundary rows). In 2D the better
#: balance of 8 did not show in wall time on the idle machine (2048², 2 threads, medians
#: of 5 interleaved: constant 0.257/0.261 s, smooth 0.292/0.302 s, FM²-shaped
#: 0.234/0.248 s with 4/8 slabs per thread): 2D keeps 4. (With :data:`SHARE_SLABS`, 2D
#: FM²-shaped 4/8: balance 1.76/1.81 for 2.2x the re-opened nodes.)
SLABS_PER_THREAD = {2: 4, 3: 4}
#: Target number of nodes frozen per window (all slabs together); the window
#: width adapts to it. Fewer, wider windows cost fewer barriers and more repairs:
#: measured on 160^3 (2 threads, CPU over the serial march's, loaded machine) constant
#: speed 8192/16384/32768 nodes 1.15x/0.97x/0.85x; FM²-shaped 32768/65536 0.92x/2.4x
#: (wider windows than the wave's crossing of a slab re-open nodes in cascades).
WINDOW_NODES = 32768
#: Share the slabs among the threads anew before every window, longest first by the
#: freezes of the last window, when that predicts a shorter window than the fixed
#: interleave (:func:`_assign`); False: always the interleave. Windows' balance with /
#: without (2 threads, 4 slabs per thread): FM²-shaped 2048^2 1.654 -> 1.759, 160^3 1.84 ->
#: 1.90; constant speed the same (1.99, 1.93 -> 1.95).
SHARE_SLABS = True
#: 2D: a far neighbour of the node a window freezes gets the one-axis update along their
#: axis, as in the serial march (valid in a slab: see the window's docstring); False: the
#: full update (the same times bit for bit; the tests run both).
FAR_ONE_AXIS = True
#: Free repair-heap slots kept before each node's pushes (one pop pushes at most 7).
HEAP_RESERVE = 8
#: Smallest start of a slab's repair heap (entries; at least 4 boundary rows) and
#: entry pool (blocks); both double when a window runs low.
HEAP_START = 4096
POOL_MIN_BLOCKS = 2 * RESERVE_BLOCKS

# slots of the per-slab control array ``ctl`` (float64)
_C_NEXT = 0    # smallest queued time after the last window or exchange (inf: none)
_C_POPS = 1    # nodes frozen in the last window
_C_REOPEN = 2  # nodes re-opened so far
_C_STATUS = 3  # 0 ok, 1 entry pool low, 2 repair heap full
_C_SIZE = 4

# slots of the march state ``st`` (uint64), shared with the serial layout
_NFREE = 2
_FH = 3
_CUR = 4
_LAST = 5
_RSIZE = 8    # entries in the repair heap
_ST = 9


def resolve_threads(threads) -> int:
    """The thread count of a march: ``threads``, else ``FM2UAV_THREADS``, else every core.

    Parameters
    ----------
    threads : int or None
        Threads the march may use (``>= 1``); None: the environment variable
        ``FM2UAV_THREADS`` if set, else the cores this process may run on
        (``os.sched_getaffinity``).

    Returns
    -------
    int
        The thread count, ``>= 1``.

    Raises
    ------
    fm2uav.InputError
        ``threads`` (or the environment variable) is not an integer ``>= 1``.
    """
    from ..errors import InputError

    if threads is None:
        env = os.environ.get(THREADS_ENV, "").strip()
        if env:
            try:
                threads = int(env)
            except ValueError:
                raise InputError(
                    f"{THREADS_ENV} must be an integer >= 1 (threads of the Fast Marching), "
                    f"got {env!r}") from None
            if threads < 1:
                raise InputError(
                    f"{THREADS_ENV} must be an integer >= 1 (threads of the Fast Marching), "
                    f"got {env!r}")
            return threads
        try:
            return max(1, len(os.sched_getaffinity(0)))
        except AttributeError:  # not Linux
            return max(1, os.cpu_count() or 1)
    if isinstance(threads, bool) or not isinstance(threads, (int, np.integer)) or threads < 1:
        raise InputError(f"threads must be an integer >= 1, got {threads!r}")
    return int(threads)


# ------------------------------------------------------------------ queue glue
@njit(cache=True, inline="always", error_model="numpy", _nrt=False)
def _enq(k, c, pool, nxt, bk, mw, st, rkey, ritem):
    """Queue node ``c`` with key bits ``k``: the radix queue if ``k`` is not below its
    lower bound, else the repair heap (the caller keeps :data:`HEAP_RESERVE` slots free)."""
    last = st[_LAST]
    if k >= last:
        nfree, fh, cur = _push(_bucket(k, last), k, c, pool, nxt, bk, mw, st[_NFREE],
                               st[_FH], st[_CUR])
        st[_NFREE] = nfree
        st[_FH] = fh
        st[_CUR] = cur
        return
    size = st[_RSIZE]
    sift_up(rkey, ritem, rkey[:0], np.int64(size), k, c)
    st[_RSIZE] = size + _ONE


@njit(cache=True, inline="always", error_model="numpy", _nrt=False)
def _deq(T, pool, nxt, bk, mw, st, rkey, ritem):
    """Remove the smallest queued entry (repair heap first); its node or ``_NIL``."""
    size = st[_RSIZE]
    if size > _ZERO:
        c = ritem[0]
        size -= _ONE
        st[_RSIZE] = size
        if size > _ZERO:
            sift_down(rkey, ritem, rkey[:0], np.int64(size), rkey[size], ritem[size])
        return c
    c, nfree, fh, cur, last = _pop(T, pool, nxt, bk, mw, st[_NFREE], st[_FH], st[_CUR],
                                   st[_LAST])
    st[_NFREE] = nfree
    st[_FH] = fh
    st[_CUR] = cur
    st[_LAST] = last
    return c


@njit(cache=True, inline="always", error_model="numpy", _nrt=False)
def _update(T, V, U, use_u, qp, c, sx, sy, ih, hh, iso, three):  # noqa: PLR0913
    """The order-1 upwind time of node ``c`` from its frozen neighbours (as the serial march;
    ``1 / speed^2`` from the plateau register ``qp`` where the mask ``U`` says so)."""
    q = _rhs(V, U, use_u, qp, c)
    if iso:
        tz = _side_min(T, c, _ONE) if three else _INF
        return _solve_iso(_side_min(T, c, sx), _side_min(T, c, sy), tz, q * hh)
    ta, aa = _axis_term(T, V, c, sx, ih[0], 1)
    tb, ab = _axis_term(T, V, c, sy, ih[1], 1)
    if three:
        tc, ac = _axis_term(T, V, c, _ONE, ih[2], 1)
    else:
        tc, ac = _INF, 0.0
    return _combine(ta, aa, tb, ab, tc, ac, q)


@njit(cache=True, inline="always", error_model="numpy", _nrt=False)
def _prefetch_rows(T, V, c, sx, sy, three, pv):
    """Prefetch ``T`` (and ``V`` if ``pv``) one and two rows (planes) away across x (and y)."""
    n = _U(T.size)
    _prefetch(T, c - sx)
    _prefetch(T, c + sx)
    if pv:
        _prefetch(V, c - sx)
        _prefetch(V, c + sx)
    _prefetch(T, c - sx - sx if c >= sx + sx else c)
    _prefetch(T, c + sx + sx if c + sx + sx < n else c)
    if three:
        _prefetch(T, c - sy)
        _prefetch(T, c + sy)
        if pv:
            _prefetch(V, c - sy)
            _prefetch(V, c + sy)
        _prefetch(T, c - sy - sy)
        _prefetch(T, c + sy + sy)


@njit(cache=True, inline="always", error_model="numpy", _nrt=False)
def _lower(T, V, c, t, fixed, sx, sy, three, pv, pool, nxt, bk, mw, st, rkey, ritem, ctl):
    """Give node ``c`` the time ``t`` if that is lower than its band or frozen time.

    A frozen node lowered is re-opened (band again), unless it was frozen on entry
    (bit ``c`` of ``fixed``: a source or its ball, final as in the serial march).
    ``pv``: prefetch the speeds of a new band node's neighbours too (off the plateau).
    """
    x = T[c]
    if x < 0.0:
        if t < -x:
            T[c] = -t
            if x == -_INF:  # a new band node: fetch the rows its freezing reads (as _relax)
                _prefetch_rows(T, V, c, sx, sy, three, pv)
            _enq(_bits(t), c, pool, nxt, bk, mw, st, rkey, ritem)
    elif t < x and _fixed_at(fixed, c, sy, three) == _ZERO:
        T[c] = -t
        ctl[_C_REOPEN] += 1.0
        _enq(_bits(t), c, pool, nxt, bk, mw, st, rkey, ritem)


@njit(cache=True, inline="always", error_model="numpy", _nrt=False)
def _room(st, rkey):
    """Whether the pool and the repair heap have room for the pushes of one node."""
    return st[_NFREE] >= _U(RESERVE_BLOCKS) and st[_RSIZE] + _U(HEAP_RESERVE) <= _U(rkey.size)


@njit(cache=True, inline="always", _nrt=False)
def _nbs(c, sx, sy, three):
    """The neighbours of node ``c``: six in 3D; in 2D four (``sy`` the y stride: 1, or 2 in
    the interleaved layout), then ``c`` twice (frozen: skipped)."""
    if three:
        return (c - sx, c + sx, c - sy, c + sy, c - _ONE, c + _ONE)
    return (c - sx, c + sx, c - sy, c + sy, c, c)


@njit(cache=True, inline="always", _nrt=False)
def _unit(sy, three):
    """The elements between two consecutive nodes of a slab's ``T``: 1, or 2 in the 2D
    interleaved layout (node ``c``'s time at ``2 c``, its ``1 / speed^2`` at ``2 c + 1``),
    where it is the y stride ``sy``; 3D slabs are never interleaved."""
    return _ONE if three else sy


@njit(cache=True, inline="always", _nrt=False)
def _fixed_at(fixed, c, sy, three):
    """Bit of element ``c``'s node in the frozen-on-entry mask ``fixed`` (one bit a node)."""
    n = c >> (_unit(sy, three) >> _ONE)  # node index: element index / unit (1 or 2)
    return (fixed[n >> _U(3)] >> (n & _U(7))) & _ONE


@njit(cache=True, inline="always", _nrt=False)
def _note(sent, ns, side, c):
    """Append node ``c`` (frozen in a boundary row) to the list ``side`` of the slab's
    sent nodes, or mark the list overflowed (``> capacity``: the exchange scans the row)."""
    m = ns[side]
    if m < _U(sent.shape[1]):
        sent[side, m] = c
        ns[side] = m + _ONE
    else:
        ns[side] = _U(sent.shape[1]) + _ONE


def _slab_kernels(three):
    """The compiled window, start and exchange of one dimension (``three``: 3D)."""

    # closure variables are part of numba's cache key: only ``three`` (a bool) may be
    # one (a dispatcher's pickle differs per process and would defeat the cache)
    def window(T, V, U, qp, fixed, sx, sy, ih, hh, iso, tw, pool, nxt, bk, mw, st, rkey, ritem,
               ctl, sent, ns, far):
        """Freeze the slab's queued nodes with a time below ``tw`` (resumable).

        ``T`` is the slab's padded grid (ghost x-slabs first and last). Sets
        ``ctl[_C_NEXT]`` to the smallest time left queued (inf if none). The nodes it
        freezes in its first and last own rows go to ``sent[0]`` and ``sent[1]``
        (``ns`` their counts, reset here): the neighbours' exchange reads only those.

        ``far`` (2D): a far neighbour of the node just frozen gets the one-axis update
        along their axis, as in the serial march. Valid in a slab because no far node has
        a frozen neighbour other than the node being frozen: every node that becomes
        frozen updates its band and far own neighbours at once — a pop here, a node
        frozen on entry in ``start``, a ghost in ``exchange`` (its one own neighbour) —
        and an update from a frozen neighbour is finite (or ``inf`` on both ways, where
        ``1 / speed^2`` overflows), so none of them stays far; a re-opened node was
        frozen before, so its neighbours are not far either, and nothing turns far
        again. The full update of such a node reads that one finite neighbour and
        returns bit for bit the one-axis time (tests/eikonal/test_fmm_parallel.py runs
        both ways and compares the times bit for bit).
        """
        n = _U(T.size)
        lo = sx  # the slab's own nodes: [sx, n - sx)
        hi = n - sx
        lo2 = lo + sx  # the first own row is [lo, lo2), the last [hi2, hi)
        hi2 = hi - sx
        one = _unit(sy, three)
        use_u = qp > 0.0 and one == _ONE
        kw = _bits(tw)
        pops = 0
        ns[0] = _ZERO
        ns[1] = _ZERO
        ctl[_C_NEXT] = _INF
        while True:
            if not _room(st, rkey):
                ctl[_C_STATUS] = 1.0 if st[_NFREE] < _U(RESERVE_BLOCKS) else 2.0
                break
            c = _deq(T, pool, nxt, bk, mw, st, rkey, ritem)
            if c == _NIL:
                break
            x = T[c]
            if not x < 0.0:  # outdated entry of a frozen node
                continue
            t = -x
            k = _bits(t)
            if k >= kw:  # the window is done: put it back
                _enq(k, c, pool, nxt, bk, mw, st, rkey, ritem)
                ctl[_C_NEXT] = t
                break
            T[c] = t
            pops += 1
            if c < lo2:
                _note(sent, ns, 0, c)
            if c >= hi2:
                _note(sent, ns, 1, c)
            # prefetch V apart from T off the plateau (interleaved: the same lines)
            pv = one == _ONE and not (use_u and _at_plateau(U, c))
            if three:
                for nb in _nbs(c, sx, sy, three):
                    y = T[nb]
                    if y < 0.0 or (y > t and nb >= lo and nb < hi):
                        # band/far, or frozen later than c in this slab: c may lower it
                        t_nb = _update(T, V, U, use_u, qp, nb, sx, sy, ih, hh, iso, three)
                        _lower(T, V, nb, t_nb, fixed, sx, sy, three, pv, pool, nxt, bk, mw, st,
                               rkey, ritem, ctl)
            else:
                for j in range(4):  # one site for the four neighbours, as the serial march
                    s = sx if j < 2 else sy
                    nb = c - s if j & 1 == 0 else c + s
                    y = T[nb]
                    if far and y == -_INF:  # c is its only frozen neighbour (docstring)
                        q = _rhs(V, U, use_u, qp, nb)
                        t_nb = t + math.sqrt(q * hh) if iso else t + math.sqrt(q / ih[j >> 1])
                    elif y < 0.0 or (y > t and nb >= lo and nb < hi):
                        # band/far, or frozen later than c in this slab: c may lower it
                        t_nb = _update(T, V, U, use_u, qp, nb, sx, sy, ih, hh, iso, three)
                    else:
                        continue
                    _lower(T, V, nb, t_nb, fixed, sx, sy, three, pv, pool, nxt, bk, mw, st,
                           rkey, ritem, ctl)
        ctl[_C_POPS] = pops

    def start(T, V, U, qp, fixed, sx, sy, ih, hh, iso, pool, nxt, bk, mw, st, rkey, ritem, ctl,
              c0, c1):
        """Queue the slab's band nodes given on entry and expand its frozen ones (all in
        its nodes ``[c0, c1)``, the rows of the start box: the others are far or walls)."""
        one = _unit(sy, three)
        use_u = qp > 0.0 and one == _ONE
        c = c0
        while c < c1:
            x = T[c]
            if x < 0.0 and x > -_INF:
                if not _room(st, rkey):
                    return False
                _enq(_bits(-x), c, pool, nxt, bk, mw, st, rkey, ritem)
            c += one
        c = c0
        while c < c1:
            if T[c] >= 0.0:
                if not _room(st, rkey):
                    return False
                for nb in _nbs(c, sx, sy, three):
                    if T[nb] < 0.0:
                        t_nb = _update(T, V, U, use_u, qp, nb, sx, sy, ih, hh, iso, three)
                        _lower(T, V, nb, t_nb, fixed, sx, sy, three, one == _ONE, pool, nxt, bk,
                               mw, st, rkey, ritem, ctl)
            c += one
        return True

    def exchange(T, V, U, qp, fixed, src, sent, m, base, g, own, sx, sy, ih, hh, iso, pool, nxt,
                 bk, mw, st, rkey, ritem, ctl):
        """Copy the neighbour's boundary row ``src`` (its frozen times) into the ghost row
        starting at ``g``; update the own node next to each ghost that changed (``own``:
        the start of that row). Only the neighbour's nodes ``sent[:m] - base`` are read
        (those it froze in its last window), the whole row when ``m`` exceeds the list's
        capacity. Resumable: False when a queue is full."""
        one = _unit(sy, three)
        use_u = qp > 0.0 and one == _ONE
        full = m > _U(sent.size)
        count = sx if full else m  # elements of the row, or listed nodes
        i = _ZERO
        while i < count:
            j = i if full else sent[i] - base
            i += one if full else _ONE
            v = src[j]
            if v >= 0.0 and not v >= T[g + j]:  # newly frozen or lowered there
                if not _room(st, rkey):
                    return False
                T[g + j] = v
                c = own + j
                if T[c] == T[c]:  # not a wall
                    _lower(T, V, c, _update(T, V, U, use_u, qp, c, sx, sy, ih, hh, iso, three),
                           fixed, sx, sy, three, one == _ONE, pool, nxt, bk, mw, st, rkey, ritem,
                           ctl)
                    if T[c] < 0.0 and -T[c] < ctl[_C_NEXT]:  # queued: the next window knows
                        ctl[_C_NEXT] = -T[c]
        return True

    d = 3 if three else 2
    out = []
    for f in (window, start, exchange):
        f.__name__ = f.__qualname__ = f"{f.__name__}{d}d"
        out.append(njit(cache=True, error_model="numpy", _nrt=False)(f))
    return out


_window2d, _start2d, _exchange2d = _slab_kernels(False)
_window3d, _start3d, _exchange3d = _slab_kernels(True)


@njit(cache=True, _nrt=False)
def _window(three, *args):
    """The 3D or the 2D kernel."""
    if three:
        return _window3d(*args)
    return _window2d(*args)


@njit(cache=True, _nrt=False)
def _start(three, *args):
    """The 3D or the 2D kernel."""
    if three:
        return _start3d(*args)
    return _start2d(*args)


@njit(cache=True, _nrt=False)
def _exchange(three, *args):
    """The 3D or the 2D kernel."""
    if three:
        return _exchange3d(*args)
    return _exchange2d(*args)


@njit(cache=True, error_model="numpy", _nrt=False)
def _heap_next(T, st, ritem, ctl):
    """Lower ``ctl[_C_NEXT]`` to the repair heap's smallest time (a hint for the window)."""
    if st[_RSIZE] > _ZERO:
        x = T[ritem[0]]
        if x < 0.0 and -x < ctl[_C_NEXT]:
            ctl[_C_NEXT] = -x


@njit(cache=True, error_model="numpy", _nrt=False)
def _assign(work, nth, slabs, first, load, share=True):
    """Share the slabs among the threads for the next window: thread ``t`` runs slabs
    ``slabs[first[t]:first[t + 1]]``.

    ``work[k]`` predicts slab ``k``'s freezes (those of its last window: the wave moves
    little from one window to the next). The longest-first greedy split (each slab, the
    largest first, to the thread with the least so far) is kept when it predicts a
    smaller largest share than the fixed interleave (slab ``k`` to thread ``k % nth``),
    which is kept otherwise (and before the first window, all predictions 0). On the
    FM²-shaped 2048^2 map the windows' balance rises from ~1.65 to ~1.75: while the wave
    crosses few slabs, the fixed interleave may give two busy slabs to one thread.
    ``load`` (``nth`` floats) and ``first[nth + 1:]`` (``K`` ints) are scratch;
    ``share=False``: always the fixed interleave. Returns whether the greedy split was taken.
    """
    K = work.size
    fixed_max = 0.0
    for t in range(nth):
        mine = 0.0
        for k in range(t, K, nth):
            mine += work[k]
        fixed_max = max(fixed_max, mine)
    # slabs by decreasing predicted work (insertion sort: a few dozen slabs at most)
    for i in range(K):
        slabs[i] = i
    for i in range(1, K):
        k = slabs[i]
        j = i - 1
        while j >= 0 and work[slabs[j]] < work[k]:
            slabs[j + 1] = slabs[j]
            j -= 1
        slabs[j + 1] = k
    for t in range(nth):
        load[t] = 0.0
    owner = first[nth + 1:]  # scratch: the owner of each slab (K entries)
    for i in range(K):
        k = slabs[i]
        best = 0
        for t in range(1, nth):
            if load[t] < load[best]:
                best = t
        owner[k] = best
        load[best] += work[k]
    greedy_max = 0.0
    for t in range(nth):
        greedy_max = max(greedy_max, load[t])
    greedy = share and greedy_max < fixed_max
    if not greedy:
        for k in range(K):
            owner[k] = k % nth
    # the lists, each thread's slabs in increasing order
    i = 0
    for t in range(nth):
        first[t] = i
        for k in range(K):
            if owner[k] == t:
                slabs[i] = k
                i += 1
    first[nth] = i
    return greedy


def _drive_kernel(three):
    """The compiled driver of one dimension (the parallel region runs the slabs)."""
    def drive(nth, Tp, Vp, U, qp, fx, off, end, rows, sx, sy, ih, hh, iso, pool, nxt, bk, mw, st,
              rkey, ritem, ctl, sent, ns, win, first, stops, slabs, lists, load, share, scan, far):
        """Run windows until every queue is empty; 0 done, 1/2 grow pool/heap and call again.

        ``win`` (float64): [0] window end, [1] width, [2] windows run, [3] target pops,
        [4] nodes frozen (re-freezes included), [5] sum over windows of the most a slab
        froze (the critical path: ``[4] / [5]`` bounds the speed-up), [6] the latest
        stop node's time when the stop nodes ``stops`` (indices into ``Tp``) ended it,
        [7] 1 once the start (``first``) is done, [8] windows whose slabs :func:`_assign`
        shared longest-first. ``U``, ``qp``: the plateau mask over
        ``Tp`` (one byte: every node) and its ``1 / speed^2`` (0: none); ``sent``, ``ns``:
        each slab's nodes frozen in its boundary rows in the last window (see ``window``).
        ``slabs`` (K), ``lists`` (nth + 1 + K), ``load`` (nth): scratch of :func:`_assign`
        (``share``: :data:`SHARE_SLABS`). ``scan[k]``: the nodes of slab ``k`` the start
        reads (the start box's rows). ``far``: the far neighbours' one-axis update (2D).

        ``off``, ``end``, ``sx``, ``sy``, ``scan`` and ``stops`` count elements of ``Tp``:
        nodes in the separate layout, twice that in the 2D interleaved one (``Tp`` the
        buffer, ``Vp = Tp[1:]``, ``sy = 2``); ``U`` and ``fx`` have a bit per node.
        """
        K = off.size
        sxi = np.int64(sx)
        sh = 0 if three or sy == 1 else 1  # node index = element index >> sh
        if first:
            for t in prange(nth):  # thread t runs slabs t, t + nth, ...
                for k in range(t, K, nth):
                    if not _start(three, Tp[off[k]:end[k]], Vp[off[k]:end[k]],
                                  U[0 if U.size == 1 else off[k] >> sh >> 3:], qp,
                                  fx[off[k] >> sh >> 3:], sx, sy, ih, hh, iso, pool[k], nxt[k],
                                  bk[k], mw[k], st[k], rkey[k], ritem[k], ctl[k],
                                  _U(scan[k, 0]), _U(scan[k, 1])):
                        ctl[k, _C_STATUS] = 1.0 if st[k, _NFREE] < _U(RESERVE_BLOCKS) else 2.0
            for k in range(K):
                if ctl[k, _C_STATUS] != 0.0:
                    return int(ctl[k, _C_STATUS])  # grown, the start runs again
            win[7] = 1.0
        while True:
            # the slabs of each thread for the exchange and the window (from the last
            # window's freezes)
            if _assign(ctl[:, _C_POPS], nth, slabs, lists, load, share):
                win[8] += 1.0
            # exchange: each slab refreshes its own ghosts and the rows next to them
            for t in prange(nth):  # thread t runs slabs[lists[t]:lists[t + 1]]
                for i in range(lists[t], lists[t + 1]):
                    k = slabs[i]
                    T = Tp[off[k]:end[k]]
                    V = Vp[off[k]:end[k]]
                    Uk = U[0 if U.size == 1 else off[k] >> sh >> 3:]
                    F = fx[off[k] >> sh >> 3:]
                    ok = True
                    if k > 0:
                        o = end[k - 1] - 2 * sxi  # last own row of the slab below
                        ok = _exchange(three, T, V, Uk, qp, F, Tp[o:o + sxi], sent[k - 1, 1],
                                       ns[k - 1, 1], _U(rows[k - 1]) * sx, _ZERO, sx, sx, sy, ih,
                                       hh, iso, pool[k], nxt[k], bk[k], mw[k], st[k], rkey[k],
                                       ritem[k], ctl[k])
                    if ok and k < K - 1:
                        o = off[k + 1] + sxi  # first own row of the slab above
                        r = _U(rows[k])
                        ok = _exchange(three, T, V, Uk, qp, F, Tp[o:o + sxi], sent[k + 1, 0],
                                       ns[k + 1, 0], sx, (r + _ONE) * sx, r * sx, sx, sy, ih, hh,
                                       iso, pool[k], nxt[k], bk[k], mw[k], st[k], rkey[k],
                                       ritem[k], ctl[k])
                    if not ok:
                        ctl[k, _C_STATUS] = 1.0 if st[k, _NFREE] < _U(RESERVE_BLOCKS) else 2.0
                    _heap_next(T, st[k], ritem[k], ctl[k])
            for k in range(K):
                if ctl[k, _C_STATUS] != 0.0:
                    return int(ctl[k, _C_STATUS])
            # the next window
            tmin = _INF
            empty = True
            for k in range(K):
                tmin = min(tmin, ctl[k, _C_NEXT])
                if st[k, _RSIZE] > _ZERO:
                    empty = False
                for w in range(_NW):
                    if mw[k, w] != _ZERO:
                        empty = False
            # stop nodes: done once all are frozen no later than every queued time
            # (nothing queued can lower them: an update is later than its inputs)
            if stops.size > 0:
                smax = 0.0
                for i in range(stops.size):
                    x = Tp[stops[i]]
                    if not x >= 0.0:
                        smax = _INF
                        break
                    smax = max(smax, x)
                if smax <= tmin:
                    win[6] = smax
                    return 0
            if empty:
                return 0
            if tmin < _INF:
                win[0] = max(win[0], tmin) + win[1]
            else:
                win[0] = win[0] + win[1]
            tw = win[0]
            for t in prange(nth):  # thread t runs slabs[lists[t]:lists[t + 1]]
                for i in range(lists[t], lists[t + 1]):
                    k = slabs[i]
                    _window(three, Tp[off[k]:end[k]], Vp[off[k]:end[k]],
                            U[0 if U.size == 1 else off[k] >> sh >> 3:], qp,
                            fx[off[k] >> sh >> 3:], sx, sy, ih, hh, iso, tw, pool[k], nxt[k],
                            bk[k], mw[k], st[k], rkey[k], ritem[k], ctl[k], sent[k], ns[k], far)
            win[2] += 1.0
            pops = 0.0
            most = 0.0
            for t in range(nth):
                mine = 0.0
                for i in range(lists[t], lists[t + 1]):
                    mine += ctl[slabs[i], _C_POPS]
                pops += mine
                most = max(most, mine)
            win[4] += pops
            win[5] += most
            for k in range(K):
                if ctl[k, _C_STATUS] != 0.0:
                    return int(ctl[k, _C_STATUS])
            # adapt the width toward the target pops per window
            f = win[3] / max(pops, 1.0)
            win[1] *= min(2.0, max(0.5, f))

    drive.__name__ = drive.__qualname__ = f"drive{3 if three else 2}d"
    return njit(cache=True, parallel=True, error_model="numpy")(drive)


_drive2d = _drive_kernel(False)
_drive3d = _drive_kernel(True)


#: The split of two slabs is chosen on a march over every ``COARSE``-th node per axis
#: (2D; 3D: ``COARSE_3D``), ~0.5 % (2D) and ~1.5 % (3D) of the work of the full march
#: (serial time: the second thread waits). 2D: the windows' balance on FM²-shaped 2048^2
#: maps (seeds 0-3, with :func:`_assign`) averaged 1.827 / 1.823 / 1.813 / 1.768 with
#: every 8th / 16th / 32nd node / equal slabs, the coarse march 8 / 2 / 0.5 ms.
COARSE = 16
COARSE_3D = 4
#: Whether the cuts are placed for the slabs shared anew before each window (the least
#: share of a time bin any sharing allows, :func:`slab_bounds`) rather than for the fixed
#: interleave. Simulated on the bench's FM²-shaped 2048^2 map from the serial times
#: (windows of 32768 nodes in time order, the slabs shared as :func:`_assign`), 8 slabs:
#: windows' balance 1.78 -> 1.84 (16 slabs 1.83 -> 1.84). 3D keeps the interleave's cuts
#: (not measured there).
SHARED_CUTS = {2: True, 3: False}
#: Bins of the split estimate, each as many coarse nodes in time order (stand-ins for
#: the windows).
SPLIT_BINS = 256


def slab_bounds(speed, start, shape3, h3, k: int, threads: int = 2) -> np.ndarray:
    """Row bounds (``k + 1`` ints) of ``k`` slabs along x, slab ``j`` marched by thread
    ``j % threads``.

    The cuts are placed where a coarse march predicts the best balance: they minimise
    ``sum over time bins of max over threads of the nodes it marches in that bin``, the
    windows' critical path (a source off-centre would otherwise leave one thread idle
    while the wave crosses the other's slabs), by coordinate descent from equal slabs
    (each cut in turn moved to its best row between its neighbours, until none moves;
    exhaustive for two slabs). Where :data:`SHARED_CUTS` says so (2D) a second descent
    counts a thread's nodes in a bin not as the fixed interleave gives them but as the least
    any sharing of the slabs allows, ``max(the bin's busiest slab, the bin's nodes /
    threads)`` (the slabs are shared anew before each window, :func:`_assign`, and cuts
    made for the interleave may leave the late wave in one slab), and the cuts of the two
    descents with the shorter critical path when the bins' slabs are shared as
    :func:`_assign` shares them (:func:`_shared_cost`) are taken. Equal slabs when the
    start is not a few point sources (its box over a quarter of the grid) or the grid is
    too thin for a coarse march.
    """
    nx = int(shape3[0])
    even = np.linspace(0, nx, k + 1).round().astype(np.int64)
    if k < 2 or threads < 2 or 4 * int(np.prod(start.shape)) > int(np.prod(shape3)):
        return even
    hist, f = _coarse_histogram(speed, start, shape3, h3)
    if hist is None:
        return even
    rows = hist.shape[0]
    gap = max(1, -(-MIN_SLAB_ROWS // f))  # coarse rows per slab at least
    if rows < k * gap:
        return even
    cum = np.vstack([np.zeros((1, hist.shape[1]), dtype=np.int64), np.cumsum(hist, axis=0)])
    cuts = np.clip(np.linspace(0, rows, k + 1).round().astype(np.int64), 0, rows)
    fixed = _descend_cuts(cum, cuts.copy(), gap, threads, False)
    if SHARED_CUTS[3 if shape3[2] > 1 else 2]:  # the better, by the windows as _assign
        cuts = _descend_cuts(cum, cuts, gap, threads, True)  # shares the slabs
        if _shared_cost(cum, fixed, threads) <= _shared_cost(cum, cuts, threads):
            cuts = fixed
    else:
        cuts = fixed
    bounds = np.minimum(cuts * f, nx)
    bounds[-1] = nx
    for i in range(1, k):  # fine rows: at least MIN_SLAB_ROWS per slab where they fit
        bounds[i] = min(max(bounds[i], bounds[i - 1] + MIN_SLAB_ROWS), nx - (k - i) * MIN_SLAB_ROWS)
    if np.any(np.diff(bounds) < 1):
        return even
    return bounds.astype(np.int64)


@njit(cache=True, error_model="numpy")
def _descend_cuts(cum, cuts, gap, threads, shared):
    """Coordinate descent of the inner cuts ``cuts[1:-1]`` (coarse rows, at least ``gap``
    apart; ``cum``: the coarse histogram cumulated over the rows, ``(rows + 1, bins)``):
    each in turn to the row between its neighbours with the least critical path, ``sum
    over bins of the largest thread's nodes``, until none moves; ``cuts`` is changed and
    returned. A thread's nodes in a bin: those of its slabs in the fixed interleave (slab
    ``j`` to thread ``j % threads``; the first best row taken), or with ``shared`` the
    least any sharing allows, ``max(busiest slab, all / threads)`` (a move only where
    strictly better: that bound ties over many rows)."""
    k = cuts.size - 1
    nb = cum.shape[1]
    base = np.empty((threads, nb))
    for _ in range(4 * k):
        moved = False
        for i in range(1, k):
            lo = cuts[i - 1] + gap
            hi = cuts[i + 1] - gap
            if hi < lo:
                continue
            # every slab but i - 1 and i: per thread (interleave) or the bound (shared)
            base[:] = 0.0
            for b in range(nb):
                if shared:
                    base[0, b] = (cum[-1, b] - cum[0, b]) / threads
            for j in range(k):
                if j == i - 1 or j == i:
                    continue
                for b in range(nb):
                    x = cum[cuts[j + 1], b] - cum[cuts[j], b]
                    if shared:
                        base[0, b] = max(base[0, b], x)
                    else:
                        base[j % threads, b] += x
            best = cuts[i]
            best_cost = np.inf
            here = np.inf
            for c in range(lo, hi + 2):
                r = cuts[i] if c == hi + 1 else c  # last: the cut's own row
                cost = 0.0
                for b in range(nb):
                    below = cum[r, b] - cum[cuts[i - 1], b]
                    above = cum[cuts[i + 1], b] - cum[r, b]
                    if shared:
                        cost += max(base[0, b], max(below, above))
                    else:
                        most = 0.0
                        for t in range(threads):
                            x = base[t, b]
                            if t == (i - 1) % threads:
                                x += below
                            if t == i % threads:
                                x += above
                            most = max(most, x)
                        cost += most
                if c == hi + 1:
                    here = cost
                elif cost < best_cost:
                    best_cost = cost
                    best = c
            if (best_cost < here) if shared else (best != cuts[i]):
                cuts[i] = best
                moved = True
        if not moved:
            break
    return cuts


def _shared_cost(cum, cuts, threads):
    """The windows' critical path (nodes) of the cuts ``cuts`` over the coarse histogram's
    time bins (``cum``: cumulated over the rows) with the slabs shared as :func:`_assign`
    shares them: longest first by the last bin's nodes when that predicts a smaller
    largest share than the fixed interleave (slab ``k`` to thread ``k % threads``)."""
    per = (cum[cuts[1:]] - cum[cuts[:-1]]).astype(np.float64)  # (slabs, bins)
    k, nb = per.shape
    pred = np.zeros_like(per)
    pred[:, 1:] = per[:, :-1]
    cols = np.arange(nb)

    def fixed_max(a):
        return np.max([a[t::threads].sum(axis=0) for t in range(threads)], axis=0)

    order = np.argsort(-pred, axis=0, kind="stable")
    load = np.zeros((threads, nb))
    owner = np.empty((k, nb), dtype=np.int64)
    for i in range(k):
        slab = order[i]
        best = np.argmin(load, axis=0)
        owner[slab, cols] = best
        load[best, cols] += pred[slab, cols]
    greedy = load.max(axis=0) < fixed_max(pred)
    shared = np.max([np.where(owner == t, per, 0.0).sum(axis=0) for t in range(threads)], axis=0)
    return float(np.where(greedy, shared, fixed_max(per)).sum())


def _coarse_histogram(speed, start, shape3, h3):
    """Nodes per coarse x-row and time bin of a march over every ``COARSE``-th node
    (``COARSE_3D`` in 3D) from the start's frozen nodes: ``(hist, f)``, ``hist`` of shape
    ``(coarse rows, SPLIT_BINS)`` and ``f`` the coarsening; ``(None, f)`` if no estimate."""
    three = shape3[2] > 1
    f = COARSE_3D if three else COARSE
    grid = speed.reshape(shape3)
    coarse = np.ascontiguousarray(grid[::f, ::f, ::f] if three else grid[::f, ::f, :])
    cshape = coarse.shape
    if cshape[0] < 4:
        return None, f
    box = np.argwhere(start.state.reshape(start.shape) == _kernels.FROZEN)
    if len(box) == 0:
        return None, f
    # the coarse nodes of the frozen ones (a mask over their box: a source ball on constant
    # speed holds ~33,000 nodes on 2048^2, and np.unique of rows took 38 ms of serial time)
    cells = (box + np.asarray(start.lo)) // np.array([f, f, f if three else 1])
    lo = cells.min(axis=0)
    bshape = tuple(int(n) for n in cells.max(axis=0) - lo + 1)
    frozen = np.zeros(bshape, dtype=bool)
    frozen[tuple((cells - lo).T)] = True
    frozen = frozen.reshape(-1)
    Tb = np.where(frozen, 0.0, np.inf)
    sb = np.where(frozen, _kernels.FROZEN, 0).astype(np.uint8)
    cstart = _kernels.Start(tuple(int(a) for a in lo), bshape, Tb, sb)
    hc = tuple(h * f for h in h3[:2]) + ((h3[2] * f,) if three else (h3[2],))
    # read-only as fast_marching's speeds: the same specialisations (the warm-up's)
    T, _ = _kernels.march(_kernels._readonly(coarse.reshape(-1)), cstart, cshape, hc, 1,
                          np.zeros((0, 3), dtype=np.int64))
    T = T.reshape(cshape[0], -1)
    fin = np.isfinite(T)
    tmax = float(T[fin].max()) if fin.any() else 0.0
    if not tmax > 0.0:
        return None, f
    rows = np.broadcast_to(np.arange(cshape[0])[:, None], T.shape)[fin]
    # bins of equal node counts in time order, as the windows (~WINDOW_NODES nodes each);
    # equal times share a bin: node bin ``rank * SPLIT_BINS // n``, ``rank`` the count of
    # earlier times, i.e. how many of the sorted times ending each bin's share are earlier
    # (a search among SPLIT_BINS - 1 edges instead of among all the times: 4 -> 0.5 ms)
    times = T[fin]
    n = times.size
    ends = -(-np.arange(1, SPLIT_BINS) * n // SPLIT_BINS) - 1  # ceil(b n / bins) - 1 >= 0
    bins = np.searchsorted(np.sort(times)[ends], times, side="left")
    hist = np.bincount(rows * SPLIT_BINS + bins,
                       minlength=cshape[0] * SPLIT_BINS).reshape(cshape[0], SPLIT_BINS)
    return hist, f


def march(speed, start, shape3, h3, threads, stop_cells=None, *, interleave=None):
    """The order-1 Fast Marching from ``start`` on ``threads`` slabs in parallel.

    Parameters
    ----------
    speed : ndarray, float64, shape (nx*ny*nz,)
        Propagation speed [m/s]; nodes with 0 are never entered.
    start : fm2uav.eikonal._kernels.Start
        The initial frozen/band nodes.
    shape3 : tuple of 3 int
        Grid shape ``(nx, ny, nz)`` (``nz = 1`` for 2D).
    h3 : tuple of 3 float
        Spacing per axis [m].
    threads : int
        Threads, ``>= 2`` (each marches :data:`SLABS_PER_THREAD` slabs, fewer
        where a slab would get fewer than :data:`MIN_SLAB_ROWS` rows or
        :data:`MIN_SLAB_NODES` nodes).
    stop_cells : ndarray, int, shape (m, 3), optional
        Stop once these nodes are frozen and final; nodes later than the latest
        of them are then ``inf``, as in the serial march.
    interleave : bool, optional
        2D slabs outside the lean layout: ``T`` and ``1 / speed^2`` interleaved in one
        array, as the serial march (:func:`fm2uav.eikonal._kernels._buffers`); default:
        unless every passable node has one speed. The times are the same bit for bit.

    Returns
    -------
    T : ndarray, float64, shape (nx*ny*nz,)
        Arrival times [s], ``inf`` where unreachable.
    stats : dict
        ``slabs``, ``windows``, ``reopened`` (nodes lowered after they were frozen) and
        ``balance``: nodes frozen over the sum of each window's largest slab share, the
        speed-up the windows allow if every freeze cost the same (``slabs`` at best), and
        ``greedy``: the windows whose slabs :func:`_assign` shared longest first.
    """
    import numba

    nx, ny, nz = (int(n) for n in shape3)
    three = nz > 1
    nth = int(max(1, min(threads, numba.config.NUMBA_NUM_THREADS)))
    K = int(max(1, min(nth * SLABS_PER_THREAD[3 if three else 2], nx // MIN_SLAB_ROWS,
                       max(nth, nx * ny * nz // max(MIN_SLAB_NODES, 1)))))
    nth = min(nth, K)
    bounds = slab_bounds(speed, start, shape3, h3, K, nth)
    rows = np.diff(bounds).astype(np.int64)
    sx = (ny + 2) * (nz + 2) if three else ny + 2
    sy = nz + 2 if three else 1
    sizes = (rows + 2) * sx
    # slabs start at multiples of 8 nodes: each slab's bits of ``fixed`` start a byte
    off = np.concatenate([[0], np.cumsum(-(-sizes // 8) * 8)[:-1]]).astype(np.int64)
    npad = int(off[-1] + sizes[-1])
    lean = (nx + 2) * sx > _kernels.LEAN_NODES  # V in float32 as the serial march
    # the serial march's buffers: in the lean layout plain mappings (the times compacted
    # in place below), else its kept ones (huge pages, no page faults on a repeat); a 2D
    # map not of one speed interleaved (Tk: node c's time at 2 c, its V at 2 c + 1; Tp and
    # Vp strided views of it) and without a plateau register, as the serial march
    Tp, Vp, Tk, Vk, unit, plat = _kernels._buffers(speed, shape3, npad, lean, interleave)
    plane = ny * nz
    boxes = _start_boxes(start, bounds)
    with _threads(nth):
        _pad_slabs(nth, _kernels._readonly(speed), start.T, start.state, boxes, bounds, off, ny,
                   nz, Tp, Vp)
    # the start box's rows in each slab, the only nodes the start reads (elements of Tk)
    scan = unit * np.stack([(boxes[:, 0] + 1) * sx, (boxes[:, 0] + boxes[:, 3] + 1) * sx],
                           axis=1)
    # the nodes frozen on entry (sources, balls) stay as they are, as in the serial march:
    # a bit per node, set from the start box's rows (the only frozen nodes on entry)
    fixed = _frozen_bits(Tp, off[:, None] + scan // unit, npad)
    if plat is None:
        plat = _kernels._plateau(speed, Vp, shape3, npad,
                                 fill=lambda vmax, bits: _slab_plateau(speed, vmax, bounds, off,
                                                                       shape3, bits))
    U, qp = plat
    # each slab's nodes frozen in its first and last own rows in the last window (the
    # neighbours' exchange reads those); a count over the capacity: read the whole row
    # (so the first exchange, after the start)
    sent = np.empty((K, 2, sx), dtype=np.uint64)
    ns = np.full((K, 2), sx + 1, dtype=np.uint64)
    # queues: one radix queue and one repair heap per slab
    nblk = max(POOL_MIN_BLOCKS, int(sizes.max()) // (16 * BLOCK))
    pool = np.empty((K, 2 * nblk * BLOCK), dtype=np.uint64)
    nxt = np.empty((K, nblk), dtype=np.uint32)
    bk = np.empty((K, 2 * int(_NB)), dtype=np.uint32)
    mw = np.empty((K, _NW), dtype=np.uint64)
    st = np.zeros((K, _ST), dtype=np.uint64)
    for k in range(K):
        _kernels.init_queue(nxt[k], bk[k], mw[k], st[k])
    rcap = max(HEAP_START, HEAP_RESERVE)
    rkey = np.empty((K, rcap), dtype=np.uint64)
    ritem = np.empty((K, rcap), dtype=np.uint64)
    ctl = np.zeros((K, _C_SIZE))
    ih = np.array([1.0 / (h * h) for h in h3])
    iso = bool(ih[0] == ih[1] and (not three or ih[1] == ih[2]))
    hh = float(1.0 / ih[0])
    # the top speed sets the first window's width only (then adapted): from the plateau's
    # register when there is one (a pass over the speeds is ~2 ms of serial time on 2048^2)
    # (a pass over the speeds, on the threads, else)
    if qp > 0.0:
        vmax = 1.0 / np.sqrt(qp)
    else:
        with _threads(nth):
            vmax = _top_speed(nth, _kernels._readonly(speed))
    width = 2.0 * min(h3[:3 if three else 2]) / max(vmax, 1e-300)
    win = np.array([0.0, width, 0.0, float(WINDOW_NODES), 0.0, 0.0, np.inf, 0.0, 0.0])
    stop_idx = np.zeros(0, dtype=np.int64)
    if stop_cells is not None and len(stop_cells):
        cells = np.asarray(stop_cells, dtype=np.int64).reshape(-1, 3)
        k = np.searchsorted(bounds, cells[:, 0], side="right") - 1
        local = ((cells[:, 0] - bounds[k] + 1) * (ny + 2) + cells[:, 1] + 1)
        if three:
            local = local * (nz + 2) + cells[:, 2] + 1
        stop_idx = unit * (off[k] + local)
    drive = _drive3d if three else _drive2d
    slabs = np.empty(K, dtype=np.int64)  # scratch of _assign: each window's slabs per thread
    lists = np.empty(nth + 1 + K, dtype=np.int64)
    load = np.empty(nth)
    first = True
    prev = numba.get_num_threads()
    numba.set_num_threads(nth)
    try:
        while True:
            status = drive(nth, Tk, Vk, U, qp, fixed, unit * off, unit * (off + sizes), rows,
                           _U(unit * sx), _U(unit * sy), ih, hh, iso, pool, nxt, bk, mw, st, rkey,
                           ritem, ctl, sent, ns, win, first, stop_idx, slabs, lists, load,
                           SHARE_SLABS, scan, FAR_ONE_AXIS)
            first = win[7] == 0.0
            if status == 0:
                break
            ctl[:, _C_STATUS] = 0.0
            if status == 1:
                pool, nxt = _grow_pools(pool, nxt, st)
            else:
                rkey, ritem = _grow_heaps(rkey, ritem)
    finally:
        numba.set_num_threads(prev)
    del Vp, Vk, Tk, pool, nxt
    # lean: in place, slab after slab, as the serial march: slab k's times go to
    # [a * plane, b * plane), from no later than its padded grid's start to before slab
    # k + 1's, so every node moves to a lower index and is read before it is written
    if lean:
        for k in range(K):
            a, b = int(bounds[k]), int(bounds[k + 1])
            seg = slice(int(off[k]), int(off[k] + sizes[k]))
            _kernels.unpad_grid(Tp[seg], b - a, ny, nz, Tp[a * plane:b * plane])
        T = Tp[:nx * ny * nz]
    else:  # a new array: the slabs in parallel
        T = np.empty(nx * ny * nz)
        with _threads(nth):
            _unpad_slabs(nth, Tp, bounds, off, ny, nz, T)
    if win[6] < np.inf:  # stopped: what the serial march would not have frozen yet
        T[T > win[6]] = np.inf
        sel = tuple(slice(a, a + m) for a, m in zip(start.lo, start.shape))
        box = T.reshape(shape3)[sel]  # nodes frozen on entry stay, whatever their time
        frozen = (start.state == _kernels.FROZEN).reshape(start.shape)
        box[frozen] = start.T.reshape(start.shape)[frozen]
    return T, {"slabs": K, "windows": int(win[2]), "reopened": int(ctl[:, _C_REOPEN].sum()),
               "balance": float(win[4] / max(win[5], 1.0)), "greedy": int(win[8])}


@contextlib.contextmanager
def _threads(nth):
    """Run numba's parallel regions on ``nth`` threads inside the block."""
    import numba

    prev = numba.get_num_threads()
    numba.set_num_threads(nth)
    try:
        yield
    finally:
        numba.set_num_threads(prev)


def _frozen_bits(Tp, rows, npad):
    """A bit per node of the padded slabs ``Tp`` (``npad`` nodes), set where ``Tp >= 0``
    (frozen) in the node ranges ``rows[k, 0] <= c < rows[k, 1]`` (each slab's start box
    rows), clear elsewhere (no other node is frozen on entry)."""
    bits = np.zeros(npad // 8 + 1, dtype=np.uint8)
    for a, b in rows:
        if b > a:
            a8 = int(a) & ~7
            packed = np.packbits(Tp[a8:int(b)] >= 0.0, bitorder="little")
            bits[a8 >> 3:(a8 >> 3) + packed.size] |= packed
    return bits


@njit(cache=True, parallel=True, error_model="numpy")
def _top_speed(nth, speed):
    """The largest speed (1.0 for none), on ``nth`` threads (one pass over 2048^2 speeds is
    ~2 ms); it sets the first window's width."""
    n = speed.size
    if n == 0:
        return 1.0
    part = np.zeros(nth)
    for t in prange(nth):
        top = 0.0
        for c in range(t * n // nth, (t + 1) * n // nth):
            top = max(top, speed[c])
        part[t] = top
    return part.max()


def _start_boxes(start, bounds):
    """Each slab's part of the start box, for :func:`_pad_slabs`: rows ``(i0, j0, k0, bx,
    by, bz, first, last)`` of ints, the box in the slab's own node indices (``bx = 0``:
    none) and the range ``[first, last)`` of ``start.T`` / ``start.state`` it takes."""
    lo, bshape = start.lo, start.shape
    bplane = bshape[1] * bshape[2]
    boxes = np.zeros((len(bounds) - 1, 8), dtype=np.int64)
    for k in range(len(bounds) - 1):
        a, b = int(bounds[k]), int(bounds[k + 1])
        i0, i1 = max(lo[0], a), min(lo[0] + bshape[0], b)
        if i1 > i0:
            boxes[k] = (i0 - a, lo[1], lo[2], i1 - i0, bshape[1], bshape[2],
                        (i0 - lo[0]) * bplane, (i1 - lo[0]) * bplane)
    return boxes


@njit(cache=True, parallel=True, error_model="numpy")
def _pad_slabs(nth, speed, Tb, sb, boxes, bounds, off, ny, nz, Tp, Vp):
    """Pad every slab (:func:`fm2uav.eikonal._kernels.pad_grid`) into its place in ``Tp`` /
    ``Vp`` (slab ``k`` from ``off[k]``), thread ``t`` the slabs ``t, t + nth, ...`` (on
    2048^2 the padding was 7 of the ~60 ms one thread spent alone)."""
    K = bounds.size - 1
    plane = ny * nz
    sx = (ny + 2) if nz == 1 else (ny + 2) * (nz + 2)
    for t in prange(nth):
        for k in range(t, K, nth):
            a, b = bounds[k], bounds[k + 1]
            bx = boxes[k]
            seg = slice(off[k], off[k] + (b - a + 2) * sx)
            pad_grid(speed[a * plane:b * plane], Tb[bx[6]:bx[7]], sb[bx[6]:bx[7]], bx[0], bx[1],
                     bx[2], bx[3], bx[4], bx[5], b - a, ny, nz, Tp[seg], Vp[seg])


@njit(cache=True, parallel=True, error_model="numpy")
def _unpad_slabs(nth, Tp, bounds, off, ny, nz, T):
    """Every slab's times into its rows of ``T`` (a new array; the lean layout compacts in
    place, slab after slab), thread ``t`` the slabs ``t, t + nth, ...``."""
    K = bounds.size - 1
    plane = ny * nz
    sx = (ny + 2) if nz == 1 else (ny + 2) * (nz + 2)
    for t in prange(nth):
        for k in range(t, K, nth):
            a, b = bounds[k], bounds[k + 1]
            unpad_grid(Tp[off[k]:off[k] + (b - a + 2) * sx], b - a, ny, nz, T[a * plane:b * plane])


def _slab_plateau(speed, vmax, bounds, off, shape3, bits):
    """Set the plateau bits (speed ``vmax``) of every slab in its own padded layout (slab
    ``k`` from byte ``off[k] / 8`` of ``bits``); returns how many nodes have ``vmax``."""
    _, ny, nz = (int(n) for n in shape3)
    plane = ny * nz
    count = 0
    for k in range(len(bounds) - 1):
        a, b = int(bounds[k]), int(bounds[k + 1])
        count += _kernels.plateau_bits(speed[a * plane:b * plane], vmax, b - a, ny, nz,
                                       bits[int(off[k]) >> 3:])
    return count


def _grow_pools(pool, nxt, st):
    """Double every slab's entry pool; the new blocks join each slab's free list."""
    K, old = nxt.shape
    new = 2 * old
    pool2 = np.empty((K, 2 * new * BLOCK), dtype=np.uint64)
    pool2[:, :pool.shape[1]] = pool
    nxt2 = np.empty((K, new), dtype=np.uint32)
    nxt2[:, :old] = nxt
    for k in range(K):
        nxt2[k, old:-1] = np.arange(old + 1, new, dtype=np.uint32)
        nxt2[k, -1] = np.uint32(st[k, _FH]) if st[k, _NFREE] > 0 else np.uint32(_NIL)
        st[k, _FH] = old
        st[k, _NFREE] = int(st[k, _NFREE]) + (new - old)
    return pool2, nxt2


def _grow_heaps(rkey, ritem):
    """Double every slab's repair heap (entries kept in place: still a heap)."""
    K, cap = rkey.shape
    rkey2 = np.empty((K, 2 * cap), dtype=np.uint64)
    ritem2 = np.empty((K, 2 * cap), dtype=np.uint64)
    rkey2[:, :cap] = rkey
    ritem2[:, :cap] = ritem
    return rkey2, ritem2
