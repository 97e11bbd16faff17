"""Compiled point-source initialisation of the Fast Marching Method (the source ball).

Private module: :func:`fm2uav.eikonal.fast_marching` calls :func:`init_sources`
before the march (:func:`fm2uav.eikonal._kernels.march`), which receives the
frozen nodes and their times and returns ``T``. Arrays are flat, C-ordered
float64 arrays of a 3D grid ``(nx, ny, nz)`` (2D runs as ``nz = 1``), as in
:mod:`fm2uav.eikonal._kernels`.

Why a ball
----------
Near a point source the arrival time is a cone, ``T ~ s_s |x - x_s|`` (``s``
= 1/speed, slowness [s/m]); its gradient jumps at the source, so the upwind
stencils make an O(h) error in the first cells, which the march carries
everywhere (second order falls to ~1). Freezing accurate times in a ball of
fixed physical radius ``R`` around the source, and marching only from its
boundary, restores second order.

What the ball holds
-------------------
* **Constant speed** in the source's box: the exact straight-ray time ``d / v``
  (bit-for-bit the value fm2uav always gave).
* **Varying speed** in the box: the time of the *factored* eikonal equation
  (Fomel, Luo & Zhao 2009; Treister & Haber 2016), solved by a Fast Marching on
  the box alone. With ``T = T0 * tau`` and ``T0 = s_s |x - x_s|`` the exact
  constant-speed cone, ``|grad T| = s`` becomes

      | tau grad T0 + T0 grad tau | = s,

  and ``tau`` (1 at the source) is smooth where ``T`` is not, so the upwind
  differences of ``tau`` keep their order right up to the source. Per axis the
  frozen neighbour with the smaller ``T`` is upwind (the minus side wins a tie);
  ``d tau / dx_k ~ sigma a (tau - b)`` with ``a = 3 / (2 h)``,
  ``b = (4 tau_1 - tau_2) / 3`` (second order) where the next node in that
  direction is frozen and not later, else ``a = 1 / h``, ``b = tau_1``
  (``sigma = +1`` when the upwind neighbour is on the minus side). Each axis
  then contributes ``(alpha_k tau - beta_k)`` with ``alpha_k = dT0/dx_k +
  T0 sigma a`` and ``beta_k = T0 sigma a b``, and ``sum (alpha_k tau -
  beta_k)^2 = s^2`` is solved for every non-empty subset of the upwind axes
  (larger root). A root is admissible when, on each axis used, the discrete
  ``dT/dx_k = alpha_k tau - beta_k`` points away from the upwind neighbour
  (``sigma dT/dx_k >= 0``) and ``T = T0 tau`` is not earlier than that
  neighbour; the earliest admissible ``T`` wins. If none is admissible (not
  seen in smooth media), the node takes the first-order one-sided update
  ``T_1 + h / v``.

  In 1D this is the trapezoidal rule of the slowness: next to the source
  ``T_1 = h (s_0 + s_1) / 2``, and with second order ``T_2 = h (s_0 + 2 s_1 +
  s_2) / 2`` (composite trapezoid); on a straight ray of a constant-speed box
  it is exact (``tau = 1``).

The box is the source's bounding box of the ball, ``floor(R / h_k)`` nodes
either side per axis, clipped to the grid; the ball is the nodes at distance
``d <= R``. A box is *clean* when every speed in it is ``> 0`` and ``max / min
<= max_ratio`` (a wall or a jump inside the box belongs to the march, with its
first-order fallback across jumps). Each source takes the largest radius of
``R, R/2, R/4, ...`` whose box is clean, the last try being ``min_radius``
(2 cells): a smooth medium that varies by more than ``max_ratio`` over the
nominal box, or a wall or layer a few cells away, only shrinks the ball. A
source that is not clean even then gets no ball. When every source is clean
the ball nodes are frozen (final); otherwise they only enter the narrow band,
so a nearer route past an obstacle near another source can lower them. With
several sources a ball node keeps the smallest time over the sources.
"""

from __future__ import annotations

import math

import numpy as np

from .._numba import njit
from ._heap import sift_down, sift_up

_INF = np.inf


