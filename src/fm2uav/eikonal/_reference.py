"""Slow, readable pure-Python Fast Marching Method, used only by the tests.

This module is an independent second implementation of the discretisation of
:func:`fm2uav.eikonal.fast_marching`: same upwind stencil, same point-source
initialisation, same ``stop_at`` semantics. It is written for clarity, not
speed: plain Python loops over index tuples, :mod:`heapq` with lazy deletion
for the narrow band, and numpy arrays only as storage. It works for any number
of dimensions (the tests use 2 and 3).

The discretisation, in words
----------------------------
Arrival times ``T`` [s] solve ``|grad T| = 1 / v`` on a node-centred grid
(node ``i`` sits at ``i * h`` [m] along each axis, ``h`` may differ per axis).

Speeds
    A positive speed below ``MIN_SPEED = 1e-150`` [m/s] is raised to it, so
    ``1 / v^2`` stays finite and such a node is merely very slow, not a wall.

Sources
    ``T = 0`` at every source node; source nodes are frozen. Then comes the
    straight-ray *ball*, unless there are more than ``MAX_BALL_SOURCES = 64``
    sources, counted as given (repeats included); then sources are plain
    ``T = 0`` nodes and nothing else is initialised. The nominal ball radius
    is ``R = max(2 * max(h), 0.05 * extent)`` [m], where ``extent`` is the
    largest physical size ``(n_axis - 1) * h_axis`` of the grid. A radius ``r``
    is clean for a source if the source's bounding box of ``r`` (clipped to
    the grid, ``floor(r / h_axis)`` nodes either side per axis) holds no node
    of speed ``<= 0`` and its largest speed is at most
    ``BALL_MAX_SPEED_RATIO = 1.5`` times its smallest. Each source tries
    ``R``, then ``max(R / 2, 2 max(h))``, halving until a clean radius or the
    try at ``2 max(h)``; a source is *clean* if one of them is. Around every
    clean source, with its radius ``r``,
    every node at physical distance ``d <= r`` other than a source gets a ball
    time if that is smaller than its current value (so the minimum over
    sources wins): if the box's speed is constant, the straight-ray time
    ``d * 0.5 * (1/v_source + 1/v_node)``; otherwise the time of the factored
    equation solved on the box (below). If *every*
    source is clean, these ball nodes are frozen: their values are final. If
    at least one source is not clean, the ball nodes only join the narrow band,
    so the march may still lower them (e.g. via a nearer route past an
    obstacle beside another source).

Factored ball (varying speed in a clean box)
    A separate march over the box nodes only, with ``T = T0 * tau``,
    ``T0 = |x - x_s| / v_source`` and ``tau = 1`` at the source. A node is
    updated from its frozen box neighbours: per axis the one with the smaller
    ``T`` (minus side on a tie), at ``x -/+ e``; ``sigma = +1`` for the minus
    side, ``-1`` for the plus side. If the next box node in that direction is
    frozen with ``T2 <= T1``: ``a = 3 / (2 h)``, ``b = (4 tau_1 - tau_2) / 3``,
    else ``a = 1 / h``, ``b = tau_1``. With ``p = dT0/dx_axis =
    (x_axis - x_s,axis) / (v_source |x - x_s|)`` the axis gives
    ``alpha = p + T0 sigma a`` and ``beta = T0 sigma a b``. For every
    non-empty subset of these axes, the larger root ``tau`` of
    ``sum (alpha tau - beta)^2 = 1 / v^2`` is a candidate if the discriminant
    is ``>= 0`` and, on every axis of the subset,
    ``sigma (alpha tau - beta) >= 0`` and ``T0 tau >= T1``; the node takes the
    smallest candidate ``T0 tau`` or, if there is none, the smallest
    ``T1 + h / v`` over its axes, when that is below its current value. The
    box march freezes the smallest time first, until the box is done.

Local update of a node ``x`` with speed ``v``
    For each axis take the frozen neighbour (``x - e`` or ``x + e``) with the
    smaller ``T`` (the minus side wins a tie), ``T1``. With order 2, if the
    next node in the same direction (``x -/+ 2e``) is frozen and its time
    ``T2 <= T1``, and the speeds at ``x``, ``x -/+ e`` and ``x -/+ 2e`` differ
    by at most a factor ``ORDER2_MAX_SPEED_RATIO = 2``, the axis contributes ``a (T - tau)^2`` with
    ``tau = (4 T1 - T2) / 3`` and ``a = 9 / (4 h^2)``; otherwise
    ``tau = T1`` and ``a = 1 / h^2``. An axis with no frozen neighbour does
    not contribute. The axes are sorted by ``tau``; the first gives
    ``T = tau_1 + sqrt(rhs / a_1)`` with ``rhs = 1 / v^2``, and each next axis
    joins while the current ``T`` is later than its ``tau`` and the
    discriminant of ``sum a_m (T - tau_m)^2 = rhs`` stays ``>= 0``; the larger
    root is taken. A node keeps the smaller of its current and the new value.

March
    Pop the band node with the smallest ``T``, freeze it, and update its
    non-frozen neighbours of positive speed. Before the march, every
    non-frozen neighbour of a node frozen by the initialisation (the sources,
    and the ball nodes when they are frozen) is updated once.
    With ``stop_at``, the march ends as soon as all stop nodes are frozen; if
    they all are frozen by the initialisation (sources, frozen ball), nothing
    is marched. Every node not frozen at the end is returned as ``inf``.
"""

