"""Compiled (numba) march of the wind-aware (Zermelo / Randers) eikonal solver.

Private module: the public entry points are :func:`fm2uav.eikonal.fast_marching`
(``wind=...``) and :func:`fm2uav.eikonal.wind.zermelo_march`, which validate the
input, build the stencil (:func:`stencil`), initialise the sources
(:mod:`._wind_sources`) and call :func:`march`. The scheme is described in
docs/eikonal.md (section "Wind") and, in words, in :mod:`._wind_reference`, the
slow pure-Python twin the tests compare this module with.

The equation
------------
Arrival times ``T`` [s] of a vehicle of airspeed ``V`` [m/s] in a wind ``w``
[m/s] (ground velocity = ``V n + w`` for a unit heading ``n``):
``V |grad T| + w . grad T = 1`` where ``|w| < V``. The time to fly a straight
displacement ``d`` [m] in a constant wind is the ``t > 0`` of ``|d - w t| = V t``:

    F(d) = (sqrt((w.d)^2 + lam |d|^2) - w.d) / lam,   lam = V^2 - |w|^2,

written ``|d|^2 / (sqrt(...) + w.d)`` when ``w.d >= 0`` (no cancellation).

The scheme: semi-Lagrangian Fast Marching on a wide stencil
----------------------------------------------------------
``T(y) = min over the faces S of y's stencil, min over z in S of
[ T interpolated at z + F_y(y - z) ]`` with ``F_y`` the local (frozen
coefficient) travel time: Tsitsiklis' / Falcone's semi-Lagrangian scheme,
monotone and consistent. The stencil is the 8 neighbours in 2D (faces: the 8
segments between angularly consecutive neighbours) and the 26 in 3D (faces: the
48 triangles of the cube surface, 6 per octant, with vertices ``e_i``,
``e_i + e_j``, ``e_i + e_j + e_k``; edges: their 72 sides). Per face the
minimum is found in closed form:

* a *vertex* ``o``: ``U + F_y(-o)``;
* a *full face* (2 vertices in 2D, 3 in 3D): the linear function through the
  vertex values with gradient ``p`` solving ``V |p| + w . p = 1`` (a quadratic
  in ``T(y)``, larger root), accepted if the characteristic ``V p/|p| + w`` (the
  ground velocity at ``y``) comes from inside the face's cone;
* an *edge* of a 3D triangle: the 1D minimum of the interpolated value plus
  ``F_y`` along the segment, in closed form (the Randers form of ``F``).

Order 2 (as the isotropic solver's), at nodes where the stencil is acute (see
below): a vertex value ``U1`` whose next node
outward, ``U2`` at ``y + 2 o``, is frozen and not later, with the speed varying
by at most ``ORDER2_MAX_SPEED_RATIO`` and the wind by at most
``ORDER2_MAX_WIND_CHANGE`` times the lowest of the three speeds, is replaced
by ``(4 U1 - U2) / 3`` at offset ``2 o / 3`` (the second-order one-sided
difference, ``u(y) - (4 U1 - U2)/3 = (2/3) o . grad u + O(h^3)``), so the same
face formulas are second-order consistent.

Causality and label correction
------------------------------
The march is causal (each node final when it leaves the narrow band) where the
stencil is *acute* for the local metric (Sethian & Vladimirsky 2003; Mirebeau
2014): the heading that flies along any face direction must stay within 90
degrees of every vertex of that face, which holds when ``|w| / V <=
cos(largest angle between two vertices of a face)``: ``1/sqrt(2)`` for the
2D stencil, ``1/sqrt(3)`` for the 3D one (square cells). At nodes beyond it
the minimum may come from a neighbour frozen *later*; the march then corrects
labels: when a node is popped, its frozen non-acute neighbours are re-evaluated
with the faces through it and re-opened if that lowers them, and a re-opened
node, when popped again, re-evaluates all its frozen neighbours. The result is
the exact solution of the discrete equations for any ``|w| < V`` (checked by
the fixed-point test), at the price of the re-opened nodes' extra work. Label
correction needs a monotone update (values only ever go down), and the order-2
value ``(4 U1 - U2) / 3`` grows when ``U2`` is lowered later, so non-acute
nodes use order 1 (their accuracy is first order), and a grid with non-acute
nodes is marched to the end even with stop nodes (a stop node's time is then
final too).

Storage
-------
* ``T``: the padded grid (2 ghost layers per axis; 2D as ``nz = 1`` without z
  padding), state folded in: ``T >= 0`` frozen, ``-t`` narrow band (tentative
  ``t``), ``-inf`` far, NaN impassable (speed 0, wind >= airspeed) or ghost.
* ``flag``: per padded node, ``FIXED`` (source or frozen ball: never updated),
  ``POPPED`` (left the band once), ``STOP`` (an early-stop node).
* speed and wind are read from the caller's unpadded flat arrays (no copy); the
  heap holds the unpadded index of each entry beside the padded one.
* the heap: binary, lazy deletion (a lowered node gets a new entry; outdated
  entries are skipped), ordered by ``(key, padded index)`` so ties pop in a
  fixed order (the reference twin pops in the same one).
"""

