"""Exact Euclidean distance transform, compiled (numba).

Private module: :func:`fm2uav.eikonal.distance_map` is the public entry point.
The transform is separable (Felzenszwalb & Huttenlocher 2012): one 1D transform
of every line along z, then along y, then along x. Lines of one pass are
independent, so the order in which they run changes no value, and the threads
take x-slabs (passes z and y) and then blocks of the (y, z) plane (pass x).

Memory layout of the passes. A line along y or x is strided in the C-ordered
grid (stride ``nz``, resp. ``ny * nz``); gathering one line at a time touched a
whole cache line (and, along x, a page) per value. The passes gather
``LANES`` neighbouring lines at once instead — one cache line of each row — into
a small block that stays in the L1/L2 cache, transform them there and write them
back the same way (the x pass ``XLANES`` lines, four cache lines of each row: its
rows lie a page apart). A line of obstacle nodes only (all 0: the low layers of a
terrain) is zeros at once (:func:`_line_or_zeros`). The first pass (along z, on a map
of 0 and inf) is two sweeps without divisions (:func:`_binary_line`). Measured on the 1000 x 1000 x 40 terrain
grid (CPU time, with the root and the division): 1.39 -> 1.20 s
(``benchmarks/terrain_stages.py``, docs/performance.md "Big maps"); the zeros at once
and the x pass's 32 lanes then 1.555 -> 1.386 s on one thread (load 4, "round four"
there). What is left is the y and x passes' lower envelopes, a division and an
unpredictable branch per node.

The last pass can take the square root and the largest value on the way
(``root=True``): the distance map and its maximum (the normaliser of W) without
two more passes over the grid. ``np.sqrt`` and this square root are both IEEE's
correctly rounded one, so the values are the same bit for bit.
"""

from __future__ import annotations

import numpy as np

from .._numba import njit, prange
from ._kernels import _readonly

__all__ = ["squared_edt", "edt", "EDT_PARALLEL_MIN_NODES", "LANES", "XLANES",
           "squared_column_edt_layer"]

#: Lines transformed together in the y and x passes (one 64-byte cache line of float64).
LANES = 8
#: ... and in the x pass, whose rows lie a whole (y, z) plane apart (a page each): more
#: lines a row gathered at once, fewer rows fetched (and TLB misses) per value.
XLANES = 32

#: From this many nodes on, the EDT runs its lines in parallel. The parallel
#: kernel costs ~2.7 s of one-off compilation (parfors) against ~0.4 s serial;
#: below ~2 M nodes the serial transform takes < 0.3 s anyway.
EDT_PARALLEL_MIN_NODES = 2_000_000


@njit(error_model="numpy")
def _edt_line(f, n, w2, v, z, out):
    """1D squared distance transform (Felzenszwalb & Huttenlocher 2012).

    ``out[q] = min_p (w2 * (q - p)^2 + f[p])`` over the finite ``f[p]``: the
    lower envelope of the parabolas rooted at the finite samples. ``w2`` is the
    squared spacing of the axis; ``v`` (int) and ``z`` (float) are scratch of
    length ``n`` and ``n + 1``. The height ``f[p] + w2 p^2`` of each parabola of the
    envelope is kept in ``out[k]`` (free until the envelope is read) instead of
    recomputed at every intersection: the same expression, the same values.
    """
    k = -1
    den = 2.0 * w2
    for q in range(n):
        fq = f[q]
        if fq == np.inf:
            continue
        gq = fq + w2 * q * q
        if k < 0:
            k = 0
            v[0] = q
            out[0] = gq
            z[0] = -np.inf
            z[1] = np.inf
            continue
        while True:
            p = v[k]
            s = (gq - out[k]) / (den * (q - p))
            if s <= z[k] and k > 0:
                k -= 1
            else:
                break
        if s <= z[k]:  # k == 0 and the new parabola hides the first one everywhere
            v[0] = q
            out[0] = gq
            z[0] = -np.inf
            z[1] = np.inf
            continue
        k += 1
        v[k] = q
        out[k] = gq
        z[k] = s
        z[k + 1] = np.inf
    if k < 0:
        for q in range(n):
            out[q] = np.inf
        return
    k = 0
    for q in range(n):
        while z[k + 1] < q:
            k += 1
        d = q - v[k]
        out[q] = w2 * d * d + f[v[k]]


@njit(error_model="numpy", inline="always")
def _line_or_zeros(f, n, w2, v, z, out):
    """:func:`_edt_line`, or zeros at once where every ``f[q]`` is 0 (a line of obstacle
    nodes: ~17 % of the y and x lines of a 1000 x 1000 x 40 terrain, whose ground fills the
    low layers). The transform's own values: each node's nearest root is itself, so
    ``w2 * 0 * 0 + 0.0``, i.e. 0.0."""
    for q in range(n):
        if f[q] != 0.0:
            _edt_line(f, n, w2, v, z, out)
            return
    for q in range(n):
        out[q] = 0.0