from __future__ import annotations

import heapq
import itertools
import math
from collections.abc import Iterator, Sequence
from typing import Any

import numpy as np

__all__ = ["fast_marching_reference"]

# The constants of the source initialisation, written out again here rather
# than imported, so that this stays an independent implementation; a test
# checks that they equal those of fm2uav.eikonal.fmm.

#: Ball radius: at least this many largest grid spacings ...
SOURCE_RADIUS_CELLS = 2.0
#: ... and at least this share of the grid's largest physical extent.
SOURCE_RADIUS_FRACTION = 0.05
#: With more sources than this, no ball: sources are plain T = 0 nodes.
MAX_BALL_SOURCES = 64
#: Order 2 only where max/min speed along the stencil is at most this.
ORDER2_MAX_SPEED_RATIO = 2.0
#: A box whose max/min speed exceeds this is not clean (no ball).
BALL_MAX_SPEED_RATIO = 1.5
#: Positive speeds below this [m/s] are raised to it.
MIN_SPEED = 1e-150

Index = tuple[int, ...]


def _neighbours(node: Index, shape: tuple[int, ...]) -> Iterator[Index]:
    """Yield the (up to ``2 * ndim``) axis-aligned neighbours inside the grid."""
    for axis in range(len(shape)):
        for step in (-1, 1):
            coord = node[axis] + step
            if 0 <= coord < shape[axis]:
                yield node[:axis] + (coord,) + node[axis + 1:]


def _shifted(node: Index, axis: int, step: int) -> Index:
    """Return ``node`` moved by ``step`` nodes along ``axis``."""
    return node[:axis] + (node[axis] + step,) + node[axis + 1:]


def _axis_term(
    T: np.ndarray,
    frozen: np.ndarray,
    speed: np.ndarray,
    node: Index,
    axis: int,
    h: float,
    order: int,
) -> tuple[float, float] | None:
    """Upwind term ``a (T - tau)^2`` of one axis.

    Parameters
    ----------
    T : ndarray
        Current arrival times [s].
    frozen : ndarray of bool
        Which nodes are accepted.
    speed : ndarray
        Speeds [m/s] (order 2 needs a smooth speed along its stencil).
    node : tuple of int
        The node being updated.
    axis : int
        The axis.
    h : float
        Spacing along ``axis`` [m].
    order : {1, 2}
        Stencil order.

    Returns
    -------
    (tau, a) or None
        ``tau`` [s] and ``a`` [1/m^2]; ``None`` when neither neighbour on this
        axis is frozen.
    """
    n = T.shape[axis]
    best_step = 0
    best_time = math.inf
    for step in (-1, 1):  # minus side first: it wins a tie
        coord = node[axis] + step
        if 0 <= coord < n:
            nb = _shifted(node, axis, step)
            if frozen[nb] and float(T[nb]) < best_time:
                best_time = float(T[nb])
                best_step = step
    if best_step == 0:
        return None
    if order == 2:
        coord2 = node[axis] + 2 * best_step
        if 0 <= coord2 < n:
            nb2 = _shifted(node, axis, 2 * best_step)
            nb1 = _shifted(node, axis, best_step)
            speeds = [float(speed[node]), float(speed[nb1]), float(speed[nb2])]
            smooth = max(speeds) <= ORDER2_MAX_SPEED_RATIO * min(speeds)
            if frozen[nb2] and float(T[nb2]) <= best_time and smooth:
                t2 = float(T[nb2])
                return (4.0 * best_time - t2) / 3.0, 9.0 / (4.0 * h * h)
    return best_time, 1.0 / (h * h)


