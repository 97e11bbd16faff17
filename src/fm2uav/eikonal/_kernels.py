"""Compiled (numba) kernels of the Fast Marching Method.

Private module: the public entry point is :func:`fm2uav.eikonal.fast_marching`,
which validates the input and calls :func:`march`. Everything here works on
flat, C-ordered float64 arrays of a 3D grid ``(nx, ny, nz)``; a 2D grid is
passed as ``(nx, ny, 1)`` so one kernel serves both.

Conventions
-----------
* ``state``: 0 = unknown (far), 1 = narrow band (trial), 2 = frozen (accepted).
* ``T``: arrival time in seconds (``inf`` for unknown cells).
* The narrow band is a binary min-heap of flat indices with its keys stored
  beside them (``hkey``) and a back-pointer per cell (``hpos``) for
  decrease-key in O(log n).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

FAR = np.uint8(0)
BAND = np.uint8(1)
FROZEN = np.uint8(2)

_INF = np.inf

#: The order-2 stencil is used only where the speed at the node and at its two
#: upwind neighbours varies by at most this factor; elsewhere order 1.
ORDER2_MAX_SPEED_RATIO = 2.0


# --------------------------------------------------------------------------- heap
@njit(cache=True, inline="always", error_model="numpy", _nrt=False)
def _sift_up(heap, hkey, hpos, pos):
    idx = heap[pos]
    key = hkey[pos]
    while pos > 0:
        parent = (pos - 1) >> 1
        if hkey[parent] <= key:
            break
        pidx = heap[parent]
        heap[pos] = pidx
        hkey[pos] = hkey[parent]
        hpos[pidx] = pos
        pos = parent
    heap[pos] = idx
    hkey[pos] = key
    hpos[idx] = pos


@njit(cache=True, inline="always", error_model="numpy", _nrt=False)
def _pop(heap, hkey, hpos, size):
    """Remove the root of a heap of ``size`` items; return the removed index.

    Bottom-up deletion (Floyd / Wegener): the hole left by the root walks down
    along the smaller child with one comparison per level, then the last item
    is dropped into the hole and sifted up (usually 0-1 steps). About half the
    comparisons of the textbook sift-down, and the child choice is branchless.
    """
    top = heap[0]
    size -= 1
    if size == 0:
        return top
    last = heap[size]
    lkey = hkey[size]
    pos = 0
    child = 1
    while child + 1 < size:
        child += hkey[child + 1] < hkey[child]
        cidx = heap[child]
        heap[pos] = cidx
        hkey[pos] = hkey[child]
        hpos[cidx] = pos
        pos = child
        child = 2 * pos + 1
    if child < size:  # one child left
        cidx = heap[child]
        heap[pos] = cidx
        hkey[pos] = hkey[child]
        hpos[cidx] = pos
        pos = child
    heap[pos] = last
    hkey[pos] = lkey
    hpos[last] = pos
    _sift_up(heap, hkey, hpos, pos)
    return top


# ------------------------------------------------------------------ local solver
@njit(cache=True, inline="always", error_model="numpy", _nrt=False)
def _axis_term(T, state, speed, c, coord, n_axis, stride, inv_h2, order):
    """Upwind term of one axis: returns ``(tau, a)`` for ``a (T - tau)^2``.

    ``a = 0`` (and ``tau = inf``) when no neighbour on this axis is frozen.
    Second order, ``a = 9/(4h^2)`` and ``tau = (4 T1 - T2)/3``, is used when the
    next cell in the same upwind direction is frozen, not later than T1, and
    the speed along the three nodes varies by at most ``ORDER2_MAX_SPEED_RATIO``
    (the stencil assumes T smooth: across a sharp speed jump, e.g. a thin slow
    wall, it would charge only 2/3 of the crossing time).
    """
    best = _INF
    direction = 0
    if coord > 0 and state[c - stride] == 2:
        best = T[c - stride]
        direction = -1
    if coord < n_axis - 1 and state[c + stride] == 2:
        t = T[c + stride]
        if t < best:
            best = t
            direction = 1
    if direction == 0:
        return _INF, 0.0
    if order == 2:
        if direction == -1:
            ok = coord > 1
        else:
            ok = coord < n_axis - 2
        if ok:
            c1 = c + direction * stride
            c2 = c1 + direction * stride
            if state[c2] == 2:
                t2 = T[c2]
                if t2 <= best:
                    v0 = speed[c]
                    v1 = speed[c1]
                    v2 = speed[c2]
                    vmax = max(v0, max(v1, v2))
                    vmin = min(v0, min(v1, v2))
                    if vmax <= ORDER2_MAX_SPEED_RATIO * vmin:
                        return (4.0 * best - t2) / 3.0, 2.25 * inv_h2
    return best, inv_h2


@njit(cache=True, inline="always", error_model="numpy", _nrt=False)
def _combine(ta, aa, tb, ab, tc, ac, rhs):
    """Solve ``sum_m a_m (T - tau_m)^2 = rhs`` using the upwind axes in order.

    Axes are sorted by ``tau``; an axis joins only while the solution is later
    than its ``tau`` (causality) and the discriminant stays non-negative.
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
    A = aa + ab
    B = aa * ta + ab * tb
    C = aa * ta * ta + ab * tb * tb
    disc = B * B - A * (C - rhs)
    if disc < 0.0:
        return t
    t = (B + math.sqrt(disc)) / A
    if ac == 0.0 or t <= tc:
        return t
    A3 = A + ac
    B3 = B + ac * tc
    C3 = C + ac * tc * tc
    disc = B3 * B3 - A3 * (C3 - rhs)
    if disc < 0.0:
        return t
    return (B3 + math.sqrt(disc)) / A3


