"""Compiled (numba) kernel of the geodesic extraction (gradient descent on T).

Private module: the public entry point is :func:`fm2uav.planning.geodesic.descend`,
which validates the input and calls :func:`descend_kernel`. Everything here works
on a 3D float64 array ``T[ix, iy, iz]``; a 2D field is passed as ``(nx, ny, 1)``
so one kernel serves both. Points are continuous *index* coordinates; node ``i``
sits at coordinate ``i`` and owns the box ``[i - 0.5, i + 0.5)`` on every axis
(its Voronoi cell). ``T`` already carries ``inf`` on blocked nodes, so "free"
means "finite T" throughout.

Three ingredients (see :func:`fm2uav.planning.geodesic.descend` for the why):

* **node direction** (:func:`_node_direction`): the unit descent direction at a
  node, per axis a central difference where ``T`` is monotone through the node
  and the Fast Marching upwind choice where it is not (one-sided towards the
  smaller neighbour, 0 when no neighbour is smaller);
* **direction field** (:func:`_direction`): those unit vectors blended with
  cubic B-spline weights over the 4 x 4 x 4 nodes around the point (a C2 field),
  or linearly over the cell's corners when a smooth step is blocked;
* **potential** (:func:`_potential`): ``min(trilinear T, cone estimate)``, the
  value that must go down for a step to be accepted (non-monotone, against the
  largest of the last ``_WINDOW`` accepted values, with sufficient decrease).

Status codes returned by :func:`descend_kernel`
------------------------------------------------
``OK`` (0)
    The path reached the goal; its last point is the goal.
``STUCK`` (1)
    Discrete descent reached a node with no free neighbour of strictly smaller
    ``T`` that is not within one cell of the goal (a local minimum of ``T``
    that is not the goal: the field was not made from this goal, or it has
    plateaus without an exit). ``info`` holds that node.
"""

from __future__ import annotations

import math

import numpy as np

from .._numba import njit

OK = 0
STUCK = 1

#: Boxes are shrunk by this much [cells] in the segment test, so a segment that
#: only *touches* a blocked node's cell (a face, edge or corner) is not "inside".
_EPS = 1e-9
#: Step-length divisors tried (backtracking) before falling back to a discrete move.
_N_BACKTRACK = 3
#: Non-monotone acceptance: a step must bring the potential below the largest
#: of the last ``_WINDOW`` accepted potentials (Grippo, Lampariello & Lucidi
#: 1986), so that maximum strictly decreases every ``_WINDOW`` steps.
_WINDOW = 8
#: ... by at least this fraction of the nominal decrease of T over the step
#: (step length times the local slowness), so a stalled, oscillating descent
#: is stopped within a few steps.
_DECREASE = 0.1


# --------------------------------------------------------------------------- helpers
@njit(cache=True, inline="always", error_model="numpy")
def _nearest(x, n):
    """Nearest node index of coordinate ``x`` on an axis of ``n`` nodes (half up)."""
    i = int(math.floor(x + 0.5))
    if i < 0:
        return 0
    if i > n - 1:
        return n - 1
    return i


@njit(cache=True, inline="always", error_model="numpy")
def _cell(x, n):
    """Lower corner index and fraction of the interpolation cell holding ``x``."""
    if n == 1:
        return 0, 0, 0.0
    i0 = int(math.floor(x))
    if i0 < 0:
        i0 = 0
    if i0 > n - 2:
        i0 = n - 2
    f = x - i0
    if f < 0.0:
        f = 0.0
    if f > 1.0:
        f = 1.0
    return i0, i0 + 1, f


@njit(cache=True, inline="always", error_model="numpy")
def _axis_slope(tc, tm, tp, h):
    """Derivative [s/m] of T along one axis at a free node, from its neighbours.

    ``tm``/``tp`` are the lower/upper neighbours, ``inf`` if blocked,
    unreached or off the grid. Where T is monotone through the node
    (``tm < tc < tp`` or ``tp < tc < tm``, both finite) the central difference
    ``(tp - tm) / 2h``. Elsewhere the node is a kink of T along the axis (or
    next to a blocked node or the grid's edge) and the Fast Marching upwind
    choice is used, as in :func:`fm2uav.eikonal._kernels._axis_term`: the
    one-sided difference towards the smaller neighbour if it is below ``tc``,
    and 0 if no neighbour is below ``tc`` (no characteristic arrives along
    this axis: the node is a minimum along it, e.g. on a one-cell bright
    layer, or the only lower side is blocked or off the map) or both are
    equal (a ridge).
    """
    if math.isfinite(tm) and math.isfinite(tp) and (tm < tc < tp or tp < tc < tm):
        return (tp - tm) / (2.0 * h)
    if tm < tc and tm < tp:
        return (tc - tm) / h
    if tp < tc and tp < tm:
        return (tp - tc) / h
    return 0.0