from __future__ import annotations

import itertools
import math
from typing import NamedTuple

import numpy as np

from .._numba import njit

__all__ = ["Stencil", "stencil", "march", "zermelo_time", "ORDER2_MAX_SPEED_RATIO",
           "ORDER2_MAX_WIND_CHANGE", "CONE_TOL", "REOPEN_RTOL", "FIXED", "POPPED", "STOP"]

FIXED = np.uint8(1)
POPPED = np.uint8(2)
STOP = np.uint8(4)

#: Order 2 at a vertex only where the speed along (node, vertex, next vertex)
#: varies by at most this factor (as the isotropic solver) ...
ORDER2_MAX_SPEED_RATIO = 2.0
#: ... and the wind by at most this share of the lowest of the three speeds.
ORDER2_MAX_WIND_CHANGE = 0.5
#: A full-face solution is taken when its characteristic is inside the face's
#: cone up to this share of the barycentric weights (rounding on a face side).
CONE_TOL = 1e-9
#: A frozen node is re-opened only when a new value is below it by more than
#: this share of it (rounding must not re-open nodes forever).
REOPEN_RTOL = 1e-12

# No NRT (numba's reference counting): the march allocates nothing (its scratch
# and heap come from the caller) and no incref/decref runs in the hot loop.
_OPT = dict(cache=True, error_model="numpy", _nrt=False)
_INL = dict(cache=True, error_model="numpy", _nrt=False, inline="always")


# ---------------------------------------------------------------------- stencil
class Stencil(NamedTuple):
    """The wide stencil of one grid (offsets, faces, edges) as flat arrays.

    ``K`` vertices (8 in 2D, 26 in 3D); vertex ``k`` is the neighbour at
    ``grid offset off[k]``, physical offset ``oph[k]`` [m]. Full faces
    ``fvert[f]`` (``ndim`` vertices each) with ``fminv[f] = E^-T`` (``E`` the
    columns ``oph`` of the face's vertices, embedded in 3x3); the faces through
    vertex ``k`` are ``fid[fptr[k]:fptr[k+1]]``. Edges (3D only) ``evert[e]``,
    through ``k``: ``eid[eptr[k]:eptr[k+1]]``. No corner cutting: vertex ``k``
    is used only if the nodes of the grid box between the node and it
    (``boff[bptr[k]:bptr[k+1]]``, grid offsets other than the two ends) are
    passable; a face or edge only if the box of its outermost vertex
    (``fbig[f]``, ``ebig[e]``) is, which holds the face. ``acute`` is the largest
    ``|w| / V`` for which every face is acute (cosine of the largest angle
    between two vertices of a face).
    """

    ndim: int
    off: np.ndarray
    oph: np.ndarray
    fvert: np.ndarray
    fminv: np.ndarray
    fptr: np.ndarray
    fid: np.ndarray
    evert: np.ndarray
    eptr: np.ndarray
    eid: np.ndarray
    bptr: np.ndarray
    boff: np.ndarray
    fbig: np.ndarray
    ebig: np.ndarray
    acute: float


def _offsets_faces(ndim: int) -> tuple[list[tuple[int, int, int]], list[tuple[int, ...]]]:
    """Grid offsets of the stencil and its full faces (vertex index tuples)."""
    if ndim == 2:
        ring = [(1, 0), (1, 1), (0, 1), (-1, 1), (-1, 0), (-1, -1), (0, -1), (1, -1)]
        offs = [(a, b, 0) for a, b in ring]
        faces = [(k, (k + 1) % 8) for k in range(8)]
        return offs, faces
    offs = [o for o in itertools.product((-1, 0, 1), repeat=3) if o != (0, 0, 0)]
    index = {o: k for k, o in enumerate(offs)}
    faces = []
    for sign in itertools.product((-1, 1), repeat=3):
        for perm in itertools.permutations(range(3)):
            v1 = [0, 0, 0]
            v1[perm[0]] = sign[perm[0]]
            v2 = list(v1)
            v2[perm[1]] = sign[perm[1]]
            faces.append((index[tuple(v1)], index[tuple(v2)], index[tuple(sign)]))
    return offs, faces


