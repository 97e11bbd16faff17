"""Slow, readable pure-Python twin of the wind march, used only by the tests.

An independent second implementation of :func:`fm2uav.eikonal.wind.zermelo_march`
(times only): plain Python loops over index tuples, :mod:`heapq` with lazy
deletion, numpy only for storage and the 2x2 / 3x3 solves. The tests check that
the compiled solver and this one agree to rounding.

The discretisation, in words
----------------------------
A vehicle of airspeed ``V`` [m/s] in a wind ``w`` [m/s] flies the straight
displacement ``d`` [m] in the time ``F(d)``, the ``t > 0`` of
``|d - w t| = V t``. Nodes sit at ``i * h`` per axis.

Passable nodes
    Speed ``> 0`` and ``|w| < V``; every other node (speed 0: impassable;
    ``|w| >= V``: refused) never gets a time.

Stencil
    2D: the 8 neighbours ``o`` in angular order from ``(1, 0)``; the full faces
    are the 8 segments between consecutive ones. 3D: the 26 neighbours; the
    full faces are the 48 triangles ``(s_a e_a, s_a e_a + s_b e_b, s)`` for
    every sign vector ``s`` in ``{-1, 1}^3`` and every ordering ``(a, b, c)``
    of the axes; the edges are the sides of these triangles. A vertex may be
    used from node ``y`` only if every node of the grid box spanned by ``y``
    and ``y + o`` is passable (no corner cutting); a face or an edge only if
    the box of its vertex with the most nonzero components is.

Vertex values (order 2)
    The value of a frozen vertex ``v = y + o`` is ``U1 = T(v)`` with scale 1,
    unless the order is 2, ``y`` is acute (below), ``v + o`` is frozen with
    ``U2 = T(v + o) <= U1``,
    the speeds at ``y``, ``v``, ``v + o`` have ``max <= 2 min`` and (for a
    wind given per node) the winds at ``v`` and ``v + o`` differ from ``y``'s
    by at most ``0.5 min`` in norm: then ``(4 U1 - U2) / 3`` with scale 2/3.

Factored values (only in the source box, below)
    With the source's cone ``T0`` and ``g = grad T0(y)``, a vertex's factored
    value is its (order-2 extrapolated) ``tau = T - T0`` plus ``T0(y)``;
    unfactored, ``g = 0`` and the factored value is the value. A factored
    candidate earlier than all of its vertices (below their smallest value) is
    dropped: the shifted travel time ``F(v) - g . v`` may be negative.

Candidates at ``y`` when its stencil vertex ``k`` (the popped node) is frozen
    * vertex: ``Fk + s_k (F_y(-o_k) + g . o_k)``;
    * full face with all vertices frozen: ``u`` and ``p = g + E^-T r``,
      ``r_i = (factored value_i - u) / s_i`` (``E``: the vertex offsets as
      columns), with ``V |p| + w . p = 1`` (larger root), taken only if the
      ground velocity ``c = V p / |p| + w`` has barycentric weights
      ``-E^-1 c`` all ``>= -1e-9`` times the sum of their magnitudes;
    * edge (3D) with both vertices frozen: the minimum over the open segment
      between the scaled offsets ``P_a = s_a o_a``, ``P_b = s_b o_b`` of the
      linear interpolation of ``factored value + g . P`` plus ``F_y(-P)``.
    A face or edge is tried only if, moving from vertex ``k`` towards one of
    its other vertices ``j``, the objective decreases:
    ``slope_j = Fj - Fk - (grad F_y(-o_k) - g) . (s_j o_j - s_k o_k) < 0``
    (``grad F(d) = n / (V + w . n)``, ``n`` the heading flying along ``d``).
    The node takes the smallest candidate.

March
    Start nodes (sources at 0, and the ball) are pushed with their times;
    frozen start nodes are *fixed* (never updated). Pop the smallest
    ``(time, flat index)``; a popped band node is frozen. Then, for every
    passable, non-fixed neighbour ``y = x - o_k`` (``x`` is ``y``'s vertex
    ``k``): if ``y`` is frozen, it is re-evaluated only if ``x`` was popped
    before (re-opened) or ``y`` is *non-acute* (``|w|^2 > acute^2 V^2``,
    ``acute`` the cosine of the largest angle between two vertices of a face),
    and re-opened (back to the band) if the new value is below ``T(y) (1 -
    1e-12)``; a band or far ``y`` takes the new value if it is smaller.
    With stop nodes and no non-acute passable node, the march ends when every
    stop node has been popped; nodes not frozen then are ``inf``.

Source ball
    As the isotropic solver: ``R = max(2 max(h), 0.05 * extent)`` (none with
    more than 64 sources); each source tries ``R, R/2, ...`` down to
    ``2 max(h)`` until its box (``floor(r / h)`` nodes either side, clipped) is
    clean: all passable, and the ground speed ``g`` of ``|g d - w| = V`` at
    every node within a factor 1.5 of the source's along each direction ``d``
    (16 at 22.5 degrees in 2D, the 26 neighbour directions in 3D). Ball nodes (distance ``<= r``) get the exact cone
    ``F_s(x - x_s)`` if speed and wind are constant in the box, else the time
    of the factored march (above) on the box from the source alone (every node
    counts as acute there: the shifted metric may be negative, so no label
    correction); the
    smallest over the sources wins. They are fixed when every source is clean,
    else only band nodes.
"""

