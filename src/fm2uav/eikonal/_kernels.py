"""Compiled (numba) kernels of the Fast Marching Method.

Private module: the public entry point is :func:`fm2uav.eikonal.fast_marching`,
which validates the input, initialises the sources and calls :func:`march`
(``initial frozen nodes and values in, arrival times out``).

Layout of the march (see docs/performance.md for the measurements behind it)
---------------------------------------------------------------------------
* The grid is copied into a **padded** grid with one ghost layer per axis
  (2D grids stay 2D: ``(nx + 2, ny + 2)``; 3D: ``(nx + 2, ny + 2, nz + 2)``),
  so a node's six (four) neighbours are ``c +- sx, c +- sy, c +- 1`` on the
  flat index with no bounds checks and no index divisions.
* **State folded into T**: one float per node says everything the march needs:
  ``T >= 0`` frozen (final time), ``-t`` narrow band with tentative time ``t``,
  ``-inf`` far, ``NaN`` impassable (speed 0) or ghost. ``T >= 0`` and
  ``T < 0`` are false for NaN, so walls and ghosts need no separate test.
* **Monotone radix queue** (Ahuja et al. 1990, with 8-bit digits): FMM pops
  non-decreasing keys, and for non-negative IEEE doubles the order of the bit
  patterns is the order of the values. A key goes into the bucket given by the
  highest 8-bit digit in which it differs from ``last`` (a lower bound of
  every key in the queue) and that digit's value; buckets are ordered, so the
  smallest key is in the lowest non-empty bucket. A level-0 bucket holds one
  key value (``last`` itself has a level-0 bucket of its own), so its last
  entry is popped without a scan: ties, frequent where the speed is constant
  and the grid symmetric, cost O(1) each (measured 0.77x the march time on
  160^3 order 1 constant speed, unchanged elsewhere). A bucket of higher level
  with at most ``SCAN_MAX`` entries is scanned for its exact minimum; a larger
  one is split one digit down. Keys a rounding error below ``last`` go to
  bucket 0, which is always scanned, so the popped node is the exact minimum
  (ties in any order).
  Entries (key bits, node) sit in blocks of ``BLOCK`` slots. **No
  decrease-key**: a lowered band node gets a new entry and its old one (a
  larger key) stays behind; a split drops the entries whose key is no longer
  the node's band time, and a popped entry of a node frozen already is
  skipped. The march needs no node-sized position array, and with the deferred
  entries (below) a node is queued about once. Measured on 2048^2 order 1 (march
  only, interleaved): 0.91x the time of the position-array queue with lazy
  entries, 0.70x with the splits dropping the outdated ones.
* **Plateau**: where the grid's largest speed covers at least half of the nodes (or
  every passable node has one speed), the march takes ``1 / speed^2`` of those nodes
  from a register, a bit mask telling which (:func:`_plateau`), instead of reading the
  speed grid, half of the memory the march touches (measured -24 % on 2048^2 constant
  speed); the times are bit for bit the same.
* **Fetching ahead (3D)**: where the speed varies strongly (W rising from ~0 at the
  ground of a terrain map) the front is sheared and its band wide, so consecutive pops
  lie far apart in memory and the lines an expansion reads are cold. The 3D marches pop
  with :func:`_pop_ahead`: the next pop, the smallest other entry of a scanned bucket,
  gets its lines prefetched (:func:`_fetch_around`) while the popped node is expanded, and
  a split prefetches its blocks' nodes before checking them. Measured -7 to -12 % on the 1000 x 1000 x 40 terrain march and
  on 160^3 FM²-shaped, -13 to -21 % on 160^3 smooth (docs/performance.md); on 2D grids it
  cost +4 %, so 2D pops plainly. The queue pops the same nodes: times bit for bit.
  Prefetching around *every* other entry of the bucket (as first built) re-issued the
  same ~16 lines per entry at every pop of a bucket; the next pop only, and no prefetch
  of a new 3D band node's lines in :func:`_relax` (frozen much later, evicted by then),
  measured together 0.92x the march time on 160^3 FM²-shaped order 1 (see "3D march,
  round two" in docs/performance.md).
* **Interleaved 2D layout**: a 2D map (outside the lean layout) whose passable nodes do
  not all have one speed marches with ``T`` and ``V`` in one array, node ``c``'s time at
  ``2 c`` and its ``1 / speed^2`` at ``2 c + 1`` (the kernel's node indices are element
  indices, ``unit = 2``), so an update reads a neighbour's time and speed from one cache
  line: measured -8 % on 2048^2 FM²-shaped order 1, -17 % on the smooth field, and faster
  than the plateau mask on FM² maps saturated on 57-70 % of the nodes (:func:`_buffers`).
* **Interleaved 3D layout**: a 3D map without a plateau mask marches interleaved too
  (``unit = 2``); one with a plateau keeps the mask in separate arrays (measured -22 % on
  160^3 constant speed). Measured -1.3 to -1.7 % on 160^3 FM²-shaped and smooth: the 3D
  march's cold lines are mostly ``T`` lines of other planes, which the layout does not
  bring closer.
* **Far neighbours while popping** (2D and 3D): a far neighbour of the node just frozen
  has no other frozen neighbour (every frozen node has queued its neighbours), so its time
  is the one-axis solution along that axis, which the full update would compute from the
  same numbers (half of the updates in 2D, a third in 3D; times bit for bit). At order 2
  its term reads only the node beyond the one just frozen (:func:`_upwind_term`), not the
  far node's other side: measured 0.89x the march time on 2048^2 FM²-shaped order 2.
* **Deferred entries** (2D and 3D): a far neighbour ``nb`` of the node just frozen gets its
  time ``t`` (the one-axis solution above) but no queue entry when a neighbour of ``nb``
  across another axis is in the band earlier than ``t`` (:func:`_earlier_band`): that
  neighbour is frozen first (the queue pops in time order) and updates ``nb`` again, which
  almost always lowers it (the two-axis solution) and queues it then; where that update does
  not lower it, :func:`_relax` queues ``nb`` at the time it has (a band node not lowered is
  queued again: a second entry at the same key is skipped as outdated). So a node is queued
  about once instead of twice (2048^2 FM²-shaped order 1: 3,100,435 of 3,142,765 frozen
  nodes deferred, 6,412 updates that did not lower a band node, each queued again), and the
  splits no longer sort the outdated first entries. The 2D deferral fetches the lines of
  the node's rows as :func:`_relax` does for a new band node. The times are the same bit
  for bit but where tied times pop in another order (the queue holds other entries) and an
  order-2 update depends on which tied neighbour froze first; measured in
  docs/performance.md ("Deferred entries": 0.87x the one-thread time on 2048^2 FM²-shaped
  order 1, 0.91x order 2, 0.89x on 160^3 at a constant speed, 1.00x 160^3 FM²-shaped).
* **The start box**: band and frozen nodes on entry lie in the start box, so the seeding
  and the expansion of the frozen nodes scan its span only, not the grid (a 2048^2
  march that freezes almost nothing: 29 ms before, 19 ms with the interleaved layout).
* Unsigned (``uint64``) indices throughout: numba emits negative-index
  wraparound code for signed indices, measured 1.8x slower in the hot loop.

Where a march starts and what it returns
----------------------------------------
* :class:`Start`: a box of the grid (the sources and their balls, or the whole
  grid for a restart) with flat C-ordered ``T`` (seconds, ``inf`` for unknown)
  and ``state`` (0 = far, 1 = narrow band, 2 = frozen); every node outside the
  box is far. No grid-sized array is needed before the padded one.
* :func:`march` returns the flat arrival times of the ``(nx, ny, nz)`` grid
  (``inf`` where not frozen). Grids over :data:`LEAN_NODES` padded nodes use the
  lean layout: ``V`` in float32 and the result compacted in place in the padded
  time buffer, so a march needs ~12 bytes per node beside the caller's speed.
* Stop nodes are a bit mask over the padded grid (one bit per node).
"""

from __future__ import annotations

import math
import mmap
import threading
import weakref
from typing import NamedTuple

import numpy as np
from llvmlite import ir
from numba.core import cgutils
from numba.cpython.unsafe.numbers import leading_zeros, trailing_zeros
from numba.extending import intrinsic

from .._numba import njit, prange, types
from ..errors import InputError

FAR = np.uint8(0)
BAND = np.uint8(1)
FROZEN = np.uint8(2)

_INF = np.inf

#: The order-2 stencil is used only where the speed at the node and at its two
#: upwind neighbours varies by at most this factor; elsewhere order 1.
ORDER2_MAX_SPEED_RATIO = 2.0
_ORDER2_MAX_W_RATIO = ORDER2_MAX_SPEED_RATIO**2

#: Small hot helpers are inlined at numba IR level (``inline="always"``); larger
#: or cold ones (the seeding pass, the march bodies) are compiled as functions of
#: their own: IR inlining deep-copies the callee per call site, and inlining the
#: whole march into a per-order wrapper cost 4 s of the 7 s compile of a 3D kernel.
_OPT = dict(cache=True, inline="always", error_model="numpy", _nrt=False)
_CALL = dict(cache=True, error_model="numpy", _nrt=False)
_U = np.uint64
_ZERO = _U(0)
_ONE = _U(1)
#: Queue geometry: 8-bit digits; bucket 0 for keys below ``last`` (rounding),
#: then 8 levels of 256 buckets, one sentinel bucket. Against 4-bit digits (16
#: levels of 16), a split sorts its entries 8 bits down at once, so an entry is
#: moved by fewer splits: the one-thread march 4.5-12 % faster on 2048^2 and 160^3,
#: the two-thread march 1-8 % (its windows' queues hold a slab's band only; see
#: docs/performance.md, "The radix queue's digits"). _DIGIT must divide 64 and be
#: a power of two (_LEV).
_DIGIT = _U(8)
_NVAL = _U(1) << _DIGIT
_NOB = _U(64) // _DIGIT * _NVAL + _ONE  # sentinel "no bucket"
_NB = _NOB + _ONE
_NW = (int(_NB) + 63) // 64  # 64-bit words of the bucket occupancy mask
_LOW = _NVAL - _ONE  # a digit's bits
_LEV = _U(int(_DIGIT).bit_length() - 1)  # bit index >> _LEV = the bit's level
#: Slots per block of the entry pool.
BLOCK = 64
_BS = _U(BLOCK)
#: Buckets with at most this many entries are scanned for their minimum
#: (measured best of 8/16/32/48: 16).
SCAN_MAX = _U(16)
#: End of a block list / empty bucket.
_NIL = _U(0xFFFFFFFF)
_KEYMAX = _U(0x7FFFFFFFFFFFFFFF)
#: Free blocks the march keeps in reserve: one split may open a head block in
#: every bucket, and one pop pushes at most 6 entries.
RESERVE_BLOCKS = int(_NB) + 8
#: Largest padded grid the uint32 node indices of the queue can address.
MAX_NODES = 2**32 - 2
#: The plateau mask of a march without one (see :func:`_plateau`).
_NO_BITS = np.zeros(1, dtype=np.uint8)