# ------------------------------------------------------------ heap of the box march
@njit(cache=True, error_model="numpy")
def _heap_push(heap, key, pos, size, c, t):
    """Insert ``c`` with key ``t``, or lower its key; return the new size."""
    p = pos[c]
    if p < 0:
        p = size
        size += 1
    sift_up(key, heap, pos, p, t, c)
    return size


@njit(cache=True, error_model="numpy")
def _heap_pop(heap, key, pos, size):
    """Remove the root of a heap of ``size`` items; return ``(index, new size)``."""
    top = heap[0]
    pos[top] = -1
    size -= 1
    if size > 0:
        sift_down(key, heap, pos, size, key[size], heap[size])
    return top, size


# ------------------------------------------------------- factored local solver
@njit(cache=True, error_model="numpy", inline="always")  # 2048^2 smooth's ball 9.4 -> 8.2 ms
def _factored_update(tb, tau, st, sb, c, coord, dims, strides, h, x, dist, ss,
                     alpha, beta, sgn, tnb, hnb):
    """Arrival time [s] at box node ``c`` from its frozen neighbours (factored).

    ``tb``/``tau``/``st``/``sb``: time, factor, state and speed of the box nodes;
    ``coord``: the node's box indices; ``x``: its offset from the source [m] per
    axis and ``dist`` its distance [m]; ``ss``: the source's slowness [s/m].
    ``alpha``/``beta``/``sgn``/``tnb``/``hnb``: work arrays of length 3.
    Returns ``inf`` when no axis has a frozen neighbour.
    """
    s = 1.0 / sb[c]
    t0 = ss * dist
    m = 0
    for a in range(3):
        n_a = dims[a]
        if n_a == 1:
            continue
        stride = strides[a]
        best = _INF
        d = 0
        if coord[a] > 0 and st[c - stride] == 2:
            best = tb[c - stride]
            d = -1
        if coord[a] < n_a - 1 and st[c + stride] == 2 and tb[c + stride] < best:
            best = tb[c + stride]
            d = 1
        if d == 0:
            continue
        c1 = c + d * stride
        ka = 1.0 / h[a]
        kb = tau[c1]
        ok2 = coord[a] > 1 if d == -1 else coord[a] < n_a - 2
        if ok2:
            c2 = c1 + d * stride
            if st[c2] == 2 and tb[c2] <= best:
                ka = 1.5 / h[a]
                kb = (4.0 * tau[c1] - tau[c2]) / 3.0
        sg = -1.0 * d
        alpha[m] = ss * x[a] / dist + t0 * sg * ka
        beta[m] = t0 * sg * ka * kb
        sgn[m] = sg
        tnb[m] = best
        hnb[m] = h[a]
        m += 1
    if m == 0:
        return _INF
    best_t = _INF
    for mask in range(1, 1 << m):
        A = 0.0
        B = 0.0
        C = 0.0
        for a in range(m):
            if (mask >> a) & 1:
                A += alpha[a] * alpha[a]
                B += alpha[a] * beta[a]
                C += beta[a] * beta[a]
        if A <= 0.0:
            continue
        disc = B * B - A * (C - s * s)
        if disc < 0.0:
            continue
        f = (B + math.sqrt(disc)) / A
        t = t0 * f
        if not t < best_t:
            continue
        ok = True
        for a in range(m):
            if (mask >> a) & 1:
                if sgn[a] * (alpha[a] * f - beta[a]) < 0.0 or t < tnb[a]:
                    ok = False
                    break
        if ok:
            best_t = t
    if best_t == _INF:  # no admissible root: first-order one-sided update
        for a in range(m):
            best_t = min(best_t, tnb[a] + hnb[a] * s)
    return best_t