@njit(cache=True, error_model="numpy")
def _node_direction(T, i, j, k, hx, hy, hz):
    """Unit physical gradient of T at a free node (0 vector if it vanishes).

    Each component from :func:`_axis_slope`; neighbours off the grid count as
    ``inf``. Returns ``(ux, uy, uz)``.
    """
    nx, ny, nz = T.shape
    tc = T[i, j, k]
    gx = _axis_slope(
        tc, T[i - 1, j, k] if i > 0 else np.inf, T[i + 1, j, k] if i < nx - 1 else np.inf, hx
    )
    gy = _axis_slope(
        tc, T[i, j - 1, k] if j > 0 else np.inf, T[i, j + 1, k] if j < ny - 1 else np.inf, hy
    )
    gz = _axis_slope(
        tc, T[i, j, k - 1] if k > 0 else np.inf, T[i, j, k + 1] if k < nz - 1 else np.inf, hz
    )
    g = math.sqrt(gx * gx + gy * gy + gz * gz)
    if not (g > 0.0) or not math.isfinite(g):
        return 0.0, 0.0, 0.0
    return gx / g, gy / g, gz / g


@njit(cache=True, inline="always", error_model="numpy")
def _smoothing(h, hmin):
    """Share ``lam`` of the cubic B-spline in an axis' blend (the rest: linear).

    The blend ``lam * cubic + (1 - lam) * linear`` has variance
    ``(1 + lam) / 6`` cells^2, i.e. ``(1 + lam) h^2 / 6`` m^2. ``lam = 1`` on the
    finest axis and ``2 (hmin / h)^2 - 1`` (clipped to [0, 1]) on coarser ones
    keeps the smoothing isotropic in metres where possible, so that the blend
    does not turn the direction of a curved field (near the goal) on
    anisotropic grids.
    """
    lam = 2.0 * (hmin / h) ** 2 - 1.0
    if lam < 0.0:
        return 0.0
    if lam > 1.0:
        return 1.0
    return lam


@njit(cache=True, inline="always", error_model="numpy")
def _bspline_weights(x, n, lam, w, o):
    """Uniform cubic B-spline weights of the 4 nodes around ``x`` on an axis of ``n``.

    Fills ``w[o:o + 4]`` (weights of nodes ``i0 - 1 .. i0 + 2``, ``i0 = floor(x)``,
    summing to 1) and returns ``i0 - 1``. A single-node axis gets weight 1 on
    node 0. Nodes off the grid are skipped by the caller.
    """
    if n == 1:
        w[o] = 1.0
        w[o + 1] = 0.0
        w[o + 2] = 0.0
        w[o + 3] = 0.0
        return 0
    i0 = int(math.floor(x))
    if i0 > n - 2:
        i0 = n - 2
    if i0 < 0:
        i0 = 0
    f = x - i0
    g = 1.0 - f
    w[o] = lam * g * g * g / 6.0
    w[o + 1] = lam * (3.0 * f * f * f - 6.0 * f * f + 4.0) / 6.0 + (1.0 - lam) * g
    w[o + 2] = lam * (3.0 * g * g * g - 6.0 * g * g + 4.0) / 6.0 + (1.0 - lam) * f
    w[o + 3] = lam * f * f * f / 6.0
    return i0 - 1


#: Slots of a descent's cache of node directions (``keys``/``vals`` of :func:`_direction`):
#: node (i, j, k) goes to slot ((i mod 16) * 16 + j mod 16) * 4 + k mod 4, so the
#: 4 x 4 x 4 nodes of one blend never share a slot, and consecutive steps, whose blends
#: overlap, find most of their nodes there (T does not change during a descent).
_CACHE_SLOTS = 1024