from __future__ import annotations

import heapq
import itertools
import math
from typing import Any

import numpy as np

__all__ = ["zermelo_march_reference"]

#: Written out again rather than imported (an independent implementation); a
#: test checks they equal the compiled solver's.
SOURCE_RADIUS_CELLS = 2.0
SOURCE_RADIUS_FRACTION = 0.05
MAX_BALL_SOURCES = 64
BALL_MAX_SPEED_RATIO = 1.5
ORDER2_MAX_SPEED_RATIO = 2.0
ORDER2_MAX_WIND_CHANGE = 0.5
CONE_TOL = 1e-9
REOPEN_RTOL = 1e-12

Vec = tuple[float, float, float]


def travel_time(d: Vec, V: float, w: Vec) -> float:
    """``F(d)``: the ``t > 0`` of ``|d - w t| = V t`` (``|w| < V``)."""
    wd = w[0] * d[0] + w[1] * d[1] + w[2] * d[2]
    dd = d[0] * d[0] + d[1] * d[1] + d[2] * d[2]
    lam = V * V - (w[0] * w[0] + w[1] * w[1] + w[2] * w[2])
    root = math.sqrt(wd * wd + lam * dd)
    if wd >= 0:
        return dd / (root + wd) if root + wd > 0 else 0.0
    return (root - wd) / lam


def travel_gradient(d: Vec, V: float, w: Vec) -> Vec:
    """``grad F(d) = n / (V + w . n)`` with ``n`` the unit heading flying along ``d``."""
    t = travel_time(d, V, w)
    if t <= 0:
        return (0.0, 0.0, 0.0)
    ivt = 1.0 / (V * t)
    n = [(d[i] - w[i] * t) * ivt for i in range(3)]
    iden = 1.0 / (V + w[0] * n[0] + w[1] * n[1] + w[2] * n[2])
    return (n[0] * iden, n[1] * iden, n[2] * iden)


def _stencil(ndim: int):
    """Offsets, full faces and edges (vertex index tuples) of the stencil."""
    if ndim == 2:
        offs = [(1, 0, 0), (1, 1, 0), (0, 1, 0), (-1, 1, 0), (-1, 0, 0), (-1, -1, 0),
                (0, -1, 0), (1, -1, 0)]
        faces = [(k, (k + 1) % 8) for k in range(8)]
        return offs, faces, []
    offs = [o for o in itertools.product((-1, 0, 1), repeat=3) if any(o)]
    faces = []
    for s in itertools.product((-1, 1), repeat=3):
        for a, b, _ in itertools.permutations(range(3)):
            v1 = tuple(s[i] if i == a else 0 for i in range(3))
            v2 = tuple(s[i] if i in (a, b) else 0 for i in range(3))
            faces.append((offs.index(v1), offs.index(v2), offs.index(s)))
    edges = sorted({tuple(sorted(p)) for f in faces for p in itertools.combinations(f, 2)})
    return offs, faces, edges


