"""Multi-leg routes: FM² from start through via points to the goal (and back).

:func:`plan_route` plans one FM² path between each pair of successive points
(start → via 1 → ... → goal, and goal → start with ``return_to_start``) on the
same velocity map, and joins them into one :class:`~fm2uav.planning.Plan`, so
everything downstream (exports, reports, feasibility) sees one route. The legs
meet exactly at the points: ``route.junctions[k]`` is the index in
``route.plan.path`` of ``route.points[k]``.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from .. import progress
from ..errors import InputError, PlanningError, PointError
from ..planning import Plan, plan
from ..planning.params import FlightLevel, PlanOptions, Shaping
from ..planning.altitude import join_profiles
from ..planning.wind import WindOptions, join_timings

__all__ = ["Route", "plan_route"]


@dataclass(frozen=True, eq=False)
class Route:
    """Result of :func:`plan_route`.

    Attributes
    ----------
    plan : Plan
        The whole route as one plan: ``path``/``w`` joined, ``length`` the
        sum, ``clearance`` the smallest; ``W`` is the velocity map shared by the
        legs and ``T`` the arrival times of the first leg (each leg has its own
        in :attr:`legs`); ``params`` those of the first leg plus ``legs`` and
        ``via`` counts.
    legs : tuple of Plan
        One FM² plan per pair of successive points.
    points : ndarray, shape (k, ndim)
        Start, via points, goal (and the start again with a return leg) [m].
    junctions : ndarray of int, shape (k,)
        Index of each of ``points`` in ``plan.path``.
    """

    plan: Plan
    legs: tuple[Plan, ...] = field(repr=False)
    points: np.ndarray
    junctions: np.ndarray

    @property
    def via_indices(self) -> np.ndarray:
        """Path indices of the via points (without start, goal and return)."""
        return self.junctions[1:-1] if len(self.junctions) > 2 else self.junctions[:0]

    def summary(self) -> dict[str, Any]:
        """JSON-friendly numbers: per-leg lengths and the points."""
        return {
            "legs": len(self.legs),
            "points_m": np.round(self.points, 3).tolist(),
            "leg_lengths_m": [round(float(p.length), 3) for p in self.legs],
            "junction_indices": [int(j) for j in self.junctions],
        }


def plan_route(
    world: Any,
    start: Any,
    goal: Any,
    *,
    via: Any = (),
    return_to_start: bool = False,
    shaping: Shaping = Shaping(),
    level: FlightLevel | None = None,
    options: PlanOptions = PlanOptions(),
    wind: WindOptions | None = None,
) -> Route:
    """Plan start → via... → goal (→ start) with FM² leg by leg.

    Parameters
    ----------
    world : World
    start, goal : sequence of float
        World coordinates [m].
    via : sequence of points, optional
        Points to pass, in order [m].
    return_to_start : bool, optional
        Add a leg from the goal back to the start.
    shaping, level, options
        As :func:`fm2uav.plan`; the velocity map of the first leg is reused
        for the others (it does not depend on the points).
    wind : WindOptions, optional
        Plan every leg time-optimal in this wind (:mod:`fm2uav.planning.wind`); the
        route's ``wind_timing`` runs over all legs.

    Raises
    ------
    InputError
        A point with the wrong number of coordinates, or two successive
        points at the same place.
    fm2uav.PlanningError
        A leg cannot be planned; the message names the leg.
    """
    t0 = time.perf_counter()
    ndim = world.ndim
    try:
        pts = [np.asarray(start, dtype=float)]
        pts += [np.asarray(v, dtype=float) for v in via]
        pts.append(np.asarray(goal, dtype=float))
    except (TypeError, ValueError):
        raise InputError("start, via and goal must be points of numbers [m]") from None
    if return_to_start:
        pts.append(pts[0].copy())
    for k, p in enumerate(pts):
        if p.shape != (ndim,) or not np.all(np.isfinite(p)):
            what = "start" if k == 0 else ("goal" if k == len(pts) - 1 else f"via {k}")
            raise InputError(f"{what} must be {ndim} finite numbers [m], got {p.tolist()}")
    for k in range(len(pts) - 1):
        if np.linalg.norm(pts[k + 1] - pts[k]) < 1e-9:
            if len(pts) == 2:
                raise PointError(f"start and goal are the same place {pts[k].tolist()} m: there "
                                 "is nothing to plan; give a goal elsewhere (mission file "
                                 "start/goal; CLI --start/--goal)")
            raise InputError(f"points {k} and {k + 1} of the route are the same place "
                             f"{pts[k].tolist()} m; remove the repeated via point")
    legs: list[Plan] = []
    for k in range(len(pts) - 1):
        # later legs re-use the first leg's W (a regional leg has no world-sized W)
        reuse = legs and legs[0].params.get("storage") != "regional"
        opts = replace(options, speed_map=legs[0].W) if reuse else options
        try:
            with progress.span(f"leg {k + 1} of {len(pts) - 1}" if len(pts) > 2 else "",
                               1.0 / (len(pts) - 1)):
                legs.append(plan(world, pts[k], pts[k + 1], shaping=shaping, level=level,
                                 options=opts, wind=wind))
        except PlanningError as exc:
            raise type(exc)(f"route leg {k + 1} of {len(pts) - 1} "
                            f"({np.round(pts[k], 1).tolist()} → {np.round(pts[k + 1], 1).tolist()}"
                            f" m): {exc}") from None
    path = np.vstack([legs[0].path] + [lg.path[1:] for lg in legs[1:]])
    w = np.concatenate([legs[0].w] + [lg.w[1:] for lg in legs[1:]])
    junctions = np.concatenate([[0], np.cumsum([len(lg.path) - 1 for lg in legs])])
    timings: dict[str, float] = {}
    for lg in legs:
        for key, v in lg.timings.items():
            timings[key] = timings.get(key, 0.0) + float(v)
    timings["total"] = time.perf_counter() - t0
    params = {**legs[0].params, "legs": len(legs), "via": len(pts) - 2 - int(return_to_start),
              "return_to_start": bool(return_to_start)}
    timing = None
    if wind is not None:
        timing = join_timings([lg.wind_timing for lg in legs])
        params["wind"] = {**params["wind"], **timing.summary(), "refused_nodes": max(
            lg.params["wind"]["refused_nodes"] for lg in legs)}
    joined = Plan(
        path=path, w=w, length=float(sum(lg.length for lg in legs)),
        clearance=float(min(lg.clearance for lg in legs)), timings=timings,
        W=legs[0].W, T=legs[0].T, world=world,
        params=params,
        shaping=legs[0].shaping, level=legs[0].level,
        profile=join_profiles([lg.profile for lg in legs]),
        wind_timing=timing,
    )
    return Route(plan=joined, legs=tuple(legs), points=np.array(pts), junctions=junctions)