def _local_solution(
    T: np.ndarray,
    frozen: np.ndarray,
    speed: np.ndarray,
    node: Index,
    spacing: tuple[float, ...],
    order: int,
) -> float:
    """Solve the upwind quadratic at ``node``; return the new time [s].

    Returns ``inf`` when no axis has a frozen neighbour.
    """
    v = float(speed[node])
    rhs = 1.0 / (v * v)  # [s^2/m^2]
    terms = []
    for axis, h in enumerate(spacing):
        term = _axis_term(T, frozen, speed, node, axis, h, order)
        if term is not None:
            terms.append(term)
    if not terms:
        return math.inf
    terms.sort(key=lambda term: term[0])

    tau0, a = terms[0]
    t = tau0 + math.sqrt(rhs / a)  # one-sided solution
    # in s = T - tau0 (coefficients of the size of rhs, not of T^2: no cancellation)
    A, B, C = a, 0.0, 0.0  # sum a, sum a*d, sum a*d^2 with d = tau - tau0
    for tau, a in terms[1:]:
        if t <= tau:  # causality: this axis is not upwind of the solution
            break
        d = tau - tau0
        A, B, C = A + a, B + a * d, C + a * d * d
        disc = B * B - A * (C - rhs)
        if disc < 0.0:
            break
        t = tau0 + (B + math.sqrt(disc)) / A
    return t


def _factored_box_times(
    speed: np.ndarray,
    source: Index,
    ranges: list[range],
    spacing: tuple[float, ...],
) -> dict[Index, float]:
    """Times [s] of the factored equation on one source's box (module docstring).

    Parameters
    ----------
    speed : ndarray
        Speeds [m/s]; every node of the box has speed > 0.
    source : tuple of int
        The source node.
    ranges : list of range
        The box: node indices per axis.
    spacing : tuple of float
        Spacing per axis [m].

    Returns
    -------
    dict
        Box node -> arrival time [s] (0 at the source).
    """
    ndim = len(spacing)
    s_source = 1.0 / float(speed[source])  # slowness at the source [s/m]
    inside = set(itertools.product(*ranges))
    times: dict[Index, float] = {source: 0.0}
    factor: dict[Index, float] = {source: 1.0}  # tau = T / T0
    done: set[Index] = set()
    heap: list[tuple[float, Index]] = [(0.0, source)]

    def offset(node: Index) -> tuple[list[float], float]:
        x = [(node[ax] - source[ax]) * spacing[ax] for ax in range(ndim)]
        d2 = 0.0
        for xa in x:
            d2 += xa * xa
        return x, math.sqrt(d2)

    def update(node: Index) -> float:
        x, dist = offset(node)
        t0 = s_source * dist
        slow = 1.0 / float(speed[node])
        axes = []  # (alpha, beta, sigma, T1, h) per upwind axis
        for ax in range(ndim):
            side, t1 = 0, math.inf
            for step in (-1, 1):  # minus side first: it wins a tie
                nb = _shifted(node, ax, step)
                if nb in done and times[nb] < t1:
                    side, t1 = step, times[nb]
            if side == 0:
                continue
            nb1 = _shifted(node, ax, side)
            nb2 = _shifted(node, ax, 2 * side)
            ka, kb = 1.0 / spacing[ax], factor[nb1]
            if nb2 in done and times[nb2] <= t1:
                ka, kb = 1.5 / spacing[ax], (4.0 * factor[nb1] - factor[nb2]) / 3.0
            sigma = -1.0 * side
            alpha = s_source * x[ax] / dist + t0 * sigma * ka
            axes.append((alpha, t0 * sigma * ka * kb, sigma, t1, spacing[ax]))
        best = math.inf
        for k in range(1, len(axes) + 1):
            for subset in itertools.combinations(axes, k):
                A = B = C = 0.0
                for alpha, beta, *_ in subset:
                    A += alpha * alpha
                    B += alpha * beta
                    C += beta * beta
                if A <= 0.0:
                    continue
                disc = B * B - A * (C - slow * slow)
                if disc < 0.0:
                    continue
                f = (B + math.sqrt(disc)) / A
                t = t0 * f
                if t < best and all(
                    sigma * (alpha * f - beta) >= 0.0 and t >= t1
                    for alpha, beta, sigma, t1, _ in subset
                ):
                    best = t
        if best == math.inf:  # no admissible root: first-order one-sided update
            best = min((t1 + hx * slow for *_, t1, hx in axes), default=math.inf)
        return best

    while heap:
        t, node = heapq.heappop(heap)
        if node in done or t != times[node]:  # stale entry
            continue
        done.add(node)
        for nb in _neighbours(node, speed.shape):
            if nb in inside and nb not in done:
                t_new = update(nb)
                if t_new < times.get(nb, math.inf):
                    times[nb] = t_new
                    factor[nb] = t_new / (s_source * offset(nb)[1])
                    heapq.heappush(heap, (t_new, nb))
    return times


