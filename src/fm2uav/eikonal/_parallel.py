"""The parallel Fast Marching (order 1 and 2): slabs, time windows, ghost exchange, repair.

Private module: :func:`fm2uav.eikonal.fast_marching` calls :func:`march` for
grids of at least :data:`_tuning.PARALLEL_MIN_NODES` nodes when more than one thread is
allowed (``threads``, ``FM2UAV_THREADS``), at order 1 and 2 (:data:`_tuning.ORDER2`), ``stop_at``
too.
Order 2's stencil reads two nodes upwind: its slabs have two ghost x-slabs per
side (:func:`_pad_slabs`), the exchange copies two rows, and a changed time updates
again the nodes one *and two* away along each axis; its update is not monotone, so a
repair may also raise a time, and a node takes the time the serial march keeps, the
lowest of its updates at its neighbours' freezes (:func:`_serial_time2`): the times
equal the serial march's bit for bit (the notes above :func:`_known`). In 2D it takes the
interleaved layout as order 1 (below): its two ghost rows a side and every index count
elements, its bit masks (frozen on entry, re-opened, suspect, pending) keep a bit per node.

Design (Yang & Stern 2017, domain-decomposition FMM)
----------------------------------------------------
* The grid is cut along x (the slowest-varying axis of the C layout) into
  ``K`` slabs, :data:`_tuning.SLABS_PER_THREAD` per thread, thread ``t`` marching slabs
  ``t, t + threads, ...`` (interleaved strips keep both threads busy when the
  wave starts off-centre, and a coarse march places the cuts, :func:`slab_bounds`; in 2D
  and on 3D grids of at least :data:`_tuning.SHARED_CUTS_MIN_NODES_3D` nodes for the slabs shared
  before each window where that shortens the windows, :data:`_tuning.SHARED_CUTS`; while this
  thread places the cuts, a second one finds the top speed and faults pages in — the lean
  layout's buffers, else the result's rows the other thread unpads first —
  :class:`_PageToucher`),
  unless sharing them longest first by the last window's freezes promises a shorter
  window (:func:`_assign`, before every window). The threads take each window's slabs in
  turn, each first those it ran in the last window (:func:`_affine`,
  :data:`_tuning.SLABS_STAY_2D` and ``_3D``): a slab that changes cores reads its rows and
  queue from the other core's cache. The set-up pads the slabs in parallel
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
* **2D interleaved** (order 1 and 2), as the serial march: a 2D map (outside the lean layout) whose
  passable nodes do not all have one speed keeps each node's time and ``1 / speed^2``
  side by side in one array (node ``c``'s time at element ``2 c``, its speed term at
  ``2 c + 1``; the kernels take the buffer and the buffer shifted by one, and every node
  index in the kernels, the queues, the boundary lists, the start rows and the stop
  nodes is an element index: strides ``sx = 2 (ny + 2)``, ``sy = 2``); the frozen-on-entry
  and plateau masks keep a bit per node (element index halved). An update reads a
  neighbour's time and speed from one cache line. A uniform map keeps the separate arrays
  and reads no speed (the plateau register). ``march(..., interleave=False)`` forces the
  separate arrays (the tests: the same times bit for bit).
* **Far neighbours** (order 1, and order 2 in 2D): a window freezing a node gives its far
  neighbours the one-axis update along their axis, as the serial march
  (:data:`FAR_ONE_AXIS`). Valid in a slab because a far node never has a frozen
  neighbour: a pop, a node frozen on entry (the
  start) and a ghost (the exchange, its one own neighbour) each update their band and far
  own neighbours when they become frozen, and a re-opened node had done so when it was
  frozen first; so the full update of that node reads one frozen neighbour and gives the
  same bits (the tests run with the rule on and off, one-row slabs included, and compare
  the times and statistics bit for bit). Such a node is **deferred** as in the serial march
  (no queue entry while a band neighbour across the other axis is earlier: an own node of
  the slab, since ghosts hold frozen times or NaN, so this slab freezes it first and updates
  the node again; :func:`_lower_r` queues a band node that an update does not lower). The
  order-2 window defers so too (its far rule is its own, below): there a suspect node's time
  can go *up* when it pops, so the band neighbours it no longer precedes are queued then, and
  its update and repair paths queue a band node they do not lower; still the serial times
  bit for bit. The 3D order-1 windows take the rule and the deferral too (across either other
  axis, :func:`~fm2uav.eikonal._kernels._earlier_band3`, as the serial 3D march): on 160^3 two
  threads the windows' CPU 0.95x at constant and smooth speed, the wall 0.97-0.99x
  (docs/performance.md, session 35); the 3D order-2 window defers nothing.
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
* **Pipelined** (2D, :data:`_tuning.PIPELINE`; not toward stop nodes): no barrier between
  the windows. Each window posts the times of the nodes it froze in its boundary rows into a
  buffer of its own, two of them by the parity of the window's number (:func:`_post_rows`),
  and a slab's next exchange reads its neighbours' posts, not their rows: its step (the
  exchange, then the window) waits for its two neighbours' last windows only, and a thread
  takes whichever slab may step, first one it ran last (:func:`_pipe_kernel`). Each slab's
  exchanges read what they would between barriers; the windows' ends are set as the first
  slab reaches them, the width adapted to the last window every slab has run.
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
import threading
from functools import partial

import numpy as np
from llvmlite import ir
from numba.core import cgutils
from numba.extending import intrinsic

from .._numba import njit, prange, types
from . import _kernels, _tuning
from ._heap import sift_down, sift_up
from ._kernels import (_INF, _NB, _NIL, _NW, _ONE, _ORDER2_MAX_W_RATIO, _U, _ZERO,
                       RESERVE_BLOCKS, BLOCK,
                       _at_plateau, _axis_term, _axis_term_u, _bits, _bucket, _combine,
                       _earlier_band, _earlier_band3, _fetch_rows, _from_bits, _prefetch,
                       _pad_slab, _pop, _pop_ahead, _push, _rhs, _side_min, _solve_iso,
                       speed_range, unpad_grid)

# threads waiting at a barrier spin briefly, then sleep (:data:`_tuning.SPIN_COUNT`); read
# by libgomp when numba first starts its thread pool, values the user set stay
if "OMP_WAIT_POLICY" not in os.environ:
    os.environ["OMP_WAIT_POLICY"] = "PASSIVE"
    os.environ.setdefault("GOMP_SPINCOUNT", str(_tuning.SPIN_COUNT))

__all__ = ["march", "on_slabs", "resolve_threads"]

#: 2D and 3D order 1 (order 2: 2D): a far neighbour of the node a window freezes gets the
#: one-axis update along their axis, as in the serial march (valid in a slab: see the window's
#: docstring); False: the full update (the same times bit for bit; the tests run both).
FAR_ONE_AXIS = True
#: With :data:`FAR_ONE_AXIS`: a far neighbour so updated gets no queue entry while a band
#: neighbour across another axis is earlier (**deferred**, as in the serial march; see the
#: window's docstring; order 2 too). False: queued at once. Both end at the serial march's
#: times (order 1 to round-off, order 2 bit for bit); on a map with exact ties and repairs the
#: order-1 windows may differ in round-off (the order in which the same times pop), so the far
#: rule's bit-for-bit tests run without it.
DEFER = True
#: Free repair-heap slots kept before each node's pushes (one pop pushes at most 7).
HEAP_RESERVE = 8
#: Order 2: one pop queues at most 13 entries (six neighbours, the six nodes two away, the
#: put-back), so more free repair-heap slots and entry-pool blocks are kept than for order 1.
HEAP_RESERVE_2 = 16
POOL_EXTRA_2 = 16
#: Smallest start of a slab's repair heap (entries; at least 4 boundary rows) and
#: entry pool (blocks); both double when a window runs low.
HEAP_START = 4096
POOL_MIN_BLOCKS = 2 * RESERVE_BLOCKS

# slots of the per-slab control array ``ctl`` (float64)
_C_NEXT = 0    # smallest queued time after the last window or exchange (inf: none)
_C_POPS = 1    # nodes frozen in the last window
_C_REOPEN = 2  # nodes re-opened so far
_C_STATUS = 3  # 0 ok, 1 entry pool low, 2 repair heap full
_C_PEND = 4    # order 2: re-opened nodes raised above their old time, not frozen again
_C_RMIN = 5    # order 2: a time no later than the old times of those (inf: none)
_C_RAISED = 6  # order 2: updates that found a later time than the node had (suspects)
_C_RUNS = 7    # the slab's runs in the exchanges and windows (once per region: the tests)
_C_RLIVE = 8   # order 2: the slab's re-opened bits set (0: none, its pops read no bit)
_C_SLIVE = 9   # order 2: the slab's suspect bits set (likewise)
_C_FMAX = 10   # order 2: no node of the slab (ghosts too) frozen later, but on entry
_C_OWNER = 11  # the thread that ran the slab's last window (share 3, :func:`_affine`)
_C_SIZE = 12

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
        var = _tuning.THREADS_ENV
        env = os.environ.get(var, "").strip()
        if env:
            try:
                threads = int(env)
            except ValueError:
                raise InputError(
                    f"{var} must be an integer >= 1 (threads of the Fast Marching), "
                    f"got {env!r}") from None
            if threads < 1:
                raise InputError(
                    f"{var} must be an integer >= 1 (threads of the Fast Marching), "
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
def _keep_queue(st, nfree, fh, cur, last, rsize):
    """Store the queue's state (radix queue and repair heap's size) in ``st``."""
    st[_NFREE] = nfree
    st[_FH] = fh
    st[_CUR] = cur
    st[_LAST] = last
    st[_RSIZE] = rsize


@njit(cache=True, inline="always", error_model="numpy", _nrt=False)
def _enq_r(k, c, pool, nxt, bk, mw, rkey, ritem, nfree, fh, cur, last, rsize):
    """Queue node ``c`` with key bits ``k``: the radix queue if ``k`` is not below its
    lower bound ``last``, else the repair heap of ``rsize`` entries (the caller keeps
    :data:`HEAP_RESERVE` slots free). The queue's state in and out as values (a kernel
    keeps it in registers, :func:`_window`): ``nfree, fh, cur, rsize``."""
    if k >= last:
        nfree, fh, cur = _push(_bucket(k, last), k, c, pool, nxt, bk, mw, nfree, fh, cur)
    else:
        sift_up(rkey, ritem, rkey[:0], np.int64(rsize), k, c)
        rsize += _ONE
    return nfree, fh, cur, rsize


@njit(cache=True, inline="always", error_model="numpy", _nrt=False)
def _enq(k, c, pool, nxt, bk, mw, st, rkey, ritem):
    """:func:`_enq_r` with the queue's state in ``st``."""
    nfree, fh, cur, rsize = _enq_r(k, c, pool, nxt, bk, mw, rkey, ritem, st[_NFREE], st[_FH],
                                   st[_CUR], st[_LAST], st[_RSIZE])
    _keep_queue(st, nfree, fh, cur, st[_LAST], rsize)


@njit(cache=True, inline="always", error_model="numpy", _nrt=False)
def _pop_repair_r(rkey, ritem, rsize):
    """Remove the smallest entry of the repair heap of ``rsize`` entries (not empty): its
    node and the new size."""
    c = ritem[0]
    rsize -= _ONE
    if rsize > _ZERO:
        sift_down(rkey, ritem, rkey[:0], np.int64(rsize), rkey[rsize], ritem[rsize])
    return c, rsize


@njit(cache=True, inline="always", error_model="numpy", _nrt=False)
def _pop_repair(st, rkey, ritem):
    """:func:`_pop_repair_r` with the heap's size in ``st``."""
    c, rsize = _pop_repair_r(rkey, ritem, st[_RSIZE])
    st[_RSIZE] = rsize
    return c


@njit(cache=True, inline="always", error_model="numpy", _nrt=False)
def _deq_r(T, pool, nxt, bk, mw, rkey, ritem, nfree, fh, cur, last, rsize):
    """Remove the smallest queued entry (repair heap first): its node or ``_NIL``, and the
    queue's state ``nfree, fh, cur, last, rsize`` (values, as :func:`_enq_r`)."""
    if rsize > _ZERO:
        c, rsize = _pop_repair_r(rkey, ritem, rsize)
        return c, nfree, fh, cur, last, rsize
    c, nfree, fh, cur, last = _pop(T, pool, nxt, bk, mw, nfree, fh, cur, last)
    return c, nfree, fh, cur, last, rsize


@njit(cache=True, inline="always", error_model="numpy", _nrt=False)
def _deq(T, pool, nxt, bk, mw, st, rkey, ritem):
    """:func:`_deq_r` with the queue's state in ``st``."""
    c, nfree, fh, cur, last, rsize = _deq_r(T, pool, nxt, bk, mw, rkey, ritem, st[_NFREE],
                                            st[_FH], st[_CUR], st[_LAST], st[_RSIZE])
    _keep_queue(st, nfree, fh, cur, last, rsize)
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
    _fetch_rows(T, V, c, sx, _U(T.size), pv)
    if three:
        _prefetch(T, c - sy)
        _prefetch(T, c + sy)
        if pv:
            _prefetch(V, c - sy)
            _prefetch(V, c + sy)
        _prefetch(T, c - sy - sy)
        _prefetch(T, c + sy + sy)


@njit(cache=True, inline="always", error_model="numpy", _nrt=False)
def _lower_r(T, V, c, t, fixed, sx, sy, three, pv, pool, nxt, bk, mw, rkey, ritem, ctl, rows,
             nfree, fh, cur, last, rsize):
    """Give node ``c`` the time ``t`` if that is lower than its band or frozen time.

    A frozen node lowered is re-opened (band again), unless it was frozen on entry
    (bit ``c`` of ``fixed``: a source or its ball, final as in the serial march). A band node
    not lowered is queued again at its time: it may be a deferred one without an entry (the
    2D window; a second entry at the same key is skipped as outdated).
    ``rows``: prefetch the rows a new band node's freezing reads (``pv``: their speeds
    too, off the plateau); the 3D order-2 window fetches around its next pops instead.
    The queue's state in and out as values (:func:`_enq_r`): ``nfree, fh, cur, rsize``.
    """
    x = T[c]
    if x < 0.0:
        if t < -x:
            T[c] = -t
            if rows and x == -_INF:  # a new band node: fetch the rows its freezing reads
                _prefetch_rows(T, V, c, sx, sy, three, pv)
            return _enq_r(_bits(t), c, pool, nxt, bk, mw, rkey, ritem, nfree, fh, cur, last,
                          rsize)
        if x > -_INF:  # a band node not lowered: it may be deferred
            return _enq_r(_bits(-x), c, pool, nxt, bk, mw, rkey, ritem, nfree, fh, cur, last,
                          rsize)
    elif t < x and _fixed_at(fixed, c, sy, three) == _ZERO:
        T[c] = -t
        ctl[_C_REOPEN] += 1.0
        return _enq_r(_bits(t), c, pool, nxt, bk, mw, rkey, ritem, nfree, fh, cur, last, rsize)
    return nfree, fh, cur, rsize


@njit(cache=True, inline="always", error_model="numpy", _nrt=False)
def _lower(T, V, c, t, fixed, sx, sy, three, pv, pool, nxt, bk, mw, st, rkey, ritem, ctl,
           rows=True):
    """:func:`_lower_r` with the queue's state in ``st``."""
    nfree, fh, cur, rsize = _lower_r(T, V, c, t, fixed, sx, sy, three, pv, pool, nxt, bk, mw,
                                     rkey, ritem, ctl, rows, st[_NFREE], st[_FH], st[_CUR],
                                     st[_LAST], st[_RSIZE])
    _keep_queue(st, nfree, fh, cur, st[_LAST], rsize)


@njit(cache=True, inline="always", error_model="numpy", _nrt=False)
def _room_r(nfree, rsize, rkey):
    """Whether the pool (``nfree`` blocks free) and the repair heap (``rsize`` entries) have
    room for the pushes of one node."""
    return nfree >= _U(RESERVE_BLOCKS) and rsize + _U(HEAP_RESERVE) <= _U(rkey.size)


@njit(cache=True, inline="always", _nrt=False)
def _room(st, rkey):
    """:func:`_room_r` with the queue's state in ``st``."""
    return _room_r(st[_NFREE], st[_RSIZE], rkey)


@njit(cache=True, inline="always", _nrt=False)
def _nbs(c, sx, sy, three):
    """The neighbours of node ``c``: six in 3D; in 2D four (``sy`` the y stride: 1, or 2 in
    the interleaved layout), then ``c`` twice (frozen: skipped)."""
    if three:
        return (c - sx, c + sx, c - sy, c + sy, c - _ONE, c + _ONE)
    return (c - sx, c + sx, c - sy, c + sy, c, c)


@njit(cache=True, inline="always", _nrt=False)
def _nb_at(c, j, sx, sy, one):
    """Neighbour ``j`` of node ``c`` (x-, x+, y-, y+, z-, z+), from its axis' stride (``sx``,
    ``sy`` or ``one``, the z stride) and side: in 2D (``j < 4``) as the serial march computes
    it (on 2048^2 1-3 % faster than the tuple of :func:`_nbs`; in 3D the order-2 window reads
    the tuple, 1.034x faster on 160^3 FM²-shaped)."""
    s = sx if j < 2 else (sy if j < 4 else one)
    return c - s if j & 1 == 0 else c + s


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