@njit(cache=True, error_model="numpy")
def _direction(T, x, y, z, hx, hy, hz, hmin, smooth, keys, vals, w):
    """Index-space displacement of one unit-physical-length descent step.

    The unit node directions (:func:`_node_direction`) of the free nodes among
    the 4 x 4 x 4 around the point are blended with cubic B-spline weights
    (renormalised over the free nodes; per axis mixed with linear weights,
    see :func:`_smoothing`, and ``smooth = 0`` gives the plain linear blend
    of the 2 x 2 x 2 corners). The blend is C2 in the point, and it
    averages over about two cells, so a path following it rounds the corners
    of a staircase (a one-cell layer over sloping terrain) instead of
    tracing them. The physical direction ``d = -blend / |blend|`` is converted
    to index units ``d_i / h_i`` and scaled by ``hmin`` so that the caller's
    step length ``step`` [cells] is ``step * hmin`` metres. Returns
    ``(dx, dy, dz, ok)``; ``ok`` is False when no free node contributes or the
    blend vanishes.

    ``keys`` (int64, :data:`_CACHE_SLOTS`, -1 = empty) and ``vals`` (``(_CACHE_SLOTS,
    3)``) cache the node directions of the descent (each node's the same numbers,
    computed once); ``w`` (12) is scratch for the three axes' weights (no allocation
    per call). The loops are written out here, not in a helper: numba's inlining
    adds a reference count update of every array argument per call.
    """
    nx, ny, nz = T.shape
    ia = _bspline_weights(x, nx, smooth * _smoothing(hx, hmin), w, 0)
    ja = _bspline_weights(y, ny, smooth * _smoothing(hy, hmin), w, 4)
    ka = _bspline_weights(z, nz, smooth * _smoothing(hz, hmin), w, 8)
    gx = 0.0
    gy = 0.0
    gz = 0.0
    for a in range(4):
        i = ia + a
        if i < 0 or i >= nx or w[a] == 0.0:
            continue
        for b in range(4):
            j = ja + b
            if j < 0 or j >= ny or w[4 + b] == 0.0:
                continue
            wab = w[a] * w[4 + b]
            for c in range(4):
                k = ka + c
                if k < 0 or k >= nz or w[8 + c] == 0.0:
                    continue
                if not math.isfinite(T[i, j, k]):
                    continue
                wt = wab * w[8 + c]
                key = (i * ny + j) * nz + k
                slot = ((i & 15) * 16 + (j & 15)) * 4 + (k & 3)
                if keys[slot] != key:
                    ux, uy, uz = _node_direction(T, i, j, k, hx, hy, hz)
                    keys[slot] = key
                    vals[slot, 0] = ux
                    vals[slot, 1] = uy
                    vals[slot, 2] = uz
                else:
                    ux = vals[slot, 0]
                    uy = vals[slot, 1]
                    uz = vals[slot, 2]
                gx += wt * ux
                gy += wt * uy
                gz += wt * uz
    g = math.sqrt(gx * gx + gy * gy + gz * gz)
    if not (g > 0.0) or not math.isfinite(g):
        return 0.0, 0.0, 0.0, False
    return -gx / g * hmin / hx, -gy / g * hmin / hy, -gz / g * hmin / hz, True


@njit(cache=True, error_model="numpy")
def _interp_T(T, x, y, z):
    """Trilinear T at a point, averaged over the finite corners only.

    Returns ``inf`` if every corner with a non-zero weight is ``inf``.
    """
    nx, ny, nz = T.shape
    i0, i1, fx = _cell(x, nx)
    j0, j1, fy = _cell(y, ny)
    k0, k1, fz = _cell(z, nz)
    acc = 0.0
    wsum = 0.0
    for a in range(2):
        i = i1 if a else i0
        wa = fx if a else 1.0 - fx
        if wa == 0.0:
            continue
        for b in range(2):
            j = j1 if b else j0
            wb = wa * (fy if b else 1.0 - fy)
            if wb == 0.0:
                continue
            for c in range(2):
                k = k1 if c else k0
                w = wb * (fz if c else 1.0 - fz)
                if w == 0.0:
                    continue
                t = T[i, j, k]
                if math.isfinite(t):
                    acc += w * t
                    wsum += w
    if wsum == 0.0:
        return np.inf
    return acc / wsum