def _as_nodes(points: Any, ndim: int) -> list[Index]:
    """Turn one index tuple or a sequence of them into a list of int tuples."""
    arr = np.asarray(points)
    if arr.ndim == 1:
        arr = arr[None, :]
    return [tuple(int(c) for c in row) for row in arr.reshape(-1, ndim)]


def _source_ball(
    speed: np.ndarray, source_nodes: list[Index], is_source: set[Index], h: tuple[float, ...]
) -> tuple[dict[Index, float], bool]:
    """The ball times around every clean source (node -> smallest over the sources) [s],
    and whether every source is clean (then the ball nodes are final)."""
    shape, ndim = speed.shape, speed.ndim
    ball: dict[Index, float] = {}
    extent = max((n - 1) * hx for n, hx in zip(shape, h))  # [m]
    radius = max(SOURCE_RADIUS_CELLS * max(h), SOURCE_RADIUS_FRACTION * extent)  # [m]
    smallest = SOURCE_RADIUS_CELLS * max(h)  # [m] the last radius tried
    radii, boxes, box_ranges, clean, constant = [], [], [], [], []
    for s in source_nodes:
        r = radius
        while True:  # radius, radius / 2, ... down to 2 cells: the first clean box
            reach = [int(math.floor(r / hx)) for hx in h]  # nodes per axis
            ranges = [
                range(max(s[ax] - reach[ax], 0), min(s[ax] + reach[ax], shape[ax] - 1) + 1)
                for ax in range(ndim)
            ]
            box = list(itertools.product(*ranges))
            speeds = [float(speed[node]) for node in box]
            ok = min(speeds) > 0.0 and max(speeds) <= BALL_MAX_SPEED_RATIO * min(speeds)
            if ok or r <= smallest:
                break
            r = max(0.5 * r, smallest)
        radii.append(r)
        box_ranges.append(ranges)
        boxes.append(box)
        clean.append(ok)
        constant.append(min(speeds) == max(speeds))
    for s, r, box, ranges, ok, flat in zip(
        source_nodes, radii, boxes, box_ranges, clean, constant
    ):
        if not ok:
            continue
        v_source = float(speed[s])
        factored = None if flat else _factored_box_times(speed, s, ranges, h)
        for node in box:
            d2 = 0.0
            for ax in range(ndim):
                dx = (node[ax] - s[ax]) * h[ax]
                d2 += dx * dx
            if d2 > r * r or node in is_source:
                continue
            if factored is None:  # constant speed: the exact straight ray
                t = math.sqrt(d2) * 0.5 * (1.0 / v_source + 1.0 / float(speed[node]))
            else:
                t = factored[node]
            if t < ball.get(node, math.inf):
                ball[node] = t
    return ball, all(clean)