def _csr(items: list[tuple[int, ...]], nvert: int) -> tuple[np.ndarray, np.ndarray]:
    lists: list[list[int]] = [[] for _ in range(nvert)]
    for i, verts in enumerate(items):
        for v in verts:
            lists[v].append(i)
    ptr = np.zeros(nvert + 1, dtype=np.int64)
    ptr[1:] = np.cumsum([len(lst) for lst in lists])
    ids = np.array([i for lst in lists for i in lst], dtype=np.int64)
    return ptr, ids


def stencil(ndim: int, h3: tuple[float, float, float]) -> Stencil:
    """The stencil of a ``ndim``-D grid of spacing ``h3`` [m] (``h3[2]`` unused in 2D)."""
    offs, faces = _offsets_faces(ndim)
    off = np.array(offs, dtype=np.int64)
    oph = off * np.asarray(h3, dtype=float)
    if ndim == 2:
        oph[:, 2] = 0.0
    fvert = np.array(faces, dtype=np.int64)
    fminv = np.zeros((len(faces), 3, 3))
    cosmin = 1.0
    for f, verts in enumerate(faces):
        E = oph[list(verts)][:, :ndim].T  # columns: the vertices' offsets
        fminv[f, :ndim, :ndim] = np.linalg.inv(E).T
        for a, b in itertools.combinations(verts, 2):
            ca = oph[a] @ oph[b] / math.sqrt((oph[a] @ oph[a]) * (oph[b] @ oph[b]))
            cosmin = min(cosmin, float(ca))
    fptr, fid = _csr(faces, len(offs))
    if ndim == 3:
        edges = sorted({tuple(sorted(p)) for f in faces for p in itertools.combinations(f, 2)})
        evert = np.array(edges, dtype=np.int64)
        eptr, eid = _csr(edges, len(offs))
    else:
        evert = np.zeros((0, 2), dtype=np.int64)
        eptr, eid = np.zeros(len(offs) + 1, dtype=np.int64), np.zeros(0, dtype=np.int64)
    boxes = []
    for o in offs:
        ranges = [range(min(0, c), max(0, c) + 1) for c in o]
        boxes.append([b for b in itertools.product(*ranges)
                      if b != (0, 0, 0) and b != tuple(o)])
    bptr = np.zeros(len(offs) + 1, dtype=np.int64)
    bptr[1:] = np.cumsum([len(b) for b in boxes])
    boff = np.array([b for bs in boxes for b in bs], dtype=np.int64).reshape(-1, 3)
    size = [len(b) for b in boxes]
    fbig = np.array([max(f, key=lambda v: size[v]) for f in faces], dtype=np.int64)
    ebig = np.array([max(e, key=lambda v: size[v]) for e in evert.tolist()], dtype=np.int64)
    return Stencil(ndim, off, oph, fvert, fminv, fptr, fid, evert, eptr, eid, bptr, boff, fbig,
                   ebig, cosmin)


# ------------------------------------------------------------------ local solves
@njit(**_INL)
def zermelo_time(dx, dy, dz, V, wx, wy, wz):
    """Time [s] to fly the displacement ``(dx, dy, dz)`` [m] at airspeed ``V`` in wind ``w``.

    The ``t`` of ``|d - w t| = V t`` (``|w| < V``), without cancellation.
    """
    wd = wx * dx + wy * dy + wz * dz
    dd = dx * dx + dy * dy + dz * dz
    lam = V * V - (wx * wx + wy * wy + wz * wz)
    root = math.sqrt(wd * wd + lam * dd)
    if wd >= 0.0:
        s = root + wd
        return dd / s if s > 0.0 else 0.0
    return (root - wd) / lam


@njit(**_INL)
def _roots(ax, ay, az, bx, by, bz, U0, V, wx, wy, wz):
    """Solve ``V |p| + w . p = 1`` for ``p = b - (u - U0) a``: ``(u, ground velocity)``
    with the larger root ``u`` (``inf`` if none)."""
    V2 = V * V
    wa = wx * ax + wy * ay + wz * az
    wb = wx * bx + wy * by + wz * bz
    one = 1.0 - wb
    alpha = V2 * (ax * ax + ay * ay + az * az) - wa * wa
    beta = V2 * (ax * bx + ay * by + az * bz) + one * wa
    gamma = V2 * (bx * bx + by * by + bz * bz) - one * one
    disc = beta * beta - alpha * gamma
    if disc < 0.0 or alpha <= 0.0:
        return np.inf, 0.0, 0.0, 0.0
    up = (beta + math.sqrt(disc)) / alpha
    px = bx - up * ax
    py = by - up * ay
    pz = bz - up * az
    pn = math.sqrt(px * px + py * py + pz * pz)
    if pn <= 0.0:
        return np.inf, 0.0, 0.0, 0.0
    r = V / pn
    return U0 + up, px * r + wx, py * r + wy, pz * r + wz