@njit(cache=True, error_model="numpy")
def _slowness(T, i, j, k, hx, hy, hz):
    """Slowness estimate [s/m] at a free node: ``|grad T|`` of the upwind stencil.

    Per axis ``max(T - min(neighbours), 0) / h`` (the first-order Fast Marching
    stencil, whose norm is ``1 / speed``). At a node with no smaller neighbour
    (the source) the smallest positive one-sided slope is used instead.
    """
    nx, ny, nz = T.shape
    tc = T[i, j, k]
    acc = 0.0
    low = np.inf
    for ax in range(3):
        if ax == 0:
            tm = T[i - 1, j, k] if i > 0 else np.inf
            tp = T[i + 1, j, k] if i < nx - 1 else np.inf
            h = hx
        elif ax == 1:
            tm = T[i, j - 1, k] if j > 0 else np.inf
            tp = T[i, j + 1, k] if j < ny - 1 else np.inf
            h = hy
        else:
            tm = T[i, j, k - 1] if k > 0 else np.inf
            tp = T[i, j, k + 1] if k < nz - 1 else np.inf
            h = hz
        u = min(tm, tp)
        if u < tc:
            acc += ((tc - u) / h) ** 2
        elif math.isfinite(u) and u > tc:
            low = min(low, (u - tc) / h)
    if acc > 0.0:
        return math.sqrt(acc)
    return low if math.isfinite(low) else 0.0


@njit(cache=True, error_model="numpy")
def _potential(T, x, y, z, hx, hy, hz):
    """Descent potential [s] at a point: ``min(trilinear T, cone estimate)``.

    The cone estimate is ``min_c T_c + s_c |p - c|`` over the free corners
    ``c`` of the interpolation cell, ``s_c`` the slowness at ``c``
    (:func:`_slowness`): the time to fly straight to ``c`` and on from there
    (the one-step Hopf-Lax / semi-Lagrangian form of the eikonal equation).
    Trilinear ``T`` blends in the (much larger) times of the dark nodes
    beside a one-cell bright channel, so it rises steeply as soon as the point
    leaves the channel's centre line; the cone grows only with the distance
    to the next channel node (to second order across the channel). In smooth
    regions the cone lies above ``T`` and the minimum is the trilinear value.
    Returns ``inf`` if no corner with a non-zero weight is free.
    """
    t = _interp_T(T, x, y, z)
    if not math.isfinite(t):
        return t
    nx, ny, nz = T.shape
    i0, i1, _ = _cell(x, nx)
    j0, j1, _ = _cell(y, ny)
    k0, k1, _ = _cell(z, nz)
    # a single-node axis (2D: z) has i0 == i1: its corner once (a second visit of the
    # same corner changes nothing)
    for a in range(1 if i0 == i1 else 2):
        i = i1 if a else i0
        for b in range(1 if j0 == j1 else 2):
            j = j1 if b else j0
            for c in range(1 if k0 == k1 else 2):
                k = k1 if c else k0
                tc = T[i, j, k]
                if not (tc < t):  # also skips inf
                    continue
                dx = (x - i) * hx
                dy = (y - j) * hy
                dz = (z - k) * hz
                v = tc + _slowness(T, i, j, k, hx, hy, hz) * math.sqrt(dx * dx + dy * dy + dz * dz)
                if v < t:
                    t = v
    return t


@njit(cache=True, inline="always", error_model="numpy")
def _clamp(x, n):
    if x < 0.0:
        return 0.0
    if x > n - 1.0:
        return n - 1.0
    return x


@njit(cache=True, error_model="numpy")
def _segment_free(T, px, py, pz, qx, qy, qz):
    """True if the segment p-q enters no cell (Voronoi box) of a non-finite node.

    Exact: every node whose box ``[c - 0.5, c + 0.5]`` (shrunk by ``_EPS``) the
    segment intersects is checked (slab test); touching a box only on its
    boundary does not count.
    """
    nx, ny, nz = T.shape
    dx = qx - px
    dy = qy - py
    dz = qz - pz
    ia = _nearest(min(px, qx) - 0.5, nx)
    ib = _nearest(max(px, qx) + 0.5, nx)
    ja = _nearest(min(py, qy) - 0.5, ny)
    jb = _nearest(max(py, qy) + 0.5, ny)
    ka = _nearest(min(pz, qz) - 0.5, nz)
    kb = _nearest(max(pz, qz) + 0.5, nz)
    for i in range(ia, ib + 1):
        for j in range(ja, jb + 1):
            for k in range(ka, kb + 1):
                if math.isfinite(T[i, j, k]):
                    continue
                # slab test of the segment against the shrunk box of node (i, j, k)
                t0 = 0.0
                t1 = 1.0
                hit = True
                for ax in range(3):
                    if ax == 0:
                        p, d, c = px, dx, i
                    elif ax == 1:
                        p, d, c = py, dy, j
                    else:
                        p, d, c = pz, dz, k
                    lo = c - 0.5 + _EPS
                    hi = c + 0.5 - _EPS
                    if d == 0.0:
                        if p <= lo or p >= hi:
                            hit = False
                            break
                    else:
                        ta = (lo - p) / d
                        tb = (hi - p) / d
                        if ta > tb:
                            ta, tb = tb, ta
                        if ta > t0:
                            t0 = ta
                        if tb < t1:
                            t1 = tb
                        if t0 >= t1:
                            hit = False
                            break
                if hit:
                    return False
    return True