class _Grid:
    """Speeds, winds and spacing of one grid (x, y, z; 2D as nz = 1)."""

    def __init__(self, speed: np.ndarray, wind: np.ndarray, h: Vec, ndim: int):
        self.speed = speed  # (nx, ny, nz)
        self.wind = wind    # (nx, ny, nz, 3)
        self.h = h
        self.ndim = ndim
        self.shape = speed.shape
        self.wind_varies = not bool(np.all(wind == wind[0, 0, 0]))

    def inside(self, p) -> bool:
        return all(0 <= p[i] < self.shape[i] for i in range(3))

    def passable(self, p) -> bool:
        if not self.inside(p):
            return False
        V = float(self.speed[p])
        w = self.wind[p]
        return V > 0 and float(w[0] ** 2 + w[1] ** 2 + w[2] ** 2) < V * V

    def V(self, p) -> float:
        return float(self.speed[p])

    def w(self, p) -> Vec:
        return tuple(float(c) for c in self.wind[p])


def _add(p, o, k=1):
    return (p[0] + k * o[0], p[1] + k * o[1], p[2] + k * o[2])


class _March:
    """One march (the whole grid, or a source box in factored mode)."""

    def __init__(self, grid: _Grid, order: int, factor=None):
        self.g = grid
        self.order = order
        self.factor = factor  # (source point [m], V_s, w_s) or None
        self.offs, self.faces, self.edges = _stencil(grid.ndim)
        h = grid.h
        self.oph = [(o[0] * h[0], o[1] * h[1], (o[2] * h[2]) if grid.ndim == 3 else 0.0)
                    for o in self.offs]
        nd = grid.ndim
        self.minv = []
        cos = 1.0
        for f in self.faces:
            E = np.array([self.oph[v][:nd] for v in f]).T
            self.minv.append(np.linalg.inv(E).T)
            for a, b in itertools.combinations(f, 2):
                oa, ob = np.array(self.oph[a]), np.array(self.oph[b])
                cos = min(cos, float(oa @ ob / math.sqrt((oa @ oa) * (ob @ ob))))
        self.acute = cos
        self.nonzero = [sum(1 for c in o if c) for o in self.offs]

    # --- pieces of an evaluation --------------------------------------------
    def box_ok(self, y, o) -> bool:
        ranges = [range(min(0, c), max(0, c) + 1) for c in o]
        return all(self.g.passable(_add(y, b)) for b in itertools.product(*ranges))

    def cone_t0(self, p) -> float:
        src, Vs, ws = self.factor
        x = tuple(p[i] * self.g.h[i] if i < self.g.ndim else 0.0 for i in range(3))
        return travel_time(tuple(x[i] - src[i] for i in range(3)), Vs, ws)

    def grad_t0(self, y) -> Vec:
        if self.factor is None:
            return (0.0, 0.0, 0.0)
        src, Vs, ws = self.factor
        x = tuple(y[i] * self.g.h[i] if i < self.g.ndim else 0.0 for i in range(3))
        return travel_gradient(tuple(x[i] - src[i] for i in range(3)), Vs, ws)

    def vertex(self, T, y, j, order):
        """(value, scale, factored value) of frozen vertex ``j`` of ``y``, or None."""
        o = self.offs[j]
        v = _add(y, o)
        t1 = T.get(v)
        if t1 is None or not self.frozen.get(v, False):
            return None
        value, scale, second = t1, 1.0, False
        v2 = _add(v, o)
        if order == 2 and self.frozen.get(v2, False) and T[v2] <= t1:
            speeds = [self.g.V(y), self.g.V(v), self.g.V(v2)]
            second = max(speeds) <= ORDER2_MAX_SPEED_RATIO * min(speeds)
            if second and self.g.wind_varies:
                wy = self.g.w(y)
                lim = (ORDER2_MAX_WIND_CHANGE * min(speeds)) ** 2
                for q in (v, v2):
                    wq = self.g.w(q)
                    if sum((wq[i] - wy[i]) ** 2 for i in range(3)) > lim:
                        second = False
            if second:
                value, scale = (4.0 * t1 - T[v2]) / 3.0, 2.0 / 3.0
        fvalue = value
        if self.factor is not None:
            tau = t1 - self.cone_t0(v)
            if second:
                tau = (4.0 * tau - (T[v2] - self.cone_t0(v2))) / 3.0
            fvalue = tau + self.cone_t0(y)
        return value, scale, fvalue

    def face(self, f, data, U0, g, V, w):
        verts = self.faces[f]
        nd = self.g.ndim
        M = self.minv[f]  # E^-T, nd x nd
        # p = g + M (Fv - u) / s = b - (u - U0) a
        a = np.zeros(3)
        b = np.array(g, dtype=float)
        for i, v in enumerate(verts):
            _, s, fv = data[v]
            a[:nd] += M[:, i] / s
            b[:nd] += M[:, i] * (fv - U0) / s
        wv = np.array(w)
        A = V * V * (a @ a) - (wv @ a) ** 2
        one = 1.0 - wv @ b
        B = V * V * (a @ b) + one * (wv @ a)
        C = V * V * (b @ b) - one * one
        disc = B * B - A * C
        if disc < 0 or A <= 0:
            return math.inf, None
        up = (B + math.sqrt(disc)) / A
        p = b - up * a
        pn = math.sqrt(p @ p)
        if pn <= 0:
            return math.inf, None
        c = V * p / pn + wv
        lam = -(M.T @ c[:nd])
        if lam.min() < -CONE_TOL * np.abs(lam).sum():
            return math.inf, None
        return U0 + up, c

    def edge(self, e, data, U0, g, V, w):
        a, b = self.edges[e]
        (_, sa, fa), (_, sb, fb) = data[a], data[b]
        Pa = np.array(self.oph[a]) * sa
        Pb = np.array(self.oph[b]) * sb
        ga, gb = fa + float(np.dot(g, Pa)), fb + float(np.dot(g, Pb))
        # minimise (1 - t) ga + t gb + F(-(Pa + t (Pb - Pa))) over 0 < t < 1: F(-d) =
        # (sqrt(d'Qd) + w.d) / lam with Q = lam I + w w', so the derivative vanishes
        # where (A t + B) / sqrt(A t^2 + 2 B t + C) = -((gb - ga) lam + w.e)
        wv = np.array(w)
        lam = V * V - wv @ wv
        ev = Pb - Pa
        A = lam * (ev @ ev) + (wv @ ev) ** 2
        B = lam * (ev @ Pa) + (wv @ ev) * (wv @ Pa)
        C = lam * (Pa @ Pa) + (wv @ Pa) ** 2
        s = -((gb - ga) * lam + wv @ ev)
        if A - s * s <= 0:
            return math.inf, None
        t = (s * math.sqrt(max(A * C - B * B, 0.0) / (A - s * s)) - B) / A
        if not 0 < t < 1:
            return math.inf, None
        d = Pa + t * ev
        return ga + t * (gb - ga) + travel_time(tuple(-d), V, w), -d

    def evaluate(self, T, y, k):
        """Smallest candidate at ``y`` through its frozen vertex ``k``."""
        V, w = self.g.V(y), self.g.w(y)
        g = self.grad_t0(y)
        order = self.order if not self.non_acute(y) else 1
        data = {}

        def get(j):
            if j not in data:
                data[j] = self.vertex(T, y, j, order)
            return data[j]

        _, sk, fk = get(k)
        ok = self.oph[k]
        minus = (-ok[0], -ok[1], -ok[2])
        best = math.inf
        guard = self.factor is not None  # factored: never earlier than the vertices
        if self.box_ok(y, self.offs[k]):
            cand = fk + sk * (travel_time(minus, V, w) + sum(g[i] * ok[i] for i in range(3)))
            if not (guard and cand < data[k][0]):
                best = cand
        grad = travel_gradient(minus, V, w)
        slope_dir = [grad[i] - g[i] for i in range(3)]

        def slope(j):
            _, sj, fj = data[j]
            oj = self.oph[j]
            return fj - fk - sum(slope_dir[i] * (sj * oj[i] - sk * ok[i]) for i in range(3))

        groups = [(self.faces, self.face), (self.edges, self.edge)]
        for items, solve in groups:
            for idx, verts in enumerate(items):
                if k not in verts:
                    continue
                others = [j for j in verts if j != k]
                if any(get(j) is None for j in others):
                    continue
                if not any(slope(j) < 0 for j in others):
                    continue
                big = max(verts, key=lambda v: self.nonzero[v])
                if not self.box_ok(y, self.offs[big]):
                    continue
                cand, _ = solve(idx, data, fk, g, V, w)
                if guard and cand < min(data[j][0] for j in verts):
                    continue
                best = min(best, cand)
        return best

    def non_acute(self, p) -> bool:
        if self.factor is not None:
            return False  # factored: F(v) - g.v may be negative, so no label correction
        w = self.g.w(p)
        return w[0] ** 2 + w[1] ** 2 + w[2] ** 2 > self.acute ** 2 * self.g.V(p) ** 2

    # --- the march --------------------------------------------------------------
    def run(self, starts, stops=None):
        """``starts``: {node: (time, fixed)}; returns {node: time} of frozen nodes."""
        g = self.g
        T: dict[Any, float] = {}
        self.frozen: dict[Any, bool] = {}
        fixed = set()
        popped = set()
        heap = []
        for p, (t, fx) in starts.items():
            T[p] = t
            if fx:
                fixed.add(p)
                self.frozen[p] = True
            heapq.heappush(heap, (t, p))
        nonacute_any = False
        for p in itertools.product(*(range(n) for n in g.shape)):
            if g.passable(p) and self.non_acute(p):
                nonacute_any = True
        left = set(stops) if stops else set()
        left = {p for p in left if g.passable(p)}
        can_stop = bool(left) and not nonacute_any
        while heap:
            t, x = heapq.heappop(heap)
            if x in fixed:
                if x in popped:
                    continue
            elif self.frozen.get(x, False) or T.get(x) != t:
                continue
            self.frozen[x] = True
            again = x in popped
            popped.add(x)
            left.discard(x)
            for k, o in enumerate(self.offs):
                y = _add(x, o, -1)
                if not g.passable(y) or y in fixed:
                    continue
                if self.frozen.get(y, False) and not (again or self.non_acute(y)):
                    continue
                best = self.evaluate(T, y, k)
                if self.frozen.get(y, False):
                    if not best < T[y] - REOPEN_RTOL * T[y]:
                        continue
                    self.frozen[y] = False
                elif not best < T.get(y, math.inf):
                    continue
                T[y] = best
                heapq.heappush(heap, (best, y))
            if can_stop and not left:
                break
        return {p: T[p] for p, f in self.frozen.items() if f}