# ------------------------------------------------------------------ intrinsics
@intrinsic
def _bits(typingctx, x):
    """The IEEE-754 bit pattern of a float64 as a uint64."""
    sig = types.uint64(types.float64)

    def codegen(context, builder, signature, args):
        return builder.bitcast(args[0], ir.IntType(64))

    return sig, codegen


@intrinsic
def _from_bits(typingctx, u):
    """The float64 of an IEEE-754 bit pattern (a uint64)."""
    sig = types.float64(types.uint64)

    def codegen(context, builder, signature, args):
        return builder.bitcast(args[0], ir.DoubleType())

    return sig, codegen


@intrinsic
def _prefetch(typingctx, arr, idx):
    """Prefetch the cache line of ``arr[idx]`` (LLVM ``prefetch``, read, high locality)."""
    sig = types.void(arr, idx)

    def codegen(context, builder, signature, args):
        aryty = signature.args[0]
        ary = context.make_array(aryty)(context, builder, args[0])
        ptr = cgutils.get_item_pointer(context, builder, aryty, ary, [args[1]], wraparound=False)
        i8p = ir.IntType(8).as_pointer()
        i32 = ir.IntType(32)
        fnty = ir.FunctionType(ir.VoidType(), [i8p, i32, i32, i32])
        fn = cgutils.get_or_insert_function(builder.module, fnty, "llvm.prefetch.p0i8")
        builder.call(fn, [builder.bitcast(ptr, i8p), ir.Constant(i32, 0), ir.Constant(i32, 3),
                          ir.Constant(i32, 1)])
        return context.get_dummy_value()

    return sig, codegen


# ----------------------------------------------------------------------- queue
# pool[2 s] = key bits, pool[2 s + 1] = node, slot s = block * BLOCK + i
# nxt[b] = next block after block b in its bucket's list, or in the free list
# bk[2 b] = head block of bucket b (_NIL: empty); bk[2 b + 1] = entries in that head
#   block (the other blocks of a bucket are full); side by side, one line per push
# mw[w] = occupancy bits of buckets 64 w .. 64 w + 63

@njit(**_OPT)
def _bucket(k, last):
    """Bucket of key bits ``k`` relative to ``last``.

    ``1 + 256 * level + digit value`` of the highest 8-bit digit in which ``k``
    differs from ``last``; ``k == last`` goes to level 0 under ``last``'s own
    lowest digit (which no larger key of level 0 has), so every level-0 bucket
    holds a single key value. Keys below ``last`` (rounding) go to bucket 0.
    """
    if k <= last:
        return _ONE + (last & _LOW) if k == last else _ZERO
    lev = (_U(63) - leading_zeros(k ^ last)) >> _LEV
    return _ONE + lev * _NVAL + ((k >> (lev * _DIGIT)) & _LOW)


@njit(**_OPT)
def _push(b, k, c, pool, nxt, bk, mw, nfree, fh, cur):
    """Add the entry (key bits ``k``, node ``c``) to bucket ``b``."""
    cnt = bk[b + b + _ONE]
    if cnt == _BS:  # head block full (or bucket empty): take a free block
        nb = fh
        fh = _U(nxt[nb])
        nfree -= _ONE
        nxt[nb] = bk[b + b]
        bk[b + b] = nb
        cnt = _ZERO
        mw[b >> _U(6)] |= _ONE << (b & _U(63))
        if b < cur:
            cur = b
    slot = _U(bk[b + b]) * _BS + cnt
    pool[slot + slot] = k
    pool[slot + slot + _ONE] = c
    bk[b + b + _ONE] = cnt + _ONE
    return nfree, fh, cur


@njit(**_OPT)
def _remove(p, b, pool, nxt, bk, mw, nfree, fh):
    """Remove slot ``p`` of bucket ``b``: the head block's last entry fills the hole."""
    hb = _U(bk[b + b])
    cnt = _U(bk[b + b + _ONE])
    q = hb * _BS + cnt - _ONE
    pool[p + p] = pool[q + q]
    pool[p + p + _ONE] = pool[q + q + _ONE]
    if cnt == _ONE:
        nx = nxt[hb]
        nxt[hb] = fh
        fh = hb
        nfree += _ONE
        bk[b + b] = nx
        bk[b + b + _ONE] = _BS
        if nx == _NIL:
            mw[b >> _U(6)] &= ~(_ONE << (b & _U(63)))
    else:
        bk[b + b + _ONE] = cnt - _ONE
    return nfree, fh


@njit(**_OPT)
def _pop(T, pool, nxt, bk, mw, nfree, fh, cur, last):
    """Remove the entry with the smallest key; returns its node (``_NIL`` if none)."""
    return _pop_ahead(T, T, pool, nxt, bk, mw, nfree, fh, cur, last, _ZERO, _ZERO, False, False)


@njit(**_OPT)
def _fetch_around(T, V, e, s1, s2, pv):
    """Prefetch the lines of ``T`` and ``V`` that expanding the inner node ``e`` reads:
    ``e`` and its neighbours across the strides ``s1`` (x) and ``s2`` (y; 0 in 2D), the
    nodes two strides away and the diagonal ones (read by the neighbours' updates).
    ``pv``: the speeds ``V`` too (not on a plateau map, whose speeds are mostly not
    read). Every address lies in the arrays (two x strides away is clamped to ``e``)."""
    _prefetch(T, e)
    _prefetch(T, e - s1)
    _prefetch(T, e + s1)
    if pv:
        _prefetch(V, e)
        _prefetch(V, e - s1)
        _prefetch(V, e + s1)
    _prefetch(T, e - s1 - s1 if e >= s1 + s1 else e)
    _prefetch(T, e + s1 + s1 if e + s1 + s1 < _U(T.size) else e)
    if s2 != _ZERO:
        _prefetch(T, e - s2)
        _prefetch(T, e + s2)
        if pv:
            _prefetch(V, e - s2)
            _prefetch(V, e + s2)
        _prefetch(T, e - s2 - s2)
        _prefetch(T, e + s2 + s2)
        _prefetch(T, e - s1 - s2)
        _prefetch(T, e - s1 + s2)
        _prefetch(T, e + s1 - s2)
        _prefetch(T, e + s1 + s2)


@njit(**_OPT)
def _pop_ahead(T, V, pool, nxt, bk, mw, nfree, fh, cur, last, s1, s2, pv, scans):
    """:func:`_pop`, fetching ahead the lines of the nodes popped next.

    With ``s1 > 0`` (the x stride of the padded grid; ``s2`` the y stride in 3D, 0 in
    2D): a scanned bucket's other entries are the next nodes to pop, so the lines their
    expansion reads (:func:`_fetch_around`, ``V`` too if ``pv``) are prefetched while
    the popped node is expanded (the smallest other entry), and so are those of a level-0
    bucket's next entry (one key value: on a uniform map the wave reaches the nodes
    symmetric about a source at one time, far apart in memory; measured 0.80x the time on
    160^3 constant speed order 1, docs/performance.md); a split prefetches the ``T`` of a
    block's nodes before it reads them (the check for outdated entries). Where the front
    is sheared (slow air near terrain, ``docs/performance.md``) consecutive pops lie far
    apart in memory and these lines are cold. ``scans`` False: the level-0 bucket's next pop
    only (the 3D order-1 windows of :mod:`fm2uav.eikonal._parallel`, whose scans' and splits'
    prefetches measured slower). The queue and the popped nodes are those of :func:`_pop`.
    """
    while True:
        if bk[cur + cur] == _NIL:  # also for the sentinel cur == _NOB
            w = _ZERO if cur == _NOB else cur >> _U(6)
            while w < _U(_NW) and mw[w] == _ZERO:
                w += _ONE
            if w == _U(_NW):
                return _NIL, nfree, fh, _NOB, last
            cur = _U(w) * _U(64) + trailing_zeros(mw[w])
        hb = _U(bk[cur + cur])
        cnt = _U(bk[cur + cur + _ONE])
        if cur - _ONE < _NVAL:  # level 0: one key value, take the last entry (LIFO)
            bp = hb * _BS + cnt - _ONE
            c = pool[bp + bp + _ONE]
            if s1 != _ZERO:  # the next pop: the entry below (a full block's last if none)
                if cnt > _ONE:
                    _fetch_around(T, V, pool[bp + bp - _ONE], s1, s2, pv)
                elif nxt[hb] != _NIL:
                    q = _U(nxt[hb]) * _BS + _BS - _ONE
                    _fetch_around(T, V, pool[q + q + _ONE], s1, s2, pv)
            nfree, fh = _remove(bp, cur, pool, nxt, bk, mw, nfree, fh)
            return c, nfree, fh, cur, last
        if cur == _ZERO or (nxt[hb] == _NIL and cnt <= SCAN_MAX):
            # exact minimum by a scan; bucket 0 (keys below last) may span blocks
            bp = hb * _BS
            m = pool[bp + bp]
            b = hb
            while True:
                base = b * _BS
                for p in range(base, base + cnt):
                    kk = pool[p + p]
                    if kk < m:
                        m = kk
                        bp = p
                b = _U(nxt[b])
                if b == _NIL:
                    break
                cnt = _BS
            c = pool[bp + bp + _ONE]
            if scans and s1 != _ZERO and cur != _ZERO:  # one block: the next pop
                base = hb * _BS
                m2 = _KEYMAX
                p2 = bp
                for p in range(base, base + _U(bk[cur + cur + _ONE])):
                    kk = pool[p + p]
                    if kk < m2 and p != bp:
                        m2 = kk
                        p2 = p
                if p2 != bp:
                    _fetch_around(T, V, pool[p2 + p2 + _ONE], s1, s2, pv)
            nfree, fh = _remove(bp, cur, pool, nxt, bk, mw, nfree, fh)
            return c, nfree, fh, cur, last
        # split one digit level down, relative to the bucket's lower bound: every
        # key of the bucket shares the digits above this level with last and has
        # this digit's value, so the lower bound is <= all of them and > last
        lev = (cur - _ONE) // _NVAL
        dig = cur - _ONE - lev * _NVAL
        hsh = (lev + _ONE) * _DIGIT
        hi = _ZERO if hsh >= _U(64) else (last >> hsh) << hsh
        last = hi | (dig << (lev * _DIGIT))
        bk[cur + cur] = _NIL
        bk[cur + cur + _ONE] = _BS
        mw[cur >> _U(6)] &= ~(_ONE << (cur & _U(63)))
        cur = _NOB
        b = hb
        while True:
            base = b * _BS
            if scans and s1 != _ZERO:
                for p in range(base, base + cnt):
                    _prefetch(T, pool[p + p + _ONE])
            for p in range(base, base + cnt):
                kk = pool[p + p]
                e = pool[p + p + _ONE]
                if _bits(-T[e]) == kk:  # drop outdated entries (frozen node, or a newer key)
                    nfree, fh, cur = _push(_bucket(kk, last), kk, e, pool, nxt, bk, mw, nfree,
                                           fh, cur)
            nb = _U(nxt[b])
            nxt[b] = fh
            fh = b
            nfree += _ONE
            if nb == _NIL:
                break
            b = nb
            cnt = _BS