@njit(**_INL)
def _face2(fm, f, u0, i0, u1, i1, U0, gx, gy, V, wx, wy):
    """Full-face solve in 2D: ``(time, ground velocity)``, ``inf`` outside the cone.

    ``fm[f]`` = E^-T of the face (its vertices' offsets as columns), ``u_i`` the
    (order-2, factored) values of its two vertices in ``fvert[f]`` order and
    ``i_i`` the inverses of their offset scales (1 or 3/2), ``U0`` a reference
    value subtracted for accuracy, ``g`` the factored gradient (0 unfactored).
    """
    r0 = (u0 - U0) * i0
    r1 = (u1 - U0) * i1
    m00 = fm[f, 0, 0]
    m01 = fm[f, 0, 1]
    m10 = fm[f, 1, 0]
    m11 = fm[f, 1, 1]
    t, vx, vy, vz = _roots(m00 * i0 + m01 * i1, m10 * i0 + m11 * i1, 0.0,
                           gx + m00 * r0 + m01 * r1, gy + m10 * r0 + m11 * r1, 0.0,
                           U0, V, wx, wy, 0.0)
    if t == np.inf:
        return t, vx, vy, vz
    l0 = -(m00 * vx + m10 * vy)
    l1 = -(m01 * vx + m11 * vy)
    if min(l0, l1) < -CONE_TOL * (abs(l0) + abs(l1)):
        return np.inf, 0.0, 0.0, 0.0
    return t, vx, vy, vz


@njit(**_INL)
def _face3(fm, f, u0, i0, u1, i1, u2, i2, U0, gx, gy, gz, V, wx, wy, wz):
    """Full-face solve in 3D (as :func:`_face2`, three vertices)."""
    r0 = (u0 - U0) * i0
    r1 = (u1 - U0) * i1
    r2 = (u2 - U0) * i2
    ax = fm[f, 0, 0] * i0 + fm[f, 0, 1] * i1 + fm[f, 0, 2] * i2
    ay = fm[f, 1, 0] * i0 + fm[f, 1, 1] * i1 + fm[f, 1, 2] * i2
    az = fm[f, 2, 0] * i0 + fm[f, 2, 1] * i1 + fm[f, 2, 2] * i2
    bx = gx + fm[f, 0, 0] * r0 + fm[f, 0, 1] * r1 + fm[f, 0, 2] * r2
    by = gy + fm[f, 1, 0] * r0 + fm[f, 1, 1] * r1 + fm[f, 1, 2] * r2
    bz = gz + fm[f, 2, 0] * r0 + fm[f, 2, 1] * r1 + fm[f, 2, 2] * r2
    t, vx, vy, vz = _roots(ax, ay, az, bx, by, bz, U0, V, wx, wy, wz)
    if t == np.inf:
        return t, vx, vy, vz
    l0 = -(fm[f, 0, 0] * vx + fm[f, 1, 0] * vy + fm[f, 2, 0] * vz)
    l1 = -(fm[f, 0, 1] * vx + fm[f, 1, 1] * vy + fm[f, 2, 1] * vz)
    l2 = -(fm[f, 0, 2] * vx + fm[f, 1, 2] * vy + fm[f, 2, 2] * vz)
    if min(l0, min(l1, l2)) < -CONE_TOL * (abs(l0) + abs(l1) + abs(l2)):
        return np.inf, 0.0, 0.0, 0.0
    return t, vx, vy, vz


@njit(**_INL)
def _edge(Ua, ax, ay, az, Ub, bx, by, bz, V, wx, wy, wz):
    """Minimum over the open segment from ``a`` to ``b`` (offsets [m], values
    ``Ua``, ``Ub`` [s]) of the interpolated value plus ``F(-d)``; (inf, ...) if
    the minimum is at an end (the vertex candidates cover those)."""
    lam = V * V - (wx * wx + wy * wy + wz * wz)
    ex = bx - ax
    ey = by - ay
    ez = bz - az
    wa = wx * ax + wy * ay + wz * az
    we = wx * ex + wy * ey + wz * ez
    A = lam * (ex * ex + ey * ey + ez * ez) + we * we
    B = lam * (ex * ax + ey * ay + ez * az) + we * wa
    C = lam * (ax * ax + ay * ay + az * az) + wa * wa
    s = -((Ub - Ua) * lam + we)
    den = A - s * s
    if den <= 0.0:
        return np.inf, 0.0, 0.0, 0.0
    D = A * C - B * B
    if D < 0.0:
        D = 0.0
    t = (s * math.sqrt(D / den) - B) / A
    if not (t > 0.0 and t < 1.0):
        return np.inf, 0.0, 0.0, 0.0
    dx = ax + t * ex
    dy = ay + t * ey
    dz = az + t * ez
    # F(-d) = (sqrt(d'Qd) + w.d) / lam, Q = lam I + w w'
    wd = wa + t * we
    dd = dx * dx + dy * dy + dz * dz
    root = math.sqrt(wd * wd + lam * dd)
    if wd >= 0.0:
        F = (root + wd) / lam
    else:
        F = dd / (root - wd)
    return Ua + t * (Ub - Ua) + F, -dx, -dy, -dz


