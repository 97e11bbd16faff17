"""Sampling-based baselines: OMPL's RRT, RRT* and RRT-Connect in a voxel world.

Thesis §3.3.1 compares FM² with an RRT "under the same conditions": same map,
same start and goal, the RRT path then smoothed. Here the planners come from
the OMPL wheel (``from ompl import base as ob, geometric as og``):

* state space: ``RealVectorStateSpace`` over the world's bounds (2D or 3D, m);
* a state is valid iff it lies in the map and its nearest grid node is free
  (the same nearest-node rule as :meth:`World.to_cell`); motions are checked
  every half cell;
* RRT and RRT-Connect stop at their first solution (``time_limit`` caps them);
  RRT* improves its path length until ``time_limit``;
* smoothing (``"shortcut"``, default): OMPL's ``PathSimplifier.simplify``
  (vertex reduction, close-vertex collapsing and random shortcutting, within
  ``simplify_time``); ``"bspline"`` adds ``smoothBSpline``; ``"none"`` keeps
  the raw tree path;
* the result is densified to half a cell so that clearance and curvature are
  measured like the FM² path's.

Determinism: OMPL seeds one process-wide generator, and only before its first
use; :func:`plan_rrt` sets ``seed`` the first time it runs in a process
(``RRTResult.seeded`` says whether that happened). Later calls in the same
process continue the sequence, so compare RRT runs by their statistics.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from typing import Any, Callable

import numpy as np

from ..errors import InputError, PointError, UnreachableError
from ..geometry import densify, path_length
from ..world import World
from ..world.clearance import clearance_profile

__all__ = ["RRT_PLANNERS", "RRTOptions", "RRTResult", "plan_rrt"]

#: Planner name → OMPL class name.
RRT_PLANNERS = {"rrt": "RRT", "rrtstar": "RRTstar", "rrtconnect": "RRTConnect"}
_SEEDED = {"done": False}


@dataclass(frozen=True)
class RRTOptions:
    """How :func:`plan_rrt` runs its OMPL planner.

    Attributes
    ----------
    time_limit : float
        Planning time budget [s] (RRT*: always used in full). Default 5.
    range_m : float, optional
        Maximum tree edge length [m]; default OMPL's (20 % of the map diagonal).
    goal_bias : float
        Probability of sampling the goal (RRT, RRT*). Default 0.05.
    smoothing : {"shortcut", "bspline", "none"}
        Smoothing of the tree path (see the module docstring). Default "shortcut".
    simplify_time : float
        Time cap of the shortcut smoothing [s]. Default 1.
    seed : int
        OMPL seed (see the module note on determinism). Default 0.
    """

    time_limit: float = 5.0
    range_m: float | None = None
    goal_bias: float = 0.05
    smoothing: str = "shortcut"
    simplify_time: float = 1.0
    seed: int = 0


@dataclass(frozen=True, eq=False)
class RRTResult:
    """Result of :func:`plan_rrt`.

    Attributes
    ----------
    path : ndarray (N, ndim)
        Smoothed path densified every half cell [m], start → goal exactly.
    vertices : ndarray (M, ndim)
        Vertices of the smoothed path [m].
    raw : ndarray (K, ndim)
        Vertices of the tree path before smoothing [m].
    tree : ndarray (E, 2, ndim)
        Edges of the search tree(s) [m] (for figures).
    length, raw_length : float
        Path lengths [m].
    clearance : float
        Smallest distance from the densified path to an obstacle node [m].
    timings : dict
        ``solve``, ``simplify``, ``total`` [s].
    planner : str
    seeded : bool
        Whether ``seed`` was applied (first OMPL use in the process).
    """

    path: np.ndarray = field(repr=False)
    vertices: np.ndarray = field(repr=False)
    raw: np.ndarray = field(repr=False)
    tree: np.ndarray = field(repr=False)
    length: float
    raw_length: float
    clearance: float
    timings: dict[str, float]
    planner: str
    seeded: bool

    def summary(self) -> dict[str, Any]:
        """JSON-friendly numbers."""
        return {
            "planner": self.planner,
            "length_m": round(self.length, 3),
            "raw_length_m": round(self.raw_length, 3),
            "clearance_m": round(self.clearance, 3) if math.isfinite(self.clearance) else None,
            "vertices": int(len(self.vertices)),
            "tree_edges": int(len(self.tree)),
            "timings_s": {k: round(v, 6) for k, v in self.timings.items()},
            "seeded": self.seeded,
        }


def _check_rrt_args(world: Any, planner: str, smoothing: str, time_limit: float) -> str:
    """Check the world, planner, smoothing and time budget of :func:`plan_rrt`; the planner key."""
    if not isinstance(world, World):
        raise InputError(f"world must be a fm2uav.World, got {type(world).__name__}")
    key = str(planner).lower().replace("-", "").replace("_", "").replace("*", "star")
    if key not in RRT_PLANNERS:
        raise InputError(f"unknown planner {planner!r}; valid: {', '.join(RRT_PLANNERS)}")
    if smoothing not in ("shortcut", "bspline", "none"):
        raise InputError(f"smoothing must be 'shortcut', 'bspline' or 'none', got {smoothing!r}")
    if not (math.isfinite(float(time_limit)) and time_limit > 0):
        raise InputError(f"time_limit must be > 0 seconds, got {time_limit!r}")
    return key


def _rrt_points(world: World, start: Any, goal: Any) -> dict[str, np.ndarray]:
    """Start and goal [m] as arrays, checked inside the map and in free space."""
    nd = world.ndim
    pts = {}
    for what, p in (("start", start), ("goal", goal)):
        arr = np.asarray(p, dtype=float).reshape(-1)
        if arr.size != nd or not np.all(np.isfinite(arr)):
            raise InputError(f"{what} must be {nd} finite coordinates in metres, got {p!r}")
        cell = world.to_cell(arr, what=what)  # PointError outside the map
        if world.occupancy[cell]:
            raise PointError(f"{what} {arr.tolist()} m is inside an obstacle (node {list(cell)}); "
                             f"move the {what} to free space")
        pts[what] = arr
    return pts


def _validity_checker(world: World) -> Callable[[Any], bool]:
    """OMPL state validity: inside the map and its nearest node free."""
    nd = world.ndim
    occ = world.occupancy
    org = np.asarray(world.origin)
    sp = np.asarray(world.spacing)
    hi_idx = np.asarray(world.shape) - 1

    def valid(state: Any) -> bool:
        idx = []
        for k in range(nd):
            v = (state[k] - org[k]) / sp[k]
            if v < -1e-9 or v > hi_idx[k] + 1e-9:
                return False
            idx.append(int(v + 0.5))
        return not occ[tuple(idx)]

    return valid


def _simple_setup(ob: Any, og: Any, world: World, pts: dict[str, np.ndarray]
                  ) -> tuple[Any, Any, Callable[[Any], bool]]:
    """OMPL SimpleSetup on the world's box with its validity checker, start and goal; its space
    information (collision checks every half cell) and the checker."""
    nd = world.ndim
    sp = np.asarray(world.spacing)
    space = ob.RealVectorStateSpace(nd)
    bounds = ob.RealVectorBounds(nd)
    b = world.bounds
    for k in range(nd):
        bounds.setLow(k, float(b[k, 0]))
        bounds.setHigh(k, float(b[k, 1]))
    space.setBounds(bounds)
    ss = og.SimpleSetup(space)
    valid = _validity_checker(world)
    ss.setStateValidityChecker(valid)
    si = ss.getSpaceInformation()
    si.setStateValidityCheckingResolution(0.5 * float(sp.min()) / space.getMaximumExtent())
    s_state, g_state = space.allocState(), space.allocState()
    for k in range(nd):
        s_state[k] = float(pts["start"][k])
        g_state[k] = float(pts["goal"][k])
    ss.setStartAndGoalStates(s_state, g_state, 1e-6)
    return ss, si, valid


def _states(path: Any, nd: int) -> np.ndarray:
    """The states of an OMPL path as an (n, nd) array [m]."""
    return np.array([[path.getState(i)[k] for k in range(nd)]
                     for i in range(path.getStateCount())])


def _tree_edges(data: Any, nd: int) -> np.ndarray:
    """The edges of OMPL planner data as an (n, 2, nd) array [m]."""
    edges = []
    for i in range(data.numVertices()):
        a = data.getVertex(i).getState()
        for j in data.getEdges(i):
            c = data.getVertex(int(j)).getState()
            edges.append([[a[k] for k in range(nd)], [c[k] for k in range(nd)]])
    return np.asarray(edges, dtype=float).reshape(-1, 2, nd)


def _seed_once(ou: Any, seed: int) -> bool:
    """Seed OMPL's global RNG on the first plan of the process (see the module note);
    whether this call seeded it."""
    if _SEEDED["done"]:
        return False
    ou.RNG.setSeed(int(seed))
    _SEEDED["done"] = True
    return True


def _planner(og: Any, si: Any, key: str, range_m: float | None, goal_bias: float) -> Any:
    """The OMPL planner ``key`` on the space information ``si``, with its range [m] and
    goal bias (RRT, RRT*)."""
    pl = getattr(og, RRT_PLANNERS[key])(si)
    if range_m is not None:
        pl.setRange(float(range_m))
    if key != "rrtconnect":
        pl.setGoalBias(float(goal_bias))
    return pl


def _smoothed(og: Any, si: Any, sol: Any, smoothing: str, simplify_time: float) -> Any:
    """A copy of the solution path ``sol``, shortcut (``simplify_time`` [s] cap) and
    B-spline smoothed as ``smoothing`` asks."""
    work = og.PathGeometric(sol)
    if smoothing != "none":
        ps = og.PathSimplifier(si)
        ps.simplify(work, float(simplify_time))
        if smoothing == "bspline":
            ps.smoothBSpline(work)
    return work


def plan_rrt(
    world: World,
    start: Any,
    goal: Any,
    *,
    planner: str = "rrt",
    options: RRTOptions = RRTOptions(),
) -> RRTResult:
    """Plan with an OMPL sampling-based planner on a :class:`World`.

    Parameters
    ----------
    world : World
        2D or 3D occupancy grid (True = obstacle).
    start, goal : sequence of float
        World coordinates [m].
    planner : {"rrt", "rrtstar", "rrtconnect"}
    options : RRTOptions
        Time budget, tree range, goal bias, smoothing and seed.

    Raises
    ------
    PointError
        Start/goal outside the map or in an obstacle.
    UnreachableError
        No exact solution within ``options.time_limit``.
    InputError
        Unknown planner/smoothing, bad numbers.
    """
    from ompl import base as ob
    from ompl import geometric as og
    from ompl import util as ou

    o = options
    key = _check_rrt_args(world, planner, o.smoothing, o.time_limit)
    nd = world.ndim
    pts = _rrt_points(world, start, goal)

    ou.setLogLevel(ou.LOG_ERROR)
    seeded = _seed_once(ou, o.seed)
    sp = np.asarray(world.spacing)
    ss, si, valid = _simple_setup(ob, og, world, pts)  # keep the Python callback alive
    pl = _planner(og, si, key, o.range_m, o.goal_bias)
    ss.setPlanner(pl)

    t0 = time.perf_counter()
    ss.solve(float(o.time_limit))
    t1 = time.perf_counter()
    if not ss.haveExactSolutionPath():
        raise UnreachableError(
            f"{RRT_PLANNERS[key]} found no path from {pts['start'].tolist()} m to "
            f"{pts['goal'].tolist()} m within {o.time_limit:g} s; raise time_limit or check that "
            "the goal is reachable"
        )
    sol = ss.getSolutionPath()
    raw = _states(sol, nd)
    work = _smoothed(og, si, sol, o.smoothing, o.simplify_time)
    t2 = time.perf_counter()
    verts = _states(work, nd)
    verts[0], verts[-1] = pts["start"], pts["goal"]
    data = ob.PlannerData(si)
    pl.getPlannerData(data)
    tree = _tree_edges(data, nd)
    dense, _ = densify(verts, 0.5 * float(sp.min()))
    clearance = float(clearance_profile(world, dense).min())
    # drop OMPL objects (and the Python callback they hold) before returning
    ss.clear()
    del ss, pl, si, work, sol, data
    return RRTResult(
        path=dense, vertices=verts, raw=raw, tree=tree, length=path_length(verts),
        raw_length=path_length(raw), clearance=clearance,
        timings={"solve": t1 - t0, "simplify": t2 - t1, "total": t2 - t0},
        planner=RRT_PLANNERS[key], seeded=seeded,
    )
