"""Motion primitives of the (x, y, θ) lattice: biarcs between lattice poses.

A lattice state is a grid node and one of ``K`` headings. The headings are the
directions of the primitive integer vectors ``(a, b)`` (``gcd = 1``) with
``max(|a|, |b|) <= max_int`` — 48 headings for ``max_int = 4`` — so that a
straight path along any lattice heading is exact (no zig-zag, no curvature
cost), as in Pivtoraiko & Kelly's state lattices (ref. [6] of the seed).

A primitive joins ``(0, 0, θ_i)`` to ``(dx, dy, θ_j)`` (integer ``dx, dy`` in
cells) *exactly*, with a biarc: two circular arcs with a common tangent at the
junction. Biarcs between two poses form a one-parameter family (the ratio of
the two tangent-leg lengths); for each model the member of least cost is
kept. The cost of a curve ``x(s)`` of curvature ``κ(s)`` is, with the
seed's eq. (5) and ``γ = 1``:

* ``dubins``:   ``∫ ds`` if ``|ξ κ| <= 1`` everywhere, else infeasible;
* ``elastica``: ``∫ (1 + ξ² κ²) ds`` (Euler–Mumford);
* ``rs``:       ``∫ sqrt(1 + ξ² κ²) ds`` (Reeds–Shepp forward). This model
  also turns in place at cost ``ξ |Δθ|`` (a sub-Riemannian metric, the
  ``|ẋ| → 0`` limit of the same cost), so it has rotation primitives.

Primitives that are no cheaper than a chain of two shorter primitives
(in free space) are dropped, which keeps the lattice small without changing
free-space optimal costs (Pivtoraiko & Kelly's control-set reduction).
Everything here is in cells; costs scale to metres by the node spacing.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache
from typing import Any

import numpy as np

from ...errors import InputError

__all__ = ["MODELS", "Primitives", "lattice_headings", "build_primitives", "biarc"]

#: The three cost models of the seed's eq. (5).
MODELS = ("dubins", "elastica", "rs")

#: Biarc leg ratios tried for each pose pair (geometric, symmetric around 1).
_RATIOS = np.geomspace(0.2, 5.0, 25)
#: Sampling step of primitives [cells] (collision cells and output points).
_SAMPLE_STEP = 0.2


def lattice_headings(max_int: int = 4) -> np.ndarray:
    """Lattice headings: directions of primitive integer vectors [rad], sorted in [0, 2π).

    Parameters
    ----------
    max_int : int
        Largest component magnitude of the vectors (>= 1). 1 gives the 8
        compass directions, 2 gives 16, 3 gives 32, 4 gives 48.
    """
    if isinstance(max_int, bool) or not isinstance(max_int, (int, np.integer)) or max_int < 1:
        raise InputError(f"max_int must be an integer >= 1, got {max_int!r}")
    angles = {
        round(math.atan2(b, a) % (2 * math.pi), 12)
        for a in range(-max_int, max_int + 1)
        for b in range(-max_int, max_int + 1)
        if (a or b) and math.gcd(a, b) == 1
    }
    return np.array(sorted(angles))


def _wrap(a: np.ndarray) -> np.ndarray:
    return (a + np.pi) % (2 * np.pi) - np.pi


def _arc(p0x, p0y, tx, ty, cx, cy):
    """Circular arc from a point with unit tangent ``t`` whose chord is ``c``.

    Returns (turning angle [rad], length, curvature), vectorised.
    """
    chord = np.hypot(cx, cy)
    phi = 2.0 * np.arctan2(tx * cy - ty * cx, tx * cx + ty * cy)
    half = 0.5 * phi
    with np.errstate(invalid="ignore", divide="ignore"):
        factor = np.where(np.abs(half) < 1e-9, 1.0, half / np.sin(half))
        length = chord * factor
        kappa = np.where(length > 0, phi / length, 0.0)
    return phi, length, kappa


def biarc(theta0, dx, dy, theta1, ratio):
    """Biarc from ``(0, 0, θ0)`` to ``(dx, dy, θ1)`` with leg ratio ``d1/d2 = ratio``.

    Vectorised over broadcast arguments.

    Returns
    -------
    tuple of ndarray
        ``(phi1, L1, k1, phi2, L2, k2, ok)``: turning angle [rad], length and
        curvature of each arc (units of ``dx``), and a validity mask (a real,
        forward biarc that ends with heading θ1).
    """
    t0x, t0y = np.cos(theta0), np.sin(theta0)
    t1x, t1y = np.cos(theta1), np.sin(theta1)
    vv = dx * dx + dy * dy
    a = 2.0 * ratio * (t0x * t1x + t0y * t1y - 1.0)
    b = -2.0 * (dx * (ratio * t0x + t1x) + dy * (ratio * t0y + t1y))
    with np.errstate(invalid="ignore", divide="ignore"):
        disc = np.sqrt(np.maximum(b * b - 4.0 * a * vv, 0.0))
        d2 = 2.0 * vv / (-b + disc)
    d1 = ratio * d2
    q1x, q1y = d1 * t0x, d1 * t0y
    q2x, q2y = dx - d2 * t1x, dy - d2 * t1y
    with np.errstate(invalid="ignore", divide="ignore"):
        mx = (d2 * q1x + d1 * q2x) / (d1 + d2)
        my = (d2 * q1y + d1 * q2y) / (d1 + d2)
    phi1, L1, k1 = _arc(0.0, 0.0, t0x, t0y, mx, my)
    th_m = theta0 + phi1
    phi2, L2, k2 = _arc(mx, my, np.cos(th_m), np.sin(th_m), dx - mx, dy - my)
    end_err = np.abs(_wrap(theta0 + phi1 + phi2 - theta1))
    ok = (
        np.isfinite(d2)
        & (d2 > 0)
        & np.isfinite(L1)
        & np.isfinite(L2)
        & (end_err < 1e-7)
        & (np.abs(phi1) < 0.75 * np.pi)
        & (np.abs(phi2) < 0.75 * np.pi)
    )
    return phi1, L1, k1, phi2, L2, k2, ok


def _model_cost(model: str, L1, k1, L2, k2, xi: float):
    if model == "dubins":
        lim = (1.0 + 1e-9) / xi
        feasible = (np.abs(k1) <= lim) & (np.abs(k2) <= lim)
        return np.where(feasible, L1 + L2, np.inf)
    if model == "elastica":
        return L1 * (1.0 + (xi * k1) ** 2) + L2 * (1.0 + (xi * k2) ** 2)
    return L1 * np.sqrt(1.0 + (xi * k1) ** 2) + L2 * np.sqrt(1.0 + (xi * k2) ** 2)


@dataclass(frozen=True, eq=False)
class Primitives:
    """A lattice control set for one model (all lengths in cells).

    Attributes
    ----------
    model : str
    xi : float
        ξ [cells].
    headings : ndarray, shape (K,)
        Lattice headings [rad].
    ptr : ndarray of int64, shape (K + 1,)
        Primitives of start heading ``i`` are ``ptr[i]:ptr[i+1]``.
    dx, dy, end : ndarray of int64, shape (P,)
        Displacement [cells] and end heading index.
    cost, length : ndarray, shape (P,)
        Model cost and arc length [cells].
    cell_ptr, cell_x, cell_y : ndarray of int64
        Grid cells (offsets from the start node) swept by each primitive.
    pt_ptr, pt_x, pt_y, pt_th : ndarray
        Sample points along each primitive (offsets [cells], heading [rad]),
        start excluded, end included.
    """

    model: str
    xi: float
    headings: np.ndarray
    ptr: np.ndarray
    dx: np.ndarray
    dy: np.ndarray
    end: np.ndarray
    cost: np.ndarray
    length: np.ndarray
    cell_ptr: np.ndarray
    cell_x: np.ndarray
    cell_y: np.ndarray
    pt_ptr: np.ndarray
    pt_x: np.ndarray
    pt_y: np.ndarray
    pt_th: np.ndarray

    @property
    def count(self) -> int:
        """Number of primitives."""
        return int(len(self.dx))

    def start_heading(self) -> np.ndarray:
        """Start heading index of every primitive."""
        return np.repeat(np.arange(len(self.headings)), np.diff(self.ptr))


def _sample(theta0, phi1, L1, k1, phi2, L2, k2, dx, dy):
    """Points (x, y, θ) every ~_SAMPLE_STEP along a biarc (or an in-place turn)."""
    total = L1 + L2
    if total <= 0:  # rotation in place
        return np.array([0.0]), np.array([0.0]), np.array([theta0 + phi1 + phi2])
    n = max(1, int(math.ceil(total / _SAMPLE_STEP)))
    s = np.linspace(0.0, total, n + 1)[1:]
    xs, ys, th = np.empty(n), np.empty(n), np.empty(n)

    def along(s_, x0, y0, h0, k):
        if abs(k) < 1e-12:
            return x0 + s_ * math.cos(h0), y0 + s_ * math.sin(h0), np.full_like(s_, h0)
        h = h0 + k * s_
        return x0 + (np.sin(h) - math.sin(h0)) / k, y0 - (np.cos(h) - math.cos(h0)) / k, h

    first = s <= L1
    xs[first], ys[first], th[first] = along(s[first], 0.0, 0.0, theta0, k1)
    mx, my, mth = along(np.array([L1]), 0.0, 0.0, theta0, k1)
    rest = ~first
    xs[rest], ys[rest], th[rest] = along(s[rest] - L1, mx[0], my[0], mth[0], k2)
    xs[-1], ys[-1] = dx, dy  # exact end
    return xs, ys, th


def _candidates(model: str, xi: float, th: np.ndarray, radius: float, r: int, max_turn: float,
                cone: float) -> dict[str, np.ndarray]:
    """Cheapest biarc primitive of every admissible (heading i, displacement, heading j).

    Displacements up to ``radius`` [cells]; a candidate turns at most ``max_turn`` and
    its displacement lies within ``cone`` of both headings [rad]. Returns the arrays
    ``i``, ``dx``, ``dy``, ``j``, ``cost`` and ``geom`` (phi1, L1, k1, phi2, L2, k2).
    """
    K = len(th)
    disp = np.array(
        [(a, b) for a in range(-r, r + 1) for b in range(-r, r + 1)
         if (a or b) and math.hypot(a, b) <= radius + 1e-9],
        dtype=float,
    )
    dang = np.arctan2(disp[:, 1], disp[:, 0])
    # candidate (i, d, j)
    I, D, J = np.meshgrid(np.arange(K), np.arange(len(disp)), np.arange(K), indexing="ij")
    I, D, J = I.ravel(), D.ravel(), J.ravel()
    keep = (
        (np.abs(_wrap(th[J] - th[I])) <= max_turn + 1e-9)
        & (np.abs(_wrap(dang[D] - th[I])) <= cone)
        & (np.abs(_wrap(dang[D] - th[J])) <= cone)
    )
    I, D, J = I[keep], D[keep], J[keep]
    t0, t1 = th[I][:, None], th[J][:, None]
    dx, dy = disp[D, 0][:, None], disp[D, 1][:, None]
    phi1, L1, k1, phi2, L2, k2, ok = biarc(t0, dx, dy, t1, _RATIOS[None, :])
    cost = np.where(ok, _model_cost(model, L1, k1, L2, k2, xi), np.inf)
    best = np.argmin(cost, axis=1)
    rows = np.arange(len(I))
    c = cost[rows, best]
    good = np.isfinite(c)
    sel = rows[good]
    bsel = best[good]
    return {
        "i": I[good], "dx": disp[D[good], 0].astype(np.int64), "dy": disp[D[good], 1].astype(np.int64),
        "j": J[good], "cost": c[good],
        "geom": np.stack([phi1[sel, bsel], L1[sel, bsel], k1[sel, bsel],
                          phi2[sel, bsel], L2[sel, bsel], k2[sel, bsel]], axis=1),
    }


def _with_rotations(prim: dict[str, np.ndarray], th: np.ndarray, xi: float) -> dict[str, np.ndarray]:
    """``prim`` plus the Reeds–Shepp rotations in place to both neighbouring headings (cost ξ|Δθ|)."""
    K = len(th)
    ii = np.concatenate([np.arange(K), np.arange(K)])
    jj = np.concatenate([(np.arange(K) + 1) % K, (np.arange(K) - 1) % K])
    dth = _wrap(th[jj] - th[ii])
    geom = np.zeros((2 * K, 6))
    geom[:, 0] = dth
    return {
        "i": np.concatenate([prim["i"], ii]),
        "dx": np.concatenate([prim["dx"], np.zeros(2 * K, np.int64)]),
        "dy": np.concatenate([prim["dy"], np.zeros(2 * K, np.int64)]),
        "j": np.concatenate([prim["j"], jj]),
        "cost": np.concatenate([prim["cost"], xi * np.abs(dth)]),
        "geom": np.concatenate([prim["geom"], geom]),
    }


def _sample_all(theta0: np.ndarray, geom: np.ndarray, dx: np.ndarray, dy: np.ndarray
                ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """:func:`_sample` of every primitive at once, the same values: ``(ptr, x, y, θ)``.

    Each primitive's arc lengths are its ``np.linspace`` (``i * (total / n)``, the last one
    ``total``); the scalar sines and cosines of the arcs' start headings are ``math``'s,
    as in :func:`_sample`.
    """
    phi1, L1, k1, phi2, L2, k2 = geom.T
    total = L1 + L2
    rot = total <= 0
    n = np.where(rot, 1, np.maximum(1, np.ceil(total / _SAMPLE_STEP))).astype(np.int64)
    ptr = np.concatenate([[0], np.cumsum(n)])
    owner = np.repeat(np.arange(len(n)), n)
    local = (np.arange(ptr[-1]) - ptr[:-1][owner] + 1).astype(float)
    s = local * (total / n)[owner] + 0.0
    last = ptr[1:] - 1
    s[last] = total
    first = s <= L1[owner]

    def trig(v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        return (np.array([math.sin(a) for a in v.tolist()]),
                np.array([math.cos(a) for a in v.tolist()]))

    def along(s_, o, x0, y0, h0, k, sin0, cos0):
        straight = np.abs(k[o]) < 1e-12
        kk = np.where(straight, 1.0, k[o])
        h = h0[o] + k[o] * s_
        x = np.where(straight, x0[o] + s_ * cos0[o], x0[o] + (np.sin(h) - sin0[o]) / kk)
        y = np.where(straight, y0[o] + s_ * sin0[o], y0[o] - (np.cos(h) - cos0[o]) / kk)
        return x, y, np.where(straight, h0[o], h)

    zero = np.zeros(len(n))
    sin0, cos0 = trig(theta0)
    xs, ys, th = np.empty(len(s)), np.empty(len(s)), np.empty(len(s))
    o = owner[first]
    xs[first], ys[first], th[first] = along(s[first], o, zero, zero, theta0, k1, sin0, cos0)
    allp = np.arange(len(n))
    mx, my, mth = along(L1, allp, zero, zero, theta0, k1, sin0, cos0)
    sin_m, cos_m = trig(mth)
    rest = ~first
    o = owner[rest]
    xs[rest], ys[rest], th[rest] = along(s[rest] - L1[o], o, mx, my, mth, k2, sin_m, cos_m)
    xs[last], ys[last] = dx, dy  # exact end
    r = np.flatnonzero(rot)  # rotations in place: one point, the heading after the turn
    xs[last[r]], ys[last[r]], th[last[r]] = 0.0, 0.0, theta0[r] + phi1[r] + phi2[r]
    return ptr, xs, ys, th


def _sweeps(prim: dict[str, np.ndarray], th: np.ndarray) -> tuple[list[Any], ...]:
    """Per primitive: its swept cells (nearest nodes of its samples, start node included) and its
    sampled points; CSR pointers and parts ``cell_ptr, cell_x, cell_y, pt_ptr, pt_x, pt_y, pt_th``.
    The cells of a primitive are sorted by (x, y), each once."""
    ptr, xs, ys, ths = _sample_all(th[prim["i"]], prim["geom"], prim["dx"].astype(float),
                                   prim["dy"].astype(float))
    pt_ptr = ptr.tolist()
    pt_x = [xs[a:b] for a, b in zip(pt_ptr[:-1], pt_ptr[1:])]
    pt_y = [ys[a:b] for a, b in zip(pt_ptr[:-1], pt_ptr[1:])]
    pt_th = [ths]
    n_prim = len(pt_x)
    if not n_prim:
        return [0], [], [], pt_ptr, pt_x, pt_y, pt_th
    # every primitive's samples and its start node (0, 0), their nearest nodes, then the
    # distinct (primitive, x, y) in one sort
    counts = np.diff(np.asarray(pt_ptr)) + 1
    owner = np.repeat(np.arange(n_prim, dtype=np.int64), counts)
    zero = np.zeros(1)
    cx = np.floor(np.concatenate([a for xs in pt_x for a in (xs, zero)]) + 0.5).astype(np.int64)
    cy = np.floor(np.concatenate([a for ys in pt_y for a in (ys, zero)]) + 0.5).astype(np.int64)
    x0, y0 = int(cx.min()), int(cy.min())
    wx, wy = int(cx.max()) - x0 + 1, int(cy.max()) - y0 + 1
    key = np.unique((owner * wx + (cx - x0)) * wy + (cy - y0))
    cell_x = (key // wy) % wx + x0
    cell_y = key % wy + y0
    cell_ptr = np.searchsorted(key // (wx * wy), np.arange(n_prim + 1)).tolist()
    return cell_ptr, [cell_x], [cell_y], pt_ptr, pt_x, pt_y, pt_th


@lru_cache(maxsize=16)
def build_primitives(
    model: str,
    xi: float,
    *,
    max_int: int = 4,
    radius: float = 4.5,
    max_turn: float = math.pi / 2,
    cone: float = math.radians(70.0),
) -> Primitives:
    """Build (and cache) the reduced control set of one model.

    Parameters
    ----------
    model : {"dubins", "elastica", "rs"}
    xi : float
        ξ [cells]: turning radius (Dubins) or curvature weight.
    max_int : int
        Heading set, see :func:`lattice_headings`.
    radius : float
        Longest displacement of a primitive [cells]; must reach the longest
        heading vector (``hypot(max_int, 1)``) so that every heading has a
        straight primitive.
    max_turn : float
        Largest heading change of one primitive [rad].
    cone : float
        Largest angle between the displacement and either end heading [rad].
    """
    if model not in MODELS:
        raise InputError(f"model must be one of {', '.join(MODELS)}, got {model!r}")
    if not (np.isfinite(xi) and xi > 0):
        raise InputError(f"xi must be > 0 cells, got {xi!r}")
    if radius < math.hypot(max_int, 1) - 1e-9:
        raise InputError(
            f"radius {radius} cells is shorter than the longest heading vector "
            f"({math.hypot(max_int, 1):.3f} cells); raise radius or lower max_int"
        )
    th = lattice_headings(max_int)
    K = len(th)
    r = int(math.floor(radius))
    prim = _candidates(model, xi, th, radius, r, max_turn, cone)
    if model == "rs":  # rotations in place to the neighbouring headings
        prim = _with_rotations(prim, th, xi)
    keep = _reduce(prim, K, r)
    prim = {k: v[keep] for k, v in prim.items()}
    order = np.lexsort((prim["j"], prim["dy"], prim["dx"], prim["i"]))
    prim = {k: v[order] for k, v in prim.items()}
    ptr = np.searchsorted(prim["i"], np.arange(K + 1)).astype(np.int64)

    cell_ptr, cell_x, cell_y, pt_ptr, pt_x, pt_y, pt_th = _sweeps(prim, th)
    length = prim["geom"][:, 1] + prim["geom"][:, 4]
    cat = lambda parts, dt: np.concatenate(parts).astype(dt) if parts else np.zeros(0, dt)  # noqa: E731
    return Primitives(
        model=model,
        xi=float(xi),
        headings=th,
        ptr=ptr,
        dx=prim["dx"].astype(np.int64),
        dy=prim["dy"].astype(np.int64),
        end=prim["j"].astype(np.int64),
        cost=prim["cost"].astype(np.float64),
        length=length.astype(np.float64),
        cell_ptr=np.asarray(cell_ptr, np.int64),
        cell_x=cat(cell_x, np.int64),
        cell_y=cat(cell_y, np.int64),
        pt_ptr=np.asarray(pt_ptr, np.int64),
        pt_x=cat(pt_x, np.float64),
        pt_y=cat(pt_y, np.float64),
        pt_th=cat(pt_th, np.float64),
    )


def _reduce(prim: dict, K: int, r: int) -> np.ndarray:
    """Mask of primitives not dominated by a chain of two shorter primitives.

    ``p = (i, d, j)`` is dropped when some ``p1 = (i, d1, k)`` and
    ``p2 = (k, d - d1, j)``, both with a strictly shorter displacement (or
    a rotation in place), cost together no more than ``p`` (relative
    tolerance 1e-9). Strictly shorter parts make the relation well founded,
    so dropping all dominated primitives at once keeps every free-space
    optimal cost.
    """
    i, j, dx, dy, c = prim["i"], prim["j"], prim["dx"], prim["dy"], prim["cost"]
    n2 = dx * dx + dy * dy
    span = 4 * r + 1
    off = 2 * r

    def key(ddx, ddy, jj):
        return ((ddx + off) * span + (ddy + off)) * K + jj

    by_start = [np.flatnonzero(i == h) for h in range(K)]
    sizes = np.array([len(b) for b in by_start], dtype=np.int64)
    keep = np.ones(len(i), dtype=bool)
    for h in range(K):
        own = by_start[h]
        if len(own) == 0:
            continue
        # every composite p1 (own) + p2 (starting at p1's end heading), flattened
        reps = sizes[j[own]]
        if not reps.sum():
            continue
        p1 = np.repeat(own, reps)
        p2 = np.concatenate([by_start[j[q]] for q in own])
        ck = key(dx[p1] + dx[p2], dy[p1] + dy[p2], j[p2])
        cc = c[p1] + c[p2]
        cn = np.maximum(n2[p1], n2[p2])
        # the own primitive with each composite's (displacement, end heading), if any (one
        # primitive per (start, displacement, end): the keys of own are distinct)
        own_keys = key(dx[own], dy[own], j[own])
        order = np.argsort(own_keys, kind="stable")
        pos = np.minimum(np.searchsorted(own_keys[order], ck), len(own) - 1)
        match = own_keys[order][pos] == ck
        p = own[order][pos]
        # dominated: a composite of strictly shorter parts costing no more
        beat = match & (n2[p] > 0) & (cn < n2[p]) & (cc <= c[p] * (1.0 + 1e-9))
        keep[p[beat]] = False
    return keep