@njit(cache=True, inline="always", error_model="numpy", _nrt=False)
def _solve(T, state, speed, c, i, j, k, nx, ny, nz, sx, sy, ihx2, ihy2, ihz2, order):
    v = speed[c]
    rhs = 1.0 / (v * v)
    ta, aa = _axis_term(T, state, speed, c, i, nx, sx, ihx2, order)
    tb, ab = _axis_term(T, state, speed, c, j, ny, sy, ihy2, order)
    tc, ac = _axis_term(T, state, speed, c, k, nz, 1, ihz2, order)
    return _combine(ta, aa, tb, ab, tc, ac, rhs)


@njit(cache=True, inline="always", error_model="numpy", _nrt=False)
def _relax(T, state, speed, heap, hkey, hpos, size, c, i, j, k,
           nx, ny, nz, sx, sy, ihx2, ihy2, ihz2, order):
    """Recompute a non-frozen neighbour ``c`` and insert/decrease it in the heap."""
    t = _solve(T, state, speed, c, i, j, k, nx, ny, nz, sx, sy, ihx2, ihy2, ihz2, order)
    if t < T[c]:
        T[c] = t
        if state[c] == 1:
            pos = hpos[c]
            hkey[pos] = t
            _sift_up(heap, hkey, hpos, pos)
        else:
            state[c] = 1
            heap[size] = c
            hkey[size] = t
            hpos[c] = size
            _sift_up(heap, hkey, hpos, size)
            size += 1
    return size


