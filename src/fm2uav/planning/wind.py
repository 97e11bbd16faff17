"""FM² in a wind: time-optimal routes over the safe airspeed ``W × airspeed``.

With :class:`WindOptions` :func:`fm2uav.plan` keeps the velocity map W (the share of
the airspeed that is safe near the obstacles) and replaces the goal wave by the
Zermelo march (:func:`fm2uav.eikonal.wind.zermelo_march`) over the airspeed
``W · V`` [m/s] in the wind field, run *towards* the goal (the time to fly from each
node to it, in seconds), with the unit ground track of the time-optimal flight at
every node. The path follows that track field from the start (:func:`descend_track`):
in a wind the fastest ground track is not the steepest descent of ``T`` but
``V n + w`` with the heading ``n = −∇T/|∇T|``.

Where the wind is at least the safe airspeed ``W · V`` (always next to obstacles,
where W → 0, and wherever the wind is stronger than the vehicle) the node is
**refused**: impassable, counted in the plan's ``params["wind"]``; a start or goal
there is an error that says so. Nothing is crossed silently.

:func:`path_timing` gives the ground speed, heading and time along a path from the
same field (``Plan.wind_timing``), which the exports turn into speeds.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from scipy import ndimage

from .. import _validate as v
from ..eikonal.wind import ground_speed, zermelo_march
from ..errors import InputError, PlanningError, UnreachableError

__all__ = ["WindOptions", "wind_times", "descend_track", "path_timing", "PathTiming",
           "join_timings"]


@dataclass(frozen=True, eq=False)
class WindOptions:
    """How :func:`fm2uav.plan` plans in a wind.

    Attributes
    ----------
    field : WindField
        The wind (:class:`fm2uav.world.wind.WindField`).
    airspeed : float
        The vehicle's airspeed at W = 1 [m/s] (its cruise or maximum speed): the safe
        airspeed at a node is ``W × airspeed``.
    """

    field: Any
    airspeed: float

    def __post_init__(self) -> None:
        from ..world.wind import WindField

        if not isinstance(self.field, WindField):
            raise InputError(f"wind field must be a fm2uav.world.wind.WindField, got "
                             f"{type(self.field).__name__}")
        object.__setattr__(self, "airspeed", v.positive(
            self.airspeed, "airspeed", unit="m/s",
            where=("airframe.cruise_speed / hover_speed", "--cruise-speed / --hover-speed")))

    def summary(self) -> dict[str, Any]:
        """JSON-friendly record (``Plan.params["wind"]``)."""
        return {**self.field.summary(), "airspeed_mps": self.airspeed}


def wind_times(world: Any, W: np.ndarray, goal_cell: tuple[int, ...],
               start_cell: tuple[int, ...], opts: WindOptions, *, order: int
               ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(T, track, refused)``: time [s] from each node to the goal at the safe airspeed
    in the wind, the unit ground track towards the goal, and the refused nodes.

    Raises
    ------
    PlanningError
        The start or the goal is refused (the wind there is at least ``W × airspeed``).
    """
    airspeed = W * opts.airspeed
    wind = opts.field.on_nodes(world)
    for cell, what in ((start_cell, "start"), (goal_cell, "goal")):
        ws = float(np.linalg.norm(wind[cell]))
        if ws >= airspeed[cell]:
            raise PlanningError(
                f"the wind at the {what} ({ws:.3g} m/s) is not below the safe airspeed there "
                f"(W {W[cell]:.3g} x {opts.airspeed:g} m/s = {airspeed[cell]:.3g} m/s): the "
                f"vehicle cannot hold its way; move the {what} away from obstacles, fly faster "
                "(--cruise-speed / --hover-speed) or on a calmer day")
    # stop once the start's neighbourhood is final: the descent interpolates around it
    box = np.stack(np.meshgrid(*[np.arange(max(c - 2, 0), min(c + 3, n))
                                 for c, n in zip(start_cell, W.shape)], indexing="ij"),
                   axis=-1).reshape(-1, W.ndim)
    box = box[W[tuple(box.T)] > 0]
    res = zermelo_march(airspeed, [goal_cell], wind, spacing=world.spacing, order=order,
                        stop_at=box, towards=True, track=True)
    return res.times, res.track, res.refused