def _start(speed: np.ndarray, source_nodes: list[Index], h: tuple[float, ...],
           source_ball: bool) -> tuple[np.ndarray, np.ndarray, list[tuple[float, Index]],
                                       list[Index]]:
    """``(T, frozen, band, seeds)`` before the march: the sources at ``T = 0`` (frozen), the
    ball nodes (frozen when every source is clean, else in the band heap of ``(time,
    node)``); ``seeds`` are the frozen nodes whose neighbours join the band."""
    shape = speed.shape
    T = np.full(shape, math.inf)
    frozen = np.zeros(shape, dtype=bool)
    band: list[tuple[float, Index]] = []  # heap of (time, node); stale entries skipped
    for s in source_nodes:
        T[s] = 0.0
        frozen[s] = True
    ball: dict[Index, float] = {}  # node -> smallest ball time [s]
    if source_ball and len(source_nodes) <= MAX_BALL_SOURCES:  # counted with repeats
        ball, freeze_ball = _source_ball(speed, source_nodes, set(source_nodes), h)
        for node, t in ball.items():
            T[node] = t
            if freeze_ball:
                frozen[node] = True  # final: never lowered
            else:
                heapq.heappush(band, (t, node))  # may still be lowered
    return T, frozen, band, source_nodes + [node for node in ball if frozen[node]]


def fast_marching_reference(
    speed: Any,
    sources: Any,
    *,
    spacing: float | Sequence[float] = 1.0,
    order: int = 2,
    stop_at: Any = None,
    source_ball: bool = True,
) -> np.ndarray:
    """Arrival times by a slow pure-Python Fast Marching Method (tests only).

    The march is one readable loop written out step by step to be checked against
    the compiled march; the start (sources and ball) is :func:`_start`.

    Same discretisation as :func:`fm2uav.eikonal.fast_marching` (see the
    module docstring). Inputs are assumed valid: no checks beyond what is
    needed to read them.

    Parameters
    ----------
    speed : array_like, shape (nx, ny) or (nx, ny, nz)
        Propagation speed at each node [m/s], ``>= 0``; 0 marks impassable
        nodes. Indexed x first.
    sources : sequence of int tuples or (m, ndim) int array
        Source node indices (speed > 0), where ``T = 0`` [s].
    spacing : float or sequence of float, optional
        Node spacing [m], one value or one per axis. Default 1.
    order : {1, 2}, optional
        Upwind stencil order. Default 2.
    stop_at : sequence of int tuples, optional
        Stop once all these nodes are frozen; nodes not frozen by then are
        ``inf``.
    source_ball : bool, optional
        Use the source ball (default True); False: sources are plain
        ``T = 0`` nodes, as with more than ``MAX_BALL_SOURCES`` sources.

    Returns
    -------
    ndarray of float64, same shape as ``speed``
        Arrival time [s]; ``inf`` where unreached.
    """
    speed = np.asarray(speed, dtype=np.float64)
    speed = np.where((speed > 0.0) & (speed < MIN_SPEED), MIN_SPEED, speed)
    shape = speed.shape
    ndim = speed.ndim
    h = tuple(float(x) for x in np.broadcast_to(np.asarray(spacing, dtype=float), (ndim,)))

    # ---- sources (T = 0, frozen) and the ball around every clean source
    T, frozen, band, seeds = _start(speed, _as_nodes(sources, ndim), h, source_ball)

    def relax(node: Index) -> None:
        """Recompute a non-frozen node and push it if its time decreased."""
        t = _local_solution(T, frozen, speed, node, h, order)
        if t < T[node]:
            T[node] = t
            heapq.heappush(band, (t, node))

    # ---- every free neighbour of a node frozen so far joins the band
    for node in seeds:
        for nb in _neighbours(node, shape):
            if not frozen[nb] and speed[nb] > 0.0:
                relax(nb)

    # ---- stop nodes still to freeze
    remaining: set[Index] | None = None
    if stop_at is not None:
        remaining = {node for node in _as_nodes(stop_at, ndim) if not frozen[node]}

    # ---- the march
    while band and (remaining is None or remaining):
        t, node = heapq.heappop(band)
        if frozen[node] or t != T[node]:  # stale entry (lazy deletion)
            continue
        frozen[node] = True
        if remaining is not None:
            remaining.discard(node)
            if not remaining:
                break
        for nb in _neighbours(node, shape):
            if not frozen[nb] and speed[nb] > 0.0:
                relax(nb)

    T[~frozen] = math.inf
    return T
