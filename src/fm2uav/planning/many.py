"""Many routes from one wave: the FM² route to one goal from every start of a list.

FM² plans by descending the arrival times ``T`` of a wave started at the goal, and the
wave does not depend on the start: one march from a depot gives the route from every
address. :func:`plan_many` marches it once (the same velocity map W, shaping, flight
level and options as :func:`fm2uav.plan`), descends it from every start in a few threads
(:func:`fm2uav.planning.geodesic.descend_stopped`) and gives each path its heights and
figures by the routine :func:`fm2uav.plan` uses (:func:`~fm2uav.planning.planner.finish_plans`).

Each route is the :class:`~fm2uav.planning.planner.Plan` that ``plan(world, start, goal,
...)`` returns, path, ``w``, length, clearance and profile element for element:
:func:`fm2uav.plan` stops its march when the start freezes, and the descent of every
start here sees exactly that field, rebuilt from the one whole march. What differs is
``T`` (the whole march here, shared by every route) and the timings (each route has the
batch's: ``geodesic`` and ``metrics`` cover every route).

A start that cannot be planned — not a point, outside the map, in an obstacle or a
no-fly zone, on the goal's node, cut off from the goal, no path traced, no altitude
profile within the limits — gets a :class:`RouteFailure` with the reason and the message
:func:`fm2uav.plan` would raise for it; the other starts are planned all the same.
"""

from __future__ import annotations

import os
import time
from collections import Counter
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .. import _validate, progress
from ..eikonal.fmm import fast_marching
from ..errors import Fm2uavError, InputError, PlanningError, PointError
from ..world import World
from ..world.zones import check_points_allowed
from .geodesic import descend_stopped, reaches_any
from .params import FlightLevel, PlanOptions, Shaping
from .planner import (MAX_PATH_STEPS, Plan, _check_free, _check_objects, _check_work,
                      finish_plans, plan_velocity, stuck_error, unreachable_error)
from .regional import use_regional

__all__ = ["FAILURE_REASONS", "RouteFailure", "ManyPlans", "plan_many", "default_threads"]

#: Why a start got no route, and what each reason means.
FAILURE_REASONS = {
    "invalid": "not a point of the map's dimension (missing, non-numeric or non-finite "
               "coordinates), or absurdly far for the geodesic step",
    "outside": "outside the map's bounds",
    "blocked": "inside an obstacle (a building, the terrain) or where W is 0",
    "no-fly": "inside a no-fly zone",
    "at-goal": "on the goal's grid node: nothing to plan",
    "unreachable": "cut off from the goal: the wave from the goal never reached it",
    "no-path": "reached, but no path could be traced (W too dark along the only passage)",
    "altitude": "no altitude profile meets the flight level's limits along the route",
}


@dataclass(frozen=True)
class RouteFailure:
    """Why one start got no route.

    Attributes
    ----------
    reason : str
        One key of :data:`FAILURE_REASONS`.
    message : str
        The error :func:`fm2uav.plan` raises for this start (what, where, how to fix).
    """

    reason: str
    message: str


@dataclass(frozen=True, eq=False)
class ManyPlans:
    """The result of :func:`plan_many`.

    Attributes
    ----------
    goal : ndarray, shape (ndim,)
        The goal [m].
    routes : tuple of (Plan or RouteFailure)
        One entry per start, in the order given.
    W : ndarray
        The velocity map marched on (shared by every route).
    T : ndarray
        Arrival times of the whole march from the goal [s·(1/W)], ``inf`` where unreached.
    world : World
        The map.
    timings : dict of str to float
        Wall time of each stage of the batch [s]: ``velocity_map``, ``checks`` (every
        start checked as :func:`fm2uav.plan` checks it), ``fast_marching`` (the whole
        march and the source ball), ``routes`` (descents, heights and figures of every
        route, in the threads), ``total``; and ``cpu`` [s], the CPU time of the process
        during the call (every thread).
    threads : int
        Threads the descents ran in.
    """

    goal: np.ndarray
    routes: tuple[Plan | RouteFailure, ...]
    W: np.ndarray = field(repr=False)
    T: np.ndarray = field(repr=False)
    world: World = field(repr=False)
    timings: dict[str, float] = field(default_factory=dict)
    threads: int = 1

    def __len__(self) -> int:
        return len(self.routes)

    @property
    def ok(self) -> np.ndarray:
        """Bool per start: True where it got a route."""
        return np.array([isinstance(r, Plan) for r in self.routes], dtype=bool)

    @property
    def plans(self) -> list[Plan | None]:
        """The route of each start, None where it got none."""
        return [r if isinstance(r, Plan) else None for r in self.routes]

    def failures(self) -> dict[int, RouteFailure]:
        """The starts without a route: index (0-based, in the order given) → why."""
        return {k: r for k, r in enumerate(self.routes) if isinstance(r, RouteFailure)}

    def summary(self) -> dict[str, Any]:
        """Plain-Python summary: counts, failures per reason, lengths, timings."""
        lengths = [r.length for r in self.routes if isinstance(r, Plan)]
        reasons = Counter(r.reason for r in self.routes if isinstance(r, RouteFailure))
        return {
            "goal_m": [round(float(v), 3) for v in self.goal],
            "starts": len(self.routes),
            "routes": len(lengths),
            "failed": sum(reasons.values()),
            "failed_by_reason": dict(sorted(reasons.items())),
            "length_m": ({"min": round(float(min(lengths)), 3),
                          "median": round(float(np.median(lengths)), 3),
                          "max": round(float(max(lengths)), 3)} if lengths else None),
            "threads": int(self.threads),
            "timings_s": {k: round(v, 6) for k, v in self.timings.items()},
        }