@njit(cache=True, error_model="numpy")
def _best_neighbour(T, i, j, k):
    """Free 26-neighbour (8 in 2D) with the smallest T, strictly below ``T[i, j, k]``.

    A diagonal move is allowed only if every node of the box spanned by the two
    nodes is free (no squeezing between obstacles that touch at an edge or a
    corner). Returns ``(bi, bj, bk, found)``.
    """
    nx, ny, nz = T.shape
    best = T[i, j, k]
    bi, bj, bk = i, j, k
    found = False
    for di in range(-1, 2):
        ii = i + di
        if ii < 0 or ii >= nx:
            continue
        for dj in range(-1, 2):
            jj = j + dj
            if jj < 0 or jj >= ny:
                continue
            for dk in range(-1, 2):
                kk = k + dk
                if kk < 0 or kk >= nz:
                    continue
                if di == 0 and dj == 0 and dk == 0:
                    continue
                t = T[ii, jj, kk]
                if not (t < best):
                    continue
                if abs(di) + abs(dj) + abs(dk) > 1:
                    clear = True
                    for a in range(min(i, ii), max(i, ii) + 1):
                        for b in range(min(j, jj), max(j, jj) + 1):
                            for c in range(min(k, kk), max(k, kk) + 1):
                                if not math.isfinite(T[a, b, c]):
                                    clear = False
                    if not clear:
                        continue
                best = t
                bi, bj, bk = ii, jj, kk
                found = True
    return bi, bj, bk, found


@njit(cache=True, error_model="numpy")
def _push(out, n, x, y, z):
    """Append a point to the growable buffer ``out`` holding ``n`` points."""
    if n > 0 and out[n - 1, 0] == x and out[n - 1, 1] == y and out[n - 1, 2] == z:
        return out, n  # never store a zero-length segment
    if n == out.shape[0]:
        # element by element: a slice assignment compiles numba's shape-mismatch
        # error formatting (~3 s of one-off compilation)
        bigger = np.empty((2 * out.shape[0], 3))
        for r in range(n):
            bigger[r, 0] = out[r, 0]
            bigger[r, 1] = out[r, 1]
            bigger[r, 2] = out[r, 2]
        out = bigger
    out[n, 0] = x
    out[n, 1] = y
    out[n, 2] = z
    return out, n + 1


@njit(cache=True, error_model="numpy")
def _near_goal(T, px, py, pz, gx, gy, gz):
    """Within one cell (Chebyshev, index units) of the goal, with a free segment."""
    if abs(px - gx) > 1.0 or abs(py - gy) > 1.0 or abs(pz - gz) > 1.0:
        return False
    return _segment_free(T, px, py, pz, gx, gy, gz)