# ------------------------------------------------------------------- the march
@njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
def march(speed, T, state, nx, ny, nz, hx, hy, hz, order, stop_mask, n_stop, heap, hkey, hpos):
    """Run the Fast Marching Method in place.

    Parameters
    ----------
    speed : ndarray, float64, shape (nx*ny*nz,)
        Propagation speed [m/s]; cells with 0 are never entered.
    T : ndarray, float64, shape (nx*ny*nz,)
        Arrival times [s]: initial values for frozen/band cells, ``inf`` elsewhere.
        Overwritten with the result.
    state : ndarray, uint8, shape (nx*ny*nz,)
        0 far, 1 band, 2 frozen. Band cells must carry a finite ``T``.
    nx, ny, nz : int
        Grid shape (``nz = 1`` for 2D).
    hx, hy, hz : float
        Spacing per axis [m].
    order : int
        1 or 2.
    stop_mask : ndarray, uint8
        ``stop_mask[c] == 1`` marks cells whose freezing ends the march; a
        1-element array when unused.
    n_stop : int
        Number of marked cells not frozen yet (0 = march until the band is empty).
    heap, hkey, hpos : ndarray, shape (nx*ny*nz,)
        Work space (contents ignored): heap of flat indices (int32 or int64),
        their keys (float64) and each cell's heap position (same int type).
        Allocated by the caller because the kernels run without numba's
        reference-counted runtime (``_nrt=False``): array reference counting
        inside the inlined helpers cost ~2.7x in speed.

    Returns
    -------
    int
        Number of cells frozen by the march.
    """
    n = nx * ny * nz
    sx = ny * nz
    sy = nz
    ihx2 = 1.0 / (hx * hx)
    ihy2 = 1.0 / (hy * hy)
    ihz2 = 1.0 / (hz * hz)
    use_stop = n_stop > 0

    size = 0

    # Seed the heap with the band cells. Cells frozen on entry (the sources)
    # are expanded first, by the same loop body as popped cells, so the
    # neighbour code is compiled once.
    for c in range(n):
        if state[c] == 1:
            heap[size] = c
            hkey[size] = T[c]
            hpos[c] = size
            _sift_up(heap, hkey, hpos, size)
            size += 1
    scan = 0  # cursor of the pass over cells frozen on entry
    frozen = 0
    while True:
        if scan < n:
            c = scan
            scan += 1
            if state[c] != 2:
                continue
        else:
            if size == 0:
                break
            c = _pop(heap, hkey, hpos, size)
            size -= 1
            state[c] = 2
            frozen += 1
            if use_stop and stop_mask[c] == 1:
                n_stop -= 1
                if n_stop == 0:
                    break
        i = c // sx
        r = c - i * sx
        j = r // nz
        k = r - j * nz
        if i > 0 and state[c - sx] != 2 and speed[c - sx] > 0.0:
            size = _relax(T, state, speed, heap, hkey, hpos, size, c - sx, i - 1, j, k,
                          nx, ny, nz, sx, sy, ihx2, ihy2, ihz2, order)
        if i < nx - 1 and state[c + sx] != 2 and speed[c + sx] > 0.0:
            size = _relax(T, state, speed, heap, hkey, hpos, size, c + sx, i + 1, j, k,
                          nx, ny, nz, sx, sy, ihx2, ihy2, ihz2, order)
        if j > 0 and state[c - sy] != 2 and speed[c - sy] > 0.0:
            size = _relax(T, state, speed, heap, hkey, hpos, size, c - sy, i, j - 1, k,
                          nx, ny, nz, sx, sy, ihx2, ihy2, ihz2, order)
        if j < ny - 1 and state[c + sy] != 2 and speed[c + sy] > 0.0:
            size = _relax(T, state, speed, heap, hkey, hpos, size, c + sy, i, j + 1, k,
                          nx, ny, nz, sx, sy, ihx2, ihy2, ihz2, order)
        if k > 0 and state[c - 1] != 2 and speed[c - 1] > 0.0:
            size = _relax(T, state, speed, heap, hkey, hpos, size, c - 1, i, j, k - 1,
                          nx, ny, nz, sx, sy, ihx2, ihy2, ihz2, order)
        if k < nz - 1 and state[c + 1] != 2 and speed[c + 1] > 0.0:
            size = _relax(T, state, speed, heap, hkey, hpos, size, c + 1, i, j, k + 1,
                          nx, ny, nz, sx, sy, ihx2, ihy2, ihz2, order)

    # finalise: anything not frozen is unreached (or beyond stop_at)
    for c in range(n):
        if state[c] != 2:
            T[c] = _INF
    return frozen