@njit(**_INL)
def _t0(px, py, pz, src, Vs, ws):
    """Factored cone ``T0`` at the physical point ``p``: the source's constant-wind time."""
    return zermelo_time(px - src[0], py - src[1], pz - src[2], Vs, ws[0], ws[1], ws[2])


@njit(**_INL)
def _grad_t0(px, py, pz, src, Vs, ws):
    """``grad T0`` at ``p``: ``n / (V_s + w_s . n)``, ``n`` the heading flying there."""
    dx = px - src[0]
    dy = py - src[1]
    dz = pz - src[2]
    t = zermelo_time(dx, dy, dz, Vs, ws[0], ws[1], ws[2])
    if t <= 0.0:
        return 0.0, 0.0, 0.0
    ivt = 1.0 / (Vs * t)
    nx = (dx - ws[0] * t) * ivt
    ny = (dy - ws[1] * t) * ivt
    nz = (dz - ws[2] * t) * ivt
    iden = 1.0 / (Vs + ws[0] * nx + ws[1] * ny + ws[2] * nz)
    return nx * iden, ny * iden, nz * iden


# --------------------------------------------------------------------------- heap
# An indexed 4-ary min-heap of (key, padded node) pairs (ties: smaller node
# first) with the unpadded node alongside; pos[c] = slot of node c, -1 if absent.
_ARITY = 4


@njit(**_INL)
def _before(k1, c1, k2, c2):
    return k1 < k2 or (k1 == k2 and c1 < c2)


@njit(**_INL)
def _sift_up(hk, hc, hu, pos, p, key, c, u):
    while p > 0:
        q = (p - 1) >> 2
        if not _before(key, c, hk[q], hc[q]):
            break
        hk[p] = hk[q]
        hc[p] = hc[q]
        hu[p] = hu[q]
        pos[hc[p]] = p
        p = q
    hk[p] = key
    hc[p] = c
    hu[p] = u
    pos[c] = p


@njit(**_INL)
def _pop(hk, hc, hu, pos, n):
    """Remove the smallest entry; returns it and the new size (``n > 0``)."""
    key = hk[0]
    c = hc[0]
    u = hu[0]
    pos[c] = -1
    n -= 1
    if n > 0:
        lk = hk[n]
        lc = hc[n]
        lu = hu[n]
        p = 0
        while True:
            ch = 4 * p + 1
            if ch >= n:
                break
            end = min(ch + _ARITY, n)
            m = ch
            mk = hk[ch]
            mc = hc[ch]
            for i in range(ch + 1, end):
                if _before(hk[i], hc[i], mk, mc):
                    m = i
                    mk = hk[i]
                    mc = hc[i]
            if not _before(mk, mc, lk, lc):
                break
            hk[p] = mk
            hc[p] = mc
            hu[p] = hu[m]
            pos[mc] = p
            p = m
        hk[p] = lk
        hc[p] = lc
        hu[p] = lu
        pos[lc] = p
    return key, c, u, n


# -------------------------------------------------------------------------- march
@njit(**_INL)
def _wind_at(wind, wconst, u):
    if wconst:
        return wind[0, 0], wind[0, 1], wind[0, 2]
    return wind[u, 0], wind[u, 1], wind[u, 2]


@njit(**_INL)
def _coords(u, ny, nz, h):
    """Physical coordinates [m] of the unpadded flat node ``u`` (origin at node 0)."""
    i = u // (ny * nz)
    r = u - i * ny * nz
    j = r // nz
    k = r - j * nz
    return i * h[0], j * h[1], k * h[2]