@njit(cache=True, error_model="numpy")
def _try_step(T, px, py, pz, ref, hx, hy, hz, hmin, step, keys, vals, w):
    """One continuous descent step from p; returns ``(qx, qy, qz, phi(q), ok)``.

    Midpoint rule (RK2): the direction is taken at p + L/2 * d(p) (or d(p) if
    that is invalid or turns back). The step is accepted if the potential at q
    (:func:`_potential`) is below ``ref`` by at least ``_DECREASE`` times the
    nominal decrease ``slowness * length``, q's nearest node is free and the
    segment p-q enters no blocked cell; otherwise the length is halved, up to
    ``_N_BACKTRACK`` tries. If all fail with the smooth (B-spline) direction
    field, they are repeated with the linear blend (``smooth = 0``), which
    follows the node directions tightly around the corner of a blocked cell
    that the smooth field would cut. ``keys``, ``vals``, ``w``: the descent's cache
    and scratch for :func:`_direction`.
    """
    nx, ny, nz = T.shape
    # sufficient decrease: a fraction of what a step of L cells lowers T by
    # at the local slowness
    slow = _slowness(T, _nearest(px, nx), _nearest(py, ny), _nearest(pz, nz), hx, hy, hz)
    for smooth in (1.0, 0.0):
        d1x, d1y, d1z, ok = _direction(T, px, py, pz, hx, hy, hz, hmin, smooth, keys, vals, w)
        if not ok:
            continue
        L = step
        for _ in range(_N_BACKTRACK):
            mx = _clamp(px + 0.5 * L * d1x, nx)
            my = _clamp(py + 0.5 * L * d1y, ny)
            mz = _clamp(pz + 0.5 * L * d1z, nz)
            d2x, d2y, d2z, ok2 = _direction(T, mx, my, mz, hx, hy, hz, hmin, smooth, keys, vals, w)
            if not ok2 or (d1x * d2x + d1y * d2y + d1z * d2z) <= 0.0:
                d2x, d2y, d2z = d1x, d1y, d1z
            qx = _clamp(px + L * d2x, nx)
            qy = _clamp(py + L * d2y, ny)
            qz = _clamp(pz + L * d2z, nz)
            bound = ref - _DECREASE * slow * L * hmin
            # the step, then (if it enters a blocked cell) the step sliding
            # along that cell's face: one axis component dropped
            for drop in range(-1, 3):
                if drop == 0:
                    qx = px
                elif drop == 1:
                    qx = _clamp(px + L * d2x, nx)
                    qy = py
                elif drop == 2:
                    qy = _clamp(py + L * d2y, ny)
                    qz = pz
                if qx == px and qy == py and qz == pz:
                    continue
                tq = _potential(T, qx, qy, qz, hx, hy, hz)
                if (
                    tq < bound
                    and math.isfinite(T[_nearest(qx, nx), _nearest(qy, ny), _nearest(qz, nz)])
                    and _segment_free(T, px, py, pz, qx, qy, qz)
                ):
                    return qx, qy, qz, tq, True
                if drop == -1 and _segment_free(T, px, py, pz, qx, qy, qz):
                    break  # free but not low enough: shorten, do not slide
            L *= 0.5
    return px, py, pz, ref, False


@njit(cache=True, inline="always", error_model="numpy")
def _fill(a, x):
    """``a[:] = x`` as a loop (numba's slice assignment compiles error-formatting code)."""
    for r in range(a.size):
        a[r] = x


@njit(cache=True, inline="always", error_model="numpy")
def _nanmax(a):
    """``a.max()`` with numpy's semantics (NaN if any element is NaN), as a loop."""
    m = a[0]
    for r in range(a.size):
        x = a[r]
        if math.isnan(x):
            return x
        if x > m:
            m = x
    return m