# ------------------------------------------------------------------ validation
@njit(cache=True, error_model="numpy", _nrt=False)
def scan_speed(v, min_speed):
    """One pass over a flat speed array.

    Returns ``(bad, n_tiny)``: the flat index of the first non-finite or
    negative speed (-1 if none) and the number of speeds in ``(0, min_speed)``.
    """
    n_tiny = 0
    for c in range(v.size):
        x = v[c]
        if not (x >= 0.0 and x < np.inf):  # NaN, inf or negative
            return c, n_tiny
        if 0.0 < x < min_speed:
            n_tiny += 1
    return -1, n_tiny


# ------------------------------------------------------------ source initialisation
@njit(cache=True, error_model="numpy")
def init_sources(speed, T, state, nx, ny, nz, hx, hy, hz, src, radius, max_ratio):
    """Initialise point sources: T = 0 at each source (frozen) and, around each
    clean source (see below), the straight-ray time in a ball.

    Inside the ball of physical radius ``radius`` [m] the time is the distance
    ``d`` times the trapezoidal mean slowness ``(1/v_s + 1/v) / 2``, which is
    exact for constant speed and second-order accurate for smooth speed.
    A source gets a ball only if the speed in its bounding box is positive and
    varies by at most ``max_ratio`` (max/min): the straight ray only sees the
    speeds at its two ends, so a slow wall or a speed jump inside the box
    would otherwise be crossed for free. When
    every source has its ball, the ball cells are frozen (kept exact: letting
    the march lower them costs the order-2 scheme its rate, which falls to
    ~1); otherwise they only enter the narrow band.

    Parameters
    ----------
    src : ndarray, int64, shape (m, 3)
        Source indices.
    radius : float
        Ball radius [m]; 0 disables the ball.
    max_ratio : float
        Largest admissible max/min speed ratio in a source's box.
    """
    sx = ny * nz
    sy = nz
    m = src.shape[0]
    ri = int(math.floor(radius / hx)) if radius > 0 else 0
    rj = int(math.floor(radius / hy)) if radius > 0 else 0
    rk = int(math.floor(radius / hz)) if (radius > 0 and nz > 1) else 0
    r2 = radius * radius
    for s in range(m):
        si, sj, sk = src[s, 0], src[s, 1], src[s, 2]
        cs = si * sx + sj * sy + sk
        T[cs] = 0.0
        state[cs] = 2
    if radius <= 0:
        return
    # A ball is used only if its bounding box holds speeds > 0 only, with
    # max/min <= max_ratio; its cells are frozen (exact, kept) when every source
    # has a clean ball, else they only enter the band, so that a nearer route
    # past an obstacle near another source can still lower them.
    clean = np.ones(m, dtype=np.uint8)
    for s in range(m):
        si, sj, sk = src[s, 0], src[s, 1], src[s, 2]
        vmin = np.inf
        vmax = 0.0
        for i in range(max(si - ri, 0), min(si + ri, nx - 1) + 1):
            for j in range(max(sj - rj, 0), min(sj + rj, ny - 1) + 1):
                for k in range(max(sk - rk, 0), min(sk + rk, nz - 1) + 1):
                    v = speed[i * sx + j * sy + k]
                    vmin = min(vmin, v)
                    vmax = max(vmax, v)
        if not (vmin > 0.0 and vmax <= max_ratio * vmin):
            clean[s] = 0
    all_clean = True
    for s in range(m):
        if clean[s] == 0:
            all_clean = False
    ball_state = 2 if all_clean else 1
    for s in range(m):
        if clean[s] == 0:
            continue
        si, sj, sk = src[s, 0], src[s, 1], src[s, 2]
        cs = si * sx + sj * sy + sk
        vs = speed[cs]
        i0, i1 = max(si - ri, 0), min(si + ri, nx - 1)
        j0, j1 = max(sj - rj, 0), min(sj + rj, ny - 1)
        k0, k1 = max(sk - rk, 0), min(sk + rk, nz - 1)
        for i in range(i0, i1 + 1):
            dx = (i - si) * hx
            for j in range(j0, j1 + 1):
                dy = (j - sj) * hy
                for k in range(k0, k1 + 1):
                    dz = (k - sk) * hz
                    d2 = dx * dx + dy * dy + dz * dz
                    if d2 > r2:
                        continue
                    c = i * sx + j * sy + k
                    if T[c] == 0.0:
                        continue
                    t = math.sqrt(d2) * 0.5 * (1.0 / vs + 1.0 / speed[c])
                    if t < T[c]:
                        T[c] = t
                        state[c] = ball_state