@njit(**_INL)
def _vertex(T, speed, wind, wconst, y, yu, j, doff, uoff, order, V, wx, wy, wz,
            fac, T0y, ny, nz, h, fsrc, fV, fw):
    """Vertex ``j`` of node ``y``: ``(frozen, value, scale, factored value)``.

    The value is ``U1`` (scale 1) or, with order 2 where allowed (module
    docstring), ``(4 U1 - U2) / 3`` (scale 2/3); the factored value is the same
    extrapolation of ``tau = T - T0`` plus ``T0(y)`` (unfactored: the value).

    """
    cj = y + doff[j]
    tj = T[cj]
    if not (tj >= 0.0):
        return False, 0.0, 1.0, 0.0
    uj = yu + uoff[j]
    uv = tj
    s = 1.0
    second = False
    t2 = 0.0
    if order == 2:
        t2 = T[cj + doff[j]]
        if t2 >= 0.0 and t2 <= tj:
            v1 = speed[uj]
            v2 = speed[uj + uoff[j]]
            vmin = min(V, min(v1, v2))
            vmax = max(V, max(v1, v2))
            second = vmax <= ORDER2_MAX_SPEED_RATIO * vmin
            if second and not wconst:
                u2 = uj + uoff[j]
                lim = (ORDER2_MAX_WIND_CHANGE * vmin) ** 2
                d1 = (wind[uj, 0] - wx) ** 2 + (wind[uj, 1] - wy) ** 2 + (wind[uj, 2] - wz) ** 2
                d2 = (wind[u2, 0] - wx) ** 2 + (wind[u2, 1] - wy) ** 2 + (wind[u2, 2] - wz) ** 2
                second = d1 <= lim and d2 <= lim
            if second:
                uv = (4.0 * tj - t2) / 3.0
                s = 2.0 / 3.0
    fv = uv
    if fac:
        px, py, pz = _coords(uj, ny, nz, h)
        tau = tj - _t0(px, py, pz, fsrc, fV, fw)
        if second:
            qx, qy, qz = _coords(uj + uoff[j], ny, nz, h)
            tau = (4.0 * tau - (t2 - _t0(qx, qy, qz, fsrc, fV, fw))) / 3.0
        fv = tau + T0y
    return True, uv, s, fv


@njit(**_INL)
def _box_ok(T, y, j, bptr, bdoff, Bv, epoch):
    """Are the nodes between ``y`` and its vertex ``j`` passable (cached per epoch)?"""
    b = Bv[j]
    if b == epoch:
        return True
    if b == -epoch:
        return False
    for i in range(bptr[j], bptr[j + 1]):
        t = T[y + bdoff[i]]
        if not (t == t):
            Bv[j] = -epoch
            return False
    Bv[j] = epoch
    return True