# --------------------------------------------------------------------------- kernel
# long on purpose: one compiled loop (numba kernel); helpers would add calls in the hot path;
# nogil: the many-routes descent (geodesic.descend_stopped) runs it in several threads
@njit(cache=True, error_model="numpy", nogil=True)
def descend_kernel(T, start, goal, hx, hy, hz, step, max_steps):
    """Descend ``T`` from ``start`` to ``goal``; see the module docstring.

    Long by design (kernel): one compiled loop; splitting adds call overhead in the hot path.

    Parameters
    ----------
    T : float64 array (nx, ny, nz)
        Arrival times [s], ``inf`` on blocked / unreached nodes.
    start, goal : float64 array (3,)
        Continuous index coordinates; their nearest nodes are free (checked by
        the caller).
    hx, hy, hz : float
        Node spacing [m].
    step : float
        Step length in cells: each continuous step is ``step * min(h)`` metres.
    max_steps : int
        Number of continuous iterations (accepted steps + fallbacks) after which
        only discrete descent is used.

    Returns
    -------
    path : float64 array (n, 3)
    status : int
        ``OK`` or ``STUCK``.
    info : int64 array (3,)
        The node where the descent got stuck (status ``STUCK``).
    n_fallback : int
        Number of discrete fallback moves made.
    """
    nx, ny, nz = T.shape
    hmin = min(hx, min(hy, hz))
    gx, gy, gz = goal[0], goal[1], goal[2]
    px, py, pz = start[0], start[1], start[2]
    info = np.zeros(3, dtype=np.int64)
    out = np.empty((256, 3))
    out[0, 0] = px  # the first point stored directly, and n typed int64 (not the
    out[0, 1] = py  # literal 1): a call with a literal argument compiles a second
    out[0, 2] = pz  # specialisation of the callee (~0.3 s each, first use)
    n = np.int64(1)
    # potential of the current point, and the last _WINDOW accepted ones
    phi = _potential(T, px, py, pz, hx, hy, hz)
    hist = np.empty(_WINDOW)
    keys = np.empty(_CACHE_SLOTS, dtype=np.int64)
    _fill(keys, -1)
    vals = np.empty((_CACHE_SLOTS, 3))
    wbuf = np.empty(12)
    _fill(hist, phi)
    hpos = 0
    iters = 0
    n_fallback = 0
    while True:
        if _near_goal(T, px, py, pz, gx, gy, gz):
            out, n = _push(out, n, gx, gy, gz)
            return out[:n].copy(), OK, info, n_fallback

        if iters < max_steps:
            iters += 1
            # ---- continuous step: midpoint (RK2) on the direction field, with
            #      backtracking on the step length; non-monotone acceptance
            ref = _nanmax(hist)
            qx, qy, qz, tq, ok = _try_step(T, px, py, pz, ref, hx, hy, hz, hmin, step, keys, vals,
                                           wbuf)
            if ok:
                px, py, pz = qx, qy, qz
                phi = tq
                hpos = (hpos + 1) % _WINDOW
                hist[hpos] = phi
                out, n = _push(out, n, px, py, pz)
                continue
            # ---- fallback: discrete steepest descent from the nearest node of p
            #      until the node's T is below the potential. The first move
            #      goes straight from p to the chosen neighbour if that segment
            #      is free, else via p's nearest node (inside its free cell).
            moved = False
            i = _nearest(px, nx)
            j = _nearest(py, ny)
            k = _nearest(pz, nz)
            while not _near_goal(T, px, py, pz, gx, gy, gz):
                bi, bj, bk, found = _best_neighbour(T, i, j, k)
                if not found:
                    break
                if (px != i or py != j or pz != k) and not _segment_free(
                    T, px, py, pz, float(bi), float(bj), float(bk)
                ):
                    out, n = _push(out, n, float(i), float(j), float(k))
                i, j, k = bi, bj, bk
                px, py, pz = float(i), float(j), float(k)
                out, n = _push(out, n, px, py, pz)
                n_fallback += 1
                moved = True
                if T[i, j, k] < phi:
                    break
            if moved:
                phi = T[i, j, k]
                _fill(hist, phi)
            elif not _near_goal(T, px, py, pz, gx, gy, gz):
                info[0], info[1], info[2] = i, j, k
                return out[:n].copy(), STUCK, info, n_fallback
            continue

        # ---- step budget used up: pure discrete descent
        i = _nearest(px, nx)
        j = _nearest(py, ny)
        k = _nearest(pz, nz)
        out, n = _push(out, n, float(i), float(j), float(k))
        px, py, pz = float(i), float(j), float(k)
        while not _near_goal(T, px, py, pz, gx, gy, gz):
            bi, bj, bk, found = _best_neighbour(T, i, j, k)
            if not found:
                info[0], info[1], info[2] = i, j, k
                return out[:n].copy(), STUCK, info, n_fallback
            i, j, k = bi, bj, bk
            px, py, pz = float(i), float(j), float(k)
            out, n = _push(out, n, px, py, pz)
            n_fallback += 1