@njit(cache=True, error_model="numpy")
def factored_box(sb, bx, by, bz, li, lj, lk, hx, hy, hz):
    """Solve the factored eikonal equation on one source's box by Fast Marching.

    Parameters
    ----------
    sb : ndarray, float64, shape (bx*by*bz,)
        Speeds [m/s] of the box nodes, all ``> 0``, C order.
    bx, by, bz : int
        Box shape.
    li, lj, lk : int
        The source's indices in the box.
    hx, hy, hz : float
        Spacing per axis [m].

    Returns
    -------
    ndarray, float64, shape (bx*by*bz,)
        Arrival time [s] of every box node (0 at the source).
    """
    n = bx * by * bz
    # every array from np.empty with one of three dtypes: each distinct numpy
    # constructor call (np.full, np.ones, np.array of a list, ...) compiles its
    # own overload on first use (~0.1 s each)
    three = np.int64(3)
    dims = np.empty(three, dtype=np.int64)
    strides = np.empty(three, dtype=np.int64)
    h = np.empty(three, dtype=np.float64)
    lsrc = np.empty(three, dtype=np.int64)
    dims[0], dims[1], dims[2] = bx, by, bz
    strides[0], strides[1], strides[2] = by * bz, bz, 1
    h[0], h[1], h[2] = hx, hy, hz
    lsrc[0], lsrc[1], lsrc[2] = li, lj, lk
    tb = np.empty(n, dtype=np.float64)
    tau = np.empty(n, dtype=np.float64)
    st = np.empty(n, dtype=np.uint8)
    heap = np.empty(n, dtype=np.int64)
    key = np.empty(n, dtype=np.float64)
    pos = np.empty(n, dtype=np.int64)
    for c in range(n):
        tb[c] = _INF
        tau[c] = 1.0
        st[c] = 0
        pos[c] = -1
    coord = np.empty(three, dtype=np.int64)
    ncoord = np.empty(three, dtype=np.int64)
    x = np.empty(three, dtype=np.float64)
    alpha = np.empty(three, dtype=np.float64)
    beta = np.empty(three, dtype=np.float64)
    sgn = np.empty(three, dtype=np.float64)
    tnb = np.empty(three, dtype=np.float64)
    hnb = np.empty(three, dtype=np.float64)
    ss = 1.0 / sb[li * strides[0] + lj * strides[1] + lk]
    cs = li * strides[0] + lj * strides[1] + lk
    tb[cs] = 0.0
    # the source as the heap's only entry (what _heap_push does on an empty heap;
    # a call with the literal size 0 would compile a second specialisation of it)
    heap[0] = cs
    key[0] = 0.0
    pos[cs] = 0
    size = np.int64(1)  # int64, not the literal 1 (see above)
    while size > 0:
        c, size = _heap_pop(heap, key, pos, size)
        st[c] = 2
        coord[0] = c // strides[0]
        coord[1] = (c - coord[0] * strides[0]) // strides[1]
        coord[2] = c - coord[0] * strides[0] - coord[1] * strides[1]
        for a in range(3):
            for step in (-1, 1):
                q = coord[a] + step
                if q < 0 or q >= dims[a]:
                    continue
                d = c + step * strides[a]
                if st[d] == 2:
                    continue
                dist2 = 0.0
                for b in range(3):
                    ncoord[b] = coord[b]
                ncoord[a] = q
                for b in range(3):
                    x[b] = (ncoord[b] - lsrc[b]) * h[b]
                    dist2 += x[b] * x[b]
                dist = math.sqrt(dist2)
                t = _factored_update(tb, tau, st, sb, d, ncoord, dims, strides, h, x, dist,
                                     ss, alpha, beta, sgn, tnb, hnb)
                if t < tb[d]:
                    tb[d] = t
                    tau[d] = t / (ss * dist)
                    size = _heap_push(heap, key, pos, size, d, t)
    return tb


# ------------------------------------------------------------------ the ball
@njit(cache=True, error_model="numpy")
def _box_range(speed, si, sj, sk, ri, rj, rk, nx, ny, nz):
    """Smallest and largest speed [m/s] in the box of half-widths ``ri, rj, rk`` nodes."""
    sx = ny * nz
    vmin = np.inf
    vmax = 0.0
    for i in range(max(si - ri, 0), min(si + ri, nx - 1) + 1):
        for j in range(max(sj - rj, 0), min(sj + rj, ny - 1) + 1):
            for k in range(max(sk - rk, 0), min(sk + rk, nz - 1) + 1):
                v = speed[i * sx + j * nz + k]
                vmin = min(vmin, v)
                vmax = max(vmax, v)
    return vmin, vmax