def _directions(ndim: int) -> list[Vec]:
    """Unit directions of the ground-speed comparison: 16 in 2D, 26 in 3D."""
    if ndim == 2:
        return [(math.cos(k * math.pi / 8), math.sin(k * math.pi / 8), 0.0) for k in range(16)]
    out = []
    for o in itertools.product((-1, 0, 1), repeat=3):
        if any(o):
            n = math.sqrt(sum(c * c for c in o))
            out.append(tuple(c / n for c in o))
    return out


def _ground_speed(V: float, w: Vec, d: Vec) -> float:
    wd = w[0] * d[0] + w[1] * d[1] + w[2] * d[2]
    return wd + math.sqrt(wd * wd + V * V - (w[0] ** 2 + w[1] ** 2 + w[2] ** 2))


def _ball(grid: _Grid, src, radius, min_radius, order):
    """{node: time} of the ball of one source, or None if no radius is clean."""
    h = grid.h
    Vs, ws = grid.V(src), grid.w(src)
    r = radius
    while True:
        reach = [int(math.floor(r / h[i])) if i < grid.ndim else 0 for i in range(3)]
        lo = [max(src[i] - reach[i], 0) for i in range(3)]
        hi = [min(src[i] + reach[i], grid.shape[i] - 1) for i in range(3)]
        box = list(itertools.product(*(range(lo[i], hi[i] + 1) for i in range(3))))
        clean = all(grid.passable(p) for p in box)
        if clean:
            for d in _directions(grid.ndim):
                gs = _ground_speed(Vs, ws, d)
                for p in box:
                    ratio = _ground_speed(grid.V(p), grid.w(p), d) / gs
                    if not 1 / BALL_MAX_SPEED_RATIO <= ratio <= BALL_MAX_SPEED_RATIO:
                        clean = False
        if clean:
            break
        if r <= min_radius:
            return None
        r = max(r / 2, min_radius)
    xs = [(src[i] - lo[i]) * h[i] for i in range(3)]

    def dist(p):
        return math.sqrt(sum(((p[i] - src[i]) * h[i]) ** 2 for i in range(3)))

    inside = [p for p in box if dist(p) <= r]
    if all(grid.V(p) == Vs for p in box) and all(grid.w(p) == ws for p in box):
        return {p: travel_time(tuple((p[i] - src[i]) * h[i] for i in range(3)), Vs, ws)
                for p in inside}
    sl = tuple(slice(lo[i], hi[i] + 1) for i in range(3))
    sub = _Grid(grid.speed[sl], grid.wind[sl], h, grid.ndim)
    local = tuple(src[i] - lo[i] for i in range(3))
    times = _March(sub, order, factor=(tuple(xs), Vs, ws)).run({local: (0.0, True)})
    out = {}
    for p in inside:
        q = tuple(p[i] - lo[i] for i in range(3))
        if q in times:
            out[p] = times[q]
    return out