# slots of the march's resumable scalar state ``st`` (uint64)
_PHASE = 0   # 0 seeding the band, 1 expanding frozen-on-entry nodes, 2 popping, 3 done
_SCAN = 1    # cursor of phases 0 and 1
_NFREE = 2   # free blocks
_FH = 3      # head of the free-block list
_CUR = 4     # lowest possibly non-empty bucket
_LAST = 5    # lower bound of every key in the queue (bits)
_FROZEN = 6  # nodes frozen by the march
_NSTOP = 7   # stop nodes not frozen yet (0: no stop set)
_BEGIN = 8   # phases 0 and 1 scan [st[_BEGIN], st[_END]) (the start box; _END 0: all)
_END = 9     # (set by march(); init_queue leaves these two slots alone)
ST_SIZE = 10


@njit(cache=True, error_model="numpy", _nrt=False)
def init_queue(nxt, bk, mw, st):
    """Empty queue: every block in the free list, every bucket empty; ``st`` reset."""
    nblk = nxt.size
    for b in range(nblk - 1):
        nxt[b] = b + 1
    nxt[nblk - 1] = _NIL
    for b in range(_NB):
        bk[b + b] = _NIL
        bk[_U(b) + _U(b) + _ONE] = _BS
    for w in range(_NW):
        mw[w] = _ZERO
    st[_PHASE] = 0
    st[_SCAN] = 0
    st[_NFREE] = nblk
    st[_FH] = 0
    st[_CUR] = _NOB
    st[_LAST] = 0
    st[_FROZEN] = 0




# ------------------------------------------------------------------ local solver
@njit(**_OPT)
def _axis_term(T, V, c, s, ih2, order):
    """Upwind term of one axis: returns ``(tau, a)`` for ``a (T - tau)^2``.

    :func:`_axis_term_u` without a plateau mask (see there).
    """
    return _axis_term_u(T, V, _NO_BITS, False, c, s, ih2, order)


@njit(**_OPT)
def _at_plateau(U, c):
    """Whether node ``c`` has the plateau's speed: bit ``c`` of the plateau mask ``U``;
    every node of a uniform grid (a mask of one byte, :func:`_plateau`)."""
    if U.size == 1:
        return True
    return (U[c >> _U(3)] >> (c & _U(7))) & _ONE != _ZERO


@njit(**_OPT)
def _rhs(V, U, use_u, qp, c):
    """``V[c]`` (``1 / speed^2``), read from the plateau value ``qp`` where the mask says so."""
    if use_u and _at_plateau(U, c):
        return qp
    return V[c] + 0.0  # float64 also in the lean (float32) layout


@njit(**_OPT)
def _axis_term_u(T, V, U, use_u, c, s, ih2, order):
    """Upwind term of one axis: returns ``(tau, a)`` for ``a (T - tau)^2``.

    ``T`` is the padded, state-folded time array, ``V`` the padded ``1 /
    speed^2`` [s^2/m^2] (see :func:`pad_grid`).

    ``a = 0`` (and ``tau = inf``) when no neighbour on this axis is frozen (the
    smaller of the two frozen ones is used; the minus side wins a tie).
    Second order, ``a = 9/(4h^2)`` and ``tau = (4 T1 - T2)/3``, is used when the
    next node in the same upwind direction is frozen, not later than T1, and
    the speed along the three nodes varies by at most ``ORDER2_MAX_SPEED_RATIO``
    (the stencil assumes T smooth: across a sharp speed jump, e.g. a thin slow
    wall, it would charge only 2/3 of the crossing time).
    """
    a = T[c - s]
    b = T[c + s]
    if not a >= 0.0:  # band, far, wall or ghost (NaN)
        a = _INF
    if not b >= 0.0:
        b = _INF
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
    return _upwind_term(T, V, U, use_u, c, best, c1, c2, ih2, order)


@njit(**_OPT)
def _upwind_term(T, V, U, use_u, c, best, c1, c2, ih2, order):
    """The term of node ``c``'s axis whose frozen upwind neighbour ``c1`` has the time
    ``best``, ``c2`` the next node beyond it: ``(tau, a)`` as :func:`_axis_term_u`.

    The march's far-neighbour shortcut calls it directly: a far node's only frozen
    neighbour is the node just frozen, so the axis's other side needs no read.
    """
    if order == 2:
        t2 = T[c2]  # c1 is a frozen (inner) node, so c2 is at worst a ghost
        if t2 >= 0.0 and t2 <= best:
            if use_u and _at_plateau(U, c) and _at_plateau(U, c1) and _at_plateau(U, c2):
                return (4.0 * best - t2) / 3.0, 2.25 * ih2  # one speed: the ratio is 1
            # V holds 1 / speed^2: the speed ratio is at most R where the ratio of
            # these is at most R^2 (exact for R = 2: powers of two scale exactly)
            w0 = V[c]
            w1 = V[c1]
            w2 = V[c2]
            wmax = max(w0, max(w1, w2))
            wmin = min(w0, min(w1, w2))
            if wmax <= _ORDER2_MAX_W_RATIO * wmin:
                return (4.0 * best - t2) / 3.0, 2.25 * ih2
    return best, ih2


@njit(**_OPT)
def _combine(ta, aa, tb, ab, tc, ac, rhs):
    """Solve ``sum_m a_m (T - tau_m)^2 = rhs`` using the upwind axes in order.

    Axes are sorted by ``tau``; an axis joins only while the solution is later
    than its ``tau`` (causality) and the discriminant stays non-negative.

    The quadratic is solved for ``s = T - tau_1`` (the earliest axis's time), in the
    differences ``d_m = tau_m - tau_1``: its coefficients are of the size of ``rhs``, not of
    ``T^2``. In ``T`` itself the discriminant ``B^2 - A (C - rhs)`` cancels terms of size
    ``a T^2`` down to one of size ``a rhs``, losing about ``T^2 / (h / speed)^2`` ulps: at
    ``T = 150 s`` on a 0.68 x 0.80 m grid the time came out 1.4e-12 s *lower* from an upwind
    time 2.6e-12 s *higher* (not monotone), and the parallel march, whose repairs update
    nodes in another order, differed from the serial one by up to 1.4e-11 relative on
    2048^2 (FM²-shaped, order 1, spacing 1 x 0.7). Shifted, the time is within a few ulps of
    the exact root (tests/eikonal/test_kernels_update.py) and the two marches agreed bit for
    bit on 2048^2 and 160^3 (7 December 2026).
    """
    # sort the three (tau, a) pairs by tau (tiny network)
    if tb < ta:
        ta, tb = tb, ta
        aa, ab = ab, aa
    if tc < tb:
        tb, tc = tc, tb
        ab, ac = ac, ab
        if tb < ta:
            ta, tb = tb, ta
            aa, ab = ab, aa
    if aa == 0.0:
        return _INF
    t = ta + math.sqrt(rhs / aa)
    if ab == 0.0 or t <= tb:
        return t
    # in s = T - ta: A s^2 - 2 B s + C - rhs = 0 with B, C the sums of a d and a d^2
    db = tb - ta
    A = aa + ab
    B = ab * db
    C = B * db
    disc = B * B - A * (C - rhs)
    if disc < 0.0:
        return t
    t = ta + (B + math.sqrt(disc)) / A
    if ac == 0.0 or t <= tc:
        return t
    dc = tc - ta
    A3 = A + ac
    B3 = B + ac * dc
    C3 = C + ac * dc * dc
    disc = B3 * B3 - A3 * (C3 - rhs)
    if disc < 0.0:
        return t
    return ta + (B3 + math.sqrt(disc)) / A3


@njit(**_OPT)
def _side_min(T, c, s):
    """Order 1: the smaller frozen neighbour time of node ``c`` along one axis (inf if none)."""
    a = T[c - s]
    b = T[c + s]
    a = a if a >= 0.0 else _INF  # band, far, wall or ghost (NaN)
    b = b if b >= 0.0 else _INF
    return min(a, b)


@njit(**_OPT)
def _solve_iso(a, b, c, q):
    """Order-1 update with the same spacing on every axis: ``sum (T - tau)^2 = q``.

    ``q = h^2 / speed^2``; ``a, b, c`` the axes' upwind times (inf: none). The same
    causal rule as :func:`_combine` (an axis joins while the solution is later than its
    time), with the equal weights folded in: the one-axis solution ``a + sqrt(q)`` stands
    when ``(b - a)^2 >= q``, the two-axis one ``a + (b - a + sqrt(2q - (b - a)^2)) / 2`` when
    it is not later than ``c``, else the three-axis one, solved in ``T - a``. One square root
    per update and no division (measured -12 % on 2048^2 order 1 constant speed, -7 % on an
    FM²-shaped map).
    """
    if b < a:
        a, b = b, a
    if c < b:
        b, c = c, b
        if b < a:
            a, b = b, a
    if a == _INF:
        return _INF
    d = b - a
    if d * d >= q:  # also for b = inf
        return a + math.sqrt(q)
    t = a + 0.5 * (d + math.sqrt(q + q - d * d))
    if t <= c:
        return t
    # three axes in s = T - a, as :func:`_combine` (in T the discriminant cancelled terms
    # of size T^2 down to one of size q: on 160^3 FM²-shaped order 1 the parallel march's
    # repairs, which update nodes in another order, then differed from the serial march by
    # up to 5.5e-13 relative)
    e = c - a
    s = d + e
    disc = s * s - 3.0 * (d * d + e * e - q)
    if disc < 0.0:
        return t
    return a + (s + math.sqrt(disc)) / 3.0