@njit(error_model="numpy")
def _binary_line(occ, i, j, nz, w2, out):
    """:func:`_edt_line` of a line of 0 (obstacle) and inf (free): ``w2 d^2`` with ``d``
    the number of nodes to the nearest obstacle on the line (``inf`` without one).

    The transform's own result on such a line, bit for bit: its chosen parabola is a
    nearest obstacle's (two at the same distance give the same value) and its value is
    ``w2 * d * d + 0.0``, computed here the same way; two sweeps, no divisions.
    """
    last = -1
    for k in range(nz):  # distance to the nearest obstacle at or below k
        if occ[i, j, k]:
            last = k
        out[k] = np.inf if last < 0 else float(k - last)
    last = -1
    for k in range(nz - 1, -1, -1):  # ... or above it
        if occ[i, j, k]:
            last = k
        if last >= 0 and last - k < out[k]:
            out[k] = float(last - k)
    for k in range(nz):
        if out[k] < np.inf:
            d = np.int64(out[k])
            out[k] = w2 * d * d + 0.0


@njit(cache=True, error_model="numpy", inline="always")
def _pass_zy(occ, d, i, wy, wz, buf, res, v, z):
    """Passes z and y of the x-slab ``i`` (``d`` of shape ``(nx, ny * nz)``)."""
    _, ny, nz = occ.shape
    out = res[0]
    for j in range(ny):
        row = j * nz
        _binary_line(occ, i, j, nz, wz, out)
        for k in range(nz):
            d[i, row + k] = out[k]
    if ny > 1:
        for k0 in range(0, nz, LANES):
            m = min(LANES, nz - k0)
            for j in range(ny):
                for k in range(m):
                    buf[k, j] = d[i, j * nz + k0 + k]
            for k in range(m):
                _line_or_zeros(buf[k], ny, wy, v, z, res[k])
            for j in range(ny):
                for k in range(m):
                    d[i, j * nz + k0 + k] = res[k, j]


@njit(cache=True, error_model="numpy", inline="always")
def _pass_x(d, c0, m, wx, root, buf, res, v, z):
    """Pass x of the ``m`` columns ``c0 ..`` of the (y, z) plane; the square root if
    ``root``. Returns the largest value written (0 for none)."""
    nx = d.shape[0]
    for i in range(nx):
        for c in range(m):
            buf[c, i] = d[i, c0 + c]
    for c in range(m):
        _line_or_zeros(buf[c], nx, wx, v, z, res[c])
    top = 0.0
    for i in range(nx):
        for c in range(m):
            x = res[c, i]
            if root:
                x = np.sqrt(x)
            d[i, c0 + c] = x
            top = max(top, x)
    return top


@njit(cache=True, error_model="numpy")
def _edt_serial(occ, hx, hy, hz, root, norm):
    nx, ny, nz = occ.shape
    plane = ny * nz
    d = np.empty((nx, plane), dtype=np.float64)
    nmax = max(nx, max(ny, nz))
    buf = np.empty((LANES, nmax))
    res = np.empty((LANES, nmax))
    v = np.empty(nmax, dtype=np.int64)
    z = np.empty(nmax + 1)
    for i in range(nx):
        _pass_zy(occ, d, i, hy * hy, hz * hz, buf, res, v, z)
    top = 0.0
    xbuf = np.empty((XLANES, nmax))
    xres = np.empty((XLANES, nmax))
    for c0 in range(0, plane, XLANES):
        top = max(top, _pass_x(d, c0, min(XLANES, plane - c0), hx * hx, root, xbuf, xres, v,
                               z))
    if norm and 0.0 < top < np.inf:
        flat = d.reshape(-1)
        for c in range(flat.size):
            flat[c] = flat[c] / top
    return d, top