def zermelo_march_reference(speed: Any, sources: Any, wind: Any, *, spacing: Any = 1.0,
                            order: int = 2, stop_at: Any = None, source_ball: bool = True,
                            towards: bool = False) -> np.ndarray:
    """Arrival times [s] (``inf`` where not frozen), as :func:`zermelo_march` ``.times``."""
    v = np.asarray(speed, dtype=float)
    ndim = v.ndim
    shape = v.shape + (1,) * (3 - ndim)
    hs = np.broadcast_to(np.asarray(spacing, dtype=float), (ndim,))
    h = tuple(float(hs[i]) if i < ndim else 1.0 for i in range(3))
    w = np.asarray(wind, dtype=float) * (-1.0 if towards else 1.0)
    wind3 = np.zeros(shape + (3,))
    wind3[..., :ndim] = np.broadcast_to(w, v.shape + (ndim,)).reshape(shape + (ndim,))
    grid = _Grid(v.reshape(shape), wind3, h, ndim)
    src = [tuple(int(c) for c in s) + (0,) * (3 - ndim)
           for s in np.atleast_2d(np.asarray(sources))]
    extent = max((v.shape[i] - 1) * h[i] for i in range(ndim))
    radius = max(SOURCE_RADIUS_CELLS * max(h[:ndim]), SOURCE_RADIUS_FRACTION * extent)
    if len(src) > MAX_BALL_SOURCES or not source_ball:
        radius = 0.0
    balls, all_clean = {}, True
    if radius > 0:
        for s in src:
            ball = _ball(grid, s, radius, SOURCE_RADIUS_CELLS * max(h[:ndim]), order)
            if ball is None:
                all_clean = False
                continue
            for p, t in ball.items():
                balls[p] = min(t, balls.get(p, math.inf))
    starts = {p: (t, all_clean) for p, t in balls.items()}
    for s in src:
        starts[s] = (0.0, True)
    stops = None
    if stop_at is not None:
        stops = [tuple(int(c) for c in s) + (0,) * (3 - ndim)
                 for s in np.atleast_2d(np.asarray(stop_at))]
    times = _March(grid, order).run(starts, stops)
    out = np.full(shape, np.inf)
    for p, t in times.items():
        out[p] = t
    return out.reshape(v.shape)