def default_threads() -> int:
    """The cores this process may run on (``os.sched_getaffinity``, else ``os.cpu_count``)."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:  # not on Linux
        return max(1, os.cpu_count() or 1)


def _check_threads(threads: Any) -> int:
    if threads is None:
        return default_threads()
    if isinstance(threads, bool) or not isinstance(threads, (int, np.integer)) or threads < 1:
        raise InputError(f"threads must be a positive integer or None (all cores), got "
                         f"{threads!r} (CLI --threads)")
    return int(threads)


def _classify(world: World, W: np.ndarray, start: Any, goal_m: np.ndarray,
              goal_cell: tuple[int, ...], options: PlanOptions
              ) -> tuple[np.ndarray, tuple[int, ...]] | RouteFailure:
    """The start [m] and its node, checked as :func:`fm2uav.plan` checks it, or why not."""
    try:
        s = _validate.point(start, world.ndim, "start")
    except InputError as exc:
        return RouteFailure("invalid", str(exc))
    try:
        if world.zones:
            check_points_allowed(world, {"start": s})
    except PlanningError as exc:
        return RouteFailure("no-fly", str(exc))
    if not bool(np.all(world.contains(s))):
        try:
            world.to_cell(s, what="start")
        except Fm2uavError as exc:
            return RouteFailure("outside", str(exc))
    try:
        cell = _check_free(world, s, "start")
    except PlanningError as exc:
        return RouteFailure("blocked", str(exc))
    try:
        _check_work(world, s, goal_m, cell, goal_cell, options)
    except PointError as exc:
        return RouteFailure("at-goal", str(exc))
    except InputError as exc:
        return RouteFailure("invalid", str(exc))
    if W[cell] <= 0:
        return RouteFailure("blocked", "the velocity map is 0 at the start node; move the "
                            "start away from obstacles")
    return s, cell


def _classify_all(world: World, W: np.ndarray, starts: Sequence[Any], goal_m: np.ndarray,
                  goal_cell: tuple[int, ...], options: PlanOptions
                  ) -> list[tuple[np.ndarray, tuple[int, ...]] | RouteFailure]:
    """:func:`_classify` of every start; the plain ones checked at once (numpy), the others
    (and every start on a map with zones) one by one for their messages."""
    n = len(starts)
    good = np.zeros(n, dtype=bool)
    pts = np.zeros((n, world.ndim))
    if not world.zones:
        try:
            arr = np.asarray(starts, dtype=float)
        except (TypeError, ValueError):
            arr = None
        if arr is not None and arr.shape == (n, world.ndim):
            pts = arr
            good = np.all(np.isfinite(pts), axis=1)
            good[good] = np.atleast_1d(world.contains(pts[good]))
            cells = np.clip(np.floor(world.to_index(pts) + 0.5).astype(np.int64), 0,
                            np.asarray(world.shape) - 1)
            at = tuple(cells.T)
            good &= ~world.occupancy[at] & (W[at] > 0)
            good &= np.any(cells != np.asarray(goal_cell), axis=1)
            h = float(np.min(world.spacing))
            good &= (np.linalg.norm(pts - goal_m, axis=1) / (float(options.step) * h)
                     <= MAX_PATH_STEPS)
    out: list[tuple[np.ndarray, tuple[int, ...]] | RouteFailure] = []
    cell_list = cells.tolist() if good.any() else []  # Python ints, converted at once
    for k in range(n):
        if good[k]:
            out.append((pts[k].copy(), tuple(cell_list[k])))
        else:
            out.append(_classify(world, W, starts[k], goal_m, goal_cell, options))
    return out


@progress.stage()
def plan_many(
    world: World,
    goal: Any,
    starts: Sequence[Any],
    *,
    shaping: Shaping = Shaping(),
    level: FlightLevel | None = None,
    options: PlanOptions = PlanOptions(),
    threads: int | None = None,
) -> ManyPlans:
    """The FM² route from each of ``starts`` to one ``goal``, from one wave.

    Parameters
    ----------
    world : World
        The map (occupancy True = obstacle; zones included).
    goal : sequence of float
        The goal (the depot) in world coordinates [m].
    starts : sequence of sequence of float
        Start points in world coordinates [m], any number (one per address).
    shaping, level, options
        As :func:`fm2uav.plan` (``options.storage`` must allow the full grid).
    threads : int, optional
        Threads for the descents; None (default) = every core this process may use.

    Returns
    -------
    ManyPlans
        One :class:`~fm2uav.planning.planner.Plan` per start — the one
        ``plan(world, start, goal, shaping=shaping, level=level, options=options)``
        returns, path and figures element for element (``T`` and timings excepted) — or a
        :class:`RouteFailure` saying why it has none.

    Raises
    ------
    fm2uav.InputError
        Bad parameter objects or threads; a map planned regionally (too big for one grid).
    fm2uav.PointError
        The goal is outside the map, in an obstacle or a zone, or where W is 0.

    Examples
    --------
    >>> import numpy as np
    >>> from fm2uav import World, plan
    >>> occ = np.zeros((40, 30), bool); occ[18:22, 0:20] = True
    >>> world = World(occ, spacing=1.0)
    >>> many = plan_many(world, (35.0, 5.0), [(5.0, 5.0), (20.0, 5.0), (5.0, 25.0)])
    >>> [type(r).__name__ for r in many.routes]
    ['Plan', 'RouteFailure', 'Plan']
    >>> many.routes[1].reason
    'blocked'
    >>> bool(np.array_equal(many.routes[0].path, plan(world, (5.0, 5.0), (35.0, 5.0)).path))
    True
    """
    t_all = time.perf_counter()
    c_all = time.process_time()
    if not isinstance(world, World):
        raise InputError(f"world must be a fm2uav.World, got {type(world).__name__}")
    _check_objects(shaping, level, options)
    n_threads = _check_threads(threads)
    goal_m = _validate.point(goal, world.ndim, "goal")
    if world.zones:
        check_points_allowed(world, {"goal": goal_m})
    goal_cell = _check_free(world, goal_m, "goal")
    if use_regional(world, shaping, level, options):
        raise InputError("many routes need one full grid, and this map is planned regionally "
                         "(too big for one grid): use a coarser cell size (--cell-size) or "
                         "planner.storage: full (--storage full)")
    if isinstance(starts, np.ndarray) and starts.ndim == 1 and starts.size == world.ndim:
        raise InputError(f"starts must be a list of points, got one point {starts.tolist()}; "
                         "give [[x, y, ...], ...]")

    t0 = time.perf_counter()
    progress.step("velocity map W", 0.1)
    W = plan_velocity(world, shaping, level, options)
    if W[goal_cell] <= 0:
        raise PointError("the velocity map is 0 at the goal node; move the goal away from "
                         "obstacles")
    t1 = time.perf_counter()
    checked = _classify_all(world, W, starts, goal_m, goal_cell, options)
    t_checks = time.perf_counter() - t1
    t1 = time.perf_counter()
    progress.step("arrival times T (Fast Marching, once)", 0.2)
    # the march plan() runs (threads too: the parallel order-1 march on large grids)
    T = fast_marching(W, [goal_cell], spacing=world.spacing, order=options.order,
                      threads=options.threads)
    ball = fast_marching(W, [goal_cell], spacing=world.spacing, order=options.order,
                         stop_at=[goal_cell], threads=options.threads)  # frozen before the march
    t2 = time.perf_counter()
    routes: list[Plan | RouteFailure | None] = [None] * len(checked)
    todo: list[int] = []
    for k, c in enumerate(checked):
        if isinstance(c, RouteFailure):
            routes[k] = c
        elif not np.isfinite(T[c[1]]):
            routes[k] = RouteFailure("unreachable", str(unreachable_error(c[0], goal_m)))
        else:
            todo.append(k)
    progress.step(f"routes from {len(todo)} starts (descents, heights, figures)", 0.7)
    # as plan(): obstacles are masked only if W gave them a speed
    blocked = world.occupancy if reaches_any(T, world.occupancy) else None
    finish_plans(world, W, T, [np.asarray([world.to_index(goal_m)] * 2)], shaping, None,
                 options, (t_all, t0, t1, t2))  # fills the world's caches before the threads
    marks = (t_all, t0, t1, t2)

    def finish(positions: list[int], results: list[Any]) -> None:
        """The routes of descended starts (in the descending thread)."""
        traced: list[tuple[int, np.ndarray]] = []
        for pos, res in zip(positions, results):
            k = todo[pos]
            if isinstance(res, Exception):
                routes[k] = RouteFailure("no-path", str(stuck_error(checked[k][0], goal_m,
                                                                    shaping, res)))
            else:
                traced.append((k, res))
        plans = finish_plans(world, W, T, [q for _, q in traced], shaping, level, options,
                             marks)
        for (k, _), p in zip(traced, plans):
            routes[k] = RouteFailure("altitude", str(p)) if isinstance(p, PlanningError) else p

    todo_idx = world.to_index(np.array([checked[k][0] for k in todo]).reshape(-1, world.ndim))
    descend_stopped(T, todo_idx, world.to_index(goal_m), frozen=ball, spacing=world.spacing,
                    blocked=blocked, step=options.step, threads=n_threads, on_done=finish)
    t3 = time.perf_counter()
    timings = {"velocity_map": t1 - t0 - t_checks, "checks": t_checks, "fast_marching": t2 - t1,
               "routes": t3 - t2, "total": t3 - t_all, "cpu": time.process_time() - c_all}
    return ManyPlans(goal=goal_m, routes=tuple(routes), W=W, T=T, world=world,
                     timings=timings, threads=n_threads)
