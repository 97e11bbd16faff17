"""Curvature-penalised shortest paths among obstacles on a 2D map.

The reference planners of the curvature study (seed 004, §2.2, eq. (5)):
Dubins, Euler–Mumford elastica and Reeds–Shepp forward. The seed computes
them with Mirebeau's Hamiltonian Fast Marching; here they are cheapest paths
in an (x, y, θ) state lattice whose edges are biarcs between lattice poses
(:mod:`.primitives`), searched with a compiled Dijkstra (:mod:`._kernels`).
Every edge is a real curve, so the result is a feasible path of the model
(for Dubins: curvature ``<= 1/ξ`` everywhere) whose cost converges to the
continuous optimum as the lattice is refined; in free space the Dubins
length is within 2 % of the exact one (tests/baselines/reference).

A primitive is collision-free when the grid nodes nearest to its samples
(every 0.2 cell) are all free.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ...errors import InputError, PointError, UnreachableError
from ...geometry import path_length
from ...world import World
from . import _kernels as _k
from .primitives import MODELS, Primitives, build_primitives

__all__ = ["ReferencePath", "reference_path", "default_radius", "DEFAULT_XI"]

#: Default ξ [m]: turning radius of the Dubins model, curvature weight of the others.
DEFAULT_XI = 10.0


@dataclass(frozen=True, eq=False)
class ReferencePath:
    """A reference path of one curvature model.

    Attributes
    ----------
    model : str
        ``"dubins"``, ``"elastica"`` or ``"rs"``.
    path : ndarray, shape (N, 2)
        Points [m] from start to goal (consecutive duplicates removed).
    heading : ndarray, shape (N,)
        Heading at each point [rad].
    cost : float
        Model cost [m] (eq. (5), ``γ = 1``).
    length : float
        Arc length [m].
    xi : float
        ξ [m].
    expanded : int
        Lattice states settled by the search.
    timings : dict
        ``primitives`` (control set, cached after the first call), ``search``,
        ``total`` [s].
    """

    model: str
    path: np.ndarray
    heading: np.ndarray
    cost: float
    length: float
    xi: float
    expanded: int
    timings: dict[str, float] = field(default_factory=dict)

    def summary(self) -> dict[str, Any]:
        """JSON-friendly numbers."""
        return {
            "model": self.model,
            "points": int(len(self.path)),
            "cost_m": round(self.cost, 4),
            "length_m": round(self.length, 4),
            "xi_m": self.xi,
            "start_heading_deg": round(math.degrees(self.heading[0]) % 360.0, 3),
            "goal_heading_deg": round(math.degrees(self.heading[-1]) % 360.0, 3),
            "expanded": self.expanded,
            "timings_s": {k: round(v, 6) for k, v in self.timings.items()},
        }


def default_radius(xi_cells: float, max_int: int = 4, model: str = "dubins") -> float:
    """Default primitive reach [cells].

    ``max(hypot(max_int, 1) + 0.4, c ξ)`` with ``c = 1.2`` for Dubins and 0.9
    for the other models: long enough for a straight primitive along every
    heading and for a turn of radius ξ to the next heading off an axis. The
    Dubins lattice needs the longer reach to follow straight segments between
    lattice directions without breaking the curvature bound (with 0.9 ξ a
    free-space case was 2.8 % longer than the exact Dubins path, with 1.2 ξ
    0.75 %); the elastica and Reeds–Shepp costs allow sharper corrections, and
    their (larger) control sets would grow ~2x.
    """
    c = 1.2 if model == "dubins" else 0.9
    return max(math.hypot(max_int, 1) + 0.4, c * float(xi_cells))


def _node(world: World, p: Any, what: str) -> tuple[int, int]:
    try:
        arr = np.asarray(p, dtype=float).reshape(-1)
    except (TypeError, ValueError):
        raise InputError(f"{what} must be 2 coordinates in metres, got {p!r}") from None
    if arr.size != 2 or not np.all(np.isfinite(arr)):
        raise InputError(f"{what} must be 2 finite coordinates (x, y) in metres, got {p!r}")
    cell = world.to_cell(arr, what=what)
    if world.occupancy[cell]:
        raise PointError(
            f"{what} {arr.tolist()} m is inside an obstacle (node {list(cell)}); "
            f"move the {what} to free space"
        )
    return int(cell[0]), int(cell[1])


def _heading_mask(headings: np.ndarray, value: float | None, what: str) -> np.ndarray:
    if value is None:
        return np.ones(len(headings), dtype=bool)
    v = float(value)
    if not np.isfinite(v):
        raise InputError(f"{what} must be a finite angle in radians or None, got {value!r}")
    diff = np.abs((headings - v + np.pi) % (2 * np.pi) - np.pi)
    mask = np.zeros(len(headings), dtype=bool)
    mask[int(np.argmin(diff))] = True
    return mask


def _check_reference_args(world: Any, model: str, xi: float) -> float:
    """Check the world (2D, square cells), the model and ξ of :func:`reference_path`; the spacing [m]."""
    if not isinstance(world, World) or world.ndim != 2:
        raise InputError("reference_path needs a 2D fm2uav.World")
    h = float(world.spacing[0])
    if abs(world.spacing[1] - h) > 1e-9 * h:
        raise InputError(
            f"reference_path needs the same spacing on x and y, got {world.spacing}; "
            "resample the map"
        )
    if model not in MODELS:
        raise InputError(f"model must be one of {', '.join(MODELS)}, got {model!r}")
    if not (np.isfinite(xi) and xi > 0):
        raise InputError(f"xi must be > 0 metres, got {xi!r}")
    return h


def reference_path(
    world: World,
    start: Any,
    goal: Any,
    *,
    model: str = "dubins",
    xi: float = DEFAULT_XI,
    start_heading: float | None = None,
    goal_heading: float | None = None,
    max_int: int = 4,
    radius: float | None = None,
    heuristic: bool = False,
) -> ReferencePath:
    """Cheapest path of a curvature model between two points of a 2D map.

    Parameters
    ----------
    world : World
        2D map with the same spacing on x and y (occupancy True = obstacle).
    start, goal : sequence of 2 floats
        Points [m], snapped to the nearest node.
    model : {"dubins", "elastica", "rs"}
        Cost of eq. (5) of the seed: Dubins (length, curvature ``<= 1/ξ``),
        Euler–Mumford elastica ``∫(1 + ξ²κ²) ds``, Reeds–Shepp forward
        ``∫ sqrt(1 + ξ²κ²) ds`` (which may also turn in place).
    xi : float
        ξ [m]. Default :data:`DEFAULT_XI`.
    start_heading, goal_heading : float or None
        Headings [rad], snapped to the nearest lattice heading; ``None`` leaves
        the heading free (the default: FM² paths have no prescribed heading).
    max_int, radius : int, float
        Lattice resolution: headings from integer vectors up to ``max_int``
        (48 headings for 4, 80 for 5) and primitives up to ``radius`` cells
        long. ``radius=None`` (default) takes :func:`default_radius`.
    heuristic : bool
        Use A* with the Euclidean distance (same optimum, fewer states
        expanded). Default False: plain Dijkstra, like a full-field solver.

    Returns
    -------
    ReferencePath

    Raises
    ------
    fm2uav.PointError
        Start or goal outside the map or in an obstacle.
    fm2uav.UnreachableError
        No lattice path joins them.
    fm2uav.InputError
        Bad model, ξ, headings, or a 3D / anisotropic world.
    """
    t_all = time.perf_counter()
    h = _check_reference_args(world, model, xi)
    sx, sy = _node(world, start, "start")
    gx, gy = _node(world, goal, "goal")

    t0 = time.perf_counter()
    xi_cells = float(xi) / h
    rad = default_radius(xi_cells, max_int, model) if radius is None else float(radius)
    prims = build_primitives(model, xi_cells, max_int=max_int, radius=rad)
    t1 = time.perf_counter()
    K = len(prims.headings)
    smask = _heading_mask(prims.headings, start_heading, "start_heading")
    gmask = _heading_mask(prims.headings, goal_heading, "goal_heading")
    ny = world.shape[1]
    sources = ((sx * ny + sy) * K + np.flatnonzero(smask)).astype(np.int64)
    free = np.ascontiguousarray(~world.occupancy)
    goal_state, _cost, parent, expanded = _k.lattice_search(
        free, K, prims.ptr, prims.dx, prims.dy, prims.end, prims.cost,
        prims.cell_ptr, prims.cell_x, prims.cell_y,
        sources, gx, gy, gmask, 1.0 if heuristic else 0.0,
    )
    t2 = time.perf_counter()
    if goal_state < 0:
        raise UnreachableError(
            f"no {model} path (ξ = {xi} m) joins start {np.round(world.to_world((sx, sy)), 3).tolist()} m "
            f"and goal {np.round(world.to_world((gx, gy)), 3).tolist()} m on this map; the streets "
            "may be too narrow for the curvature bound: lower xi or move the points"
        )
    path_cells, heading, cost = _trace(prims, parent, goal_state, ny, K)
    path = world.to_world(path_cells)
    length = path_length(path)
    t3 = time.perf_counter()
    return ReferencePath(
        model=model,
        path=path,
        heading=heading,
        cost=cost * h,
        length=length,
        xi=float(xi),
        expanded=int(expanded),
        timings={"primitives": t1 - t0, "search": t2 - t1, "total": t3 - t_all},
    )


def _trace(prims: Primitives, parent: np.ndarray, goal_state: int, ny: int, K: int):
    """Follow the parents back from the goal; return points [cells], headings, cost [cells]."""
    starts = prims.start_heading()
    chain = []
    s = int(goal_state)
    while parent[s] >= 0:
        p = int(parent[s])
        chain.append((p, s))
        cell = s // K
        ix, iy = cell // ny - prims.dx[p], cell % ny - prims.dy[p]
        s = (int(ix) * ny + int(iy)) * K + int(starts[p])
    cell = s // K
    xs, ys, th = [float(cell // ny)], [float(cell % ny)], [float(prims.headings[s % K])]
    cost = 0.0
    for p, _ in reversed(chain):
        a, b = prims.pt_ptr[p], prims.pt_ptr[p + 1]
        x0, y0 = xs[-1], ys[-1]
        xs.extend((x0 + prims.pt_x[a:b]).tolist())
        ys.extend((y0 + prims.pt_y[a:b]).tolist())
        th.extend(prims.pt_th[a:b].tolist())
        xs[-1], ys[-1] = round(xs[-1]), round(ys[-1])
        cost += float(prims.cost[p])
    pts = np.column_stack([xs, ys])
    heading = np.asarray(th)
    keep = np.ones(len(pts), dtype=bool)
    keep[1:] = np.any(np.abs(np.diff(pts, axis=0)) > 1e-12, axis=1)
    # a rotation in place keeps the point; keep the heading after the rotation
    idx = np.flatnonzero(keep)
    last_of_run = np.append(idx[1:] - 1, len(pts) - 1)
    return pts[idx], heading[last_of_run], cost