# --------------------------------------------------------------- many starts
@njit(cache=True, error_model="numpy", nogil=True)
def descend_sweep(work, shape, flat, order, vals, hi, ball_idx, ball_vals, times, nodes,
                  starts, goal, hx, hy, hz, step, max_steps, sweep):
    """:func:`descend_kernel` from each of ``starts`` on the field a march stopped there
    sees, rebuilt in ``work`` (see :func:`fm2uav.planning.geodesic.descend_stopped`).

    For each start ``s`` (time ``t``, flat node ``n``), in the order given (latest
    first): if ``sweep``, the nodes ``order[lo:hi]`` (``vals[lo:]`` >= t) are made
    ``inf`` in the flat ``work`` (``hi = lo`` after) and ``work[n] = t``; the nodes of
    the ball ``ball_idx`` (sorted by ``ball_vals``) with time ``t`` other than ``n``
    are made ``inf`` during the descent and restored from ``flat`` after it; if
    ``sweep``, ``work[n]`` is ``inf`` again after the descent.

    Parameters
    ----------
    work, flat : float64 arrays, flat
        The field descended (written) and the whole march's times [s] (``inf`` on
        blocked nodes), C order of ``shape``.
    shape : tuple of 3 int
        The field's shape, padded to 3 axes.
    order, vals, hi
        The nodes outside the ball sorted by time, their times, and how many of them
        are finite in ``work`` now.
    ball_idx, ball_vals
        The ball's nodes sorted by time, and their times.
    times : float64 array (m,); nodes : int64 array (m,)
        Each start's time and flat node.
    starts : float64 array (m, 3)
        Index coordinates, padded with 0 to 3 axes.
    goal : float64 array (3,)
    hx, hy, hz, step, max_steps
        As :func:`descend_kernel`.
    sweep : bool
        Whether the starts lie outside the ball (the field is swept down to each).

    Returns
    -------
    points : float64 array (N, 3)
        Every path, one after the other, the first point the start and the last the
        goal exactly when the descent got there.
    offsets : int64 array (m + 1,)
    status : int64 array (m,)
        ``OK`` or ``STUCK`` per start; ``info`` (m, 3) the node where it got stuck.
    hi : int
        The sweep's position after the last start.
    """
    m = times.shape[0]
    work3 = work.reshape(shape)
    pts = np.empty((max(1024, 64 * m), 3))
    offsets = np.zeros(m + 1, dtype=np.int64)
    status = np.zeros(m, dtype=np.int64)
    info = np.zeros((m, 3), dtype=np.int64)
    n = 0
    for r in range(m):
        t = times[r]
        node = nodes[r]
        if sweep:
            lo = np.searchsorted(vals, t, side="left")
            if lo < hi:
                for q in range(lo, hi):
                    work[order[q]] = np.inf
                hi = lo
            work[node] = t
        a = np.searchsorted(ball_vals, t, side="left")
        b = np.searchsorted(ball_vals, t, side="right")
        for q in range(a, b):
            if ball_idx[q] != node:
                work[ball_idx[q]] = np.inf
        path, st, where, _ = descend_kernel(work3, starts[r], goal, hx, hy, hz, step,
                                            max_steps)
        for q in range(a, b):
            if ball_idx[q] != node:
                work[ball_idx[q]] = flat[ball_idx[q]]
        if sweep:
            work[node] = np.inf
        status[r] = st
        info[r, 0], info[r, 1], info[r, 2] = where[0], where[1], where[2]
        k = path.shape[0]
        if n + k > pts.shape[0]:
            bigger = np.empty((2 * (n + k), 3))
            for q in range(n):
                bigger[q, 0] = pts[q, 0]
                bigger[q, 1] = pts[q, 1]
                bigger[q, 2] = pts[q, 2]
            pts = bigger
        for q in range(k):
            pts[n + q, 0] = path[q, 0]
            pts[n + q, 1] = path[q, 1]
            pts[n + q, 2] = path[q, 2]
        if st == OK:  # the ends exact (as descend's)
            pts[n, 0], pts[n, 1], pts[n, 2] = starts[r, 0], starts[r, 1], starts[r, 2]
            pts[n + k - 1, 0], pts[n + k - 1, 1], pts[n + k - 1, 2] = goal[0], goal[1], goal[2]
        n += k
        offsets[r + 1] = n
    return pts[:n], offsets, status, info, hi


# ------------------------------------------------------------- whole-field scans
# One compiled pass each over a field the descent reads, in place of numpy expressions
# that allocate map-sized temporaries (40 M nodes: a bool array per comparison, or a
# copy of every obstacle node's time) before reducing them.


@njit(cache=True, error_model="numpy")
def first_invalid_time(T):
    """Flat index of the first NaN or ``-inf`` of the flat field ``T`` (-1: none)."""
    bad = False
    for c in range(T.size):  # no early exit: the loop vectorises
        x = T[c]
        bad |= (x != x) | (x == -np.inf)
    if not bad:
        return -1
    for c in range(T.size):
        x = T[c]
        if x != x or x == -np.inf:
            return c
    return -1


@njit(cache=True, error_model="numpy")
def any_finite_on(T, mask):
    """Whether a node of the flat ``mask`` has a finite time in the flat ``T``."""
    for c in range(T.size):
        if mask[c] and abs(T[c]) < np.inf:
            return True
    return False


@njit(cache=True, error_model="numpy")
def drop_equal(T, node, t):
    """``inf`` on every node of the flat ``T`` whose time is ``t``, except ``node``, if
    there is another; returns how many nodes had that time."""
    count = 0
    for c in range(T.size):
        count += T[c] == t
    if count > 1:
        for c in range(T.size):
            if T[c] == t and c != node:
                T[c] = np.inf
    return count