@njit(**_OPT)
def _fetch_rows(T, V, c, s, n, pv):
    """Prefetch the lines of ``T`` (and ``V`` if ``pv``) one row away from node ``c`` across
    the x stride ``s``, and of ``T`` two rows away (clamped to ``c`` at the ends of the
    ``n`` elements): what freezing ``c`` will read in a 2D march (across x in 3D)."""
    _prefetch(T, c - s)
    _prefetch(T, c + s)
    if pv:
        _prefetch(V, c - s)
        _prefetch(V, c + s)
    _prefetch(T, c - s - s if c >= s + s else c)
    _prefetch(T, c + s + s if c + s + s < n else c)


@njit(**_OPT)
def _earlier_band(T, c, s, t):
    """Whether a neighbour of node ``c`` across the stride ``s`` is in the band with a
    time below ``t`` (far nodes, ``-inf``, and walls or ghosts, NaN, are not)."""
    a = T[c - s]
    b = T[c + s]
    return (a < 0.0 and -a < t) or (b < 0.0 and -b < t)


@njit(**_OPT)
def _earlier_band3(T, c, k, sx, sy, sz, t):
    """Whether a neighbour of node ``c`` of a 3D grid (strides ``sx``, ``sy``, ``sz``) across
    the two axes other than neighbour ``k``'s (0, 1: x; 2, 3: y; 4, 5: z) is in the band
    with a time below ``t`` (:func:`_earlier_band`)."""
    if k < 2:
        return _earlier_band(T, c, sy, t) or _earlier_band(T, c, sz, t)
    if k < 4:
        return _earlier_band(T, c, sx, t) or _earlier_band(T, c, sz, t)
    return _earlier_band(T, c, sx, t) or _earlier_band(T, c, sy, t)


@njit(**_OPT)
def _relax(T, V, c, t, last, pool, nxt, bk, mw, nfree, fh, cur, pf1, pf2, n, pv=True):
    """Lower the band/far node ``c`` to ``t`` if that is smaller and queue it; a band node
    that ``t`` does not lower is queued again at its time.

    A lowered band node gets a new entry; its old one (a larger key) stays in
    the queue and is skipped when popped (the node is frozen by then). A band node
    not lowered is queued again because it may have no entry: a far node reached
    first while a band neighbour across another axis is earlier gets its time but no
    entry (**deferred**, see the march kernels); that neighbour is frozen first and
    updates it, and this is where the node is queued then if the update did not lower
    it (rare: 0.2 % of the updates on 2048^2 FM²-shaped order 1; an entry that turns out
    to be a second one at the same key is skipped as outdated).
    A new band node of a 2D march (``pf2 == 0``) gets the lines its expansion will read
    prefetched (:func:`_fetch_rows`), ``V`` too if ``pv`` (not on a plateau, whose speeds are
    not read); a 3D march (``pf2`` its y stride) prefetches none: its band is wide, the lines
    were evicted before the node froze (measured 0.98x without them on 160^3
    FM²-shaped order 1).
    """
    x = T[c]
    if t < -x:
        T[c] = -t
        k = _bits(t)
        if x == -_INF and pf2 == _ZERO:
            # a new band node: when it is frozen, the march reads the nodes up to
            # two rows away across x; fetch those lines now.
            # Measured: -10 % (one row), -12 % more (two rows) on 2048^2.
            _fetch_rows(T, V, c, pf1, n, pv)
    elif x > -_INF:
        k = _bits(-x)
    else:  # a far node that t does not reach (t = inf: 1 / speed^2 overflows)
        return nfree, fh, cur
    return _push(_bucket(k, last), k, c, pool, nxt, bk, mw, nfree, fh, cur)


@njit(**_CALL)
def _seed(T, n, step, pool, nxt, bk, mw, st):
    """Phase 0: queue the band nodes given on entry, every ``step``-th element of ``T``
    from ``st[_SCAN]`` up to ``n`` (2 in the interleaved layout, whose other elements are
    speeds, unset beside the ghosts). False if the pool ran low."""
    nfree = _U(st[_NFREE])
    fh = _U(st[_FH])
    cur = _U(st[_CUR])
    last = _U(st[_LAST])
    c = _U(st[_SCAN])
    ok = True
    while c < n:
        if nfree < _U(RESERVE_BLOCKS):
            ok = False
            break
        x = T[c]
        if x < 0.0 and x > -_INF:
            k = _bits(-x)
            nfree, fh, cur = _push(_bucket(k, last), k, c, pool, nxt, bk, mw, nfree, fh, cur)
        c += step
    st[_SCAN] = c
    st[_NFREE] = nfree
    st[_FH] = fh
    st[_CUR] = cur
    return ok


# One compiled kernel per (dimension, order), each compiled on first use: the
# order is a closure constant of the kernel, so its order-2 branches fold away
# (measured -7 % on 2048^2 order 1) without a wrapper that inlines the march.
_KERNEL = dict(cache=True, nogil=True, error_model="numpy", _nrt=False)


def _kernel(march, name):
    """Jit ``march`` under its own name (its own cache index file)."""
    march.__name__ = march.__qualname__ = name
    return njit(**_KERNEL)(march)


def _march2d_kernel(order, pairs=False):
    """The compiled 2D march of one order (1 or 2); ``pairs``: of the interleaved layout
    only (``unit`` 2 a constant of the kernel, no plateau register; see :func:`march`)."""

    def march(T, V, U, qp, nx, ny, unit, ihx2, ihy2, stop, pool, nxt, bk, mw, st):
        """March a padded 2D grid ``(nx, ny)`` (ghost ring included) in place.

        ``unit`` is the distance of two consecutive nodes in ``T`` and ``V`` (elements):
        1 for the separate arrays of :func:`_work_pair`, 2 for the **interleaved** layout
        (:func:`_work_interleaved`: ``T = buf``, ``V = buf[1:]``, node ``c``'s time at
        ``buf[2 c]`` and its ``1 / speed^2`` beside it, in the same cache line). Node
        indices (queue entries, ``st``) are element indices of ``T``.

        ``U`` is the plateau mask (bit ``c & 7`` of ``U[c >> 3]``: node ``c`` has the
        speed whose ``V`` is ``qp``; :func:`plateau_bits`), ``qp = 0`` for none; the
        interleaved layout reads every speed (a uniform map marches in the separate one).

        Resumable: returns 0 when done, 1 when fewer than ``RESERVE_BLOCKS`` free
        blocks are left (the caller grows the pool and calls again with the same
        ``st``). Bit ``c & 7`` of ``stop[c >> 3]`` marks stop nodes (1-element array when unused;
        ``st[_NSTOP]`` counts those not frozen yet, 0 = no stop set).
        """
        one = _U(2) if pairs else _U(unit)
        n = _U(nx) * _U(ny) * one
        sx = _U(ny) * one
        node = one >> _ONE  # element index >> node = node index (stop mask)
        end = _U(st[_END]) if st[_END] != _ZERO else n
        use_u = qp > 0.0 and one == _ONE
        pv = one == _ONE  # prefetch V apart from T (interleaved: the same lines)
        # order 1 on equal spacings: the cheaper update (_solve_iso)
        iso = order == 1 and ihx2 == ihy2
        hh = 1.0 / ihx2
        if st[_PHASE] == 0:
            if not _seed(T, end, one, pool, nxt, bk, mw, st):
                return 1
            st[_PHASE] = 1
            st[_SCAN] = st[_BEGIN]
        scan = _U(st[_SCAN])
        nfree = _U(st[_NFREE])
        fh = _U(st[_FH])
        cur = _U(st[_CUR])
        last = _U(st[_LAST])
        frozen = _U(st[_FROZEN])
        n_stop = _U(st[_NSTOP])
        use_stop = n_stop != _ZERO
        phase = st[_PHASE]
        status = 0
        while True:
            if nfree < _U(RESERVE_BLOCKS):
                status = 1
                break
            if phase == 1:  # expand the nodes frozen on entry, in index order
                if scan < end:
                    c = scan
                    scan += one
                    if not T[c] >= 0.0:
                        continue
                else:
                    phase = 2
                    continue
            else:
                c, nfree, fh, cur, last = _pop(T, pool, nxt, bk, mw, nfree, fh, cur, last)
                if c == _NIL:
                    phase = 3
                    break
                if not T[c] < 0.0:  # an outdated entry of a node frozen already
                    continue
                T[c] = -T[c]
                frozen += _ONE
                if use_stop:
                    cs = c >> node
                    if (stop[cs >> _U(3)] >> (cs & _U(7))) & _ONE != _ZERO:
                        n_stop -= _ONE
                        if n_stop == _ZERO:
                            phase = 3
                            break
            tc = T[c]
            pvc = pv and not (use_u and _at_plateau(U, c))
            # one relax site for the four neighbours (unrolled by hand: 4x the
            # compile time, 17 s instead of 4.5 s, for no measurable speed)
            for k in range(4):
                s = sx if k < 2 else one
                nb = c - s if k & 1 == 0 else c + s
                x = T[nb]
                if x < 0.0:
                    q = _rhs(V, U, use_u, qp, nb)
                    if x == -_INF and phase == 2:
                        # a far node while popping: c is its only frozen neighbour (every
                        # frozen node has queued its neighbours), so the update is the
                        # one-axis solution along c's axis, as the full update gives it
                        ih2 = ihx2 if k < 2 else ihy2
                        if iso:
                            t = tc + math.sqrt(q * hh)
                        elif order == 1:
                            t = tc + math.sqrt(q / ih2)
                        else:  # c2: the node beyond c (nb's other side is not frozen)
                            c2 = c + s if k & 1 == 0 else c - s
                            ta, aa = _upwind_term(T, V, U, use_u, nb, tc, c, c2, ih2, order)
                            t = ta + math.sqrt(q / aa)
                        if _earlier_band(T, nb, one if k < 2 else sx, t):
                            # deferred: that neighbour is frozen first and queues nb
                            # (_relax); fetch the lines as for a new band node
                            T[nb] = -t
                            _fetch_rows(T, V, nb, sx, n, pvc)
                            continue
                    elif iso:
                        t = _solve_iso(_side_min(T, nb, sx), _side_min(T, nb, one), _INF,
                                       q * hh)
                    else:
                        ta, aa = _axis_term_u(T, V, U, use_u, nb, sx, ihx2, order)
                        tb, ab = _axis_term_u(T, V, U, use_u, nb, one, ihy2, order)
                        t = _combine(ta, aa, tb, ab, _INF, 0.0, q)
                    nfree, fh, cur = _relax(T, V, nb, t, last, pool, nxt, bk, mw, nfree, fh, cur,
                                            sx, _ZERO, n, pvc)
        st[_PHASE] = phase
        st[_SCAN] = scan
        st[_NFREE] = nfree
        st[_FH] = fh
        st[_CUR] = cur
        st[_LAST] = last
        st[_FROZEN] = frozen
        st[_NSTOP] = n_stop
        return status

    return _kernel(march, f"march2d_o{order}" + ("_pairs" if pairs else ""))