@njit(cache=True, error_model="numpy", parallel=True)
def _edt_parallel(occ, hx, hy, hz, root, norm, nth):
    """:func:`_edt_serial` on ``nth`` threads: thread ``t`` takes the ``t``-th share of
    the x-slabs, then of the blocks of the plane, then of the division (contiguous
    shares: neighbouring threads share at most one cache line)."""
    nx, ny, nz = occ.shape
    plane = ny * nz
    d = np.empty((nx, plane), dtype=np.float64)
    nmax = max(nx, max(ny, nz))
    nblk = (plane + XLANES - 1) // XLANES
    tops = np.zeros(nth)
    for t in prange(nth):
        buf = np.empty((LANES, nmax))
        res = np.empty((LANES, nmax))
        v = np.empty(nmax, dtype=np.int64)
        z = np.empty(nmax + 1)
        for i in range(t * nx // nth, (t + 1) * nx // nth):
            _pass_zy(occ, d, i, hy * hy, hz * hz, buf, res, v, z)
    for t in prange(nth):
        buf = np.empty((XLANES, nmax))
        res = np.empty((XLANES, nmax))
        v = np.empty(nmax, dtype=np.int64)
        z = np.empty(nmax + 1)
        top = 0.0
        for b in range(t * nblk // nth, (t + 1) * nblk // nth):
            c0 = b * XLANES
            top = max(top, _pass_x(d, c0, min(XLANES, plane - c0), hx * hx, root, buf, res,
                                   v, z))
        tops[t] = top
    top = tops.max()
    if norm and 0.0 < top < np.inf:
        flat = d.reshape(-1)
        n = flat.size
        for t in prange(nth):
            for c in range(t * n // nth, (t + 1) * n // nth):
                flat[c] = flat[c] / top
    return d, top


def edt(occ, hx, hy, hz, *, root=True, normalise=False, threads=1):
    """Exact Euclidean distance [m] (``root``) or its square [m²] from every node to the
    nearest True node, and the largest of these values.

    Parameters
    ----------
    occ : ndarray of bool, shape (nx, ny, nz)
        C-contiguous; True = obstacle.
    hx, hy, hz : float
        Spacing per axis [m].
    root : bool
        The distance (True) or its square (False).
    normalise : bool
        Divide the map by its largest value, in place, when that is finite and
        positive (the map ``d / max d`` of :func:`fm2uav.eikonal.normalise_distance`,
        the same values).
    threads : int
        Threads (``>= 1``, resolved by the caller) for grids of at least
        :data:`EDT_PARALLEL_MIN_NODES` nodes; smaller grids run on one.

    Returns
    -------
    d : ndarray of float64, shape (nx, ny, nz)
        ``inf`` everywhere if ``occ`` has no True node.
    top : float
        The largest value before the division [m or m²].
    """
    occ = _readonly(occ)
    args = (float(hx), float(hy), float(hz), bool(root), bool(normalise))
    if threads > 1 and occ.size >= EDT_PARALLEL_MIN_NODES:
        import numba

        # prange(nth) below: nth threads of numba's pool, whatever its size
        d, top = _edt_parallel(occ, *args, int(min(threads, numba.config.NUMBA_NUM_THREADS)))
    else:
        d, top = _edt_serial(occ, *args)
    return d.reshape(occ.shape), float(top)


def squared_edt(occ, hx, hy, hz, threads=1):
    """Exact squared Euclidean distance [m²] from every node to the nearest True node.

    :func:`edt` without the root: ``occ`` is a C-contiguous bool array of shape
    (nx, ny, nz); returns float64 of the same shape (``inf`` everywhere if ``occ``
    has no True node).
    """
    return edt(occ, hx, hy, hz, root=False, threads=threads)[0]


@njit(cache=True, error_model="numpy")
def squared_column_edt_layer(top, k, hx, hy, hz):
    """Exact squared distance [m²] from the nodes of layer ``k`` to a column world's obstacles.

    A column world has obstacle nodes ``(i, j, l)`` for ``l <= top[i, j]`` (``top = -1``:
    a column without obstacle). The transform is the separable EDT of
    :func:`squared_edt` restricted to one layer: the pass along z is the closed form
    ``hz^2 (k - top)^2`` (0 at and below ``top``), then the passes along y and x, in
    the same order and arithmetic as :func:`squared_edt`, so the values are those of the
    full 3D transform's layer ``k``. Returns float64 ``(nx, ny)``.
    """
    nx, ny = top.shape
    d = np.empty((nx, ny), dtype=np.float64)
    nmax = max(nx, ny)
    f = np.empty(nmax)
    out = np.empty(nmax)
    v = np.empty(nmax, dtype=np.int64)
    z = np.empty(nmax + 1)
    wz = hz * hz
    for i in range(nx):
        for j in range(ny):
            t = top[i, j]
            if t < 0:
                f[j] = np.inf
            else:
                m = k - t
                f[j] = 0.0 if m <= 0 else wz * m * m + 0.0
        if ny > 1:
            _edt_line(f, ny, hy * hy, v, z, out)
            for j in range(ny):
                d[i, j] = out[j]
        else:
            d[i, 0] = f[0]
    if nx > 1:
        for j in range(ny):
            for i in range(nx):
                f[i] = d[i, j]
            _edt_line(f, nx, hx * hx, v, z, out)
            for i in range(nx):
                d[i, j] = out[i]
    return d