# ------------------------------------------------------- exact distance transform
@njit(cache=True, error_model="numpy", inline="always")
def _edt_line(f, n, w2, v, z, out):
    """1D squared distance transform (Felzenszwalb & Huttenlocher 2012).

    ``out[q] = min_p (w2 * (q - p)^2 + f[p])`` over the finite ``f[p]``: the
    lower envelope of the parabolas rooted at the finite samples. ``w2`` is the
    squared spacing of the axis; ``v`` (int) and ``z`` (float) are scratch of
    length ``n`` and ``n + 1``.
    """
    k = -1
    for q in range(n):
        fq = f[q]
        if fq == np.inf:
            continue
        if k < 0:
            k = 0
            v[0] = q
            z[0] = -np.inf
            z[1] = np.inf
            continue
        while True:
            p = v[k]
            s = ((fq + w2 * q * q) - (f[p] + w2 * p * p)) / (2.0 * w2 * (q - p))
            if s <= z[k] and k > 0:
                k -= 1
            else:
                break
        if s <= z[k]:  # k == 0 and the new parabola hides the first one everywhere
            v[0] = q
            z[0] = -np.inf
            z[1] = np.inf
            continue
        k += 1
        v[k] = q
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


@njit(cache=True, error_model="numpy", parallel=True)
def squared_edt(occ, hx, hy, hz):
    """Exact squared Euclidean distance [m²] from every node to the nearest True node.

    Separable: one 1D transform per axis (z, then y, then x), lines in parallel.
    ``occ`` is a C-contiguous bool array of shape (nx, ny, nz); returns float64
    of the same shape (``inf`` everywhere if ``occ`` has no True node).
    """
    nx, ny, nz = occ.shape
    d = np.empty((nx, ny, nz), dtype=np.float64)
    wz, wy, wx = hz * hz, hy * hy, hx * hx
    nmax = max(nx, max(ny, nz))
    for i in prange(nx):
        f = np.empty(nmax)
        out = np.empty(nmax)
        v = np.empty(nmax, dtype=np.int64)
        z = np.empty(nmax + 1)
        for j in range(ny):
            for k in range(nz):
                f[k] = 0.0 if occ[i, j, k] else np.inf
            _edt_line(f, nz, wz, v, z, out)
            for k in range(nz):
                d[i, j, k] = out[k]
        if ny > 1:
            for k in range(nz):
                for j in range(ny):
                    f[j] = d[i, j, k]
                _edt_line(f, ny, wy, v, z, out)
                for j in range(ny):
                    d[i, j, k] = out[j]
    if nx > 1:
        for j in prange(ny):
            f = np.empty(nmax)
            out = np.empty(nmax)
            v = np.empty(nmax, dtype=np.int64)
            z = np.empty(nmax + 1)
            for k in range(nz):
                for i in range(nx):
                    f[i] = d[i, j, k]
                _edt_line(f, nx, wx, v, z, out)
                for i in range(nx):
                    d[i, j, k] = out[i]
    return d