# long on purpose: one compiled loop (numba kernel); helpers would add calls in the hot path
@njit(cache=True, error_model="numpy", nogil=True)
def init_sources(speed, T, state, nx, ny, nz, hx, hy, hz, src, radius, min_radius, max_ratio):
    """Initialise point sources in place: ``T = 0`` (frozen) and the source balls.

    Long by design (kernel): one compiled loop; splitting adds call overhead in the hot path.

    See the module docstring for the rule. Same interface as the march expects:
    on return ``T``/``state`` hold the sources (0, frozen) and the ball nodes
    (frozen when every source is clean, else in the band, ``state = 1``).

    Parameters
    ----------
    speed : ndarray, float64, shape (nx*ny*nz,)
        Speed [m/s] (validated, ``>= 0``).
    T, state : ndarray, shape (nx*ny*nz,)
        ``inf`` / 0 on entry; written.
    nx, ny, nz : int
        Grid shape (``nz = 1`` for 2D).
    hx, hy, hz : float
        Spacing per axis [m].
    src : ndarray, int64, shape (m, 3)
        Source indices.
    radius : float
        Ball radius [m]; 0 disables the ball.
    min_radius : float
        Smallest ball radius [m]: a source whose box is not clean at ``radius``
        tries half of it, and so on, down to ``min_radius`` (the last try).
    max_ratio : float
        Largest admissible max/min speed ratio in a source's box.
    """
    sx = ny * nz
    sy = nz
    m = src.shape[0]
    for s in range(m):
        cs = src[s, 0] * sx + src[s, 1] * sy + src[s, 2]
        T[cs] = 0.0
        state[cs] = 2
    if radius <= 0:
        return
    # each source's radius: the largest of radius, radius/2, ..., min_radius whose
    # box is clean (speeds > 0, max/min <= max_ratio); none: not clean
    clean = np.empty(m, dtype=np.uint8)  # np.empty only: see factored_box
    constant = np.empty(m, dtype=np.uint8)
    rad = np.empty(m, dtype=np.float64)
    reach = np.empty(m * 3, dtype=np.int64).reshape(m, 3)
    for s in range(m):
        clean[s] = 1
        constant[s] = 0
    for s in range(m):
        r = radius
        ri = rj = rk = 0
        vmin = vmax = 0.0
        while True:
            ri = int(math.floor(r / hx))
            rj = int(math.floor(r / hy))
            rk = int(math.floor(r / hz)) if nz > 1 else 0
            vmin, vmax = _box_range(speed, src[s, 0], src[s, 1], src[s, 2], ri, rj, rk, nx, ny, nz)
            if vmin > 0.0 and vmax <= max_ratio * vmin:
                break
            if r <= min_radius:
                clean[s] = 0
                break
            r = max(0.5 * r, min_radius)
        rad[s] = r
        reach[s, 0] = ri
        reach[s, 1] = rj
        reach[s, 2] = rk
        if clean[s] == 1 and vmax == vmin:
            constant[s] = 1
    all_clean = True
    for s in range(m):
        if clean[s] == 0:
            all_clean = False
    ball_state = 2 if all_clean else 1
    for s in range(m):
        if clean[s] == 0:
            continue
        si, sj, sk = src[s, 0], src[s, 1], src[s, 2]
        vs = speed[si * sx + sj * sy + sk]
        r2 = rad[s] * rad[s]
        i0, i1 = max(si - reach[s, 0], 0), min(si + reach[s, 0], nx - 1)
        j0, j1 = max(sj - reach[s, 1], 0), min(sj + reach[s, 1], ny - 1)
        k0, k1 = max(sk - reach[s, 2], 0), min(sk + reach[s, 2], nz - 1)
        bx, by, bz = i1 - i0 + 1, j1 - j0 + 1, k1 - k0 + 1
        tb = np.empty(np.int64(0), dtype=np.float64)
        if constant[s] == 0:
            sb = np.empty(bx * by * bz, dtype=np.float64)
            for i in range(i0, i1 + 1):
                for j in range(j0, j1 + 1):
                    for k in range(k0, k1 + 1):
                        sb[((i - i0) * by + (j - j0)) * bz + (k - k0)] = speed[i * sx + j * sy + k]
            tb = factored_box(sb, bx, by, bz, si - i0, sj - j0, sk - k0, hx, hy, hz)
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
                    if constant[s] == 1:
                        t = math.sqrt(d2) * 0.5 * (1.0 / vs + 1.0 / speed[c])
                    else:
                        t = tb[((i - i0) * by + (j - j0)) * bz + (k - k0)]
                    if t < T[c]:
                        T[c] = t
                        state[c] = ball_state