@njit(**_OPT)
def march(T, flag, speed, wind, wconst, dims, h, st, order, hk, hc, hu, pos, cnt,
          can_stop, acute2, all_acute, fac, fsrc, fV, fw, track, scratch):
    """Run (or resume) the march; returns True when done, False when the heap is full.

    Resumable: everything it needs is in its arguments, so the caller grows the
    heap arrays (copying ``hk[:n]``, ``hc[:n]``, ``hu[:n]``) and calls again.

    Parameters (all arrays flat, C order)
    ----------
    T, flag : padded grid state (module docstring), modified in place.
    speed : (n,) airspeed [m/s] of the unpadded grid; wind : (n, 3) or (1, 3) [m/s]
        (``wconst``: one vector for every node). Nodes with speed 0 or
        ``|w| >= V`` must already be NaN in ``T``.
    dims : int64[3] unpadded ``(nx, ny, nz)``; h : float[3] spacing [m].
    st : the stencil as a tuple ``(doff, uoff, oph, fvert, fminv, fptr, fid,
        evert, eptr, eid, bptr, bdoff, fbig, ebig, ndim)`` (:class:`Stencil`;
        ``doff``/``uoff``/``bdoff``: flat index offsets in the padded/unpadded/
        padded grid).
    order : 1 or 2. hk, hc, hu : the heap (keys, padded and unpadded indices),
        ``pos`` the heap slot of each padded node (-1: none); on the first call
        the heap holds every start node (frozen or band), sorted.
    cnt : int64[4] ``(heap size, STOP nodes not popped yet, pops, re-opened
        nodes)``; the march ends when no STOP node is left if ``can_stop``.
    acute2 : ``acute**2``; a node with ``|w|^2 > acute2 V^2`` is non-acute
        (label correction, order 1). all_acute : no passable node is non-acute (or
        factored mode): frozen nodes are never re-evaluated.
    fac, fsrc, fV, fw : factored mode (the source box): the cone of the source
        at physical point ``fsrc`` [m] with airspeed ``fV`` and wind ``fw``.
    track : (n, 3) ground-track direction (not normalised) of each node's
        last improvement, or (0, 3) not to record it.
    scratch : float[8, K] per-vertex cache of one evaluation.
    """
    doff, uoff, oph, fvert, fminv, fptr, fid, evert, eptr, eid, bptr, bdoff, fbig, ebig, ndim = st
    K = doff.shape[0]
    ny = dims[1]
    nz = dims[2]
    want_track = track.shape[0] > 0
    # per-vertex cache of one (pop, neighbour) evaluation: seen[j] == epoch
    seen = scratch[0]
    Uv = scratch[1]  # order-2 value, unfactored (NaN: not frozen)
    Sv = scratch[2]  # offset scale (1 or 2/3)
    Fv = scratch[3]  # order-2 value, factored (tau + T0(y))
    Dv = scratch[4]  # slope of the face objective from vertex k towards vertex j
    Bv = scratch[5]  # box of vertex j passable: epoch (yes), -epoch (no), else unknown
    Iv = scratch[6]  # 1 / Sv
    Av = scratch[7]  # epoch: a full face through vertex k and vertex j had a candidate
    for j in range(K):
        seen[j] = -1.0
        Bv[j] = 0.0
        Av[j] = -1.0
    epoch = 0.0
    hn = cnt[0]
    left = cnt[1]
    pops = cnt[2]
    reopened = cnt[3]
    cap = hk.shape[0]
    done = True
    while hn > 0:
        if hn + K > cap:
            done = False
            break
        key, c, cu, hn = _pop(hk, hc, hu, pos, hn)
        t = T[c]
        fl = flag[c]
        if t >= 0.0:
            # a frozen node is in the heap only as a start node not yet expanded
            if (fl & FIXED) == 0 or (fl & POPPED) != 0:
                continue
        else:
            T[c] = key
        again = (fl & POPPED) != 0
        flag[c] = fl | POPPED
        pops += 1
        if (fl & STOP) != 0 and not again:
            left -= 1
        for k in range(K):
            y = c - doff[k]
            yu = cu - uoff[k]
            ty = T[y]
            if ty >= 0.0 and not again and all_acute:
                continue  # frozen, and no node of the grid needs label correction
            if not (ty == ty) or (flag[y] & FIXED) != 0:
                continue
            V = speed[yu]
            wx, wy, wz = _wind_at(wind, wconst, yu)
            # (factored, the shifted metric F(v) - g.v may be negative where the wind
            # differs from the source's: no label correction, a plain march)
            acute = fac or (wx * wx + wy * wy + wz * wz) <= acute2 * V * V
            if ty >= 0.0 and not again and acute:
                continue  # frozen and acute: a node popped later cannot lower it
            # order 2 only where the stencil is causal: label correction lowers values
            # only, and (4 U1 - U2) / 3 grows when a non-final U2 is lowered later
            oy = order if acute else 1
            epoch += 1
            gx = gy = gz = 0.0
            T0y = 0.0
            if fac:
                pyx, pyy, pyz = _coords(yu, ny, nz, h)
                T0y = _t0(pyx, pyy, pyz, fsrc, fV, fw)
                gx, gy, gz = _grad_t0(pyx, pyy, pyz, fsrc, fV, fw)
            # vertex k alone: U_k + s_k F(-o_k)
            _, Uk, sk, Fk = _vertex(T, speed, wind, wconst, y, yu, k, doff, uoff, oy,
                                    V, wx, wy, wz, fac, T0y, ny, nz, h, fsrc, fV, fw)
            seen[k] = epoch
            Uv[k] = Uk
            Sv[k] = sk
            Iv[k] = 1.5 if sk != 1.0 else 1.0
            Fv[k] = Fk
            okx = -oph[k, 0]
            oky = -oph[k, 1]
            okz = -oph[k, 2]
            tk = zermelo_time(okx, oky, okz, V, wx, wy, wz)
            # factored (g = grad T0(y)), the semi-Lagrangian minimum is taken with
            # F(v) - g.v: the vertex candidate is Fv_k + s_k (F(-o_k) + g.o_k)
            best = np.inf
            bvx, bvy, bvz = okx, oky, okz
            Gk = Fk + sk * (tk - (gx * okx + gy * oky + gz * okz))
            if _box_ok(T, y, k, bptr, bdoff, Bv, epoch) and not (fac and Gk < Uk):
                best = Gk
            # a candidate counts only if below both best and the node's value now
            # (band: -ty; frozen: ty less the re-opening margin; far: inf)
            bound = min(best, ty - REOPEN_RTOL * ty if ty >= 0.0 else -ty)
            # grad F at -o_k: n / (V + w.n), n the heading flying along -o_k (minus
            # g, factored). The face objective (interpolated value + F) is convex:
            # it can only be below vertex k's value on a face where it decreases
            # from k towards another vertex j, i.e. where
            # slope_j = U_j - U_k - (gradF - g) . (s_j o_j - s_k o_k) < 0.
            ivt = 1.0 / (V * tk)
            hx = (okx - wx * tk) * ivt
            hy = (oky - wy * tk) * ivt
            hz = (okz - wz * tk) * ivt
            iden = 1.0 / (V + wx * hx + wy * hy + wz * hz)
            fx = hx * iden - gx
            fy = hy * iden - gy
            fz = hz * iden - gz
            nf = fptr[k + 1] - fptr[k]
            ne = eptr[k + 1] - eptr[k]
            for q in range(nf + ne):
                if q < nf:
                    f = fid[fptr[k] + q]
                    nv = ndim
                else:
                    f = eid[eptr[k] + q - nf]
                    nv = 2
                    # a full face through this edge had its minimum inside: that minimum
                    # of the convex objective is at most the edge's (3D: faces come first)
                    if Av[evert[f, 0] + evert[f, 1] - k] == epoch:
                        continue
                down = np.inf  # the most negative slope from k (convexity: the face's
                # minimum is at least Gk + that slope, so it cannot beat bound if that is higher)
                ok = True
                for i in range(nv):
                    j = fvert[f, i] if q < nf else evert[f, i]
                    if j == k:
                        continue
                    if seen[j] != epoch:
                        fj, uv, s, fv = _vertex(T, speed, wind, wconst, y, yu, j, doff, uoff,
                                                oy, V, wx, wy, wz, fac, T0y, ny, nz, h,
                                                fsrc, fV, fw)
                        seen[j] = epoch
                        Uv[j] = np.nan
                        if fj:
                            Uv[j] = uv
                            Sv[j] = s
                            Iv[j] = 1.5 if s != 1.0 else 1.0
                            Fv[j] = fv
                            Dv[j] = fv - Fk - (fx * (s * oph[j, 0] - sk * oph[k, 0])
                                               + fy * (s * oph[j, 1] - sk * oph[k, 1])
                                               + fz * (s * oph[j, 2] - sk * oph[k, 2]))
                    if not (Uv[j] == Uv[j]):  # not frozen
                        ok = False
                        break
                    if Dv[j] < down:
                        down = Dv[j]
                if not ok or not (down < 0.0) or not (Gk + down < bound):
                    continue
                if not _box_ok(T, y, fbig[f] if q < nf else ebig[f], bptr, bdoff, Bv, epoch):
                    continue
                if q < nf:
                    a = fvert[f, 0]
                    b = fvert[f, 1]
                    if ndim == 2:
                        cand, vx, vy, vz = _face2(fminv, f, Fv[a], Iv[a], Fv[b], Iv[b], Fk,
                                                  gx, gy, V, wx, wy)
                    else:
                        d = fvert[f, 2]
                        cand, vx, vy, vz = _face3(fminv, f, Fv[a], Iv[a], Fv[b], Iv[b], Fv[d],
                                                  Iv[d], Fk, gx, gy, gz, V, wx, wy, wz)
                else:
                    a = evert[f, 0]
                    b = evert[f, 1]
                    sa = Sv[a]
                    sb = Sv[b]
                    ax_ = sa * oph[a, 0]
                    ay_ = sa * oph[a, 1]
                    az_ = sa * oph[a, 2]
                    bx_ = sb * oph[b, 0]
                    by_ = sb * oph[b, 1]
                    bz_ = sb * oph[b, 2]
                    cand, vx, vy, vz = _edge(Fv[a] + gx * ax_ + gy * ay_ + gz * az_, ax_, ay_,
                                             az_, Fv[b] + gx * bx_ + gy * by_ + gz * bz_, bx_,
                                             by_, bz_, V, wx, wy, wz)
                if fac:
                    # factored, F(v) - g.v may be negative: never earlier than every
                    # vertex the candidate comes through (as an unfactored one)
                    lo = min(Uv[fvert[f, 0]], Uv[fvert[f, 1]]) if q < nf else min(
                        Uv[evert[f, 0]], Uv[evert[f, 1]])
                    if q < nf and ndim == 3:
                        lo = min(lo, Uv[fvert[f, 2]])
                    if cand < lo:
                        cand = np.inf
                if q < nf and ndim == 3 and cand < np.inf:
                    Av[fvert[f, 0]] = epoch
                    Av[fvert[f, 1]] = epoch
                    Av[fvert[f, 2]] = epoch
                if cand < best:
                    best = cand
                    bvx, bvy, bvz = vx, vy, vz
                    if cand < bound:
                        bound = cand
            if ty >= 0.0:
                if not (best < ty - REOPEN_RTOL * ty):
                    continue
                reopened += 1
            elif not (best < -ty):
                continue
            T[y] = -best
            p = pos[y]
            if p < 0:
                p = hn
                hn += 1
            _sift_up(hk, hc, hu, pos, p, best, y, yu)
            if want_track:
                track[yu, 0] = bvx
                track[yu, 1] = bvy
                track[yu, 2] = bvz
        if can_stop and left == 0:
            break
    cnt[0] = hn
    cnt[1] = left
    cnt[2] = pops
    cnt[3] = reopened
    return done