def _slab_kernels(three, pairs=False):
    """The compiled window, start and exchange of one dimension (``three``: 3D); ``pairs``:
    the 2D window of the interleaved layout only (``sy`` 2, a constant of the kernel)."""

    # closure variables are part of numba's cache key: only ``three`` and ``pairs`` (bools)
    # may be ones (a dispatcher's pickle differs per process and would defeat the cache)
    def window(T, V, U, qp, fixed, sx, sy, ih, hh, iso, tw, pool, nxt, bk, mw, st, rkey, ritem,
               ctl, sent, ns, far):
        """Freeze the slab's queued nodes with a time below ``tw`` (resumable).

        ``T`` is the slab's padded grid (ghost x-slabs first and last). Sets
        ``ctl[_C_NEXT]`` to the smallest time left queued (inf if none). The nodes it
        freezes in its first and last own rows go to ``sent[0]`` and ``sent[1]``
        (``ns`` their counts, reset here): the neighbours' exchange reads only those.

        ``far``: 1 or 2, a far neighbour of the node just frozen gets the one-axis
        update along their axis, as in the serial march (0: the full update); 2, and no queue
        entry while a neighbour across another axis is in the band earlier (deferred, as in
        the serial march: that neighbour is an own node, ghosts hold frozen times or NaN, so
        this slab freezes it first and updates the node again, and :func:`_lower_r` queues a
        band node that an update does not lower). Valid in a slab because no far node has
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
        if pairs:  # the interleaved layout: the y stride a constant (every helper's too)
            sy = _U(2)
        one = _unit(sy, three)
        use_u = qp > 0.0 and one == _ONE
        kw = _bits(tw)
        pops = 0
        ns[0] = _ZERO
        ns[1] = _ZERO
        ctl[_C_NEXT] = _INF
        # the queue's state in registers (stored back at the end): the stores into T
        # would otherwise reload it from st at every push and pop
        nfree = st[_NFREE]
        fh = st[_FH]
        cur = st[_CUR]
        last = st[_LAST]
        rsize = st[_RSIZE]
        while True:
            if not _room_r(nfree, rsize, rkey):
                ctl[_C_STATUS] = 1.0 if nfree < _U(RESERVE_BLOCKS) else 2.0
                break
            if rsize > _ZERO:
                c, rsize = _pop_repair_r(rkey, ritem, rsize)
            elif three:  # a level-0 bucket's next pop fetched ahead (the serial 3D march's)
                c, nfree, fh, cur, last = _pop_ahead(T, V, pool, nxt, bk, mw, nfree, fh, cur,
                                                     last, sx, sy, not use_u, False)
            else:
                c, nfree, fh, cur, last = _pop(T, pool, nxt, bk, mw, nfree, fh, cur, last)
            if c == _NIL:
                break
            x = T[c]
            if not x < 0.0:  # outdated entry of a frozen node
                continue
            t = -x
            k = _bits(t)
            if k >= kw:  # the window is done: put it back
                nfree, fh, cur, rsize = _enq_r(k, c, pool, nxt, bk, mw, rkey, ritem, nfree, fh,
                                               cur, last, rsize)
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
            # one site for the neighbours, as the serial march
            for j in range(6 if three else 4):
                nb = _nb_at(c, j, sx, sy, one)
                y = T[nb]
                if far != 0 and y == -_INF:  # c is its only frozen neighbour (docstring)
                    q = _rhs(V, U, use_u, qp, nb)
                    t_nb = t + math.sqrt(q * hh) if iso else t + math.sqrt(q / ih[j >> 1])
                    if far == 2 and (_earlier_band3(T, nb, j, sx, sy, one, t_nb) if three else
                                     _earlier_band(T, nb, sy if j < 2 else sx, t_nb)):
                        T[nb] = -t_nb  # deferred, as in the serial march
                        _prefetch_rows(T, V, nb, sx, sy, three, pv)
                        continue
                elif y < 0.0 or (y > t and nb >= lo and nb < hi):
                    # band/far, or frozen later than c in this slab: c may lower it
                    t_nb = _update(T, V, U, use_u, qp, nb, sx, sy, ih, hh, iso, three)
                else:
                    continue
                nfree, fh, cur, rsize = _lower_r(T, V, nb, t_nb, fixed, sx, sy, three, pv, pool,
                                                 nxt, bk, mw, rkey, ritem, ctl, True, nfree, fh,
                                                 cur, last, rsize)
        _keep_queue(st, nfree, fh, cur, last, rsize)
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
        f.__name__ = f.__qualname__ = f"{f.__name__}{d}d" + ("_pairs" if pairs else "")
        out.append(njit(cache=True, error_model="numpy", _nrt=False)(f))
    return out


_window2d, _start2d, _exchange2d = _slab_kernels(False)
_window2d_pairs = _slab_kernels(False, True)[0]
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


# ------------------------------------------------------------------ order 2
# The serial order-2 march updates a node each time one of its neighbours freezes, from the
# nodes frozen by then, and keeps the lowest update (:func:`_serial_time2` computes that
# from the frozen times around the node: each neighbour's update reads only the nodes
# :func:`_known` when it froze). That is a function of the final times of the node's
# neighbours and of the nodes two away along each axis, all earlier than the node; so the
# serial times are the one solution of ``T = serial_time(T)`` in which every node depends on
# earlier nodes only (by induction in time order), and the parallel march ends there,
# bit for bit: whenever a frozen time that an update read changes (a ghost exchanged, a
# node frozen again at another time) its dependants -- the neighbours and the nodes two
# away along each axis -- are updated again. The update is not monotone (a lower time two
# away raises the order-2 term), so a dependant may have to go *up*: a band node keeps its
# (lower) time and is marked suspect (bit ``sf``), updated again when popped; a frozen one
# is re-opened at its old time, suspect too (its queue key stays a lower bound of its
# time, which the windows and the stop test rely on). A re-opened node (bit ``rf``)
# updates all its dependants again when frozen again, since they may have read its old time.
# (Taking one update from all the final times instead differed by up to 3e-11 relative on a
# 2048^2 map: near an axis's causality limit the two-axis formula's rounding can put it
# above an earlier one-axis update, which the serial march keeps; docs/performance.md.)

@intrinsic
def _clock_ns(typingctx, clk):
    """``clock_gettime(clk)`` in nanoseconds (int64): 1 ``CLOCK_MONOTONIC``, 3
    ``CLOCK_THREAD_CPUTIME_ID`` (the calling thread's CPU time). For the drive's profile
    (:data:`PROFILE`) only."""
    sig = types.int64(clk)

    def codegen(context, builder, signature, args):
        i32, i64 = ir.IntType(32), ir.IntType(64)
        ts = cgutils.alloca_once(builder, ir.ArrayType(i64, 2))
        fnty = ir.FunctionType(i32, [i32, ir.IntType(8).as_pointer()])
        fn = cgutils.get_or_insert_function(builder.module, fnty, "clock_gettime")
        builder.call(fn, [builder.trunc(args[0], i32),
                          builder.bitcast(ts, ir.IntType(8).as_pointer())])
        zero = ir.Constant(i32, 0)
        sec = builder.load(builder.gep(ts, [zero, zero]))
        ns = builder.load(builder.gep(ts, [zero, ir.Constant(i32, 1)]))
        return builder.add(builder.mul(sec, ir.Constant(i64, 1_000_000_000)), ns)

    return sig, codegen


@intrinsic
def _fetch_add(typingctx, a, i):
    """``a[i] += 1`` atomically (int64 array), returning the old value: the next slab a
    thread takes in a dynamically shared region (:data:`_tuning.DYNAMIC_2D`)."""
    sig = types.int64(a, i)

    def codegen(context, builder, signature, args):
        aty = signature.args[0]
        arr = context.make_array(aty)(context, builder, args[0])
        ptr = cgutils.get_item_pointer(context, builder, aty, arr, [args[1]])
        return builder.atomic_rmw("add", ptr, ir.Constant(ir.IntType(64), 1), "seq_cst")

    return sig, codegen


@intrinsic
def _load(typingctx, a, i):
    """``a[i]`` read atomically (int64 array, acquire): a flag another thread sets with
    :func:`_fetch_add` while this one waits on it (a plain read may be hoisted out of the
    wait)."""
    sig = types.int64(a, i)

    def codegen(context, builder, signature, args):
        aty = signature.args[0]
        arr = context.make_array(aty)(context, builder, args[0])
        ptr = cgutils.get_item_pointer(context, builder, aty, arr, [args[1]])
        return builder.load_atomic(ptr, "acquire", 8)

    return sig, codegen


@intrinsic
def _set_threads(typingctx, n):
    """``numba.set_num_threads(n)`` for the parallel regions this thread starts, by the
    threading layer's symbol as numba's own ``get_num_threads`` calls it (numba's jitted
    ``set_num_threads`` holds a ctypes pointer, and a function holding one is not cached:
    the drive would compile again in every process)."""
    from numba.np.ufunc.parallel import _launch_threads

    _launch_threads()
    sig = types.void(n)

    def codegen(context, builder, signature, args):
        i32 = ir.IntType(32)
        fnty = ir.FunctionType(ir.VoidType(), [i32])
        fn = cgutils.get_or_insert_function(builder.module, fnty, "set_num_threads")
        builder.call(fn, [builder.trunc(args[0], i32)])
        return context.get_dummy_value()

    return sig, codegen


@njit(cache=True, inline="always", _nrt=False)
def _take(lists, nth, t, i, dyn):
    """The next position in ``slabs`` thread ``t`` runs after position ``i`` (``-1``: its
    first): with ``dyn`` 1 (True) the next one no thread has taken (the counter
    ``lists[nth]``); 2 the next not taken of its own list ``lists[t]:lists[t + 1]`` (its
    counter ``lists[lists.size - nth + t]``), then of the other threads' lists, from
    ``t + 1`` on (the slabs it ran last kept where they run: :func:`_affine`); 0 the next of
    its own list. Past the end: done (:func:`_took_all`)."""
    if dyn == 2:
        h = lists.size - nth
        for u in range(nth):
            v = t + u if t + u < nth else t + u - nth
            j = _fetch_add(lists, h + v)
            if j < lists[v + 1]:
                return j
        return lists.size  # every list taken (past the K slabs)
    if dyn:
        return _fetch_add(lists, nth)
    return lists[t] if i < 0 else i + 1


@njit(cache=True, inline="always", _nrt=False)
def _took_all(lists, nth, t, i, K, dyn):
    """Whether position ``i`` is past thread ``t``'s slabs (all ``K`` with ``dyn`` 1 or 2)."""
    return i >= (K if dyn else lists[t + 1])


@njit(cache=True, inline="always", _nrt=False)
def _bit(a, c):
    """Bit ``c`` of the bit mask ``a`` (uint8)."""
    return (a[c >> _U(3)] >> (c & _U(7))) & _ONE != _ZERO


@njit(cache=True, inline="always", _nrt=False)
def _set_bit(a, c):
    a[c >> _U(3)] |= np.uint8(_ONE << (c & _U(7)))


@njit(cache=True, inline="always", _nrt=False)
def _clear_bit(a, c):
    i = c >> _U(3)
    a[i] = np.uint8(a[i] & (np.uint8(255) ^ np.uint8(_ONE << (c & _U(7)))))


@njit(cache=True, inline="always", _nrt=False)
def _fbit(a, c):
    """Bit ``c`` of one of order 2's flag masks: the three masks interleaved a byte each in
    every 4 bytes (a node's three flags on one cache line; ``a`` starts at the mask's byte)."""
    return a[(c >> _U(3)) << _U(2)] & np.uint8(_ONE << (c & _U(7)))


@njit(cache=True, inline="always", _nrt=False)
def _set_fbit(a, c):
    a[(c >> _U(3)) << _U(2)] |= np.uint8(_ONE << (c & _U(7)))


@njit(cache=True, inline="always", _nrt=False)
def _clear_fbit(a, c):
    i = (c >> _U(3)) << _U(2)
    a[i] = np.uint8(a[i] & (np.uint8(255) ^ np.uint8(_ONE << (c & _U(7)))))


@njit(cache=True, inline="always", _nrt=False)
def _mark(a, c, ctl, slot):
    """Set flag bit ``c`` of ``a`` (:func:`_set_fbit`), counting it in ``ctl[slot]`` if it was
    clear: while the count is 0 the pops read no bit of that mask."""
    if not _fbit(a, c):
        _set_fbit(a, c)
        ctl[slot] += 1.0


@njit(cache=True, inline="always", _nrt=False)
def _mark_r(a, c, live):
    """:func:`_mark` with the mask's count ``live`` as a value: the new count."""
    if not _fbit(a, c):
        _set_fbit(a, c)
        live += 1.0
    return live


@njit(cache=True, inline="always", _nrt=False)
def _take_flag_r(a, c, live):
    """:func:`_take_flag` with the mask's count ``live`` as a value: whether the bit was set,
    and the new count."""
    if live > 0.0 and _fbit(a, c):
        _clear_fbit(a, c)
        return True, live - 1.0
    return False, live


@njit(cache=True, inline="always", _nrt=False)
def _take_flag(a, c, ctl, slot):
    """Whether flag bit ``c`` of ``a`` is set, clearing it (and its count) if so; no read
    while no bit of the mask is set (``ctl[slot] == 0``)."""
    if ctl[slot] > 0.0 and _fbit(a, c):
        _clear_fbit(a, c)
        ctl[slot] -= 1.0
        return True
    return False


@njit(cache=True, inline="always", _nrt=False)
def _known(T, fixed, c, thr, sh):
    """Node ``c``'s time if the serial march had frozen it when the node of time ``thr``
    froze (frozen on entry, or frozen no later than ``thr``), else inf (``c >> sh``: its
    node index, the bit of ``fixed``)."""
    x = T[c]
    if x >= 0.0 and (x <= thr or _bit(fixed, c >> sh)):
        return x
    return _INF


@njit(cache=True, inline="always", error_model="numpy", _nrt=False)
def _axis_term_at(T, V, U, use_u, fixed, c, s, ih2, thr, sh):
    """:func:`~fm2uav.eikonal._kernels._axis_term_u` at order 2 (the same operations, the
    same bits) reading only the nodes :func:`_known` at ``thr``."""
    a = _known(T, fixed, c - s, thr, sh)
    b = _known(T, fixed, c + s, thr, sh)
    if b < a:
        best = b
        c1 = c + s
        c2 = c1 + s
    else:
        best = a
        c1 = c - s
        c2 = c1 - s
    if best == _INF:
        return _INF, 0.0
    return _upwind_term_at(T, V, U, use_u, fixed, c, best, c1, c2, ih2, thr, sh)


@njit(cache=True, inline="always", error_model="numpy", _nrt=False)
def _upwind_term_at(T, V, U, use_u, fixed, c, best, c1, c2, ih2, thr, sh):
    """:func:`~fm2uav.eikonal._kernels._upwind_term` reading ``c2`` only if
    :func:`_known` at ``thr``: the term of ``c``'s axis whose upwind neighbour ``c1`` has
    the time ``best`` (the far-neighbour shortcut's call: no read of the other side)."""
    t2 = _known(T, fixed, c2, thr, sh)
    if t2 <= best:
        if use_u and _at_plateau(U, c) and _at_plateau(U, c1) and _at_plateau(U, c2):
            return (4.0 * best - t2) / 3.0, 2.25 * ih2
        w0 = V[c]
        w1 = V[c1]
        w2 = V[c2]
        wmax = max(w0, max(w1, w2))
        wmin = min(w0, min(w1, w2))
        if wmax <= _ORDER2_MAX_W_RATIO * wmin:
            return (4.0 * best - t2) / 3.0, 2.25 * ih2
    return best, ih2


@njit(cache=True, inline="always", error_model="numpy", _nrt=False)
def _update2_at(T, V, U, use_u, qp, fixed, c, sx, sy, ih, three, thr):
    """The serial march's order-2 update of node ``c`` when the node of time ``thr`` froze,
    from the nodes :func:`_known` at ``thr`` (``thr < 0``: the nodes frozen on entry, as the
    serial march's first updates): its terms in the serial march's order, the same bits."""
    sh = _unit(sy, three) >> _ONE
    q = _rhs(V, U, use_u, qp, c)
    ta, aa = _axis_term_at(T, V, U, use_u, fixed, c, sx, ih[0], thr, sh)
    tb, ab = _axis_term_at(T, V, U, use_u, fixed, c, sy, ih[1], thr, sh)
    if three:
        tc, ac = _axis_term_at(T, V, U, use_u, fixed, c, _ONE, ih[2], thr, sh)
    else:
        tc, ac = _INF, 0.0
    return _combine(ta, aa, tb, ab, tc, ac, q)


@njit(cache=True, inline="always", _nrt=False)
def _later_nb(T, fixed, c, sx, sy, three, t):
    """Whether a neighbour of node ``c`` is frozen later than ``t`` (and not on entry)."""
    sh = _unit(sy, three) >> _ONE
    for nb in _nbs(c, sx, sy, three):
        if T[nb] > t and not _bit(fixed, nb >> sh):  # c itself (2D): band, not > t
            return True
    return False


@njit(cache=True, error_model="numpy", _nrt=False)
def _serial_time2(T, V, U, use_u, qp, fixed, c, sx, sy, ih, three):
    """The time the serial order-2 march gives node ``c`` from the frozen times around it.

    The serial march updates ``c`` each time a neighbour freezes, from the nodes frozen by
    then, and keeps the lowest: first from the nodes frozen on entry (if one is a
    neighbour), then at each neighbour's time in increasing order, until ``c``'s own time
    (a neighbour later than it freezes after ``c``). Not one update from every frozen
    node: adding an axis near its causality limit (its time just below the
    solution) lowers the exact solution by less than the rounding of the two-axis formula,
    which can then come out *above* the one-axis solution of an earlier update (by 4e-14
    relative at the first node that differed on the 2048^2 FM²-shaped map); the serial
    march keeps that earlier one.
    """
    sh = _unit(sy, three) >> _ONE
    val = _INF
    for nb in _nbs(c, sx, sy, three):
        if nb != c and T[nb] >= 0.0 and _bit(fixed, nb >> sh):
            val = _update2_at(T, V, U, use_u, qp, fixed, c, sx, sy, ih, three, -1.0)
            break
    prev = -1.0
    while True:
        thr = _INF  # the next neighbour's time (frozen, not on entry)
        for nb in _nbs(c, sx, sy, three):
            x = T[nb]
            if nb != c and x >= 0.0 and x > prev and x < thr and not _bit(fixed, nb >> sh):
                thr = x
        if not thr < val:
            return val
        val = min(val, _update2_at(T, V, U, use_u, qp, fixed, c, sx, sy, ih, three, thr))
        prev = thr


@njit(cache=True, inline="always", _nrt=False)
def _entry_cap(eidx, evals, g, t):
    """``t``, or the time node ``g`` (an index into the slabs' buffer) had in the band on
    entry if lower: the serial march keeps it (sorted ``eidx``, times ``evals``)."""
    if eidx.size == 0 or g < eidx[0] or g > eidx[eidx.size - 1]:
        return t
    i = np.searchsorted(eidx, g)
    if i < eidx.size and eidx[i] == g:
        return min(t, evals[i])
    return t


@njit(cache=True, error_model="numpy", _nrt=False)  # a call (rare): compiles once
def _recheck(T, V, U, use_u, qp, d, sx, sy, ih, three, fixed, rf, sf, eidx, evals, base, pool,
             nxt, bk, mw, st, rkey, ritem, ctl, requeue):
    """Update the slab's own node ``d`` again after a time it may read changed (order 2).

    Far or band: a lower time is taken and queued; a higher one marks the node suspect
    (updated again when popped). Frozen: a different time re-opens it (``rf``), at the new
    time if lower, else at its old time and suspect. Walls and nodes frozen on entry stay;
    a node in the band on entry keeps that time if lower (``eidx``, ``evals``: those nodes
    by their index in the slabs' buffer, ``base + d`` for ``d``). ``requeue``: a band node
    not lowered is queued again at its time (it may be a deferred one without an entry: the
    2D window's far rule).
    """
    x = T[d]
    nd = d >> (_unit(sy, three) >> _ONE)  # its node index: its bits in the masks
    if x != x or _bit(fixed, nd):
        return
    t = _entry_cap(eidx, evals, base + d,
                   _serial_time2(T, V, U, use_u, qp, fixed, d, sx, sy, ih, three))
    if x < 0.0:
        if t < -x:
            T[d] = -t
            _enq(_bits(t), d, pool, nxt, bk, mw, st, rkey, ritem)
        elif x > -_INF:
            if t > -x:
                _mark(sf, nd, ctl, _C_SLIVE)
                ctl[_C_RAISED] += 1.0
            if requeue:
                _enq(_bits(-x), d, pool, nxt, bk, mw, st, rkey, ritem)
    elif t != x:
        ctl[_C_REOPEN] += 1.0
        _mark(rf, nd, ctl, _C_RLIVE)
        if t < x:
            T[d] = -t
            _enq(_bits(t), d, pool, nxt, bk, mw, st, rkey, ritem)
        else:
            T[d] = -x
            _mark(sf, nd, ctl, _C_SLIVE)
            ctl[_C_RAISED] += 1.0
            _enq(_bits(x), d, pool, nxt, bk, mw, st, rkey, ritem)


@njit(cache=True, inline="always", error_model="numpy", _nrt=False)
def _recheck_r(T, V, U, use_u, qp, d, sx, sy, ih, three, fixed, rf, sf, eidx, evals, base,
               pool, nxt, bk, mw, st, rkey, ritem, ctl, requeue, live):
    """:func:`_recheck` from a kernel keeping the queue's state and the flags' live counts in
    registers, ``live``: ``(nfree, fh, cur, last, rsize, slive, rlive)`` (the suspect and
    re-opened masks' counts), stored in ``st`` and ``ctl`` for the call; returns them read back
    but ``last`` (a repair is rare; a tuple: a call of more than 30 arguments compiles in
    CPython to one of ``*args``, which numba's inliner refuses)."""
    nfree, fh, cur, last, rsize, slive, rlive = live
    _keep_queue(st, nfree, fh, cur, last, rsize)
    ctl[_C_SLIVE] = slive
    ctl[_C_RLIVE] = rlive
    _recheck(T, V, U, use_u, qp, d, sx, sy, ih, three, fixed, rf, sf, eidx, evals, base, pool,
             nxt, bk, mw, st, rkey, ritem, ctl, requeue)
    return st[_NFREE], st[_FH], st[_CUR], st[_RSIZE], ctl[_C_SLIVE], ctl[_C_RLIVE]


@njit(cache=True, error_model="numpy", _nrt=False)  # a call (rare): compiles once
def _suspect2(T, V, U, use_u, qp, fixed, c, t, sx, sy, ih, three, rf, pf, eidx, evals, base,
              pool, nxt, bk, mw, st, rkey, ritem, ctl, dfr):
    """The suspect node ``c`` popped at ``t`` (order 2): its time from scratch
    (:func:`_serial_time2`); if that differs, ``c`` is queued at it (not frozen: True) and,
    if it went up, its band neighbours deferred on its old time (``dfr``, 2D) are queued; a
    re-opened node raised is pending (``pf``: the stop test must not pass ``t`` before it is
    frozen again). False: ``t`` stands, ``c`` freezes. The queue's state in ``st``; apart from
    the window's loop (on 2048^2 FM²-shaped, one slab on one thread: its windows' CPU -1 %)."""
    sh = _unit(sy, three) >> _ONE
    t2 = _entry_cap(eidx, evals, base + c,
                    _serial_time2(T, V, U, use_u, qp, fixed, c, sx, sy, ih, three))
    if t2 == t:
        return False
    if t2 > t and _fbit(rf, c >> sh) and not _fbit(pf, c >> sh):
        # nodes may still read its old time (>= t): the stop test must not pass t before it
        # is frozen again
        _set_fbit(pf, c >> sh)
        ctl[_C_PEND] += 1.0
        ctl[_C_RMIN] = min(ctl[_C_RMIN], t)
    T[c] = -t2
    if t2 < _INF:
        _enq(_bits(t2), c, pool, nxt, bk, mw, st, rkey, ritem)
    if dfr and t2 > t:  # band neighbours deferred on c's old time: queued
        for nb in _nbs(c, sx, sy, three):
            y = T[nb]
            if nb != c and y < 0.0 and y > -_INF and -y < t2:
                _enq(_bits(-y), nb, pool, nxt, bk, mw, st, rkey, ritem)
    return True


@njit(cache=True, error_model="numpy", _nrt=False)  # a call (rare): compiles once
def _refrozen2(T, V, U, use_u, qp, c, below, lo, hi, sx, sy, ih, three, fixed, rf, sf, eidx,
               evals, base, pool, nxt, bk, mw, st, rkey, ritem, ctl, requeue):
    """Node ``c`` frozen again (re-opened before, order 2): every own node that may have read
    its old time gets its time from scratch (:func:`_recheck`), the neighbours and the nodes
    two away beyond a frozen neighbour, in the window's order (the queue's state in ``st``,
    the masks' counts in ``ctl``). Apart from the window's loop, which then keeps no test of
    it (on 2048^2 FM²-shaped, one slab on one thread: its windows' CPU -3 %).

    ``below``: ``c``'s new time when it is no later than its old one (not raised since it
    was re-opened: not pending), else -1. A node frozen earlier than both read neither (each
    of its updates runs at a neighbour's time below its own, where :func:`_known` hides
    ``c``): it keeps its time, and is skipped."""
    for j in range(6 if three else 4):
        nb = _nb_at(c, j, sx, sy, _unit(sy, three))
        y = T[nb]
        if y < 0.0 or (y >= below and nb >= lo and nb < hi):  # band or far; frozen, own
            _recheck(T, V, U, use_u, qp, nb, sx, sy, ih, three, fixed, rf, sf, eidx, evals,
                     base, pool, nxt, bk, mw, st, rkey, ritem, ctl, requeue)
        if T[nb] >= 0.0:  # the node two away reads c beyond nb
            d2 = nb + nb - c
            # an own node, not a wall, not frozen before c's times
            if d2 >= lo and d2 < hi and T[d2] == T[d2] and not (T[d2] >= 0.0
                                                                  and T[d2] < below):
                _recheck(T, V, U, use_u, qp, d2, sx, sy, ih, three, fixed, rf, sf, eidx, evals,
                         base, pool, nxt, bk, mw, st, rkey, ritem, ctl, requeue)


@njit(cache=True, inline="always", _nrt=False)
def _unread2(T, fixed, d, g, v, one, sx, sy, three):
    """Whether the own node ``d`` (one row from the ghost ``g`` if ``one``, else two) keeps
    its time now that ``g``, never frozen before, froze at ``v``: ``d`` is frozen, every
    neighbour of ``d`` (``g`` aside) frozen but on entry is earlier than ``v``, and with
    ``one`` so is ``d`` (no later than ``v``). Then no update :func:`_serial_time2` makes for
    ``d`` reads ``g`` (each runs at a neighbour's time, below ``v``, where
    :func:`_known` hides ``g``), and with ``one`` the new candidate ``v`` comes no earlier than
    ``d``'s time, which ends its loop: the recheck would find the same time."""
    x = T[d]
    if not x >= 0.0 or (one and x > v):
        return False
    sh = _unit(sy, three) >> _ONE
    for nb in _nbs(d, sx, sy, three):
        if nb != d and nb != g:
            y = T[nb]
            if y >= v and not _bit(fixed, nb >> sh):
                return False
    return True


@njit(cache=True, inline="always", _nrt=False)
def _none_at_or_after(T, fixed, d, g, v, sx, sy, three):
    """Whether ``g`` (frozen at ``v``) is not frozen on entry and no neighbour of node ``d``
    but ``g`` is frozen at ``v`` or later (frozen on entry aside): then no update the serial
    march makes of ``d`` before ``g``'s freeze reads ``g`` (:func:`_known` hides it below
    ``v``; a node frozen on entry it shows to every update, the first from the nodes frozen
    on entry too)."""
    sh = _unit(sy, three) >> _ONE
    if _bit(fixed, g >> sh):
        return False
    for nb in _nbs(d, sx, sy, three):
        if nb != g and T[nb] >= v and not _bit(fixed, nb >> sh):  # d itself (2D): band
            return False
    return True


@njit(cache=True, error_model="numpy", _nrt=False)  # a call: compiles once
def _ghost_update2(T, V, U, use_u, qp, fixed, d, v, y, sx, sy, ih, three, sf, eidx, evals, base,
                   pool, nxt, bk, mw, st, rkey, ritem, ctl, requeue):
    """The exchange's update of the band or far node ``d`` (time ``-y``) next to a ghost
    frozen first at ``v``, no neighbour of ``d`` frozen at ``v`` or later
    (:func:`_none_at_or_after`): the serial march's update when the ghost froze, kept if
    lower, as the window updates a band neighbour of the node it freezes in time order (the
    same marks: a later time marks it suspect; ``requeue``, 2D: a band node not lowered is
    queued again, it may be deferred). The same time as :func:`_recheck` from scratch: the
    band time is the lowest of the updates at its neighbours' earlier freezes."""
    tn = _update2_at(T, V, U, use_u, qp, fixed, d, sx, sy, ih, three, v)
    if tn < -y:
        T[d] = -tn
        _enq(_bits(tn), d, pool, nxt, bk, mw, st, rkey, ritem)
    elif y > -_INF:
        if tn > -y and _entry_cap(eidx, evals, base + d, tn) > -y:
            _mark(sf, d >> (_unit(sy, three) >> _ONE), ctl, _C_SLIVE)
            ctl[_C_RAISED] += 1.0
        if requeue:
            _enq(_bits(-y), d, pool, nxt, bk, mw, st, rkey, ritem)


@njit(cache=True, inline="always", _nrt=False)
def _room2_r(nfree, rsize, rkey):
    """:func:`_room2` with the queue's state in registers."""
    return (nfree >= _U(RESERVE_BLOCKS + POOL_EXTRA_2)
            and rsize + _U(HEAP_RESERVE_2) <= _U(rkey.size))


@njit(cache=True, inline="always", _nrt=False)
def _room2(st, rkey):
    """Whether the pool and the repair heap have room for the pushes of one order-2 pop."""
    return _room2_r(st[_NFREE], st[_RSIZE], rkey)


def _slab_kernels2(three, pairs=False):
    """The compiled order-2 window, start and exchange of one dimension (``three``: 3D);
    the slab has two ghost x-slabs on each side (the order-2 stencil reads two rows).
    ``pairs``: the 2D window of the interleaved layout only (``sy`` 2, a constant)."""

    def window(T, V, U, qp, fixed, rf, sf, pf, eidx, evals, base, sx, sy, ih, tw, pool, nxt, bk,
               mw, st, rkey, ritem, ctl, sent, ns, far):
        """Freeze the slab's queued nodes with a time below ``tw`` (resumable), order 2.

        As the order-1 window; the boundary lists hold the nodes frozen in the first and
        last *two* own rows, and a frozen node's dependants include the nodes two away. In
        3D it pops as the serial 3D march (:func:`~fm2uav.eikonal._kernels._pop_ahead`: the
        lines the next pops read
        fetched ahead) and fetches no rows for new band nodes (on the terrain march the
        windows' CPU -8 %, docs/performance.md).

        ``far`` 2 (2D): a far node's one-axis time comes without a queue entry while a band
        neighbour across the other axis is earlier (**deferred**, as the order-1 window and
        the serial march): that neighbour freezes first and updates it. So a band node an
        update or a repair does not lower is queued again at its time, and a suspect whose
        time goes up when popped queues its band neighbours earlier than its new time (they
        may have been deferred on its old one: the only way a band time rises).
        """
        n = _U(T.size)
        g = sx + sx
        lo = g  # the slab's own nodes: [lo, hi)
        hi = n - g
        lo2 = lo + g  # the first two own rows are [lo, lo2), the last two [hi2, hi)
        hi2 = hi - g
        if pairs:  # the interleaved layout: the y stride a constant (every helper's too)
            sy = _U(2)
        one = _unit(sy, three)  # elements a node (2D interleaved: 2)
        sh = one >> _ONE  # node index = element index >> sh: the bits of the masks
        use_u = qp > 0.0 and one == _ONE
        dfr = far == 2 and not three  # far nodes deferred (2D)
        kw = _bits(tw)
        pops = 0
        ns[0] = _ZERO
        ns[1] = _ZERO
        ctl[_C_NEXT] = _INF
        # the queue's state in registers (stored back at the end, and around a repair's
        # call): the stores into T would otherwise reload it from st at every push and pop
        nfree = st[_NFREE]
        fh = st[_FH]
        cur = st[_CUR]
        last = st[_LAST]
        rsize = st[_RSIZE]
        # and the per-pop counters too (the stores into T would reload them from ctl)
        fmax = ctl[_C_FMAX]
        pend = ctl[_C_PEND]
        slive = ctl[_C_SLIVE]
        rlive = ctl[_C_RLIVE]
        while True:
            if not _room2_r(nfree, rsize, rkey):
                ctl[_C_STATUS] = 1.0 if nfree < _U(RESERVE_BLOCKS + POOL_EXTRA_2) else 2.0
                break
            heap = rsize > _ZERO
            kb = rkey[0] if heap else _ZERO
            if heap:
                c, rsize = _pop_repair_r(rkey, ritem, rsize)
            elif three:  # fetch the lines the next pops read, as the serial 3D march
                c, nfree, fh, cur, last = _pop_ahead(T, V, pool, nxt, bk, mw, nfree, fh, cur,
                                                     last, sx, sy, not use_u, True)
            else:
                c, nfree, fh, cur, last = _pop(T, pool, nxt, bk, mw, nfree, fh, cur, last)
            if c == _NIL:
                break
            if not heap:  # a lower bound of the popped key and of every key left
                kb = last
            x = T[c]
            if not x < 0.0 or x == -_INF:  # outdated entry (frozen, or far again)
                continue
            t = -x
            k = _bits(t)
            if k >= kw:  # the window is done: put it back
                nfree, fh, cur, rsize = _enq_r(k, c, pool, nxt, bk, mw, rkey, ritem, nfree, fh,
                                               cur, last, rsize)
                ctl[_C_NEXT] = min(t, _from_bits(kb))
                break
            sus, slive = _take_flag_r(sf, c >> sh, slive)
            if sus:  # suspect: its time may have to go up
                _keep_queue(st, nfree, fh, cur, last, rsize)
                ctl[_C_PEND] = pend
                moved = _suspect2(T, V, U, use_u, qp, fixed, c, t, sx, sy, ih, three, rf, pf,
                                  eidx, evals, base, pool, nxt, bk, mw, st, rkey, ritem, ctl, dfr)
                nfree, fh, cur, rsize = st[_NFREE], st[_FH], st[_CUR], st[_RSIZE]
                pend = ctl[_C_PEND]
                if moved:
                    continue
            T[c] = t
            pops += 1
            # in time order (no node frozen later than c, but on entry): no neighbour of a
            # band node is frozen later than c (:func:`_later_nb` False), as in the serial
            # march; a repair's pop below an earlier freeze is not
            inorder = t >= fmax
            if inorder:
                fmax = t
            if c < lo2:
                _note(sent, ns, 0, c)
            if c >= hi2:
                _note(sent, ns, 1, c)
            below = t  # a re-opened node frozen again no later than before (not raised)
            if pend > 0.0 and _fbit(pf, c >> sh):
                _clear_fbit(pf, c >> sh)
                pend -= 1.0
                below = -1.0
                if pend == 0.0:
                    ctl[_C_RMIN] = _INF
            # frozen again: every dependant may have read its old time (from scratch)
            full, rlive = _take_flag_r(rf, c >> sh, rlive)
            if full:
                _keep_queue(st, nfree, fh, cur, last, rsize)
                ctl[_C_SLIVE] = slive
                ctl[_C_RLIVE] = rlive
                _refrozen2(T, V, U, use_u, qp, c, below, lo, hi, sx, sy, ih, three, fixed, rf,
                           sf, eidx, evals, base, pool, nxt, bk, mw, st, rkey, ritem, ctl, dfr)
                nfree, fh, cur, rsize = st[_NFREE], st[_FH], st[_CUR], st[_RSIZE]
                slive, rlive = ctl[_C_SLIVE], ctl[_C_RLIVE]
                continue
            # prefetch V apart from T off the plateau (interleaved: the same lines)
            pv = one == _ONE and not (use_u and _at_plateau(U, c))
            nbs = _nbs(c, sx, sy, three)
            # the neighbours' repairs (rare) run after the loop, in its order: per neighbour
            # j, bit 4 j its update from scratch (a band node with a neighbour frozen later
            # than c), bit 4 j + 1 its recheck (frozen later than c), bit 4 j + 2 the check
            # of the node two away (nb frozen no earlier than c). Out of the loop, the
            # calls leave it lean: one slab on one core, 2048^2 FM²-shaped, 194.7 -> 184.4
            # ms of windows (the serial kernel 179.3); two threads 0.955x, docs/performance.md
            rare = 0
            for j in range(6 if three else 4):
                # neighbour j (x-, x+, y-, y+, z-, z+): in 2D from its stride, as the serial
                # march; in 3D from the tuple (one slab on one thread, 160^3 FM²-shaped: the
                # computed strides 1.034x the tuple's time; in 2D they gained 1-3 %)
                nb = nbs[j] if three else _nb_at(c, j, sx, sy, one)
                y = T[nb]
                if y == -_INF:
                    # far: c is its only frozen neighbour (every frozen node, ghosts too,
                    # has updated its neighbours), so the update is the one-axis solution
                    # along c's axis, as the full update gives it (the serial 2D march's
                    # shortcut): two axes' reads and terms saved on a third of the updates;
                    # c2: the node beyond c on that axis (nb's other side is not frozen)
                    ta, aa = _upwind_term_at(T, V, U, use_u, fixed, nb, t, c, c + c - nb,
                                             ih[j >> 1], t, sh)
                    t_nb = ta + math.sqrt(_rhs(V, U, use_u, qp, nb) / aa)
                    if dfr and _earlier_band(T, nb, sy if j < 2 else sx, t_nb):
                        T[nb] = -t_nb  # deferred, as in the order-1 window
                        _prefetch_rows(T, V, nb, sx, sy, three, pv)
                        continue
                    nfree, fh, cur, rsize = _lower_r(
                        T, V, nb, t_nb, fixed, sx, sy, three, pv, pool, nxt, bk, mw, rkey,
                        ritem, ctl, not three, nfree, fh, cur, last, rsize)
                elif y < 0.0:  # band: an own node
                    if not inorder and _later_nb(T, fixed, nb, sx, sy, three, t):
                        # a neighbour frozen later than c (a ghost ahead of this slab, a
                        # repair): the updates at the later freezes read nodes not frozen
                        # then, from scratch (below; c frozen again: _refrozen2 above)
                        rare |= 1 << (4 * j)
                    else:  # the serial march's update when c froze; a band time that read
                        # nodes out of time order may be too low: a later update above it
                        # marks it suspect
                        tn = _update2_at(T, V, U, use_u, qp, fixed, nb, sx, sy, ih, three, t)
                        if tn < -y:
                            nfree, fh, cur, rsize = _lower_r(
                                T, V, nb, tn, fixed, sx, sy, three, pv, pool, nxt, bk, mw, rkey,
                                ritem, ctl, not three, nfree, fh, cur, last, rsize)
                        elif y > -_INF:
                            if tn > -y and _entry_cap(eidx, evals, base + nb, tn) > -y:
                                slive = _mark_r(sf, nb >> sh, slive)
                                ctl[_C_RAISED] += 1.0
                            if dfr:  # it may be deferred: queued again at its time
                                nfree, fh, cur, rsize = _enq_r(_bits(-y), nb, pool, nxt, bk, mw,
                                                               rkey, ritem, nfree, fh, cur, last,
                                                               rsize)
                elif y >= t:  # frozen no earlier than c (band and far nodes stay so)
                    if y > t and nb >= lo and nb < hi:
                        # frozen later than c in this slab: c may change it
                        rare |= 2 << (4 * j)
                    # the node two away reads c beyond nb
                    rare |= 4 << (4 * j)
            if rare != 0:
                # the repairs in the loop's order. Each changes its own node only, nb or the
                # node d2 two away on nb's axis; no other neighbour's update in the loop reads
                # d2, and one reads nb only as the node beyond c on its axis, through
                # _known, which finds it not known either way (frozen later than c before,
                # in the band after); and the loop changes band and far nodes only, which no
                # repair reads. So the times are the same as with each repair in its place
                # (the two-away check runs after nb's repair: it is re-read)
                for j in range(6 if three else 4):
                    r = (rare >> (4 * j)) & 7
                    if r == 0:
                        continue
                    nb = nbs[j] if three else _nb_at(c, j, sx, sy, one)
                    if r & 3 != 0:
                        nfree, fh, cur, rsize, slive, rlive = _recheck_r(
                            T, V, U, use_u, qp, nb, sx, sy, ih, three, fixed, rf, sf, eidx,
                            evals, base, pool, nxt, bk, mw, st, rkey, ritem, ctl, dfr,
                            (nfree, fh, cur, last, rsize, slive, rlive))
                    y = T[nb]
                    if y >= 0.0 and t <= y:
                        d2 = nb + nb - c
                        if d2 >= lo and d2 < hi:
                            z = T[d2]
                            if z < 0.0 or z > t:
                                nfree, fh, cur, rsize, slive, rlive = _recheck_r(
                                    T, V, U, use_u, qp, d2, sx, sy, ih, three, fixed, rf, sf,
                                    eidx, evals, base, pool, nxt, bk, mw, st, rkey, ritem, ctl,
                                    dfr, (nfree, fh, cur, last, rsize, slive, rlive))
        _keep_queue(st, nfree, fh, cur, last, rsize)
        ctl[_C_FMAX] = fmax
        ctl[_C_PEND] = pend
        ctl[_C_SLIVE] = slive
        ctl[_C_RLIVE] = rlive
        ctl[_C_POPS] = pops

    def start(T, V, U, qp, fixed, sx, sy, ih, pool, nxt, bk, mw, st, rkey, ritem, ctl, c0, c1):
        """Queue the slab's band nodes given on entry and expand its frozen ones (order 2;
        all in its nodes ``[c0, c1)``, the rows of the start box: the others are far or
        walls)."""
        one = _unit(sy, three)
        use_u = qp > 0.0 and one == _ONE
        c = c0
        while c < c1:
            x = T[c]
            if x < 0.0 and x > -_INF:
                if not _room2(st, rkey):
                    return False
                _enq(_bits(-x), c, pool, nxt, bk, mw, st, rkey, ritem)
            c += one
        c = c0
        while c < c1:
            if T[c] >= 0.0:
                if not _room2(st, rkey):
                    return False
                for nb in _nbs(c, sx, sy, three):
                    if T[nb] < 0.0:
                        _lower(T, V, nb, _update2_at(T, V, U, use_u, qp, fixed, nb, sx, sy, ih,
                                                     three, -1.0),
                               fixed, sx, sy, three, one == _ONE, pool, nxt, bk, mw, st, rkey,
                               ritem, ctl)
            c += one
        return True

    def exchange(T, V, U, qp, fixed, rf, sf, eidx, evals, ebase, src, sent, m, base, g, up, sx,
                 sy, ih, pool, nxt, bk, mw, st, rkey, ritem, ctl, far):
        """Copy the neighbour's two boundary rows ``src`` (their frozen times) into the two
        ghost rows starting at ``g``; update again the own nodes one and two rows away
        from each ghost that changed (toward +x if ``up``). Only the neighbour's nodes
        ``sent[:m] - base`` are read (those it froze in its last window), both rows when
        ``m`` exceeds the list's capacity. Resumable: False when a queue is full. ``far``: the
        window's (2: a band node not lowered is queued again, it may be deferred)."""
        one = _unit(sy, three)
        use_u = qp > 0.0 and one == _ONE
        dfr = far == 2 and not three
        n = _U(T.size)
        lo = sx + sx
        hi = n - lo
        full = m > _U(sent.size)
        count = lo if full else m  # elements of the two rows, or listed nodes
        i = _ZERO
        while i < count:
            j = i if full else sent[i] - base
            i += one if full else _ONE
            v = src[j]
            if v >= 0.0 and v != T[g + j]:  # newly frozen, or frozen again at another time
                if not _room2(st, rkey):
                    return False
                gj = g + j
                was = T[gj]  # NaN (never frozen) or an earlier freeze's time
                T[gj] = v
                if v > ctl[_C_FMAX]:  # a ghost frozen later than the slab's nodes
                    ctl[_C_FMAX] = v
                for step in (sx, lo):
                    d = gj + step if up else gj - step
                    if d >= lo and d < hi:
                        # not the nodes the wave left before it reached the ghost (the
                        # exchange back across a cut): their time stands (:func:`_unread2`)
                        if not was >= 0.0 and _unread2(T, fixed, d, gj, v, step == sx, sx, sy,
                                                       three):
                            continue
                        if step != sx and T[d] == -_INF:  # far: no frozen neighbour
                            continue
                        y = T[d]
                        if not was >= 0.0 and y < 0.0 and _none_at_or_after(
                                T, fixed, d, gj, v, sx, sy, three):
                            # band or far, no update of it run at or after v: the serial
                            # march updates it when the ghost freezes (one row in), as the
                            # window does a neighbour of the node it freezes in time order;
                            # two rows in, nothing it read changed (the node reads the ghost
                            # only in an update at a neighbour's time no earlier than v)
                            if step == sx:
                                _ghost_update2(T, V, U, use_u, qp, fixed, d, v, y, sx, sy, ih,
                                               three, sf, eidx, evals, ebase, pool, nxt, bk, mw,
                                               st, rkey, ritem, ctl, dfr)
                        else:
                            _recheck(T, V, U, use_u, qp, d, sx, sy, ih, three, fixed, rf, sf,
                                     eidx, evals, ebase, pool, nxt, bk, mw, st, rkey, ritem, ctl,
                                     dfr)
                        x = T[d]
                        if x < 0.0 and -x < ctl[_C_NEXT]:  # queued: the next window knows
                            ctl[_C_NEXT] = -x
        return True

    d = 3 if three else 2
    out = []
    for f in (window, start, exchange):
        f.__name__ = f.__qualname__ = f"{f.__name__}{d}d_o2" + ("_pairs" if pairs else "")
        out.append(njit(cache=True, error_model="numpy", _nrt=False)(f))
    return out


_window2d_o2, _start2d_o2, _exchange2d_o2 = _slab_kernels2(False)
_window2d_o2_pairs = _slab_kernels2(False, True)[0]
_window3d_o2, _start3d_o2, _exchange3d_o2 = _slab_kernels2(True)


@njit(cache=True, error_model="numpy", _nrt=False)
def _heap_next(T, st, ritem, ctl):
    """Lower ``ctl[_C_NEXT]`` to the repair heap's smallest time (a hint for the window)."""
    if st[_RSIZE] > _ZERO:
        x = T[ritem[0]]
        if x < 0.0 and -x < ctl[_C_NEXT]:
            ctl[_C_NEXT] = -x


@njit(cache=True, inline="always", _nrt=False)
def _by_work(work, slabs):
    """``slabs``: the slab numbers by decreasing ``work`` (insertion sort, stable: a few
    dozen slabs at most)."""
    K = work.size
    for i in range(K):
        slabs[i] = i
    for i in range(1, K):
        k = slabs[i]
        j = i - 1
        while j >= 0 and work[slabs[j]] < work[k]:
            slabs[j + 1] = slabs[j]
            j -= 1
        slabs[j + 1] = k


@njit(cache=True, error_model="numpy", _nrt=False)
def _assign(work, nth, slabs, first, load, share=1):
    """Share the slabs among the threads for the next window: thread ``t`` runs slabs
    ``slabs[first[t]:first[t + 1]]``.

    ``work[k]`` predicts slab ``k``'s freezes (those of its last window: the wave moves
    little from one window to the next). The longest-first greedy split (each slab, the
    largest first, to the thread with the least so far) is kept when it predicts a
    smaller largest share than the fixed interleave (slab ``k`` to thread ``k % nth``),
    which is kept otherwise (and before the first window, all predictions 0). On the
    FM²-shaped 2048^2 map the windows' balance rises from ~1.65 to ~1.75: while the wave
    crosses few slabs, the fixed interleave may give two busy slabs to one thread.
    ``load`` (``nth`` floats) and ``first[nth + 1:]`` (``K`` ints) are scratch (the owner
    of each slab after the call); ``share=0``: always the fixed interleave. ``share=2``
    (:data:`_tuning.DYNAMIC_2D`): no lists; ``slabs`` holds every slab by decreasing predicted work
    and each thread takes the next one not taken (:func:`_take`, the counter
    ``first[nth]``, set to 0) when done with its last, so a window's slabs go to the
    threads by their actual work. Returns whether the greedy split was (or, ``share=2``,
    would have been) taken.
    """
    K = work.size
    fixed_max = 0.0
    for t in range(nth):
        mine = 0.0
        for k in range(t, K, nth):
            mine += work[k]
        fixed_max = max(fixed_max, mine)
    _by_work(work, slabs)
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
    greedy = share > 0 and greedy_max < fixed_max
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
    if share == 2:  # in turn: every slab by decreasing predicted work, from the first
        _by_work(work, slabs)
        first[nth] = 0
    return greedy


@njit(cache=True, error_model="numpy", _nrt=False)
def _in_turn(work, slabs, load):
    """``load[t]``: the ``work`` thread ``t`` gets when ``load.size`` threads take the slabs
    in the order ``slabs`` (:func:`_take`), each the next one when done with its last, a
    slab lasting its work (ties: the lowest thread): what the slabs taken in turn give on
    an idle machine, for the windows' balance (``stats["balance"]``)."""
    nth = load.size
    for t in range(nth):
        load[t] = 0.0
    for i in range(slabs.size):
        j = 0
        for t in range(1, nth):
            if load[t] < load[j]:
                j = t
        load[j] += work[slabs[i]]


@njit(cache=True, error_model="numpy", _nrt=False)
def _affine(work, owner, nth, slabs, lists, load):
    """The slabs of the next window in turn, each thread first on its own (``share=3``,
    :data:`_tuning.SLABS_STAY_2D` and ``_3D``; :func:`_take` with ``dyn`` 2): slab ``k`` stays with
    ``owner[k]``, the thread that ran its last window, unless that thread's predicted share
    (``work``, the last window's freezes) would pass ``1 / nth`` of the whole, then it goes
    to the thread with the least so far (the slabs by decreasing work); ``owner`` is set so.
    Thread ``t``'s list ``slabs[lists[t]:lists[t + 1]]`` is its slabs by decreasing work,
    its counter ``lists[lists.size - nth + t]`` at its start; a thread done with its list
    takes the next of the others'. A slab run on another core than its last window reads
    its rows and queue from that core's cache: on 2048^2 FM²-shaped two threads' windows
    took 158 CPU-ms (order 1) taken in turn by the whole order, 150 with the slabs fixed.
    ``lists[nth + 1:nth + 1 + K]`` is scratch."""
    K = work.size
    order = lists[nth + 1:nth + 1 + K]
    _by_work(work, order)
    total = 0.0
    for k in range(K):
        total += work[k]
    fair = total / nth
    for t in range(nth):
        load[t] = 0.0
    for i in range(K):
        k = order[i]
        p = int(owner[k])
        if load[p] + work[k] > fair:
            best = 0
            for t in range(1, nth):
                if load[t] < load[best]:
                    best = t
            if load[best] < load[p]:
                p = best
        owner[k] = p
        load[p] += work[k]
    h = lists.size - nth
    pos = 0
    for t in range(nth):
        lists[t] = pos
        lists[h + t] = pos
        for i in range(K):
            if int(owner[order[i]]) == t:
                slabs[pos] = order[i]
                pos += 1
    lists[nth] = pos


@njit(cache=True, error_model="numpy", _nrt=False)
def _in_turn_affine(work, slabs, lists, nth, load):
    """:func:`_in_turn` for :func:`_affine`'s lists: ``load[t]``, the ``work`` thread ``t``
    gets when the thread free first (ties: the lowest) takes the next slab by :func:`_take`
    (its own list, then the others' from ``t + 1`` on), each lasting its work. Resets the
    lists' counters to their starts and consumes them."""
    h = lists.size - nth
    for t in range(nth):
        load[t] = 0.0
        lists[h + t] = lists[t]
    for _ in range(lists[nth]):
        t = 0
        for u in range(1, nth):
            if load[u] < load[t]:
                t = u
        for u in range(nth):
            v = t + u if t + u < nth else t + u - nth
            j = lists[h + v]
            if j < lists[v + 1]:
                lists[h + v] = j + 1
                load[t] += work[slabs[j]]
                break


#: Debug: :func:`march` records where the drive's time goes (``stats["profile"]``, see
#: :func:`_profile`): each thread's CPU time per parallel region (``clock_gettime``), the
#: regions' wall time. Off: one branch per region, nothing else.
PROFILE = False
#: Slots of the window state ``win`` (the drive's); the profile's follow when it is on.
_W_SIZE = 10
_P_EXMAX, _P_WIMAX, _P_EXWALL, _P_WIWALL, _P_STMAX, _P_STWALL, _P_DRIVE, _P_REGIONS = range(8)
_P_THREADS = 8  # then per thread: exchange CPU, window CPU, scratch (nth each)


@njit(cache=True, inline="always", _nrt=False)
def _prof_mark(win, nth, t):
    """Profile: thread ``t`` starts its share of a region (its CPU clock)."""
    win[_W_SIZE + _P_THREADS + 2 * nth + t] = _clock_ns(3) * 1e-9


@njit(cache=True, inline="always", _nrt=False)
def _prof_done(win, nth, t):
    """Profile: thread ``t`` ends its share (the scratch slot now holds its CPU time)."""
    i = _W_SIZE + _P_THREADS + 2 * nth + t
    win[i] = _clock_ns(3) * 1e-9 - win[i]


@njit(cache=True, _nrt=False)
def _prof_region(win, nth, kind, wall0):
    """Profile: after a region (``kind`` 0 exchange, 1 window, 2 start) begun at the
    monotonic time ``wall0``: its busiest thread's CPU and its wall time summed, each
    thread's CPU too."""
    P = _W_SIZE
    most = 0.0
    for t in range(nth):
        x = win[P + _P_THREADS + 2 * nth + t]
        most = max(most, x)
        if kind < 2:
            win[P + _P_THREADS + kind * nth + t] += x
    wall = _clock_ns(1) * 1e-9 - wall0
    if kind == 0:
        win[P + _P_EXMAX] += most
        win[P + _P_EXWALL] += wall
    elif kind == 1:
        win[P + _P_WIMAX] += most
        win[P + _P_WIWALL] += wall
    else:
        win[P + _P_STMAX] += most
        win[P + _P_STWALL] += wall
    win[P + _P_REGIONS] += 1.0


def _profile(win, nth):
    """The drive's profile from ``win`` (seconds): ``start``/``exchange``/``window``: the
    regions' summed wall time (``*_wall``) and summed busiest thread's CPU time
    (``*_max``: the critical path if the barriers cost nothing); ``drive_wall``: the
    drive's wall time (the serial rest between the regions included); per thread its
    CPU in the exchanges and in the windows. With the exchanges in the windows' regions
    (:data:`_tuning.EXCHANGE_IN_WINDOW`) the exchange figures are the first exchange's, and
    the windows' include the exchanges after them and a thread's wait for a neighbour's
    window before an exchange."""
    P = _W_SIZE
    w = win[P:]
    return {"start_max": w[_P_STMAX], "start_wall": w[_P_STWALL],
            "exchange_max": w[_P_EXMAX], "exchange_wall": w[_P_EXWALL],
            "window_max": w[_P_WIMAX], "window_wall": w[_P_WIWALL],
            "drive_wall": w[_P_DRIVE], "regions": int(w[_P_REGIONS]),
            "exchange_cpu": [float(x) for x in w[_P_THREADS:_P_THREADS + nth]],
            "window_cpu": [float(x) for x in w[_P_THREADS + nth:_P_THREADS + 2 * nth]]}


@njit(cache=True, error_model="numpy", _nrt=False)  # a call: K a window
def _start_slab(three, order, k, Tp, Vp, U, qp, fx, off, end, sx, sy, ih, hh, iso, pool, nxt,
                bk, mw, st, rkey, ritem, ctl, scan):
    """Slab ``k``'s start (the drive's arguments, :func:`_drive_kernel`): its band nodes
    queued and its frozen ones expanded; ``ctl[k, _C_STATUS]`` set when a queue is full."""
    sh = 0 if three or sy == 1 else 1  # node index = element index >> sh
    T = Tp[off[k]:end[k]]
    V = Vp[off[k]:end[k]]
    Uk = U[0 if U.size == 1 else off[k] >> sh >> 3:]
    F = fx[off[k] >> sh >> 3:]
    c0 = _U(scan[k, 0])
    c1 = _U(scan[k, 1])
    if order == 2 and three:
        ok = _start3d_o2(T, V, Uk, qp, F, sx, sy, ih, pool[k], nxt[k], bk[k], mw[k], st[k],
                         rkey[k], ritem[k], ctl[k], c0, c1)
    elif order == 2:
        ok = _start2d_o2(T, V, Uk, qp, F, sx, sy, ih, pool[k], nxt[k], bk[k], mw[k], st[k],
                         rkey[k], ritem[k], ctl[k], c0, c1)
    else:
        ok = _start(three, T, V, Uk, qp, F, sx, sy, ih, hh, iso, pool[k], nxt[k], bk[k], mw[k],
                    st[k], rkey[k], ritem[k], ctl[k], c0, c1)
    if not ok:
        low = _U(RESERVE_BLOCKS + (POOL_EXTRA_2 if order == 2 else 0))
        ctl[k, _C_STATUS] = 1.0 if st[k, _NFREE] < low else 2.0


@njit(cache=True, error_model="numpy", _nrt=False)  # a call: K a window
def _window_slab(three, order, k, Tp, Vp, U, qp, fx, fl, eidx, evals, off, end, sx, sy, ih, hh,
                 iso, tw, pool, nxt, bk, mw, st, rkey, ritem, ctl, sent, ns, far):
    """Slab ``k``'s window to ``tw`` (the drive's arguments, :func:`_drive_kernel`; ``sent``,
    ``ns``: the slab's own boundary lists and counts, which it writes)."""
    sh = 0 if three or sy == 1 else 1  # node index = element index >> sh
    o3 = off[k] >> sh >> 3
    if order == 2:
        args = (Tp[off[k]:end[k]], Vp[off[k]:end[k]], U[0 if U.size == 1 else o3:], qp, fx[o3:],
                fl[4 * o3:], fl[4 * o3 + 1:], fl[4 * o3 + 2:], eidx, evals, _U(off[k]), sx, sy,
                ih, tw, pool[k], nxt[k], bk[k], mw[k], st[k], rkey[k], ritem[k], ctl[k], sent,
                ns, far)
        if three:
            _window3d_o2(*args)
        elif sy == 2:
            _window2d_o2_pairs(*args)
        else:
            _window2d_o2(*args)
    elif not three and sy == 2:
        _window2d_pairs(Tp[off[k]:end[k]], Vp[off[k]:end[k]], U[0 if U.size == 1 else o3:], qp,
                        fx[o3:], sx, sy, ih, hh, iso, tw, pool[k], nxt[k], bk[k], mw[k], st[k],
                        rkey[k], ritem[k], ctl[k], sent, ns, far)
    else:
        _window(three, Tp[off[k]:end[k]], Vp[off[k]:end[k]], U[0 if U.size == 1 else o3:], qp,
                fx[o3:], sx, sy, ih, hh, iso, tw, pool[k], nxt[k], bk[k], mw[k], st[k], rkey[k],
                ritem[k], ctl[k], sent, ns, far)
    ctl[k, _C_RUNS] += 1.0


@njit(cache=True, error_model="numpy", _nrt=False)  # a call: K a window
def _exchange_slab(three, order, k, Tp, Vp, U, qp, fx, fl, eidx, evals, off, end, rows, sx, sy,
                   ih, hh, iso, pool, nxt, bk, mw, st, rkey, ritem, ctl, sent, ns, far):
    """Slab ``k``'s exchange (``three``: 3D, ``order`` 1 or 2; the other arguments the
    drive's, :func:`_drive_kernel`): its ghosts from both neighbours' boundary rows (frozen in
    their last window, read in their buffers) and its own nodes next to them updated again
    (:func:`_exchange_from`). A module-level kernel, not one of the drive's closure: numba
    keys a closure's cache entry by its values, and a kernel among them pickles differently in
    every process (the drive compiled again)."""
    K = off.size
    n = np.int64(order) * np.int64(sx)
    lo = off[max(k - 1, 0)] + rows[max(k - 1, 0)] * np.int64(sx)  # last own rows below
    hi = off[min(k + 1, K - 1)] + n  # first own rows above
    _exchange_from(three, order, k, Tp, Vp, U, qp, fx, fl, eidx, evals, off, end, rows, sx, sy,
                   ih, hh, iso, pool, nxt, bk, mw, st, rkey, ritem, ctl, far,
                   Tp[lo:lo + n], sent[max(k - 1, 0), 1], ns[max(k - 1, 0), 1],
                   Tp[hi:hi + n], sent[min(k + 1, K - 1), 0], ns[min(k + 1, K - 1), 0])


@njit(cache=True, error_model="numpy", _nrt=False)  # a call: K a window
def _exchange_from(three, order, k, Tp, Vp, U, qp, fx, fl, eidx, evals, off, end, rows, sx, sy,
                   ih, hh, iso, pool, nxt, bk, mw, st, rkey, ritem, ctl, far, src0, sent0, m0,
                   src1, sent1, m1):
    """Slab ``k``'s exchange from given boundary rows: ``src0`` the last ``order`` own rows
    of slab ``k - 1`` (their frozen times; ``sent0[:m0]`` the nodes frozen there in its last
    window, as in its buffer, all of the rows when ``m0`` exceeds the list's capacity),
    ``src1``, ``sent1``, ``m1`` the first of slab ``k + 1`` (the drive's buffers, or the
    copies the pipeline posts, :func:`_post_rows`). Sets ``ctl[k, _C_STATUS]`` when a queue is
    full (resumable: called again, it goes on) and lowers ``ctl[k, _C_NEXT]`` to the repair heap's
    smallest time."""
    K = off.size
    low = _U(RESERVE_BLOCKS + (POOL_EXTRA_2 if order == 2 else 0))
    sh = 0 if three or sy == 1 else 1  # node index = element index >> sh
    G = _U(order)
    T = Tp[off[k]:end[k]]
    V = Vp[off[k]:end[k]]
    Uk = U[0 if U.size == 1 else off[k] >> sh >> 3:]
    F = fx[off[k] >> sh >> 3:]
    R = fl[(off[k] >> sh >> 3) * 4:]
    S = fl[(off[k] >> sh >> 3) * 4 + 1:]
    ok = True
    r = _U(rows[k])
    if k > 0:
        base = _U(rows[k - 1]) * sx
        if order == 2:
            args = (T, V, Uk, qp, F, R, S, eidx, evals, _U(off[k]), src0, sent0, m0, base,
                    _ZERO, True, sx, sy, ih, pool[k], nxt[k], bk[k], mw[k], st[k], rkey[k],
                    ritem[k], ctl[k], far)
            ok = _exchange3d_o2(*args) if three else _exchange2d_o2(*args)
        else:
            ok = _exchange(three, T, V, Uk, qp, F, src0, sent0, m0, base, _ZERO, sx, sx, sy, ih,
                           hh, iso, pool[k], nxt[k], bk[k], mw[k], st[k], rkey[k], ritem[k],
                           ctl[k])
    if ok and k < K - 1:
        if order == 2:
            args = (T, V, Uk, qp, F, R, S, eidx, evals, _U(off[k]), src1, sent1, m1, G * sx,
                    (r + G) * sx, False, sx, sy, ih, pool[k], nxt[k], bk[k], mw[k], st[k],
                    rkey[k], ritem[k], ctl[k], far)
            ok = _exchange3d_o2(*args) if three else _exchange2d_o2(*args)
        else:
            ok = _exchange(three, T, V, Uk, qp, F, src1, sent1, m1, sx, (r + _ONE) * sx, r * sx,
                           sx, sy, ih, hh, iso, pool[k], nxt[k], bk[k], mw[k], st[k], rkey[k],
                           ritem[k], ctl[k])
    if not ok:
        ctl[k, _C_STATUS] = 1.0 if st[k, _NFREE] < low else 2.0
    _heap_next(T, st[k], ritem[k], ctl[k])
    ctl[k, _C_RUNS] += 1.0


def _drive_kernel(three, order=1):
    """The compiled driver of one dimension and order (the parallel region runs the slabs)."""
    def drive(nth, Tp, Vp, U, qp, fx, fl, eidx, evals, off, end, rows, sx, sy, ih, hh, iso, pool,
              nxt, bk, mw, st, rkey, ritem, ctl, sent, ns, win, first, stops, slabs, lists, load,
              share, scan, far, alone, merge, xs):
        """Run windows until every queue is empty; 0 done, 1/2 grow pool/heap and call again.

        ``win`` (float64): [0] window end, [1] width, [2] windows run, [3] target pops,
        [4] nodes frozen (re-freezes included), [5] sum over windows of the most a thread
        froze (the critical path: ``[4] / [5]`` bounds the speed-up; slabs taken in turn:
        as an idle machine shares them, :func:`_in_turn`), [6] the latest
        stop node's time when the stop nodes ``stops`` (indices into ``Tp``) ended it,
        [7] 1 once the start (``first``) is done, [8] windows whose slabs :func:`_assign`
        shared longest-first, [9] exchanges run (each slab counts its runs in the
        exchanges and windows, ``ctl[k, _C_RUNS]``). ``U``, ``qp``: the plateau mask over
        ``Tp`` (one byte: every node) and its ``1 / speed^2`` (0: none); ``sent``, ``ns``:
        each slab's nodes frozen in its boundary rows in the last window (see ``window``).
        ``fl``: order 2's bit masks, a bit per node (re-opened, suspect, pending; unused by
        order 1), ``eidx``, ``evals`` its nodes in the band on entry (element indices into
        ``Tp``, sorted) and their times; each slab has ``order`` ghost x-slabs on each side.
        ``slabs`` (K), ``lists`` (nth + 1 + K + nth), ``load`` (nth): scratch of
        :func:`_assign` and :func:`_affine` (``share``: 0 the interleave, 1
        :data:`_tuning.SHARE_SLABS`' lists, 2 taken in turn, :data:`_tuning.DYNAMIC_2D`, 3 in
        turn each thread first on the slabs it ran last, ``ctl[k, _C_OWNER]``,
        :data:`_tuning.SLABS_STAY_2D` / ``_3D``). ``scan[k]``: the nodes of slab ``k`` the start
        reads (the start box's rows). ``far``: the far neighbours' one-axis update (2D), with
        their deferral (2; :func:`_slab_kernels`' window).
        ``alone``: the exchanges on this thread only, the slabs in turn (2D).
        ``merge`` (not with ``alone``, nor with lists fixed for the window): after the first,
        each exchange runs in the window's region, a slab's as soon as the windows of it
        and its neighbours are done (``xs``, int64 (2 K): per slab its window done, its
        exchange taken), by whichever thread is free: the thread that finishes its slabs
        first exchanges meanwhile instead of waiting at the region's end, and a region a
        window is saved. The same exchanges as in a region of their own (each reads its
        neighbours' rows once their windows are done, as there), so the same times.

        ``off``, ``end``, ``sx``, ``sy``, ``scan`` and ``stops`` count elements of ``Tp``:
        nodes in the separate layout, twice that in the 2D interleaved one (``Tp`` the
        buffer, ``Vp = Tp[1:]``, ``sy = 2``); ``U`` and ``fx`` have a bit per node.
        """
        K = off.size
        # the slabs taken in turn by the threads (DYNAMIC_2D): 1 by one order, 2 each thread
        # first its own (SLABS_STAY_2D); 0 fixed lists
        dyn = 2 if share == 3 else (1 if share == 2 else 0)
        prof = win.size > _W_SIZE  # the profile (PROFILE)
        d0 = _clock_ns(1) * 1e-9 if prof else 0.0
        if first:
            w0 = _clock_ns(1) * 1e-9 if prof else 0.0
            for t in prange(nth):  # thread t runs slabs t, t + nth, ...
                if prof:
                    _prof_mark(win, nth, t)
                for k in range(t, K, nth):
                    _start_slab(three, order, k, Tp, Vp, U, qp, fx, off, end, sx, sy, ih, hh,
                                iso, pool, nxt, bk, mw, st, rkey, ritem, ctl, scan)
                if prof:
                    _prof_done(win, nth, t)
            if prof:
                _prof_region(win, nth, 2, w0)
            for k in range(K):
                if ctl[k, _C_STATUS] != 0.0:
                    if prof:
                        win[_W_SIZE + _P_DRIVE] += _clock_ns(1) * 1e-9 - d0
                    return int(ctl[k, _C_STATUS])  # grown, the start runs again
            win[7] = 1.0
        mrg = merge and dyn != 0 and not alone  # exchanges in the window's region
        ex = True  # the next exchange in a region of its own (on entry: after the start)
        while True:
            # the slabs of each thread for the exchange and the window (from the last
            # window's freezes)
            if _assign(ctl[:, _C_POPS], nth, slabs, lists, load, min(share, 2)):
                win[8] += 1.0
            if dyn == 2:
                _affine(ctl[:, _C_POPS], ctl[:, _C_OWNER], nth, slabs, lists, load)
            # exchange: each slab refreshes its own ghosts and the rows next to them; in 2D
            # on this thread alone if ``alone``, the iterations in turn
            # (:data:`_tuning.EXCHANGE_ALONE_2D`); merged into the window's region (``mrg``)
            # but on entry
            if ex:
                w0 = _clock_ns(1) * 1e-9 if prof else 0.0
                if alone:
                    _set_threads(1)
                for t in prange(nth):  # thread t runs slabs[lists[t]:lists[t + 1]] (dyn: in turn)
                    if prof:
                        _prof_mark(win, nth, t)
                    i = _take(lists, nth, t, -1, dyn)
                    while not _took_all(lists, nth, t, i, K, dyn):
                        _exchange_slab(three, order, slabs[i], Tp, Vp, U, qp, fx, fl, eidx,
                                       evals, off, end, rows, sx, sy, ih, hh, iso, pool, nxt,
                                       bk, mw, st, rkey, ritem, ctl, sent, ns, far)
                        i = _take(lists, nth, t, i, dyn)
                    if prof:
                        _prof_done(win, nth, t)
                if alone:
                    _set_threads(nth)
                if prof:
                    _prof_region(win, nth, 0, w0)
                win[9] += 1.0
                for k in range(K):
                    if ctl[k, _C_STATUS] != 0.0:
                        if prof:
                            win[_W_SIZE + _P_DRIVE] += _clock_ns(1) * 1e-9 - d0
                        return int(ctl[k, _C_STATUS])
            ex = not mrg
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
            # (nothing queued can lower them: an update is later than its inputs) and, for
            # order 2, than the old time of every node re-opened and raised (nodes may
            # still read it)
            if stops.size > 0:
                smax = 0.0
                for i in range(stops.size):
                    x = Tp[stops[i]]
                    if not x >= 0.0:
                        smax = _INF
                        break
                    smax = max(smax, x)
                tlow = tmin
                for k in range(K):
                    tlow = min(tlow, ctl[k, _C_RMIN])
                if smax <= tlow:
                    win[6] = smax
                    if prof:
                        win[_W_SIZE + _P_DRIVE] += _clock_ns(1) * 1e-9 - d0
                    return 0
            if empty:
                if prof:
                    win[_W_SIZE + _P_DRIVE] += _clock_ns(1) * 1e-9 - d0
                return 0
            if tmin < _INF:
                win[0] = max(win[0], tmin) + win[1]
            else:
                win[0] = win[0] + win[1]
            tw = win[0]
            if dyn == 2:  # each list taken from its first again
                for t in range(nth):
                    lists[lists.size - nth + t] = lists[t]
            elif dyn:
                lists[nth] = 0  # the window's slabs taken from the first again
            if mrg:
                xs[:] = 0  # no window done, no exchange taken
            w0 = _clock_ns(1) * 1e-9 if prof else 0.0
            for t in prange(nth):  # thread t runs slabs[lists[t]:lists[t + 1]] (dyn: in turn)
                if prof:
                    _prof_mark(win, nth, t)
                i = _take(lists, nth, t, -1, dyn)
                while not _took_all(lists, nth, t, i, K, dyn):
                    k = slabs[i]
                    if dyn == 2:
                        ctl[k, _C_OWNER] = t
                    _window_slab(three, order, k, Tp, Vp, U, qp, fx, fl, eidx, evals, off, end,
                                 sx, sy, ih, hh, iso, tw, pool, nxt, bk, mw, st, rkey, ritem, ctl,
                                 sent[k], ns[k], far)
                    if mrg:
                        _fetch_add(xs, k)  # its window done (its writes before this)
                    i = _take(lists, nth, t, i, dyn)
                # merged: the exchanges whose slabs' and neighbours' windows are done, each
                # taken once, until none is left (every window is taken, so those not done
                # run on the other threads now)
                while mrg:
                    left = False
                    for k in range(K):
                        if _load(xs, K + k) != 0:
                            continue
                        left = True
                        if (_load(xs, k) != 0 and (k == 0 or _load(xs, k - 1) != 0)
                                and (k == K - 1 or _load(xs, k + 1) != 0)
                                and _fetch_add(xs, K + k) == 0):
                            _exchange_slab(three, order, k, Tp, Vp, U, qp, fx, fl, eidx, evals,
                                           off, end, rows, sx, sy, ih, hh, iso, pool, nxt, bk,
                                           mw, st, rkey, ritem, ctl, sent, ns, far)
                    if not left:
                        break
                if prof:
                    _prof_done(win, nth, t)
            if prof:
                _prof_region(win, nth, 1, w0)
            win[2] += 1.0
            if mrg:
                win[9] += 1.0
            pops = 0.0
            most = 0.0
            if dyn:  # the idle machine's share: each slab, in the order taken, to the thread
                if dyn == 2:  # free first (as many freezes, as long)
                    _in_turn_affine(ctl[:, _C_POPS], slabs, lists, nth, load)
                else:
                    _in_turn(ctl[:, _C_POPS], slabs, load)
                for t in range(nth):
                    pops += load[t]
                    most = max(most, load[t])
            for t in range(nth if not dyn else 0):
                mine = 0.0
                for k in range(K):  # the owners of _assign's lists
                    if lists[nth + 1 + k] == t:
                        mine += ctl[k, _C_POPS]
                pops += mine
                most = max(most, mine)
            win[4] += pops
            win[5] += most
            for k in range(K):
                if ctl[k, _C_STATUS] != 0.0:
                    if prof:
                        win[_W_SIZE + _P_DRIVE] += _clock_ns(1) * 1e-9 - d0
                    return int(ctl[k, _C_STATUS])
            # adapt the width toward the target pops per window
            f = win[3] / max(pops, 1.0)
            win[1] *= min(2.0, max(0.5, f))

    drive.__name__ = drive.__qualname__ = f"drive{3 if three else 2}d" + (
        "_o2" if order == 2 else "")
    return njit(cache=True, parallel=True, error_model="numpy")(drive)


#: The drivers by (dimension, order).
_DRIVES = {(d, o): _drive_kernel(d == 3, o) for d in (2, 3) for o in (1, 2)}


# ------------------------------------------------------------------ the windows pipelined
@intrinsic
def _add(typingctx, a, i, v):
    """``a[i] += v`` atomically (int64 array), returning the old value."""
    sig = types.int64(a, i, v)

    def codegen(context, builder, signature, args):
        aty = signature.args[0]
        arr = context.make_array(aty)(context, builder, args[0])
        ptr = cgutils.get_item_pointer(context, builder, aty, arr, [args[1]])
        val = context.cast(builder, args[2], signature.args[2], types.int64)
        return builder.atomic_rmw("add", ptr, val, "seq_cst")

    return sig, codegen


@njit(cache=True, error_model="numpy", _nrt=False)
def _post_rows(T, base, n, sent, m, dst):
    """Copy the nodes of a slab's boundary rows frozen in its window (``sent[:m]``, element
    indices into the slab's ``T``; all ``n`` elements from ``base`` when ``m`` exceeds the
    list's capacity) into ``dst`` (at ``c - base``): what its neighbours' exchanges read
    while it marches on (:func:`_pipe_kernel`)."""
    if m > _U(sent.size):
        for j in range(n):
            dst[j] = T[base + j]
    else:
        for i in range(m):
            dst[np.int64(sent[i]) - base] = T[sent[i]]


@njit(cache=True, error_model="numpy", _nrt=False)
def _tally(win, freezes, nth, a, b):
    """Windows ``a`` to ``b - 1`` (all slabs ran them; ``freezes[w % R, k]`` slab ``k``'s
    freezes in window ``w``) into the statistics ``win`` (as :func:`_drive_kernel`'s:
    ``[5]`` the larger of the busiest slab's freezes and a thread's mean share). Returns the
    last one's freezes."""
    R, K = freezes.shape
    last = 0.0
    for w in range(a, b):
        total = 0.0
        most = 0.0
        for k in range(K):
            x = float(freezes[w % R, k])
            total += x
            most = max(most, x)
        win[2] += 1.0
        win[4] += total
        win[5] += max(most, total / nth)
        last = total
    return last


# slots of the pipeline's int64 state ``sync`` after its three rows of K (each slab's windows
# posted, its claim, its next step's part: 0 the exchange, 1 the window)
_S_STOP = 0   # a slab's queue ran full: every thread leaves, the caller grows it
_S_DONE = 1   # every slab was empty after the same exchange
_S_LOCK = 2   # held while a window's end is set
_S_NSET = 3   # windows whose end is set
_S_TALLY = 4  # windows tallied (:func:`_tally`)
_S_SIZE = 5


def _pipe_kernel(three, order=1):
    """The compiled pipeline of one dimension and order: :func:`_drive_kernel`'s exchanges
    and windows with no barrier between them."""
    def pipe(nth, Tp, Vp, U, qp, fx, fl, eidx, evals, off, end, rows, sx, sy, ih, hh, iso, pool,
             nxt, bk, mw, st, rkey, ritem, ctl, sent, ns, post, win, first, scan, far, sync,
             ends, freezes, quiet):
        """Run each slab's exchanges and windows in turn until every slab is empty after the
        same exchange; 0 done, 1/2 grow pool/heap and call again.

        The windows of :func:`_drive_kernel` (``win`` as there), each slab at its own pace:
        a window posts the times of the nodes it froze in its boundary rows (``post[k, p,
        side]``, its lists ``sent[k, p]`` and counts ``ns[k, p]``, ``p`` the parity of the
        window's number), so a slab's step -- its exchange from the neighbours' posts of
        their last window, then its window -- waits for the two neighbours' last windows
        only. Step ``s`` of slab ``k`` runs once both posted window ``s - 1`` (the start
        posts the whole rows as window -1), and a neighbour cannot overwrite those posts
        before slab ``k`` read them (its step ``s + 1`` waits for slab ``k``'s window ``s``):
        each slab's exchanges read what they read between barriers, whatever the threads'
        order. Window ``s`` ends at ``ends[s % R]``, set once, by the first slab to reach
        it, from the smallest queued time of the slabs and the width adapted to the last
        window all slabs ran (``freezes[w % R, k]``: slab ``k``'s freezes in window ``w``;
        ``quiet[w % R]``: the slabs empty after exchange ``w``). Neighbours are at most one
        window apart, so all slabs ``K - 1``: the rings of ``R >= 2 K + 2`` windows hold.
        ``sync`` (int64): ``[0, K)`` each slab's windows posted (the start's included),
        ``[K, 2 K)`` its claim, ``[2 K, 3 K)`` its step's next part (0 the exchange, 1 the
        window: a full queue ends the call in either, and the next goes on), then the
        ``_S_*`` slots. A thread takes the slab that its neighbours let step, first one it
        ran last (``ctl[k, _C_OWNER]``), then of fewest windows, then most freezes last.
        """
        K = off.size
        R = ends.shape[1]
        G = np.int64(order)
        n = G * np.int64(sx)
        cap = _U(sent.shape[3])
        S0 = 3 * K
        if first:
            for t in prange(nth):  # thread t starts slabs t, t + nth, ...; posts their rows
                for k in range(t, K, nth):
                    _start_slab(three, order, k, Tp, Vp, U, qp, fx, off, end, sx, sy, ih, hh,
                                iso, pool, nxt, bk, mw, st, rkey, ritem, ctl, scan)
                    T = Tp[off[k]:end[k]]
                    for side in range(2):
                        ns[k, 1, side] = cap + _ONE  # window -1: the whole rows
                        b = n if side == 0 else rows[k] * np.int64(sx)
                        _post_rows(T, b, n, sent[k, 1, side], cap + _ONE, post[k, 1, side])
            for k in range(K):
                if ctl[k, _C_STATUS] != 0.0:
                    return int(ctl[k, _C_STATUS])  # grown, the start runs again
            win[7] = 1.0
            for k in range(K):
                sync[k] = 1  # window -1 posted
        for t in prange(nth):
            while _load(sync, S0 + _S_STOP) == 0 and _load(sync, S0 + _S_DONE) == 0:
                # the slab to step: its neighbours posted its last window, not taken; its own
                # first, then of fewest windows, then most freezes last
                k = -1
                best = 0.0
                for j in range(K):
                    p = _load(sync, j)
                    if ((j > 0 and _load(sync, j - 1) < p) or (j < K - 1 and _load(sync, j + 1) < p)
                            or _load(sync, K + j) != 0):
                        continue
                    key = (0.0 if ctl[j, _C_OWNER] == t else 1e18) + p * 1e9 - ctl[j, _C_POPS]
                    if k < 0 or key < best:
                        k = j
                        best = key
                if k < 0:
                    continue
                if _add(sync, K + k, 1) != 0:  # taken meanwhile
                    _add(sync, K + k, -1)
                    continue
                p = _load(sync, k)
                if (k > 0 and _load(sync, k - 1) < p) or (k < K - 1 and _load(sync, k + 1) < p):
                    _add(sync, K + k, -1)  # stepped meanwhile: its neighbours not yet
                    continue
                s = p - 1  # this step's window
                par = s & 1
                q = par ^ 1  # the neighbours' last window's posts
                if sync[2 * K + k] == 0:  # the exchange
                    lo = max(k - 1, 0)
                    hi = min(k + 1, K - 1)
                    _exchange_from(three, order, k, Tp, Vp, U, qp, fx, fl, eidx, evals, off,
                                   end, rows, sx, sy, ih, hh, iso, pool, nxt, bk, mw, st, rkey,
                                   ritem, ctl, far, post[lo, q, 1], sent[lo, q, 1], ns[lo, q, 1],
                                   post[hi, q, 0], sent[hi, q, 0], ns[hi, q, 0])
                    if ctl[k, _C_STATUS] != 0.0:  # a queue full: the next call goes on
                        _add(sync, S0 + _S_STOP, 1)
                        _add(sync, K + k, -1)
                        break
                    sync[2 * K + k] = 1
                    empty = st[k, _RSIZE] == _ZERO
                    for w in range(_NW):
                        if mw[k, w] != _ZERO:
                            empty = False
                    quiet[(s + R // 2) % R] = 0  # free again: every slab is past it
                    if empty and _add(quiet, s % R, 1) == K - 1:
                        _add(sync, S0 + _S_DONE, 1)  # every slab empty after exchange s
                while _load(sync, S0 + _S_NSET) <= s:  # the window's end, set once
                    if _add(sync, S0 + _S_LOCK, 1) == 0 and _load(sync, S0 + _S_NSET) == s:
                        tmin = _INF
                        done = _load(sync, 0)
                        for j in range(K):
                            tmin = min(tmin, ctl[j, _C_NEXT])
                            done = min(done, _load(sync, j))
                        a = sync[S0 + _S_TALLY]
                        if done - 1 > a:  # windows all slabs ran since: the width adapts,
                            # from the last one's width and freezes (not compounded: the
                            # windows set meanwhile have not told their freezes yet)
                            f = win[3] / max(_tally(win, freezes, nth, a, done - 1), 1.0)
                            win[1] = ends[1, (done - 2) % R] * min(2.0, max(0.5, f))
                            sync[S0 + _S_TALLY] = done - 1
                        prev = ends[0, (s - 1) % R] if s > 0 else win[0]
                        ends[0, s % R] = (max(prev, tmin) if tmin < _INF else prev) + win[1]
                        ends[1, s % R] = win[1]
                        _add(sync, S0 + _S_NSET, 1)
                    _add(sync, S0 + _S_LOCK, -1)
                _window_slab(three, order, k, Tp, Vp, U, qp, fx, fl, eidx, evals, off, end, sx,
                             sy, ih, hh, iso, ends[0, s % R], pool, nxt, bk, mw, st, rkey, ritem,
                             ctl, sent[k, par], ns[k, par], far)
                T = Tp[off[k]:end[k]]
                _post_rows(T, n, n, sent[k, par, 0], ns[k, par, 0], post[k, par, 0])
                _post_rows(T, rows[k] * np.int64(sx), n, sent[k, par, 1], ns[k, par, 1],
                           post[k, par, 1])
                freezes[s % R, k] = np.int64(ctl[k, _C_POPS])
                ctl[k, _C_OWNER] = t
                sync[2 * K + k] = 0
                if ctl[k, _C_STATUS] != 0.0:  # the window ended early: the next call goes on
                    _add(sync, S0 + _S_STOP, 1)
                _add(sync, k, 1)  # window s posted (after its writes)
                _add(sync, K + k, -1)
        done = sync[0]
        for j in range(K):
            done = min(done, sync[j])
        a = sync[S0 + _S_TALLY]
        if done - 1 > a:
            _tally(win, freezes, nth, a, done - 1)
            sync[S0 + _S_TALLY] = done - 1
        sync[S0 + _S_STOP] = 0
        for k in range(K):
            if ctl[k, _C_STATUS] != 0.0:
                return int(ctl[k, _C_STATUS])
        return 0

    pipe.__name__ = pipe.__qualname__ = f"pipe{3 if three else 2}d" + ("_o2" if order == 2 else "")
    return njit(cache=True, parallel=True, error_model="numpy")(pipe)


#: The pipelines by order (2D: :data:`_tuning.PIPELINE`).
_PIPES = {o: _pipe_kernel(False, o) for o in (1, 2)}


def clear_of_sources(bounds, start, shape3, rows: int) -> np.ndarray:
    """The slab bounds with every inner cut kept ``rows`` rows from the source's row, the middle
    row of the start box (a few point sources and their balls; a bigger start, over a quarter
    of the grid, keeps its cuts).

    A cut through a point source runs along the wave: the nodes beside its ghosts are marched
    a window before the neighbour's times arrive, and re-opened, all the way out (160^3 smooth
    speed, order 1: 54,663 nodes re-opened with the cut through the source, 12,631 / 8,894
    with it 8 rows above / below). A cut too near moves to the nearer of the two rows
    ``rows`` from the source's row (the lower on a tie) that lies between its neighbours,
    else stays.
    """
    nx = int(shape3[0])
    if rows <= 0 or len(bounds) < 3 or 4 * int(np.prod(start.shape)) > int(np.prod(shape3)):
        return bounds
    mid = int(start.lo[0]) + int(start.shape[0]) // 2  # the source's row
    out = np.array(bounds, dtype=np.int64)
    for i in range(1, len(out) - 1):
        c = int(out[i])  # the cut between rows c - 1 and c
        if mid - rows < c < mid + rows:
            for to in sorted((mid - rows, mid + rows), key=lambda r: abs(r - c)):
                if 0 < to < nx and out[i - 1] < to < out[i + 1]:
                    out[i] = to
                    break
    return out


def _slab_count(most: int, shape3, G: int, nth: int) -> int:
    """Slabs of a march on ``nth`` threads asking for ``most``: fewer where a slab would get
    fewer than :data:`_tuning.MIN_SLAB_ROWS` rows or :data:`_tuning.MIN_SLAB_NODES` nodes
    (but every thread one) or be thinner than its ``G`` ghost rows."""
    nx, ny, nz = (int(n) for n in shape3)
    K = int(max(1, min(most, nx // _tuning.MIN_SLAB_ROWS,
                       max(nth, nx * ny * nz // max(_tuning.MIN_SLAB_NODES, 1)))))
    return max(1, min(K, nx // G))


def slab_bounds(speed, start, shape3, h3, k: int, threads: int = 2,
                more: int = 0, cells=None, fewer: int = 0, order: int = 1) -> np.ndarray:
    """Row bounds (``k + 1`` ints) of ``k`` slabs along x, slab ``j`` marched by thread
    ``j % threads``; or of ``more`` slabs (``more + 1`` ints) where the coarse march
    predicts for them a windows' critical path shorter by the factor
    :data:`_tuning.MORE_SLABS_GAIN` (both with the slabs shared as :func:`_assign` shares
    them, :func:`_shared_cost`); or of ``fewer`` slabs (below ``k``, tried first, then no
    ``more``) where the coarse march reaches every coarse node (no walls) and predicts for
    them a critical path of at most :data:`_tuning.FEWER_SLABS_COST` times that of the ``k``
    slabs.

    The cuts are placed where a coarse march predicts the best balance: they minimise
    ``sum over time bins of max over threads of the nodes it marches in that bin``, the
    windows' critical path (a source off-centre would otherwise leave one thread idle
    while the wave crosses the other's slabs), by coordinate descent from equal slabs
    (each cut in turn moved to its best row between its neighbours, until none moves;
    exhaustive for two slabs). Where :data:`_tuning.SHARED_CUTS` says so (2D; 3D grids of at least
    :data:`_tuning.SHARED_CUTS_MIN_NODES_3D` nodes, the terrain plan's) a second descent
    counts a thread's nodes in a bin not as the fixed interleave gives them but as the least
    any sharing of the slabs allows, ``max(the bin's busiest slab, the bin's nodes /
    threads)`` (the slabs are shared anew before each window, :func:`_assign`, and cuts
    made for the interleave may leave the late wave in one slab), and the cuts of the two
    descents with the shorter critical path when the bins' slabs are shared as
    :func:`_assign` shares them (:func:`_shared_cost`) are taken. Equal slabs when the
    start is not a few point sources (its box over a quarter of the grid) or the grid is
    too thin for a coarse march. ``cells`` (int, shape (m, 3)): the coarse march starts from
    these nodes instead of the start's frozen ones (the sources, while their balls are being
    computed: :func:`march`'s ``ready``). ``order``: the full march's, which sets the coarse
    march's step in 3D (:data:`_tuning.COARSE_3D`).
    """
    nx = int(shape3[0])
    even = np.linspace(0, nx, k + 1).round().astype(np.int64)
    if k < 2 or threads < 2 or 4 * int(np.prod(start.shape)) > int(np.prod(shape3)):
        return even
    hist, f = _coarse_histogram(speed, start, shape3, h3, cells, order)
    if hist is None:
        return even
    rows = hist.shape[0]
    gap = max(1, -(-_tuning.MIN_SLAB_ROWS // f))  # coarse rows per slab at least
    if rows < k * gap:
        return even
    cum = np.vstack([np.zeros((1, hist.shape[1]), dtype=np.int64), np.cumsum(hist, axis=0)])
    cuts = _place_cuts(cum, k, gap, threads, shape3)
    # fewer: only where the coarse march reached every coarse node (no walls seen)
    if (0 < fewer < k and rows >= fewer * gap
            and int(hist.sum()) == _coarse_nodes(shape3, order)):
        alt = _place_cuts(cum, fewer, gap, threads, shape3)
        if _shared_cost(cum, alt, threads) <= (_tuning.FEWER_SLABS_COST
                                               * _shared_cost(cum, cuts, threads)):
            cuts, k, more = alt, fewer, 0
            even = np.linspace(0, nx, k + 1).round().astype(np.int64)
    if more > k and rows >= more * gap:
        alt = _place_cuts(cum, more, gap, threads, shape3)
        if _shared_cost(cum, cuts, threads) >= (_tuning.MORE_SLABS_GAIN
                                                * _shared_cost(cum, alt, threads)):
            cuts, k = alt, more
            even = np.linspace(0, nx, k + 1).round().astype(np.int64)
    bounds = np.minimum(cuts * f, nx)
    bounds[-1] = nx
    least = _tuning.MIN_SLAB_ROWS
    for i in range(1, k):  # fine rows: at least MIN_SLAB_ROWS per slab where they fit
        bounds[i] = min(max(bounds[i], bounds[i - 1] + least), nx - (k - i) * least)
    if np.any(np.diff(bounds) < 1):
        return even
    return bounds.astype(np.int64)


def _coarse_steps(shape3, order: int = 1) -> tuple[int, int]:
    """The steps of :func:`_coarse_histogram`'s coarse grid for a march of ``order``:
    ``(f, fz)``, every ``f``-th node along x and y, every ``fz``-th along z
    (:data:`_tuning.COARSE`, ``COARSE_3D[order]``, ``COARSE_3D_Z``)."""
    if shape3[2] > 1:
        return _tuning.COARSE_3D[order], _tuning.COARSE_3D_Z
    return _tuning.COARSE, 1


def _coarse_nodes(shape3, order: int = 1) -> int:
    """The nodes of :func:`_coarse_histogram`'s coarse grid (a march of ``order``)."""
    f, fz = _coarse_steps(shape3, order)
    return (-(-int(shape3[0]) // f)) * (-(-int(shape3[1]) // f)) * (-(-int(shape3[2]) // fz))


def _place_cuts(cum, k, gap, threads, shape3):
    """The ``k + 1`` coarse rows of :func:`slab_bounds`' cuts over the cumulated coarse
    histogram ``cum`` (at least ``gap`` rows apart): the descents from equal slabs."""
    rows = cum.shape[0] - 1
    cuts = np.clip(np.linspace(0, rows, k + 1).round().astype(np.int64), 0, rows)
    fixed = _descend_cuts(cum, cuts.copy(), gap, threads, False)
    three = shape3[2] > 1
    shared = _tuning.SHARED_CUTS[3 if three else 2] and not (
        three and int(np.prod(shape3)) < _tuning.SHARED_CUTS_MIN_NODES_3D)
    if shared:  # the better, by the windows as _assign shares the slabs
        cuts = _descend_cuts(cum, cuts, gap, threads, True)
        if _shared_cost(cum, fixed, threads) <= _shared_cost(cum, cuts, threads):
            cuts = fixed
    else:
        cuts = fixed
    return cuts


@njit(cache=True, error_model="numpy")
def _descend_cuts(cum, cuts, gap, threads, shared):
    """Coordinate descent of the inner cuts ``cuts[1:-1]`` (coarse rows, at least ``gap``
    apart; ``cum``: the coarse histogram cumulated over the rows, ``(rows + 1, bins)``,
    int64): each in turn to the row between its neighbours with the least critical path,
    ``sum over bins of the largest thread's nodes``, until none moves; ``cuts`` is changed
    and returned. A thread's nodes in a bin: those of its slabs in the fixed interleave
    (slab ``j`` to thread ``j % threads``; the first best row taken), or with ``shared`` the
    least any sharing allows, ``max(busiest slab, all / threads)`` (a move only where
    strictly better: that bound ties over many rows).

    The costs are integers (node counts; with ``shared`` the bound times ``threads``): exact
    in any order of summation, so the compiler vectorises the sum over the bins (2048^2
    FM²-shaped: the two descents 1.4 -> 0.25 ms on the calling thread, the same cuts; with
    three threads and more the bound is no longer rounded)."""
    k = cuts.size - 1
    nb = cum.shape[1]
    base = np.zeros((threads, nb), dtype=np.int64)  # the fixed interleave: per thread
    other = np.empty(nb, dtype=np.int64)  # what the slabs but i - 1 and i give a bin
    top = np.iinfo(np.int64).max
    for _ in range(4 * k):
        moved = False
        for i in range(1, k):
            lo = cuts[i - 1] + gap
            hi = cuts[i + 1] - gap
            if hi < lo:
                continue
            ca = cum[cuts[i - 1]]
            cz = cum[cuts[i + 1]]
            t1 = (i - 1) % threads  # the threads of slabs i - 1 and i (never one: threads >= 2)
            t2 = i % threads
            if shared:  # threads times max(all / threads, every other slab)
                for b in range(nb):
                    other[b] = cum[-1, b] - cum[0, b]
                for j in range(k):
                    if j == i - 1 or j == i:
                        continue
                    c0 = cum[cuts[j]]
                    c1 = cum[cuts[j + 1]]
                    for b in range(nb):
                        other[b] = max(other[b], threads * (c1[b] - c0[b]))
            else:  # every slab but i - 1 and i to its thread; other: the busiest of the rest
                base[:] = 0
                for j in range(k):
                    if j == i - 1 or j == i:
                        continue
                    t = j % threads
                    c0 = cum[cuts[j]]
                    c1 = cum[cuts[j + 1]]
                    for b in range(nb):
                        base[t, b] += c1[b] - c0[b]
                for b in range(nb):
                    m = 0
                    for t in range(threads):
                        if t != t1 and t != t2:
                            m = max(m, base[t, b])
                    other[b] = m
            b1 = base[t1]
            b2 = base[t2]
            best = cuts[i]
            best_cost = top
            here = top
            for c in range(lo, hi + 2):
                r = cuts[i] if c == hi + 1 else c  # last: the cut's own row
                cr = cum[r]
                cost = 0
                if shared:
                    for b in range(nb):
                        cost += max(other[b], threads * max(cr[b] - ca[b], cz[b] - cr[b]))
                else:
                    for b in range(nb):
                        cost += max(other[b], max(b1[b] + cr[b] - ca[b], b2[b] + cz[b] - cr[b]))
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


@njit(cache=True, error_model="numpy")
def _shared_cost(cum, cuts, threads):
    """The windows' critical path (nodes) of the cuts ``cuts`` over the coarse histogram's
    time bins (``cum``: cumulated over the rows) with the slabs shared as :func:`_assign`
    shares them: longest first by the last bin's nodes when that predicts a smaller
    largest share than the fixed interleave (slab ``k`` to thread ``k % threads``).
    Compiled (in numpy it was 0.8 ms per call, twice per march, on the calling thread
    alone while the other waits)."""
    k = cuts.size - 1
    per = np.zeros(k)
    pred = np.zeros(k)
    slabs = np.empty(k, dtype=np.int64)
    first = np.empty(threads + 1 + k, dtype=np.int64)
    load = np.empty(threads)
    share = np.empty(threads)
    total = 0.0
    for b in range(cum.shape[1]):
        for j in range(k):
            pred[j] = per[j]  # the last bin's nodes (0 before the first)
            per[j] = cum[cuts[j + 1], b] - cum[cuts[j], b]
        _assign(pred, threads, slabs, first, load, 1)
        share[:] = 0.0
        for j in range(k):  # the owners of the lists (greedy or the interleave)
            share[first[threads + 1 + j]] += per[j]
        total += share.max()
    return total


def _coarse_histogram(speed, start, shape3, h3, cells=None, order=1):
    """Nodes per coarse x-row and time bin of a march over every ``COARSE``-th node
    (``COARSE_3D[order]`` in 3D, along z ``COARSE_3D_Z``; ``order`` the full march's) from
    the start's frozen nodes: ``(hist, f)``, ``hist`` of shape ``(coarse rows, SPLIT_BINS)``
    and ``f`` the x coarsening; ``(None, f)`` if no estimate. ``cells``: the nodes to start
    from instead (int, (m, 3))."""
    f, fz = _coarse_steps(shape3, order)
    grid = speed.reshape(shape3)
    coarse = np.ascontiguousarray(grid[::f, ::f, ::fz])
    cshape = coarse.shape
    if cshape[0] < 4:
        return None, f
    if cells is None:
        cells = np.argwhere(start.state.reshape(start.shape) == _kernels.FROZEN)
        cells = cells + np.asarray(start.lo)
    if len(cells) == 0:
        return None, f
    # the coarse nodes of the frozen ones (a mask over their box: a source ball on constant
    # speed holds ~33,000 nodes on 2048^2, and np.unique of rows took 38 ms of serial time)
    cells = np.asarray(cells, dtype=np.int64) // np.array([f, f, fz])
    lo = cells.min(axis=0)
    bshape = tuple(int(n) for n in cells.max(axis=0) - lo + 1)
    frozen = np.zeros(bshape, dtype=bool)
    frozen[tuple((cells - lo).T)] = True
    frozen = frozen.reshape(-1)
    Tb = np.where(frozen, 0.0, np.inf)
    sb = np.where(frozen, _kernels.FROZEN, 0).astype(np.uint8)
    cstart = _kernels.Start(tuple(int(a) for a in lo), bshape, Tb, sb)
    hc = (h3[0] * f, h3[1] * f, h3[2] * fz)
    # read-only as fast_marching's speeds: the same specialisations (the warm-up's)
    T, _ = _kernels.march(_kernels._readonly(coarse.reshape(-1)), cstart, cshape, hc, 1,
                          np.zeros((0, 3), dtype=np.int64))
    T = T.reshape(cshape[0], -1)
    times = T[np.isfinite(T)]
    if times.size == 0 or not times.max() > 0.0:
        return None, f
    # bins of equal node counts in time order, as the windows (~WINDOW_NODES nodes each);
    # equal times share a bin: node bin ``rank * SPLIT_BINS // n``, ``rank`` the count of
    # earlier times, i.e. how many of the sorted times ending each bin's share are earlier
    # (a search among SPLIT_BINS - 1 edges instead of among all the times: 4 -> 0.5 ms)
    n = times.size
    nb = _tuning.SPLIT_BINS
    ends = -(-np.arange(1, nb) * n // nb) - 1  # ceil(b n / bins) - 1 >= 0
    return _time_bins(T, np.sort(times)[ends], nb), f


@njit(cache=True, error_model="numpy")
def _time_bins(T, edges, nb):
    """Nodes per row of ``T`` (2D, times; not finite: none) and bin, ``(rows, nb)`` int64, a
    node's bin the count of ``edges`` (sorted, ``nb - 1``) below its time (numpy's
    ``searchsorted(edges, t, side="left")``), found by walking from the last node's bin: the
    nodes of a row follow each other in space, their times (and bins) close. One pass; the
    numpy searchsorted and bincount it replaces took 1.8 ms on 160^3 order 2's coarse march
    (48,000 nodes), on the calling thread while the other waits."""
    m = edges.size
    hist = np.zeros((T.shape[0], nb), dtype=np.int64)
    pos = 0
    for r in range(T.shape[0]):
        for c in range(T.shape[1]):
            t = T[r, c]
            if not np.isfinite(t):
                continue
            while pos > 0 and not edges[pos - 1] < t:
                pos -= 1
            while pos < m and edges[pos] < t:
                pos += 1
            hist[r, pos] += 1
    return hist


def march(speed, start, shape3, h3, threads, stop_cells=None, order=1, *, interleave=None,
          span=None, ready=None, sources=None):
    """The Fast Marching from ``start`` on ``threads`` slabs in parallel.

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
        Threads, ``>= 2`` (each marches :data:`_tuning.SLABS_PER_THREAD` slabs, fewer
        where a slab would get fewer than :data:`_tuning.MIN_SLAB_ROWS` rows or
        :data:`_tuning.MIN_SLAB_NODES` nodes; one where the coarse march sees no walls and
        predicts no worse a balance, on a 3D grid of one speed
        (:data:`_tuning.FEWER_SLABS_3D`) or any 2D one (:data:`_tuning.FEWER_SLABS_2D`);
        2D order 2 of varying speed on its usual slabs takes narrower windows,
        :data:`_tuning.WINDOW_NODES_2D_VARYING`).
    stop_cells : ndarray, int, shape (m, 3), optional
        Stop once these nodes are frozen and final; nodes later than the latest
        of them are then ``inf``, as in the serial march.
    order : {1, 2}, optional
        Order of the upwind stencil, as in the serial march (order 2: two ghost
        x-slabs per side, the dependants two away updated again; see the notes above
        :func:`_known`).
    interleave : bool, optional
        2D slabs outside the lean layout: ``T`` and ``1 / speed^2`` interleaved in one
        array, as the serial march (:func:`fm2uav.eikonal._kernels._buffers`); default:
        unless every passable node has one speed. The times are the same bit for bit.
    span : tuple of 2 float, optional
        The smallest positive and the largest speed [m/s], if the caller knows them
        (:func:`fm2uav.eikonal.fast_marching` finds them in its input scan): the plateau
        test needs no pass over the speeds, nor the first window's width (the largest).
        None: found here.
    ready : callable, optional
        The start's times and states are still being written (the source balls, on
        another thread: :func:`fm2uav.eikonal.fmm._source_start`); called, it waits for
        them. Meanwhile the cuts are placed from the nodes ``sources`` (int, (m, 3)), the
        box's geometry (``lo``, ``shape``) being final, and, while its attribute
        ``running()`` (if any) says the balls are still being computed, the slabs are padded
        one by one on this thread with the start box's nodes left far, which are filled in
        once ``ready()`` returned (:func:`_fill_start_rows`). None: ``start`` is complete.
    sources : ndarray, int, shape (m, 3), optional
        With ``ready``: the source nodes.

    Returns
    -------
    T : ndarray, float64, shape (nx*ny*nz,)
        Arrival times [s], ``inf`` where unreachable.
    stats : dict
        ``slabs``, ``windows``, ``reopened`` (nodes changed after they were frozen),
        ``raised`` (order 2: updates that found a later time than the node had) and
        ``balance``: nodes frozen over the sum of each window's largest thread share, the
        speed-up the windows allow if every freeze cost the same (``threads`` at best; slabs
        taken in turn, :data:`_tuning.DYNAMIC_2D`: the shares an idle machine gives,
        :func:`_in_turn`, whatever this run's threads took; pipelined, :data:`_tuning.PIPELINE`:
        each window's larger of its busiest slab and a thread's mean share), ``greedy``: the
        windows whose slabs :func:`_assign` shared longest first, ``exchanges``: the exchanges
        run, ``runs``: how often each slab was marched in the exchanges and windows (every slab
        once per region: ``exchanges + windows`` each; pipelined, a slab ahead of the others
        when the march ended ran more).
    """
    import numba

    nx, ny, nz = (int(n) for n in shape3)
    three = nz > 1
    nth = int(max(1, min(threads, numba.config.NUMBA_NUM_THREADS)))
    # big 3D grids (the terrain plan's march) take their own slabs and windows
    big = three and nx * ny * nz >= _tuning.BIG_3D_NODES
    spt = (_tuning.BIG_3D_SLABS_PER_THREAD[order] if big
           else _tuning.SLABS_PER_THREAD[3 if three else 2, order])
    G = 2 if order == 2 else 1  # ghost x-slabs on each side (the rows the stencil reads)
    K = _slab_count(nth * spt, shape3, G, nth)
    wn = (_tuning.BIG_3D_WINDOW_NODES[order] if big
          else _tuning.WINDOW_NODES[3 if three else 2, order])
    nth = min(nth, K)
    sx = (ny + 2) * (nz + 2) if three else ny + 2
    sy = nz + 2 if three else 1
    lean = (nx + 2) * sx > _kernels.LEAN_NODES  # V in float32 as the serial march
    # more slabs where the coarse march predicts a better balance (slab_bounds decides;
    # not in the lean layout, whose buffers are sized for K before the cuts)
    more, more_wn = 0, wn
    if three and not big and not lean and nth > 1 and order in _tuning.MORE_SLABS_3D:
        spt2, more_wn = _tuning.MORE_SLABS_3D[order]
        more = _slab_count(nth * spt2, shape3, G, nth)
    # one slab per thread where the coarse march predicts no worse a balance: 3D on a
    # uniform speed (_tuning.FEWER_SLABS_3D), 2D per order (FEWER_SLABS_2D)
    uniform = span is not None and span[0] == span[1]
    fewer = nth if (not big and not lean and nth > 1 and (
        (three and _tuning.FEWER_SLABS_3D and uniform)
        or (not three and _tuning.FEWER_SLABS_2D.get(order, False)))) else 0
    early = toucher = None
    cells = None if ready is None else sources  # the cuts' coarse march starts from these
    if lean and nth > 1:
        # the lean layout's buffers are fresh mappings whose page faults (~0.4 CPU-s for
        # the 42 M nodes of a 1000 x 1000 x 40 terrain) the padding takes; map them at
        # their largest size now and fault them in on a second thread while this one
        # places the cuts (the coarse march: serial), the padding faults in the rest; the
        # times on huge pages or not (_tuning.LEAN_TIMES_HUGE)
        early = _kernels._buffers(speed, shape3, (nx + 2 * G * K) * sx + 8 * K, lean,
                                  interleave, huge_times=_tuning.LEAN_TIMES_HUGE, span=span)
    out = None  # the result (not lean)
    top_of = speed if span is None else None
    cut = partial(slab_bounds, speed, start, shape3, h3, K, nth, more, cells=cells, fewer=fewer,
                  order=order)
    if early is not None:
        with _PageToucher(early[0], early[1], top_of=top_of) as toucher:
            bounds = cut()
    elif nth > 1:
        # the cuts' coarse march runs on this thread alone: meanwhile a second one finds the
        # top speed (unless given) and faults in the result's pages (a fresh array's: a
        # pooled one's are there: its join waited 1.65 ms a march on 2048^2, cProfile),
        # the rows the other thread unpads first (_unpad_slabs)
        out, resident = _kernels.pooled_result_array(nx * ny * nz)
        half = out.size // 2
        touch = () if resident else (out[half:], out[:half])
        if touch or top_of is not None:
            with _PageToucher(*touch, top_of=top_of) as toucher:
                bounds = cut()
        else:
            bounds = cut()
    else:
        bounds = cut()
    if bounds.size - 1 != K:  # the more slabs taken, with their windows, or the fewer
        wn = more_wn if bounds.size - 1 == more else wn
        K = bounds.size - 1
    elif not three and span is not None and not uniform:  # 2D of varying speed, its K slabs
        wn = _tuning.WINDOW_NODES_2D_VARYING.get(order, wn)
    bounds = clear_of_sources(bounds, start, shape3,
                              _tuning.SOURCE_CUT_ROWS[3 if three else 2, order])
    if np.diff(bounds).min() < G:  # only the neighbours' rows are exchanged
        bounds = np.linspace(0, nx, K + 1).round().astype(np.int64)
    rows = np.diff(bounds).astype(np.int64)
    sizes = (rows + 2 * G) * sx
    # slabs start at multiples of 8 nodes: each slab's bits of ``fixed`` start a byte
    off = np.concatenate([[0], np.cumsum(-(-sizes // 8) * 8)[:-1]]).astype(np.int64)
    npad = int(off[-1] + sizes[-1])
    # the serial march's buffers: in the lean layout plain mappings (the times compacted
    # in place below), else its kept ones (huge pages, no page faults on a repeat); a 2D
    # map not of one speed interleaved (Tk: node c's time at 2 c, its V at 2 c + 1; Tp and
    # Vp strided views of it) and without a plateau register, as the serial march
    if early is None:
        Tp, Vp, Tk, Vk, unit, plat = _kernels._buffers(speed, shape3, npad, lean, interleave,
                                                       span=span)
    else:  # the lean layout: plain arrays, no plateau decided yet
        Tp, Vp = early[0][:npad], early[1][:npad]
        Tk, Vk, unit, plat = Tp, Vp, 1, None
        del early
    plane = ny * nz
    boxes = _start_boxes(start, bounds, nx, G)
    speed_r = _kernels._readonly(speed)
    beside = np.zeros(0, dtype=np.int64)  # the slabs padded beside the balls' computing
    running = getattr(ready, "running", None)
    if running is not None and nth > 1:
        # the balls take one core (on 2048^2 smooth speed ~8 ms, the cuts ~2.5): pad slab
        # after slab on this one meanwhile, the start box's nodes far (filled in below)
        none = np.zeros_like(boxes)
        done = []
        with _threads(1):
            for k in range(K):
                if not running():
                    break
                which = np.array([k], dtype=np.int64)
                _pad_slabs(1, speed_r, start.T, start.state, none, bounds, off, ny, nz, G, Tp,
                           Vp, which)
                done.append(k)
        beside = np.array(done, dtype=np.int64)
    if ready is not None:  # the source balls (their times and states) are written
        ready()
    rest = np.setdiff1d(np.arange(K, dtype=np.int64), beside)
    if rest.size:
        with _threads(nth):
            _pad_slabs(nth, speed_r, start.T, start.state, boxes, bounds, off, ny, nz, G, Tp,
                       Vp, rest)
    if beside.size:
        _fill_start_rows(speed_r, start.T, start.state, boxes, bounds, off, ny, nz, G, Tp, Vp,
                         beside)
    # the start box's own rows in each slab, the only nodes the start reads (nodes of Tp;
    # elements of Tk: times unit)
    b0, b1 = bounds[:-1], bounds[1:]
    i0 = np.clip(start.lo[0], b0, b1)
    i1 = np.clip(start.lo[0] + start.shape[0], i0, b1)
    rows0 = np.stack([(i0 - b0 + G) * sx, (i1 - b0 + G) * sx], axis=1)
    scan = unit * rows0
    # the nodes frozen on entry (sources, balls) stay as they are, as in the serial march:
    # a bit per node, set from the start box (the only frozen nodes on entry); order 2: the
    # nodes in the band on entry with their times (a repair keeps them if lower)
    (y0, z0), (y1, z1) = start.lo[1:], np.add(start.lo[1:], start.shape[1:])
    fixed, nodes = _start_nodes(Tp, off, i0, i1, b0, G, _U(sx), _U(sy), y0, y1, z0, z1,
                                1 if three else 0, npad, order == 2)
    if G == 2:  # order 2: the ghosts' too (the neighbours' own), which the serial march's
        _ghost_frozen_bits(fixed, Tp, off, rows, sx, G)  # first updates read (:func:`_known`)
    if plat is None:
        plat = _kernels._plateau(speed, Vp, shape3, npad,
                                 fill=lambda vmax, bits: _slab_plateau(speed, vmax, bounds, off,
                                                                       shape3, bits, G),
                                 span=span)
    U, qp = plat
    # order 2's bit masks: re-opened, suspect, pending, a bit per node (one spare byte: a 2D
    # slice below); the band nodes on entry by element index
    fl = (_kernels._work if lean else partial(_kernels._work_kept, "flags"))(
        4 * (npad // 8 + 2) if order == 2 else 4)
    fl[:] = 0
    eidx = (unit * nodes).astype(np.uint64)
    evals = -Tp[nodes]
    # each slab's nodes frozen in its first and last own rows in the last window (the
    # neighbours' exchange reads those); a count over the capacity: read the whole row
    # (so the first exchange, after the start)
    sent = np.empty((K, 2, G * sx), dtype=np.uint64)
    ns = _lined(K, 2, np.uint64, G * sx + 1)
    # queues: one radix queue and one repair heap per slab (each slab's small arrays on
    # cache lines of its own: the two threads write them at every push and pop)
    nblk = max(POOL_MIN_BLOCKS, int(sizes.max()) // (16 * BLOCK))
    # the entry pools in this thread's kept buffer (the serial march's; not in the lean
    # layout, whose buffers are not kept either): a fresh one's page faults (34 MB on
    # 2048^2, ~20 ms of system time) would be taken by the windows
    pool = (_kernels._work if lean else partial(_kernels._work_kept, "pool"))(
        K * 16 * nblk * BLOCK).view(np.uint64).reshape(K, 2 * nblk * BLOCK)
    nxt = np.empty((K, nblk), dtype=np.uint32)
    bk = _lined(K, 2 * int(_NB), np.uint32)
    mw = _lined(K, _NW, np.uint64)
    st = _lined(K, _ST, np.uint64)
    for k in range(K):
        _kernels.init_queue(nxt[k], bk[k], mw[k], st[k])
    rcap = max(HEAP_START, HEAP_RESERVE_2 if order == 2 else HEAP_RESERVE)
    rkey = np.empty((K, rcap), dtype=np.uint64)
    ritem = np.empty((K, rcap), dtype=np.uint64)
    ctl = _lined(K, _C_SIZE, np.float64)
    ctl[:, _C_RMIN] = np.inf
    ctl[:, _C_OWNER] = np.arange(K) % nth  # the interleave, before the first window
    ih = np.array([1.0 / (h * h) for h in h3])
    iso = bool(ih[0] == ih[1] and (not three or ih[1] == ih[2]))
    hh = float(1.0 / ih[0])
    # the top speed sets the first window's width only (then adapted): from the plateau's
    # register when there is one, else found beside the cuts (a pass over the speeds is
    # ~2 ms on 2048^2, on the core that waits while the cuts are placed)
    if qp > 0.0:
        vmax = 1.0 / np.sqrt(qp)
    elif span is not None:
        vmax = span[1]
    elif toucher is not None:
        vmax = toucher.top
    else:
        vmax = _top_speed(_kernels._readonly(speed))
    width = 2.0 * min(h3[:3 if three else 2]) / max(vmax, 1e-300)
    win = np.zeros(_W_SIZE + (_P_THREADS + 3 * nth if PROFILE else 0))
    win[:_W_SIZE] = [0.0, width, 0.0, float(wn), 0.0, 0.0, np.inf, 0.0, 0.0, 0.0]
    stop_idx = np.zeros(0, dtype=np.int64)
    if stop_cells is not None and len(stop_cells):
        cells = np.asarray(stop_cells, dtype=np.int64).reshape(-1, 3)
        k = np.searchsorted(bounds, cells[:, 0], side="right") - 1
        local = ((cells[:, 0] - bounds[k] + G) * (ny + 2) + cells[:, 1] + 1)
        if three:
            local = local * (nz + 2) + cells[:, 2] + 1
        stop_idx = unit * (off[k] + local)
    drive = _DRIVES[3 if three else 2, G]
    # the windows pipelined (:data:`_tuning.PIPELINE`): no barrier between them, each window
    # posting its boundary nodes' times for its neighbours (:func:`_pipe_kernel`); not toward
    # stop nodes, nor with the profile
    piped = (nth > 1 and not stop_idx.size and not PROFILE
             and not three and bool(_tuning.PIPELINE[order]))
    if piped:
        ring = 2 * K + 2  # windows the slabs may be apart, twice, and more
        psent = np.empty((K, 2, 2, G * sx), dtype=np.uint64)  # [slab, parity, side]
        pns = _lined(K, 16, np.uint64, G * sx + 1).reshape(K, 2, 8)
        post = np.empty((K, 2, 2, unit * G * sx))
        sync = np.zeros(3 * K + _S_SIZE, dtype=np.int64)
        ends = np.zeros((2, ring))  # each window's end and width
        freezes = np.zeros((ring, K), dtype=np.int64)
        quiet = np.zeros(ring, dtype=np.int64)
    # how the slabs go to the threads (_assign): in turn (2), lists (1), the interleave (0)
    if not _tuning.SHARE_SLABS:
        share = 0
    elif three:
        share = 3 if _tuning.SLABS_STAY_3D else 1
    else:
        share = (3 if _tuning.SLABS_STAY_2D else 2) if _tuning.DYNAMIC_2D else 1
    slabs = np.empty(K, dtype=np.int64)  # scratch of _assign: each window's slabs per thread
    lists = np.empty(nth + 1 + K + nth, dtype=np.int64)  # + each list's counter (share 3)
    load = np.empty(nth)
    # the exchanges in the windows' regions (_tuning.EXCHANGE_IN_WINDOW): per slab its
    # window done and its exchange taken
    merge = bool(_tuning.EXCHANGE_IN_WINDOW[3 if three else 2, order])
    xs = np.zeros(2 * K, dtype=np.int64)
    first = True
    prev = numba.get_num_threads()
    numba.set_num_threads(nth)
    try:
        while True:
            far = (1 + int(DEFER)) if FAR_ONE_AXIS else 0
            if piped:
                status = _PIPES[G](
                    nth, Tk, Vk, U, qp, fixed, fl, eidx, evals, unit * off, unit * (off + sizes),
                    rows, _U(unit * sx), _U(unit * sy), ih, hh, iso, pool, nxt, bk, mw, st, rkey,
                    ritem, ctl, psent, pns, post, win, first, scan, far, sync, ends, freezes,
                    quiet)
                win[9] = win[2]  # an exchange before each window
            else:
                status = drive(nth, Tk, Vk, U, qp, fixed, fl, eidx, evals, unit * off,
                               unit * (off + sizes), rows, _U(unit * sx), _U(unit * sy), ih, hh,
                               iso, pool, nxt, bk, mw, st, rkey, ritem, ctl, sent, ns, win, first,
                               stop_idx, slabs, lists, load, share, scan, far,
                               not three and _tuning.EXCHANGE_ALONE_2D[order], merge, xs)
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
        for k in range(K):  # from the ghost x-slab next to the own ones (unpad_grid's layout)
            a, b = int(bounds[k]), int(bounds[k + 1])
            seg = slice(int(off[k] + (G - 1) * sx), int(off[k] + sizes[k] - (G - 1) * sx))
            _kernels.unpad_grid(Tp[seg], b - a, ny, nz, Tp[a * plane:b * plane])
        T = Tp[:nx * ny * nz]
    else:  # the result array (its pages faulted in beside the cuts, the rest here): in parallel
        T = _kernels.result_array(nx * ny * nz) if out is None else out
        with _threads(nth):
            _unpad_slabs(nth, Tp, bounds, off, ny, nz, T, G)
    if win[6] < np.inf:  # stopped: what the serial march would not have frozen yet
        with _threads(nth):
            _inf_after(nth, T, win[6])
        sel = tuple(slice(a, a + m) for a, m in zip(start.lo, start.shape))
        box = T.reshape(shape3)[sel]  # nodes frozen on entry stay, whatever their time
        frozen = (start.state == _kernels.FROZEN).reshape(start.shape)
        box[frozen] = start.T.reshape(start.shape)[frozen]
    return T, {"slabs": K, "windows": int(win[2]), "reopened": int(ctl[:, _C_REOPEN].sum()),
               "raised": int(ctl[:, _C_RAISED].sum()),
               "balance": float(win[4] / max(win[5], 1.0)), "greedy": int(win[8]),
               "exchanges": int(win[9]), "runs": ctl[:, _C_RUNS].astype(np.int64),
               **({"profile": _profile(win, nth)} if PROFILE else {})}


def on_slabs(nodes: int, three: bool, order: int) -> bool:
    """Whether a march of ``nodes`` nodes marches on slabs when threads allow it.

    Parameters
    ----------
    nodes : int
        Grid nodes.
    three : bool
        A 3D grid (else 2D).
    order : {1, 2}
        Order of the stencil.

    Returns
    -------
    bool
        From :data:`_tuning.PARALLEL_MIN_NODES` nodes, order 1; order 2 while
        :data:`_tuning.ORDER2` is set and from :data:`_tuning.ORDER2_MIN_NODES_3D` (3D) or
        :data:`_tuning.ORDER2_MIN_NODES_2D` (2D) nodes too.
    """
    if nodes < _tuning.PARALLEL_MIN_NODES:
        return False
    if order == 1:
        return True
    floor = _tuning.ORDER2_MIN_NODES_3D if three else _tuning.ORDER2_MIN_NODES_2D
    return bool(_tuning.ORDER2) and nodes >= floor


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


@njit(cache=True, error_model="numpy")
def _start_nodes(Tp, off, i0, i1, b0, G, sx, sy, y0, y1, z0, z1, zpad, npad, band):
    """The start box's nodes in the padded slabs ``Tp`` (``npad`` nodes): a bit per node set
    where ``Tp >= 0`` (frozen on entry), clear elsewhere (no other node is), and with
    ``band`` the box's nodes in the band (``-inf < Tp < 0``) in increasing order (int64).

    Slab ``k`` (from ``off[k]``, its first own row ``b0[k]``, ``G`` ghost rows) holds the box's
    rows ``i0[k] <= i < i1[k]``; the box spans ``y0 <= y < y1`` and, in 3D (``zpad`` 1: the
    z ghosts), ``z0 <= z < z1`` (2D: 0, 1, ``zpad`` 0); node ``(i, y, z)`` is at
    ``off[k] + (i - b0[k] + G) * sx + (y + 1) * sy + z + zpad``. Only the box is read (its rows
    whole were 10 times the nodes on the 2048^2 bench's ball: ~1.7 ms a march)."""
    bits = np.zeros(npad // 8 + 1, dtype=np.uint8)
    cap = 0
    if band:
        for k in range(off.size):
            cap += (i1[k] - i0[k]) * (y1 - y0) * (z1 - z0)
    nodes = np.empty(cap, dtype=np.int64)
    m = 0
    for k in range(off.size):
        for i in range(i0[k], i1[k]):
            r = off[k] + (i - b0[k] + G) * sx + zpad
            for y in range(y0, y1):
                base = r + (y + 1) * sy
                for z in range(z0, z1):
                    c = base + z
                    x = Tp[c]
                    if x >= 0.0:
                        bits[c >> 3] |= np.uint8(1 << (c & 7))
                    elif band and x > -np.inf:
                        nodes[m] = c
                        m += 1
    return bits, nodes[:m]


@njit(cache=True, parallel=True, error_model="numpy")
def _inf_after(nth, T, t):
    """``T[T > t] = inf`` on ``nth`` threads (a stopped march: 40 M nodes took ~0.05 s on
    one)."""
    n = T.size
    for k in prange(nth):
        for i in range(k * n // nth, (k + 1) * n // nth):
            if T[i] > t:
                T[i] = np.inf


@njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
def _top_speed(speed):
    """The largest speed (1.0 for none), without the GIL (:class:`_PageToucher` finds it
    beside the cuts where the caller did not give it); it sets the first window's width."""
    return speed_range(speed)[1] if speed.size > 0 else 1.0


def _ghost_frozen_bits(bits, Tp, off, rows, sx, G):
    """Order 2: set the bits (frozen on entry) of every slab's ``G`` ghost x-slabs on each
    side from the neighbours' own boundary rows in ``Tp`` (nodes; slab ``k`` from
    ``off[k]`` with ``rows[k]`` own rows of ``sx`` nodes): the serial march's first updates
    read those nodes (:func:`_known`)."""
    K = len(off)
    m = G * sx
    for k in range(K):
        if k > 0:  # the last own rows of the slab below
            o = int(off[k - 1] + rows[k - 1] * sx)
            _or_bits_at(bits, np.packbits(Tp[o:o + m] >= 0.0, bitorder="little"), int(off[k]),
                        m)
        if k < K - 1:  # the first own rows of the slab above
            o = int(off[k + 1] + G * sx)
            _or_bits_at(bits, np.packbits(Tp[o:o + m] >= 0.0, bitorder="little"),
                        int(off[k] + (rows[k] + G) * sx), m)


def _start_boxes(start, bounds, nx, G=1):
    """Each slab's part of the start box, for :func:`_pad_slabs`: rows ``(i0, j0, k0, bx,
    by, bz, first, last)`` of ints, the box in the node indices of the rows the slab pads
    (:func:`_padded_rows`: its own rows, and with ``G = 2`` ghost rows ``G - 1`` deep, whose
    times the ghosts' ``NaN`` then replaces) (``bx = 0``: none) and the range
    ``[first, last)`` of ``start.T`` / ``start.state`` it takes."""
    lo, bshape = start.lo, start.shape
    bplane = bshape[1] * bshape[2]
    boxes = np.zeros((len(bounds) - 1, 8), dtype=np.int64)
    for k in range(len(bounds) - 1):
        ra, rb, _ = _padded_rows(int(bounds[k]), int(bounds[k + 1]), nx, G)
        i0, i1 = max(lo[0], ra), min(lo[0] + bshape[0], rb)
        if i1 > i0:
            boxes[k] = (i0 - ra, lo[1], lo[2], i1 - i0, bshape[1], bshape[2],
                        (i0 - lo[0]) * bplane, (i1 - lo[0]) * bplane)
    return boxes


@njit(cache=True, parallel=True, error_model="numpy")
def _pad_slabs(nth, speed, Tb, sb, boxes, bounds, off, ny, nz, G, Tp, Vp, which):
    """Pad the slabs ``which`` into their place in ``Tp`` / ``Vp`` (slab ``k`` from
    ``off[k]``, ``G`` ghost x-slabs on each side, :func:`_pad_slab_rows`), thread ``t`` the
    ``t``-th share of all their padded x-slabs, from whichever slabs hold them. By x-slabs,
    not by slabs: the cuts follow the wave, and slab by slab one thread padded 1193 of the
    2048 rows of the bench's FM²-shaped map (its slabs 71 to 729 rows) while the other
    waited (as :func:`_unpad_slabs`)."""
    K = bounds.size - 1
    nx = bounds[K]
    total = 0
    for i in range(which.size):
        k = which[i]
        total += bounds[k + 1] - bounds[k] + 2 * G
    for t in prange(nth):
        lo, hi = t * total // nth, (t + 1) * total // nth
        pos = 0
        for i in range(which.size):
            k = which[i]
            n = bounds[k + 1] - bounds[k] + 2 * G
            a, b = max(pos, lo), min(pos + n, hi)
            if b > a:
                _pad_slab_rows(speed, Tb, sb, boxes[k], bounds[k], bounds[k + 1], nx, off[k], ny,
                               nz, G, Tp, Vp, a - pos, b - pos)
            pos += n


@njit(cache=True, error_model="numpy", _nrt=False)
def _pad_slab_rows(speed, Tb, sb, bx, a, b, nx, o, ny, nz, G, Tp, Vp, p0, p1):
    """The x-slabs ``[p0, p1)`` of slab ``[a, b)``'s padded grid (from ``Tp[o]``, ``G`` ghost
    x-slabs a side; slab row ``p`` is grid row ``a - G + p``), as the whole slab's padding
    leaves them: the own rows as :func:`~fm2uav.eikonal._kernels.pad_grid` pads the grid rows
    :func:`_padded_rows` gives (the start box ``bx``, :func:`_start_boxes`, in their
    indices), the ghost rows ``NaN`` and, with ``G = 2``, the grid's ``1 / speed^2``
    [s^2/m^2] where the grid has the row (the order-2 speed check reads it), rounded as
    ``pad_grid`` rounds it; the ghosts' other speeds are never read and stay unset."""
    three = nz > 1
    pz = nz + 2 if three else 1
    sx = (ny + 2) * pz
    plane = ny * nz
    rows = b - a
    ra, rb, q0 = _padded_rows(a, b, nx, G)
    seg0 = o + q0 * sx
    T = Tp[seg0:seg0 + (rb - ra + 2) * sx]
    V = Vp[seg0:seg0 + (rb - ra + 2) * sx]
    sp = speed[ra * plane:rb * plane]
    tb = Tb[bx[6]:bx[7]]
    st = sb[bx[6]:bx[7]]
    for p in range(p0, p1):
        if p >= G and p < rows + G:  # an own row: sub-grid row p - q0 - 1 of pad_grid
            _pad_slab(sp, tb, st, bx[0], bx[1], bx[2], bx[3], bx[4], bx[5], p - q0 - 1, ny, nz,
                      T, V)
            continue
        base = o + p * sx
        for j in range(sx):
            Tp[base + j] = np.nan
        i = a - G + p
        if G < 2 or i < 0 or i >= nx:
            continue
        for y in range(ny):
            dst = base + (y + 1) * pz + (1 if three else 0)
            src = (i * ny + y) * nz
            for z in range(nz):
                v = speed[src + z]
                Vp[dst + z] = 1.0 / (v * v)


@njit(cache=True, error_model="numpy")
def _fill_start_rows(speed, Tb, sb, boxes, bounds, off, ny, nz, G, Tp, Vp, which):
    """Write the start box's nodes into the own x-slabs of the slabs ``which``
    (:func:`_pad_slabs` padded those slabs with the box's nodes far while the source balls
    were computed; the box's runs only, :func:`~fm2uav.eikonal._kernels._box_run`): the
    padded grid is then the one :func:`_pad_slabs` gives with the box. The ghost x-slabs
    keep their ``NaN`` (:func:`_pad_slab_rows`)."""
    K = bounds.size - 1
    nx = bounds[K]
    plane = ny * nz
    sx = (ny + 2) if nz == 1 else (ny + 2) * (nz + 2)
    for k in which:
        bx = boxes[k]
        if bx[3] == 0:
            continue
        a, b = bounds[k], bounds[k + 1]
        ra, rb, p0 = _padded_rows(a, b, nx, G)
        seg = slice(off[k] + p0 * sx, off[k] + (p0 + rb - ra + 2) * sx)
        T = Tp[seg]
        V = Vp[seg]
        sp = speed[ra * plane:rb * plane]
        tb = Tb[bx[6]:bx[7]]
        st = sb[bx[6]:bx[7]]
        i0, j0, k0, by, bz = bx[0], bx[1], bx[2], bx[4], bx[5]
        for i in range(max(i0, a - ra), min(i0 + bx[3], b - ra)):  # own rows only
            slab = (i + 1) * sx  # the box's runs of that x-slab, as pad_grid lays them
            if nz == 1:
                _kernels._box_run(sp, tb, st, i * ny + j0, (i - i0) * by, slab + 1 + j0, by,
                                  T, V)
                continue
            for j in range(j0, j0 + by):
                _kernels._box_run(sp, tb, st, (i * ny + j) * nz + k0,
                                  ((i - i0) * by + j - j0) * bz, slab + (j + 1) * (nz + 2) + 1
                                  + k0, bz, T, V)


@njit(cache=True, parallel=True, error_model="numpy")
def _unpad_slabs(nth, Tp, bounds, off, ny, nz, T, G):
    """Every slab's times into its rows of ``T`` (a new array; the lean layout compacts in
    place, slab after slab), thread ``t`` the ``t``-th share of the grid's rows, from
    whichever slabs hold them (each slab's grid read from its ghost x-slab next to the
    rows: ``G`` ghost x-slabs a side). By rows, not by slabs: the slabs' rows differ (the
    cuts follow the wave), and slab by slab one thread took 1136 of 2048 rows on the
    bench's FM²-shaped map while the other waited (the unpadding's wall 17 ms against its
    6 ms on the calling thread)."""
    K = bounds.size - 1
    nx = bounds[K]
    plane = ny * nz
    sx = (ny + 2) if nz == 1 else (ny + 2) * (nz + 2)
    for t in prange(nth):
        lo, hi = t * nx // nth, (t + 1) * nx // nth
        for k in range(K):
            a, b = max(bounds[k], lo), min(bounds[k + 1], hi)
            if b > a:  # grid rows [a, b) of slab k: its padded rows from a - bounds[k] + G
                o = off[k] + (G - 1 + a - bounds[k]) * sx
                unpad_grid(Tp[o:o + (b - a + 2) * sx], b - a, ny, nz, T[a * plane:b * plane])


@njit(cache=True, _nrt=False)
def _padded_rows(a, b, nx, G):
    """The grid rows ``[ra, rb)`` padded into slab ``[a, b)``'s grid and the slab row of the
    padded grid's first x-slab (its ghost), ``p0``: the slab's padded grid has ``G`` ghost
    x-slabs on each side, slab row ``p`` is grid row ``a - G + p``; rows ``a - G + 1`` to
    ``b + G - 2`` that exist are padded by :func:`~fm2uav.eikonal._kernels.pad_grid`
    (``G = 1``: the slab's own rows, ``p0 = 0``)."""
    ra, rb = max(a - G + 1, 0), min(b + G - 1, nx)
    return ra, rb, ra - 1 - a + G


def _slab_plateau(speed, vmax, bounds, off, shape3, bits, G=1):
    """Set the plateau bits (speed ``vmax``) of every slab in its own padded layout (slab
    ``k`` from byte ``off[k] / 8`` of ``bits``; the rows that :func:`_padded_rows` pads);
    returns how many nodes have ``vmax`` (with ``G = 2`` the rows next to a cut twice)."""
    nx, ny, nz = (int(n) for n in shape3)
    plane = ny * nz
    sx = (ny + 2) * (nz + 2 if nz > 1 else 1)
    count = 0
    for k in range(len(bounds) - 1):
        a, b = int(bounds[k]), int(bounds[k + 1])
        ra, rb, p0 = _padded_rows(a, b, nx, G)
        pos = int(off[k]) + p0 * sx
        if pos % 8 == 0:
            count += _kernels.plateau_bits(speed[ra * plane:rb * plane], vmax, rb - ra, ny, nz,
                                           bits[pos >> 3:])
        else:  # the first slab of order 2: its grid starts one row into its bits
            part = np.zeros((rb - ra + 2) * sx // 8 + 1, dtype=np.uint8)
            count += _kernels.plateau_bits(speed[ra * plane:rb * plane], vmax, rb - ra, ny, nz,
                                           part)
            _or_bits_at(bits, part, pos, (rb - ra + 2) * sx)
    return count


@njit(cache=True, _nrt=False)
def _or_bits_at(dst, src, pos, m):
    """Set bit ``pos + i`` of ``dst`` for every set bit ``i < m`` of ``src``."""
    for i in range(m):
        if (src[i >> 3] >> (i & 7)) & 1:
            j = pos + i
            dst[j >> 3] |= np.uint8(1 << (j & 7))


def _lined(K, n, dtype, fill=0):
    """``K`` rows of at least ``n`` items of ``dtype`` filled with ``fill``, each row on cache
    lines of its own (64-byte aligned, a multiple of 64 bytes long; a C-contiguous view).

    Each slab's queue state (``st``, ``bk``, ``mw``) and control slots (``ctl``, ``ns``)
    are written by the thread marching it at every push and pop; rows sharing a line with
    the neighbouring slab's would bounce that line between the cores while both march.
    """
    item = np.dtype(dtype).itemsize
    m = -(-n * item // _LINE) * _LINE // item
    buf = np.full(K * m + _LINE // item, fill, dtype=dtype)
    a = (-buf.ctypes.data % _LINE) // item
    return buf[a:a + K * m].reshape(K, m)


#: Bytes of a cache line (x86-64, ARMv8 cores but Apple's).
_LINE = 64


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


@njit(cache=True, nogil=True, _nrt=False)
def _touch(a, step):
    """Write a zero every ``step`` bytes of ``a`` (uint8): the pages' faults, without the GIL."""
    for i in range(0, a.size, step):
        a[i] = 0


class _PageToucher:
    """Inside the block a second thread faults in the pages of the arrays given (in chunks
    of :data:`_tuning.TOUCH_CHUNK` bytes, in turn), stopping at the block's end; whatever it did
    not reach faults in where it is first written (:func:`_pad_slabs`, on every thread).
    With ``top_of`` (speeds [m/s]) it first finds their largest (:func:`_top_speed`, not
    stopped: ``top`` after the block), work :func:`march` would otherwise do after the cuts
    while the other core waits."""

    def __init__(self, *arrays, top_of=None):
        self.bufs = [a.view(np.uint8).reshape(-1) for a in arrays]
        self.speed = None if top_of is None else _kernels._readonly(top_of)
        self.top = None
        self.stop = threading.Event()
        self.thread = threading.Thread(target=self._run, daemon=True)

    def _run(self):
        if self.speed is not None:
            self.top = _top_speed(self.speed)
        for buf in self.bufs:
            for a in range(0, buf.size, _tuning.TOUCH_CHUNK):
                if self.stop.is_set():
                    return
                _touch(buf[a:a + _tuning.TOUCH_CHUNK], 4096)

    def __enter__(self):
        self.thread.start()
        return self

    def __exit__(self, *exc):
        self.stop.set()
        self.thread.join()
        return False