def _march3d_kernel(order):
    """The compiled 3D march of one order (1 or 2); as :func:`_march2d_kernel`."""

    def march(T, V, U, qp, nx, ny, nz, unit, ihx2, ihy2, ihz2, stop, pool, nxt, bk, mw, st):
        """March a padded 3D grid ``(nx, ny, nz)`` in place; as :func:`_march2d`
        (``unit`` 2: the interleaved layout, node ``c``'s time at ``T[c]`` and its
        ``1 / speed^2`` at ``V[c] = T[c + 1]``, without a plateau register)."""
        one = _U(unit)
        n = _U(nx) * _U(ny) * _U(nz) * one
        sx = _U(ny) * _U(nz) * one
        sy = _U(nz) * one
        node = one >> _ONE  # element index >> node = node index (stop mask)
        end = _U(st[_END]) if st[_END] != _ZERO else n
        use_u = qp > 0.0 and one == _ONE
        sep = one == _ONE  # prefetch V apart from T (interleaved: the same lines)
        iso = order == 1 and ihx2 == ihy2 and ihy2 == ihz2
        hh = 1.0 / ihx2
        if st[_PHASE] == 0:
            if not _seed(T, end, one, pool, nxt, bk, mw, st):
                return 1
            st[_PHASE] = 1
            st[_SCAN] = st[_BEGIN]
        scan = _U(st[_SCAN])
        nfree = _U(st[_NFREE])
        fh = _U(st[_FH])
        cur = _U(st[_CUR])
        last = _U(st[_LAST])
        frozen = _U(st[_FROZEN])
        n_stop = _U(st[_NSTOP])
        use_stop = n_stop != _ZERO
        phase = st[_PHASE]
        status = 0
        while True:
            if nfree < _U(RESERVE_BLOCKS):
                status = 1
                break
            if phase == 1:
                if scan < end:
                    c = scan
                    scan += one
                    if not T[c] >= 0.0:
                        continue
                else:
                    phase = 2
                    continue
            else:
                c, nfree, fh, cur, last = _pop_ahead(T, V, pool, nxt, bk, mw, nfree, fh, cur, last,
                                                     sx, sy, sep and not use_u, True)
                if c == _NIL:
                    phase = 3
                    break
                if not T[c] < 0.0:  # an outdated entry of a node frozen already
                    continue
                T[c] = -T[c]
                frozen += _ONE
                cs = c >> node
                if use_stop and (stop[cs >> _U(3)] >> (cs & _U(7))) & _ONE != _ZERO:
                    n_stop -= _ONE
                    if n_stop == _ZERO:
                        phase = 3
                        break
            tcur = T[c]
            for k in range(6):
                s = sx if k < 2 else (sy if k < 4 else one)
                nb = c - s if k & 1 == 0 else c + s
                x = T[nb]
                if x < 0.0:
                    q = _rhs(V, U, use_u, qp, nb)
                    if x == -_INF and phase == 2:
                        # a far node while popping: c is its only frozen neighbour, the
                        # one-axis solution along s (as in 2D; the same numbers)
                        if iso:
                            t = tcur + math.sqrt(q * hh)
                        else:
                            ih2 = ihx2 if k < 2 else (ihy2 if k < 4 else ihz2)
                            if order == 1:
                                t = tcur + math.sqrt(q / ih2)
                            else:  # c2: the node beyond c (as in 2D)
                                c2 = c + s if k & 1 == 0 else c - s
                                ta, aa = _upwind_term(T, V, U, use_u, nb, tcur, c, c2, ih2,
                                                      order)
                                t = ta + math.sqrt(q / aa)
                        if _earlier_band3(T, nb, k, sx, sy, one, t):  # deferred (as in 2D)
                            T[nb] = -t
                            continue
                    elif iso:
                        t = _solve_iso(_side_min(T, nb, sx), _side_min(T, nb, sy),
                                       _side_min(T, nb, one), q * hh)
                    else:
                        ta, aa = _axis_term_u(T, V, U, use_u, nb, sx, ihx2, order)
                        tb, ab = _axis_term_u(T, V, U, use_u, nb, sy, ihy2, order)
                        tc, ac = _axis_term_u(T, V, U, use_u, nb, one, ihz2, order)
                        t = _combine(ta, aa, tb, ab, tc, ac, q)
                    nfree, fh, cur = _relax(T, V, nb, t, last, pool, nxt, bk, mw, nfree, fh, cur,
                                            sx, sy, n)
        st[_PHASE] = phase
        st[_SCAN] = scan
        st[_NFREE] = nfree
        st[_FH] = fh
        st[_CUR] = cur
        st[_LAST] = last
        st[_FROZEN] = frozen
        st[_NSTOP] = n_stop
        return status

    return _kernel(march, f"march3d_o{order}")


march2d_o1 = _march2d_kernel(1)
march2d_o2 = _march2d_kernel(2)
#: The interleaved layout's 2D marches: its ``unit`` (2) a constant, so its strides,
#: offsets and the plateau's branches fold away (measured -2.5 % on 2048^2 FM²-shaped
#: order 1, docs/performance.md).
march2d_o1_pairs = _march2d_kernel(1, True)
march2d_o2_pairs = _march2d_kernel(2, True)
march3d_o1 = _march3d_kernel(1)
march3d_o2 = _march3d_kernel(2)


@njit(cache=True, error_model="numpy", _nrt=False)
def pad_grid(speed, Tb, sb, i0, j0, k0, bx, by, bz, nx, ny, nz, Tp, Vp):
    """Fill the padded grid with state folded into T, from the speed and a start box.

    ``Vp`` gets ``1 / speed^2`` [s^2/m^2], the right-hand side of the local
    solver (one division per node here instead of one per update), in its own
    dtype (float64, or float32 in the lean layout).

    ``nz == 1`` gives the 2D layout ``(nx + 2, ny + 2)``, else ``(nx + 2, ny + 2,
    nz + 2)``. Nodes of the box ``[i0, i0 + bx) x [j0, j0 + by) x [k0, k0 + bz)``
    take their time and state from ``Tb``/``sb`` (flat, C order of the box):
    frozen nodes keep ``T``; band nodes get ``-T`` (a band node with ``T = 0``
    counts as frozen: nothing can lower it). Every other node is far (``-inf``);
    speed-0 nodes that are not frozen, and the ghosts, are ``NaN``. The ghosts'
    speeds are never read and stay unset.
    """
    _pad_ghost_slabs(nx, ny, nz, Tp)
    for i in range(nx):
        _pad_slab(speed, Tb, sb, i0, j0, k0, bx, by, bz, i, ny, nz, Tp, Vp)