def _interp(a: np.ndarray, p: np.ndarray) -> float:
    return float(ndimage.map_coordinates(a, p[:, None], order=1, mode="nearest")[0])


def descend_track(T: np.ndarray, track: np.ndarray, start: Any, goal: Any, *,
                  spacing: Any, blocked: np.ndarray | None = None, step: float = 0.5
                  ) -> np.ndarray:
    """Path from ``start`` to ``goal`` following the ground-track field of a wind march.

    Steps of ``step × min(spacing)`` metres along the track interpolated (linearly)
    at the point, integrated with the midpoint rule, are accepted while they lower the
    interpolated time ``T`` and land on a free node with finite ``T``; otherwise the
    path moves to the neighbour node (8 / 26) with the smallest ``T``, strictly below
    the current node's, so it always ends. The last point is ``goal`` exactly.

    Parameters
    ----------
    T : ndarray, shape grid
        Time to the goal [s] (``inf``: unreachable or refused).
    track : ndarray, shape (*grid, ndim)
        Unit ground-track direction towards the goal (physical axes).
    start, goal : array_like, shape (ndim,)
        Continuous index coordinates [cells].
    spacing : sequence of float
        Node spacing [m].
    blocked : ndarray of bool, optional
        Obstacle nodes (never entered).

    Returns
    -------
    ndarray, shape (N, ndim)
        Path in continuous index coordinates.

    Raises
    ------
    UnreachableError
        ``T`` is not finite at the start's node.
    """
    shape = T.shape
    ndim = T.ndim
    h = np.asarray(spacing, dtype=float)
    p = np.asarray(start, dtype=float).copy()
    g = np.asarray(goal, dtype=float)
    hi = np.asarray(shape, dtype=float) - 1.0

    def node(q: np.ndarray) -> tuple[int, ...]:
        return tuple(np.clip(np.rint(q), 0, hi).astype(int))

    def free(q: np.ndarray) -> bool:
        n = node(q)
        return bool(np.isfinite(T[n]) and (blocked is None or not blocked[n]))

    if not np.isfinite(T[node(p)]):
        raise UnreachableError("the start cannot reach the goal in this wind: every way "
                               "from it crosses refused or blocked nodes")
    Tf = np.where(np.isfinite(T), T, np.nanmax(np.where(np.isfinite(T), T, np.nan)) * 4 + 1)
    comps = [np.ascontiguousarray(track[..., k]) for k in range(ndim)]
    ds = float(step) * float(h.min())

    def direction(q: np.ndarray) -> np.ndarray | None:
        d = np.array([_interp(c, q) for c in comps])
        n = float(np.linalg.norm(d))
        if not (n > 1e-6 and math.isfinite(n)):
            return None
        return d / n / h * ds  # metres along the track -> index steps

    offsets = np.array(np.meshgrid(*[[-1, 0, 1]] * ndim, indexing="ij")).reshape(ndim, -1).T
    offsets = offsets[np.any(offsets != 0, axis=1)]
    path = [p.copy()]
    total = float(np.linalg.norm((g - p) * h))
    max_steps = int(20 * total / ds) + 10_000
    steps = 0
    close = 1.0  # cells: the last step goes straight to the goal
    while np.max(np.abs(p - g)) > close:
        steps += 1
        if steps > 4 * max_steps:
            raise PlanningError("the wind descent did not reach the goal; please report this")
        q = None
        if steps <= max_steps:
            d1 = direction(p)
            if d1 is not None:
                d2 = direction(np.clip(p + 0.5 * d1, 0, hi))
                if d2 is not None:
                    cand = np.clip(p + d2, 0, hi)
                    if free(cand) and _interp(Tf, cand) < _interp(Tf, p):
                        q = cand
        if q is None:  # discrete move: the neighbour node with the smallest T
            n0 = np.asarray(node(p))
            best, best_t = None, T[tuple(n0)]
            for o in offsets:
                m = n0 + o
                if np.any(m < 0) or np.any(m > hi):
                    continue
                tm = T[tuple(m)]
                if tm < best_t and (blocked is None or not blocked[tuple(m)]):
                    best, best_t = m, tm
            if best is None:
                raise PlanningError("the wind descent is stuck at a local minimum of the "
                                    "arrival times; please report this")
            q = best.astype(float)
        p = q
        path.append(p.copy())
    if np.any(path[-1] != g):
        path.append(g.copy())
    return np.array(path)