@njit(cache=True, error_model="numpy", parallel=True)
def pad_grid_parallel(nth, speed, Tb, sb, i0, j0, k0, bx, by, bz, nx, ny, nz, Tp, Vp):
    """:func:`pad_grid` on ``nth`` threads, thread ``t`` the ``t``-th share of the
    x-slabs (the same values: every node is written once, from its own speed). On a
    1000 x 1000 x 40 grid most of its time is the first touch of the fresh padded
    buffers (page faults), which the threads take in parallel too."""
    _pad_ghost_slabs(nx, ny, nz, Tp)
    for t in prange(nth):
        for i in range(t * nx // nth, (t + 1) * nx // nth):
            _pad_slab(speed, Tb, sb, i0, j0, k0, bx, by, bz, i, ny, nz, Tp, Vp)


@njit(cache=True, error_model="numpy", _nrt=False, inline="always")
def _pad_ghost_slabs(nx, ny, nz, Tp):
    """The ghost slabs ``i = -1`` and ``i = nx`` of :func:`pad_grid` (NaN)."""
    row = (ny + 2) * (1 if nz == 1 else nz + 2)  # one padded x-slab
    for c in range(row):
        Tp[c] = np.nan
        Tp[(nx + 1) * row + c] = np.nan


@njit(cache=True, error_model="numpy", _nrt=False, inline="always")
def _pad_slab(speed, Tb, sb, i0, j0, k0, bx, by, bz, i, ny, nz, Tp, Vp):
    """The x-slab ``i`` of :func:`pad_grid`, its ghost rows included."""
    two = nz == 1
    pz = 1 if two else nz + 2
    py = ny + 2
    slab = (i + 1) * py * pz
    for c in range(pz):  # ghost rows j = -1 and j = ny
        Tp[slab + c] = np.nan
        Tp[slab + (ny + 1) * pz + c] = np.nan
    in_i = i0 <= i < i0 + bx
    if two:  # one run of ny nodes per x-slab
        if in_i:
            _pad_row(speed, Tb, sb, i * ny, (i - i0) * by, slab + 1, ny, j0, by, Tp, Vp)
        else:
            _far_run(speed, i * ny, slab + 1, ny, Tp, Vp)
        return
    for j in range(ny):
        src = (i * ny + j) * nz
        dst = slab + (j + 1) * pz
        Tp[dst] = np.nan  # ghost nodes k = -1 and k = nz
        Tp[dst + nz + 1] = np.nan
        if in_i and j0 <= j < j0 + by:
            _pad_row(speed, Tb, sb, src, ((i - i0) * by + j - j0) * bz, dst + 1, nz,
                     k0, bz, Tp, Vp)
        else:
            _far_run(speed, src, dst + 1, nz, Tp, Vp)


@njit(cache=True, error_model="numpy", _nrt=False)
def _pad_row(speed, Tb, sb, src, b, dst, m, lo, width, Tp, Vp):
    """One row of ``m`` nodes crossing the start box on ``[lo, lo + width)``."""
    _far_run(speed, src, dst, lo, Tp, Vp)
    _box_run(speed, Tb, sb, src + lo, b, dst + lo, width, Tp, Vp)
    _far_run(speed, src + lo + width, dst + lo + width, m - lo - width, Tp, Vp)


@njit(cache=True, error_model="numpy", _nrt=False)
def _far_run(speed, src, dst, m, Tp, Vp):
    """``m`` consecutive far nodes (selects only: the loop vectorises; measured
    10 -> 3 ms on 2048^2)."""
    for k in range(m):
        v = speed[src + k]
        Tp[dst + k] = -_INF if v > 0.0 else np.nan
        Vp[dst + k] = 1.0 / (v * v)  # inf for v = 0, never read


@njit(cache=True, error_model="numpy", _nrt=False)
def _box_run(speed, Tb, sb, src, b, dst, m, Tp, Vp):
    """``m`` consecutive nodes of the start box (box index ``b`` on)."""
    for k in range(m):
        s = sb[b + k]
        v = speed[src + k]
        t = Tb[b + k]
        band = -t if t > 0.0 else t
        other = band if s == 1 else -_INF
        other = np.nan if v <= 0.0 else other
        Tp[dst + k] = t if s == 2 else other
        Vp[dst + k] = 1.0 / (v * v)


@njit(cache=True, error_model="numpy", _nrt=False)
def unpad_grid(Tp, nx, ny, nz, T):
    """Write the march's result back: frozen times, ``inf`` everywhere else."""
    two = nz == 1
    pz = 1 if two else nz + 2
    py = ny + 2
    for i in range(nx):
        if two:  # one run of ny nodes per x-slab (the loop vectorises)
            src = (i + 1) * py + 1
            dst = i * ny
            for k in range(ny):
                x = Tp[src + k]
                T[dst + k] = x if x >= 0.0 else _INF
            continue
        for j in range(ny):
            dst = (i * ny + j) * nz
            src = ((i + 1) * py + j + 1) * pz + 1
            for k in range(nz):
                x = Tp[src + k]
                T[dst + k] = x if x >= 0.0 else _INF


def _readonly(a):
    """A read-only view of ``a``: numba compiles one specialisation per writeable
    flag, and the planner's arrays (cached on the world) are read-only, so every
    caller passes read-only input arrays and each kernel compiles once."""
    if not a.flags.writeable:
        return a
    v = a.view()
    v.flags.writeable = False
    return v


class Start(NamedTuple):
    """Where a march starts: a box of the grid with the times and states of its nodes.

    Every node outside the box is far. :func:`fm2uav.eikonal.fast_marching`
    passes the box around its sources (the source ball), a restart the whole
    grid (:meth:`whole`).

    Attributes
    ----------
    lo : tuple of 3 int
        Node indices of the box's first corner.
    shape : tuple of 3 int
        Box shape (``1`` on the third axis of a 2D grid).
    T : ndarray, float64, shape (prod(shape),)
        Times [s] of the box nodes (flat, C order): values of frozen/band
        nodes, ``inf`` elsewhere.
    state : ndarray, uint8, shape (prod(shape),)
        0 far, 1 band, 2 frozen. Band nodes must carry a finite ``T``.
    """

    lo: tuple[int, int, int]
    shape: tuple[int, int, int]
    T: np.ndarray
    state: np.ndarray

    @classmethod
    def whole(cls, T, state, shape3):
        """The start of a march over the whole grid ``shape3`` (flat ``T``/``state``)."""
        return cls((0, 0, 0), tuple(int(n) for n in shape3), T, state)

    def frozen_times(self, shape3):
        """Flat times of the grid ``shape3`` with only the box's frozen nodes set (``inf`` elsewhere)."""
        T = np.full(int(np.prod(shape3)), np.inf)
        box = T.reshape(shape3)[tuple(slice(a, a + n) for a, n in zip(self.lo, self.shape))]
        box[...] = np.where(self.state == FROZEN, self.T, np.inf).reshape(self.shape)
        return T

    def frozen_at(self, cells):
        """Which of the grid nodes ``cells`` (int array (m, 3)) are frozen in the box."""
        lo = np.asarray(self.lo)
        rel = np.asarray(cells, dtype=np.int64).reshape(-1, 3) - lo
        inside = np.all((rel >= 0) & (rel < np.asarray(self.shape)), axis=1)
        out = np.zeros(len(rel), dtype=bool)
        if inside.any():
            flat = np.ravel_multi_index(tuple(rel[inside].T), self.shape)
            out[inside] = self.state[flat] == FROZEN
        return out


#: Grids of more padded nodes than this march in the **lean** layout: ``V`` in
#: float32 (half the memory of the speed copy; ``1 / speed^2`` rounded to 24
#: bits, so the times differ from the float64 layout by a relative ~1e-8, far
#: below the scheme's own error) and the result compacted in place in the padded
#: time buffer instead of copied to a new array. On a 1000 x 1000 x 40 grid that
#: is 0.5 GB instead of 1.0 GB beside the caller's speed map. Smaller grids use
#: float64 throughout (the arrival times of every small case are exact to
#: round-off, as the tests check) and keep their buffers for the next march.
LEAN_NODES = 2**25


def march(speed, start, shape3, h3, order, stop_cells, *, lean=None, interleave=None,
          threads=1, span=None):
    """Run the Fast Marching Method from ``start``; returns the arrival times.

    Parameters
    ----------
    speed : ndarray, float64, shape (nx*ny*nz,)
        Propagation speed [m/s]; nodes with 0 are never entered.
    start : Start
        The initial frozen/band nodes (a box of the grid).
    shape3 : tuple of 3 int
        Grid shape ``(nx, ny, nz)`` (``nz = 1`` for 2D).
    h3 : tuple of 3 float
        Spacing per axis [m].
    order : int
        1 or 2.
    stop_cells : ndarray, int, shape (m, 3)
        Nodes whose freezing ends the march (all of them frozen: stop); ``m = 0``
        marches until the band is empty. Nodes frozen in ``start`` do not count.
    lean : bool, optional
        Use the lean layout (see :data:`LEAN_NODES`); default: for grids of more
        than ``LEAN_NODES`` padded nodes.
    interleave : bool, optional
        Grids outside the lean layout: ``T`` and ``1 / speed^2`` interleaved in one
        array (:func:`_work_interleaved`) instead of two, and no plateau register.
        Default: in 2D unless every passable node has one speed, in 3D unless the grid
        has a plateau (:func:`_buffers`). The times are the same bit for bit either way.
        Ignored in the lean layout.
    threads : int
        Threads of the set-up (``>= 1``): the lean layout of grids of at least
        :data:`SETUP_PARALLEL_MIN_NODES` padded nodes is padded on that many
        (:func:`pad_grid_parallel`); the march itself runs on one.
    span : tuple of 2 float, optional
        The smallest positive and the largest speed [m/s] (:func:`speed_range`) if the
        caller knows them (:func:`fm2uav.eikonal.fast_marching`'s input scan): the plateau
        test then needs no pass over the speeds.

    Returns
    -------
    T : ndarray, float64, shape (nx*ny*nz,)
        Arrival time [s] of every frozen node, ``inf`` elsewhere (in the lean
        layout a view of the march's time buffer).
    frozen : int
        Number of nodes frozen by the march.
    """
    nx, ny, nz = (int(n) for n in shape3)
    two = nz == 1
    pshape = (nx + 2, ny + 2) if two else (nx + 2, ny + 2, nz + 2)
    npad = int(np.prod(pshape))
    if npad > MAX_NODES:
        raise InputError(
            f"grid {tuple(shape3)} has {npad} nodes with its ghost layer, more than the "
            f"Fast Marching's {MAX_NODES}; use a coarser spacing or split the map"
        )
    if lean is None:
        lean = npad > LEAN_NODES
    Tp, Vp, Tk, Vk, unit, plat = _buffers(speed, shape3, npad, lean, interleave,
                                          interleave_3d=True, span=span)
    # the lean layout's buffers are fresh mappings: most of the padding is their page
    # faults, which the threads take in parallel; the kept buffers of smaller grids take
    # milliseconds on one
    nth = setup_threads(threads, npad) if lean else 1
    if nth > 1:  # prange(nth): nth threads of numba's pool, whatever its size
        pad_grid_parallel(nth, _readonly(speed), start.T, start.state, *start.lo,
                          *start.shape, nx, ny, nz, Tp, Vp)
    else:
        pad_grid(_readonly(speed), start.T, start.state, *start.lo, *start.shape, nx, ny,
                 nz, Tp, Vp)
    stop, n_stop = _stop_bits(stop_cells, start, shape3, npad)
    U, qp = _plateau(speed, Vp, shape3, npad, span=span) if plat is None else plat
    # the pool starts at ~1/16 of the nodes (the band is a surface) and doubles
    # when the march reports that it runs low
    nblk = max(2 * RESERVE_BLOCKS, npad // (16 * BLOCK))
    pool = (_work(16 * nblk * BLOCK) if lean else _work_kept("pool", 16 * nblk * BLOCK))
    pool = pool.view(np.uint64)  # huge pages (see _work)
    nxt = np.empty(nblk, dtype=np.uint32)
    bk = np.empty(2 * int(_NB), dtype=np.uint32)
    mw = np.empty(_NW, dtype=np.uint64)
    st = np.zeros(ST_SIZE, dtype=np.uint64)
    init_queue(nxt, bk, mw, st)
    st[_NSTOP] = n_stop
    # only the start box holds band and frozen nodes: phases 0 and 1 scan its span
    st[_SCAN] = st[_BEGIN] = unit * _padded_index(start.lo, pshape)
    st[_END] = unit * (_padded_index([a + b - 1 for a, b in zip(start.lo, start.shape)],
                                     pshape) + 1)
    ih = [1.0 / (h * h) for h in h3]
    while True:
        if two:
            if unit == 2:
                kernel = march2d_o1_pairs if order == 1 else march2d_o2_pairs
            else:
                kernel = march2d_o1 if order == 1 else march2d_o2
            status = kernel(Tk, Vk, U, qp, pshape[0], pshape[1], unit, ih[0], ih[1], stop,
                            pool, nxt, bk, mw, st)
        else:
            kernel = march3d_o1 if order == 1 else march3d_o2
            status = kernel(Tk, Vk, U, qp, *pshape, unit, *ih, stop, pool, nxt, bk, mw, st)
        if status == 0:
            break
        pool, nxt = _grow(pool, nxt, st)
    del Vp, Vk, Tk, pool, nxt
    n = nx * ny * nz
    if lean:  # in place: every node moves to a lower index, read before written
        unpad_grid(Tp, nx, ny, nz, Tp)
        T = Tp[:n]
    else:
        T = result_array(n)
        unpad_grid(Tp, nx, ny, nz, T)
    return T, int(st[_FROZEN])


#: Grids of at least this many nodes are set up on the march's threads (the padding,
#: the input scan): below it one thread takes a few milliseconds, and the parallel
#: kernels' one-off compilation is spared to small runs.
SETUP_PARALLEL_MIN_NODES = 2_000_000


def setup_threads(threads, nodes):
    """Threads for the set-up of a march over ``nodes`` nodes: ``threads`` (at most numba's
    pool) from :data:`SETUP_PARALLEL_MIN_NODES` nodes on, else 1."""
    if threads <= 1 or nodes < SETUP_PARALLEL_MIN_NODES:
        return 1
    import numba

    return int(min(threads, numba.config.NUMBA_NUM_THREADS))


def _buffers(speed, shape3, npad, lean, interleave, *, interleave_3d=False, huge_times=True,
             span=None):
    """The padded ``T`` and ``V`` of a march (see :func:`march`'s ``lean`` and ``interleave``).

    Returns ``(Tp, Vp, Tk, Vk, unit, plateau)``: the arrays :func:`pad_grid` fills and
    :func:`unpad_grid` reads (strided views in the interleaved layout), those the kernel
    takes, its ``unit`` (1, or 2 interleaved) and the plateau ``(U, qp)`` where it was
    decided here (None: not yet). By default a 2D map marches interleaved, a neighbour's
    time and speed in one cache line, unless all its passable nodes have one speed (then
    the march reads no speed at all and the separate arrays hold twice the nodes per
    line of ``T``). Measured on 2048^2 (docs/performance.md): FM²-shaped order 1 -8 %,
    smooth -17 %; FM² maps saturated (W = 1) on 57 % and 70 % of the nodes -8 % and
    -6 % against the separate arrays with the plateau mask; a uniform speed +10 %.
    ``interleave_3d`` (the serial march): a 3D map without a plateau (:func:`_plateau`,
    its mask built) marches interleaved too, one with a plateau keeps the mask in separate
    arrays (measured on 160^3 FM²-shaped and smooth: -1.3 to -1.7 %); the slab march's
    3D kernels take separate arrays (default False). ``huge_times``: the lean layout's
    times on huge pages (False: small pages, :func:`_map`). ``span``: as :func:`_plateau`.
    """
    if lean:  # two plain mappings: V goes as soon as the march is done
        Tp = _work(8 * npad, huge=huge_times).view(np.float64)
        Vp = _work(4 * npad).view(np.float32)
        return Tp, Vp, Tp, Vp, 1, None
    two = shape3[2] == 1
    plat = None
    if (two or interleave_3d) and interleave is None:
        # a 3D map with a plateau mask keeps it (the separate arrays; measured on 160^3
        # constant speed -22 %), one without marches interleaved
        plat = _plateau(speed, _F64_TYPE, shape3, npad, None, not two, span=span)
        interleave = plat[1] == 0.0
    if (two or interleave_3d) and interleave:
        Tk = _work_interleaved(npad)
        return Tk[0::2], Tk[1::2], Tk, Tk[1:], 2, (_NO_BITS, 0.0)
    Tp, Vp = _work_pair(npad)
    return Tp, Vp, Tp, Vp, 1, plat


def _padded_index(node, pshape):
    """Flat index in the padded grid ``pshape`` (2 or 3 axes) of grid node ``(i, j, k)``."""
    c = 0
    for i, n in zip(node, pshape):
        c = c * n + i + 1
    return c


#: The plateau mask is built when at least this share of the nodes has the grid's
#: largest speed (the saturated plateau of an FM² map, W = 1): there the march takes
#: the speed from a register instead of the speed grid, a bit of the mask (one bit per
#: node, cache-resident) telling where. A grid whose passable nodes all have one speed
#: needs no mask and reads no speed at all. Measured (march only, interleaved, loaded
#: 2-core machine): 2048^2 constant speed -24 %, 160^3 constant -22 %; an FM²-shaped
#: 2048^2 map saturated on 57 % of its nodes -4 %, on 21 % +10 % (the mask's reads and
#: the branch at the plateau's edges cost more than the speed reads they save), hence
#: the bar.
PLATEAU_MIN_SHARE = 0.5


def _plateau(speed, Vp, shape3, npad, fill=None, mask=True, *, span=None):
    """The plateau mask of the padded grid and the plateau's ``V`` (``qp = 0.0``: none).

    The mask marks the nodes whose speed equals the grid's largest (see
    :data:`PLATEAU_MIN_SHARE`); a grid whose passable nodes all have one speed gets the
    one-byte mask (every node, nothing to read). ``qp`` is ``1 / speed^2`` rounded as
    :func:`pad_grid` rounds it into ``Vp`` (float32 in the lean layout), so the times
    are bit for bit those read from ``Vp``. A sample of every ``_PLATEAU_STRIDE``-th
    node decides first whether a plateau is likely (the full pass over the speeds
    cost 2 % of the march on a map without one). ``fill(vmax, bits)``, if given, sets the
    bits in another layout (the parallel march's slabs) and returns how many.
    ``mask=False``: a uniform grid's plateau only (a mixed grid gets none, its mask unbuilt).
    ``span``: the speeds' :func:`speed_range` if known (else found here, a pass over them);
    with ``mask=False`` a known span of two speeds answers at once (the sample's strided
    reads, a cache line each, took 1.36 ms on a 2048^2 FM²-shaped map out of cache).
    """
    if not mask and span is not None and span[0] != span[1]:
        return _NO_BITS, 0.0
    sample = speed[::_PLATEAU_STRIDE]
    top = sample.max()
    if not top > 0.0 or np.count_nonzero(sample == top) < 0.8 * PLATEAU_MIN_SHARE * sample.size:
        return _NO_BITS, 0.0
    vmin, vmax = speed_range(speed) if span is None else span
    if not vmax > 0.0:
        return _NO_BITS, 0.0
    qp = float(Vp.dtype.type(1.0 / (vmax * vmax)))
    if vmin == vmax:
        return _ONE_BYTE, qp
    if not mask:
        return _NO_BITS, 0.0
    bits = np.zeros(npad // 8 + 1, dtype=np.uint8)
    if fill is None:
        count = plateau_bits(speed, vmax, *(int(n) for n in shape3), bits)
    else:
        count = fill(vmax, bits)
    if count < PLATEAU_MIN_SHARE * speed.size:
        return _NO_BITS, 0.0
    return bits, qp


_ONE_BYTE = np.ones(1, dtype=np.uint8)
#: Stride of the sample of :func:`_plateau` (a prime, against periodic speed fields).
_PLATEAU_STRIDE = 61


@njit(cache=True, error_model="numpy", _nrt=False)
def speed_range(speed):
    """The smallest positive and the largest value of a flat array of valid speeds
    (finite, ``>= 0``; inf, 0 when no value is positive); one vectorised pass."""
    low = ~_ZERO
    top = _ZERO
    for c in range(speed.size):
        low, top = _span_step(_bits(speed[c]), low, top)
    return _span_value(low, top)


#: A float64's bits without the sign (``-0.0`` -> ``0.0``).
_NO_SIGN = _U(0x7FFFFFFFFFFFFFFF)


@njit(**_OPT)
def _span_step(u, low, top):
    """One speed's bits ``u`` into the running span ``(low, top)`` of :func:`speed_range`.

    On the bits, as unsigned integers: they order non-negative floats as the floats do,
    and an integer minimum and maximum vectorise where a float one does not (it must
    keep NaN's order: measured on 2048^2 (cached), :func:`speed_range` 11.7 ms as floats,
    1.14 ms on the bits). ``low`` holds the smallest positive speed's
    bits minus one (0 wraps to the largest integer: not positive)."""
    w = u & _NO_SIGN
    return min(low, w - _ONE), max(top, w)


@njit(**_OPT)
def _span_value(low, top):
    """The ``(smallest positive, largest)`` speeds of a span of :func:`_span_step`."""
    return (_INF if low == ~_ZERO else _from_bits(low + _ONE)), _from_bits(top)


@njit(cache=True, error_model="numpy", _nrt=False)
def plateau_bits(speed, vmax, nx, ny, nz, bits):
    """Set bit ``c`` of ``bits`` for every node with ``speed == vmax`` (``c`` its index in
    the padded layout of :func:`pad_grid`). Returns how many."""
    pz = 1 if nz == 1 else nz + 2
    py = ny + 2
    count = 0
    rows = nx if nz == 1 else nx * ny
    m = ny if nz == 1 else nz
    for r in range(rows):
        i = r if nz == 1 else r // ny
        j = 0 if nz == 1 else r - i * ny
        src = r * m
        dst = ((i + 1) * py + j + 1) * pz + (0 if nz == 1 else 1)
        for k in range(m):  # branch-free
            on = speed[src + k] == vmax
            c = dst + k
            bits[c >> 3] |= np.uint8(on) << np.uint8(c & 7)
            count += on
    return count


def _stop_bits(stop_cells, start, shape3, npad):
    """The stop nodes as a bit mask over the padded grid, and how many are not frozen yet."""
    cells = np.asarray(stop_cells, dtype=np.int64).reshape(-1, 3)
    cells = cells[~start.frozen_at(cells)]
    if len(cells) == 0:
        return np.zeros(1, dtype=np.uint8), 0
    _, ny, nz = (int(n) for n in shape3)
    i, j, k = cells.T
    if nz == 1:
        c = (i + 1) * (ny + 2) + j + 1
    else:
        c = ((i + 1) * (ny + 2) + j + 1) * (nz + 2) + k + 1
    c = np.unique(c)
    bits = np.zeros(npad // 8 + 1, dtype=np.uint8)
    np.bitwise_or.at(bits, c >> 3, (1 << (c & 7)).astype(np.uint8))
    return bits, len(c)


def _work(nbytes, huge=True):
    """Uninitialised work memory of ``nbytes`` (uint8 view).

    From 4 MiB on, a fresh anonymous mapping advised for transparent huge pages
    (numpy advises its large arrays too, but malloc may hand back recycled
    small pages): the march reads T and V at scattered rows, and with
    4 KiB pages the TLB misses cost ~15 % on 2048^2 (measured 327 -> 382 ms).
    ``huge=False``: advised against them (:func:`_map`).
    """
    if nbytes < _HUGE_MIN:
        return np.empty(nbytes, dtype=np.uint8)
    return np.frombuffer(_map(nbytes, huge), dtype=np.uint8)[:nbytes]


def _map(nbytes, huge=True):
    """A fresh anonymous mapping of at least ``nbytes`` (whole huge pages), advised for
    transparent huge pages, or (``huge=False``) against them: small pages, whose first
    touch on a virtual machine that hands its free memory back to the host can cost far
    less (the free memory it reports is whole huge pages; recently freed small pages are
    still backed). Measured on the parallel terrain march's times (336 MB,
    docs/performance.md "The terrain march's times on small pages")."""
    size = -(-nbytes // _HUGE) * _HUGE
    mm = mmap.mmap(-1, size, flags=mmap.MAP_PRIVATE | mmap.MAP_ANONYMOUS)
    advice = "MADV_HUGEPAGE" if huge else "MADV_NOHUGEPAGE"
    if hasattr(mmap, advice):
        try:
            mm.madvise(getattr(mmap, advice))
        except OSError:  # THP unavailable: plain pages
            pass
    return mm


_HUGE = 2 * 1024 * 1024
_HUGE_MIN = 4 * 1024 * 1024


def _work_pair(npad):
    """Padded T and speed arrays in one buffer, V shifted by half a page plus a
    cache line against T, so that T[c] and V[c] do not share L1 sets."""
    shift = 2048 + 64  # bytes, a multiple of 8
    nb = 8 * npad
    buf = _work_kept("pair", 2 * nb + shift)
    return buf[:nb].view(np.float64), buf[nb + shift:nb + shift + nb].view(np.float64)


def _work_interleaved(npad):
    """Padded T and speed interleaved in one buffer of ``2 npad`` float64 (the buffer of
    :func:`_work_pair`): node ``c``'s time at ``2 c``, its ``1 / speed^2`` at ``2 c + 1``,
    so that an update reads a neighbour's time and speed from one cache line."""
    return _work_kept("pair", 16 * npad + 2048 + 64)[:16 * npad].view(np.float64)


#: A float64 array: :func:`_plateau` reads only the dtype of the speed copy.
_F64_TYPE = np.empty(0)


#: Work buffers (padded grid, entry pool) of at most this many bytes stay with
#: the calling thread for its next march instead of being unmapped: a fresh
#: mapping costs its page faults (~4 ms for 2048^2) and, where the kernel must
#: compact memory for the huge pages, measured stalls of ~0.1 s in half the calls
#: of a run alternating with scikit-fmm. Larger grids map and unmap as before.
WORK_KEEP_MAX = 256 * 2**20
_KEPT = threading.local()


def _work_kept(slot, nbytes):
    """``_work(nbytes)``, reusing this thread's buffer ``slot`` when it is large enough."""
    if nbytes > WORK_KEEP_MAX:
        return _work(nbytes)
    kept = getattr(_KEPT, "bufs", None)
    if kept is None:
        kept = _KEPT.bufs = {}
    buf = kept.get(slot)
    if buf is None or buf.size < nbytes:
        kept.pop(slot, None)  # unmapped once no march uses it
        buf = _work(nbytes)
        kept[slot] = buf
    return buf[:nbytes]


#: Result arrays (a march's times) of at least 4 MiB and at most :data:`WORK_KEEP_MAX`
#: bytes come from a pool of at most this many mappings; a mapping goes back to the pool
#: when its array and every view of it are gone, so the next march writes its times into
#: pages that are already there. A fresh array's first touch is the kernel's page faults:
#: on this virtual machine, after a few seconds idle (its free memory handed back to the
#: host), 68 ms of system time for the 32 MB of 2048^2 times, a third of the march
#: (docs/performance.md, "The result's pages"). Four: a caller keeping the last result of
#: each of a few marches (one and two threads, orders 1 and 2) still gets pooled pages.
RESULT_KEEP = 4
_RESULTS_FREE: list = []
_RESULTS_LOCK = threading.RLock()
_RESULTS_LIVE = [0]


def result_array(n):
    """An uninitialised float64 array of ``n`` elements for a march's times.

    From the pool of :data:`RESULT_KEEP` mappings when its size allows (the smallest free
    one that fits; a new one while the pool has room; the smallest free one replaced when
    none fits), else a plain ``np.empty(n)`` (small or huge arrays, or every pooled mapping
    still in use). The caller writes every element.
    """
    return pooled_result_array(n)[0]


def pooled_result_array(n):
    """:func:`result_array` and whether its pages are there already (a mapping of the pool
    that an earlier result used: its first writes take no page faults)."""
    nbytes = 8 * n
    if nbytes < _HUGE_MIN or nbytes > WORK_KEEP_MAX:
        return np.empty(n), False
    with _RESULTS_LOCK:
        free = _RESULTS_FREE
        fits = [mm for mm in free if len(mm) >= nbytes]
        resident = bool(fits)
        if fits:
            mm = min(fits, key=len)
            free.remove(mm)
        elif _RESULTS_LIVE[0] + len(free) < RESULT_KEEP:
            mm = _map(nbytes)
        elif free:  # none fits: the smallest free mapping makes room for one that does
            free.remove(min(free, key=len))
            mm = _map(nbytes)
        else:
            return np.empty(n), False
        _RESULTS_LIVE[0] += 1
    out = np.frombuffer(mm, dtype=np.float64, count=n)
    # views of ``out`` keep ``out`` (and its buffer) alive: the mapping is free once it goes
    weakref.finalize(out.base, _give_back, mm)
    return out, resident


def _give_back(mm):
    """A pooled result mapping is free again (its array and every view of it are gone)."""
    with _RESULTS_LOCK:
        _RESULTS_LIVE[0] -= 1
        _RESULTS_FREE.append(mm)


def _grow(pool, nxt, st):
    """Double the entry pool; the new blocks join the free list."""
    old = nxt.size
    new = 2 * old
    pool2 = _work(16 * new * BLOCK).view(np.uint64)
    pool2[: pool.size] = pool
    nxt2 = np.empty(new, dtype=np.uint32)
    nxt2[:old] = nxt
    nxt2[old:-1] = np.arange(old + 1, new, dtype=np.uint32)
    nxt2[-1] = np.uint32(st[_FH]) if st[_NFREE] > 0 else np.uint32(_NIL)
    st[_FH] = old
    st[_NFREE] = int(st[_NFREE]) + (new - old)
    return pool2, nxt2


# ------------------------------------------------------------------ validation
_EXP_BITS = _U(0x7FF0000000000000)
_SIGN_BIT = _U(0x8000000000000000)


@njit(cache=True, error_model="numpy", _nrt=False)
def scan_speed(v, min_speed):
    """One pass over a flat speed array.

    Returns ``(bad, n_tiny, low, top)``: the flat index of the first non-finite or
    negative speed (-1 if none), the number of speeds in ``(0, min_speed)``
    (``min_speed > 0``), and the smallest positive and the largest speed (as
    :func:`speed_range`; only meaningful when ``bad == -1``). Measured on 2048^2
    (cached): 1.65 ms for the checks alone before, 1.63-1.71 ms with the span.
    """
    tiny = _bits(min_speed) - _ONE
    n_tiny = _ZERO
    bad = _ZERO
    low = ~_ZERO
    top = _ZERO
    for c in range(v.size):  # no early exit, integer tests on the bits: the loop vectorises
        u = _bits(v[c])
        # +inf, NaN or negative: from the bits of +inf up, as unsigned (the sign bit set:
        # every negative, -inf and NaNs of either sign), but not -0.0
        bad |= _U(u >= _EXP_BITS) & _U(u != _SIGN_BIT)
        low, top = _span_step(u, low, top)
        # in (0, min_speed): the bits without the sign in (0, min_speed's), one wrapping test
        n_tiny += _U((u & _NO_SIGN) - _ONE < tiny)
    if bad == _ZERO:
        lo, hi = _span_value(low, top)
        return -1, np.int64(n_tiny), lo, hi
    n_tiny = 0
    for c in range(v.size):
        x = v[c]
        if not (x >= 0.0 and x < np.inf):
            return c, n_tiny, _INF, 0.0
        if 0.0 < x < min_speed:
            n_tiny += 1
    return -1, n_tiny, low, top


@njit(cache=True, error_model="numpy", parallel=True)
def scan_speed_parallel(nth, v, min_speed):
    """:func:`scan_speed` on ``nth`` threads, thread ``t`` the ``t``-th share of ``v``: the
    same ``(bad, n_tiny, low, top)`` (the first bad index of the first share holding one,
    the count of tiny speeds before it, the smallest positive and the largest speed)."""
    n = v.size
    bads = np.empty(nth, dtype=np.int64)
    tiny = np.empty(nth, dtype=np.int64)
    lows = np.empty(nth)
    tops = np.empty(nth)
    for t in prange(nth):
        a = t * n // nth
        bad, cnt, low, top = scan_speed(v[a:(t + 1) * n // nth], min_speed)
        bads[t] = bad if bad < 0 else a + bad
        tiny[t] = cnt
        lows[t] = low
        tops[t] = top
    count = 0
    low = _INF
    top = 0.0
    for t in range(nth):
        count += tiny[t]
        low = min(low, lows[t])
        top = max(top, tops[t])
        if bads[t] >= 0:
            return bads[t], count, _INF, 0.0
    return -1, count, low, top