@dataclass(frozen=True, eq=False)
class PathTiming:
    """Ground speed, heading and time along a path flown at ``W × airspeed`` in a wind.

    Attributes
    ----------
    airspeed : ndarray, shape (N - 1,)
        Safe airspeed on each segment [m/s] (W at its midpoint × airspeed).
    groundspeed : ndarray, shape (N - 1,)
        Speed over the ground along the segment [m/s] (``nan``: no headway).
    heading : ndarray, shape (N - 1,)
        Heading to fly, degrees clockwise from north (the crab into the wind).
    wind : ndarray, shape (N - 1, 2)
        Wind at each segment's midpoint [m/s].
    time : ndarray, shape (N,)
        Time [s] at each path point from the start (``inf`` after a segment without
        headway).
    """

    airspeed: np.ndarray
    groundspeed: np.ndarray
    heading: np.ndarray
    wind: np.ndarray
    time: np.ndarray

    @property
    def total_s(self) -> float:
        """Flight time along the whole path [s]."""
        return float(self.time[-1])

    def point_groundspeed(self) -> np.ndarray:
        """Ground speed at each path point [m/s]: the slower of its two segments (0 where
        there is no headway)."""
        g = np.nan_to_num(self.groundspeed, nan=0.0)
        if not len(g):
            return np.zeros(1)
        return np.minimum(np.concatenate([g[:1], g]), np.concatenate([g, g[-1:]]))

    def summary(self) -> dict[str, Any]:
        """JSON-friendly figures."""
        ok = np.isfinite(self.groundspeed)
        return {"time_s": round(self.total_s, 2) if math.isfinite(self.total_s) else None,
                "groundspeed_mps": [round(float(np.min(self.groundspeed[ok])), 2),
                                    round(float(np.max(self.groundspeed[ok])), 2)]
                if ok.any() else None,
                "no_headway_segments": int((~ok).sum())}


def path_timing(world: Any, path: np.ndarray, w: np.ndarray, opts: WindOptions) -> PathTiming:
    """:class:`PathTiming` of ``path`` [m] with W ``w`` at its points, in ``opts.field``.

    The ground speed of a segment of track ``u`` at airspeed ``V`` in wind ``w`` is the
    positive root of ``|g u − w| = V`` (:func:`fm2uav.eikonal.wind.ground_speed`), the
    wind and W taken at the segment's midpoint and its height above ground.
    """
    p = np.asarray(path, dtype=float)
    d = np.diff(p, axis=0)
    mid = 0.5 * (p[1:] + p[:-1])
    agl = None
    if p.shape[1] == 3:
        agl = mid[:, 2] - np.asarray(world.ground_height(mid[:, 0], mid[:, 1]), dtype=float)
    wind2 = opts.field.at(mid, agl)
    air = 0.5 * (w[1:] + w[:-1]) * opts.airspeed
    wind = np.concatenate([wind2, np.zeros((len(d), p.shape[1] - 2))], axis=1)
    seg = np.linalg.norm(d, axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        g = np.asarray(ground_speed(d, air, wind), dtype=float)
        g = np.where(np.isfinite(g) & (g > 0), g, np.nan)
        dt = np.where(seg > 0, seg / g, 0.0)
    dt = np.where(np.isfinite(dt), dt, np.inf)
    u = d[:, :2] / np.maximum(np.linalg.norm(d[:, :2], axis=1), 1e-12)[:, None]
    head_vec = np.nan_to_num(g)[:, None] * u - wind2   # air velocity: where the nose points
    heading = np.degrees(np.arctan2(head_vec[:, 0], head_vec[:, 1])) % 360.0
    return PathTiming(air, g, heading, wind2, np.concatenate([[0.0], np.cumsum(dt)]))


def join_timings(parts: list[PathTiming]) -> PathTiming:
    """The timing of legs flown one after the other (their paths share the junctions)."""
    times = [parts[0].time]
    for p in parts[1:]:
        times.append(times[-1][-1] + p.time[1:])
    return PathTiming(np.concatenate([p.airspeed for p in parts]),
                      np.concatenate([p.groundspeed for p in parts]),
                      np.concatenate([p.heading for p in parts]),
                      np.concatenate([p.wind for p in parts]), np.concatenate(times))
