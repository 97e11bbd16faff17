"""Regional plans: FM² on terrain maps too big for one full 3D grid (coarse-to-fine).

A 3000 x 3000-column DEM with 100 layers is 9e8 nodes: its full-grid plan
(distance map, W, arrival times, the marcher's padded copies: ~40 bytes per
node) would take ~36 GB. Terrain following only needs the cells near the flight
level, so :func:`plan_regional` plans in three stages:

1. **Coarse route.** The surface (ground and roofs) sampled on a horizontally
   coarser grid (at most :data:`COARSE_COLUMNS` columns; vertical cell doubled
   while the level stays >= 3 cells above the ground) and planned with the same
   shaping and flight level over the whole map.
2. **Full-resolution windows.** Waypoints every :data:`SEGMENT_CELLS` cells along
   the coarse route (on the flight-level node of their column); from the current
   point to the waypoint after next, an ordinary FM² plan on a *window* of the world:
   the columns of those two stretches of the coarse route plus :data:`MARGIN_CELLS`
   on every side, and only the layers from one below the lowest ground of the window
   to :data:`TOP_MARGIN_LAYERS` above its highest flight level. Its path is kept up to
   the point nearest the next waypoint, where the next window starts (receding
   horizon: the waypoints only pin the discarded halves, so the kept path is the fine
   route, not forced through points of the coarse one). The window's nodes are
   the world's nodes (same grid, same occupancy), and its W is normalised by the
   *whole world's* largest obstacle distance (:func:`world_max_distance`, exact), so
   W on a window is the full plan's W (except within a few cells of the window's
   sides, where obstacles outside it are not seen; the margin keeps the route away
   from there).
3. **Final heights and checks** as :func:`fm2uav.plan`: the altitude profile of
   :mod:`fm2uav.planning.altitude` over the whole world's continuous surface, the
   surface clearance, the zone check.

The route is thus the full plan's route wherever the full-resolution optimum stays
within the corridor of the coarse route (tests/planning/test_regional.py compares
both on a map where the full grid fits: lengths within 1 %, same safety figures).
Where the relief's features are finer than the coarse cells, the coarse stage may
choose another valley than the full plan and the corridor keeps the fine plan in it
(``python -m benchmarks.bench_core big``, row "rough").
"""

from __future__ import annotations

import math
import os
import time
from collections.abc import Callable
from dataclasses import dataclass, replace
from typing import Any

import numpy as np
from scipy import ndimage

from ..eikonal import _edt
from ..eikonal.fmm import fast_marching
from ..eikonal.velocity import distance_map, shape_velocity
from ..errors import InputError, PlanningError
from ..geometry import path_length
from ..world import World
from ..world.clearance import column_surface, surface_clearance
from ..world.geo import BYTES_PER_NODE
from .altitude import final_profile
from .flight_level import flight_layer, flight_level_speed
from .geodesic import descend
from .params import FlightLevel, PlanOptions, Shaping, plan_params

__all__ = [
    "plan_regional",
    "use_regional",
    "full_plan_bytes",
    "check_full_grid",
    "world_max_distance",
    "window_velocity",
    "FULL_PLAN_MEMORY_SHARE",
    "COARSE_COLUMNS",
    "SEGMENT_CELLS",
    "MARGIN_CELLS",
    "TOP_MARGIN_LAYERS",
]

#: ``storage="auto"`` plans regionally when the full grid would take more than this
#: share of the machine's physical memory.
FULL_PLAN_MEMORY_SHARE = 0.25
#: Most columns of the coarse stage's grid.
COARSE_COLUMNS = 250_000
#: Length of a full-resolution window's stretch of the coarse route [cells].
SEGMENT_CELLS = 64
#: Columns added on every side of a window around its stretch of the coarse route.
MARGIN_CELLS = 30
#: Layers a window keeps above its highest flight-level node.
TOP_MARGIN_LAYERS = 10


def full_plan_bytes(world: World) -> float:
    """Estimated memory [bytes] of a full-grid plan of ``world`` (~40 bytes per node)."""
    return float(np.prod([float(n) for n in world.shape])) * BYTES_PER_NODE


def _memory_bytes() -> float:
    try:
        return float(os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES"))
    except (ValueError, OSError, AttributeError):  # pragma: no cover - non-POSIX
        return math.inf


def check_full_grid(world: World, why: str = "terrain following (planner.agl / --agl) plans "
                    "such terrain worlds regionally") -> None:
    """Refuse a full-grid FM² map of ``world`` larger than this machine's memory.

    Raises
    ------
    InputError
        :func:`full_plan_bytes` exceeds the physical memory; the message says how
        much it would take, ``why``, and what shrinks the world.
    """
    need, have = full_plan_bytes(world), _memory_bytes()
    if need > have:
        raise InputError(
            f"the world's {world.occupancy.size:.3g} nodes need about {need / 2**30:.3g} GiB "
            f"to plan on one full grid (this machine: {have / 2**30:.3g} GiB); {why}; or use "
            "a larger world.cell_size / world.dz (CLI --cell-size / --dz) or crop with "
            "world.bbox (CLI --bbox)")


def _unsupported(world: World, shaping: Shaping, level: FlightLevel | None,
                 options: PlanOptions) -> str | None:
    """Why ``world`` cannot be planned regionally (None if it can)."""
    if world.ndim != 3 or world.terrain is None:
        return "it needs a 3D terrain world (World.from_heightmap / from_dem)"
    if level is None:
        return "it needs a flight level (planner.agl / --agl)"
    if options.speed_map is not None:
        return "a custom speed map needs the full grid"
    if world.zones:
        return "no-fly zones need the full grid"
    if shaping.method != "edt" or shaping.walls:
        return "it needs planner.method 'edt' and no walls"
    if column_surface(world) is None:
        return "the obstacles must be solid columns (terrain, buildings)"
    return None


def use_regional(world: World, shaping: Shaping, level: FlightLevel | None,
                 options: PlanOptions) -> bool:
    """Whether :func:`fm2uav.plan` plans regionally (``options.storage``, see PlanOptions).

    Raises
    ------
    InputError
        ``storage="regional"`` on a world or request that needs the full grid.
    """
    if options.storage == "full":
        return False
    if options.storage == "auto":
        need, have = full_plan_bytes(world), _memory_bytes()
        if need <= FULL_PLAN_MEMORY_SHARE * have:
            return False
        why = _unsupported(world, shaping, level, options)
        if why is not None:
            check_full_grid(world, f"a regional plan cannot take this request: {why}")
        return why is None
    why = _unsupported(world, shaping, level, options)
    if why is not None:
        raise InputError(f"storage 'regional' cannot plan this request: {why} (mission file: "
                         "planner.storage; CLI: --storage)")
    return True


def world_max_distance(world: World) -> float:
    """Largest distance [m] from a node of a column world to its obstacles, exact.

    What :func:`fm2uav.planning.planner.max_distance` gives for the full grid
    (the EDT's maximum), from one layer: the distance to obstacle columns grows
    with height, so the maximum is on the top layer. Cached on the world.
    """
    key = ("regional_max_distance",)
    if key not in world._cache:
        top = column_surface(world)
        hx, hy, hz = world.spacing
        d2 = _edt.squared_column_edt_layer(np.ascontiguousarray(top), world.shape[2] - 1,
                                               hx, hy, hz)
        world._cache[key] = float(np.sqrt(d2.max()))
    return world._cache[key]


@dataclass(frozen=True)
class _Leg:
    """One full-resolution window plan: path [m] and W along it."""

    path: np.ndarray
    w: np.ndarray
    timings: tuple[float, float, float]  # velocity map, fast marching, geodesic [s]


def _coarse_world(world: World, level: FlightLevel) -> World:
    """The surface on a coarser grid spanning the same bounds (see the module docstring)."""
    nx, ny, _ = world.shape
    f = max(2, math.ceil(math.sqrt(nx * ny / COARSE_COLUMNS)))
    b = world.bounds
    ncx, ncy = math.ceil((nx - 1) / f) + 1, math.ceil((ny - 1) / f) + 1
    xs, ys = np.linspace(b[0, 0], b[0, 1], ncx), np.linspace(b[1, 0], b[1, 1], ncy)
    X, Y = np.meshgrid(xs, ys, indexing="ij")
    H = np.asarray(world.surface_height(X, Y), dtype=float)
    dz = world.spacing[2]
    cdz = dz * max(1, int(round(level.agl / dz)) // 3)
    z0 = float(H.min()) - cdz
    nz = int(math.ceil((float(H.max()) + level.agl + TOP_MARGIN_LAYERS * cdz - z0) / cdz)) + 1
    cdx = (b[0, 1] - b[0, 0]) / (ncx - 1)
    cdy = (b[1, 1] - b[1, 0]) / (ncy - 1)
    return World.from_heightmap(H, (cdx, cdy, cdz), nz, origin=(xs[0], ys[0], z0),
                                name=f"{world.name} (coarse x{f})")


def _coarse_route(world: World, start: np.ndarray, goal: np.ndarray, shaping: Shaping,
                  level: FlightLevel, options: PlanOptions, plan: Callable[..., Any]):
    """The coarse stage's plan by the full-grid planner ``plan`` (module docstring, stage 1)."""
    cw = _coarse_world(world, level)

    def lift(p: np.ndarray) -> np.ndarray:
        i, j, _ = cw.to_cell(np.array([p[0], p[1], cw.origin[2]]))
        return np.array([p[0], p[1], float(cw.terrain[i, j]) + level.agl])

    coarse_level = replace(level, heights="fm2", min_agl=None, max_agl=None)
    return plan(cw, lift(start), lift(goal), shaping=shaping, level=coarse_level,
                options=replace(options, storage="full"))


def _waypoints(world: World, layer: np.ndarray, route_xy: np.ndarray, start: np.ndarray,
               goal: np.ndarray) -> tuple[list[np.ndarray], list[np.ndarray]]:
    """Waypoints [m] every SEGMENT_CELLS along the route, and each stretch's route points."""
    seg = np.sqrt(np.sum(np.diff(route_xy, axis=0) ** 2, axis=1))
    cum = np.concatenate([[0.0], np.cumsum(seg)])
    step = SEGMENT_CELLS * min(world.spacing[:2])
    n = max(1, int(round(cum[-1] / step)))
    marks = np.linspace(0.0, cum[-1], n + 1)
    points = [start]
    for s in marks[1:-1]:
        x, y = np.interp(s, cum, route_xy[:, 0]), np.interp(s, cum, route_xy[:, 1])
        i, j, _ = world.to_cell(np.array([x, y, world.origin[2]]))
        points.append(world.to_world(np.array([i, j, layer[i, j]], dtype=float)))
    points.append(goal)
    stretches = []
    for a, b in zip(marks[:-1], marks[1:]):
        inside = (cum >= a) & (cum <= b)
        ends = [np.array([np.interp(s, cum, route_xy[:, 0]), np.interp(s, cum, route_xy[:, 1])])
                for s in (a, b)]
        stretches.append(np.vstack([ends[0], route_xy[inside], ends[1]]))
    return points, stretches


def _window(world: World, top: np.ndarray, layer: np.ndarray, xy: np.ndarray,
            ends: tuple[np.ndarray, np.ndarray]) -> World:
    """The world's sub-grid around the route points ``xy`` [m] (module docstring, stage 2)."""
    nx, ny, nz = world.shape
    idx = (xy - np.asarray(world.origin[:2])) / np.asarray(world.spacing[:2])
    i0 = max(0, int(np.floor(idx[:, 0].min())) - MARGIN_CELLS)
    i1 = min(nx - 1, int(np.ceil(idx[:, 0].max())) + MARGIN_CELLS)
    j0 = max(0, int(np.floor(idx[:, 1].min())) - MARGIN_CELLS)
    j1 = min(ny - 1, int(np.ceil(idx[:, 1].max())) + MARGIN_CELLS)
    cols = (slice(i0, i1 + 1), slice(j0, j1 + 1))
    kz = [world.to_cell(p)[2] for p in ends]
    k0 = max(0, int(top[cols].min()) - 1)
    k1 = min(nz - 1, max(int(layer[cols].max()) + TOP_MARGIN_LAYERS, *kz))
    o = world.origin
    h = world.spacing
    return World(occupancy=world.occupancy[cols + (slice(k0, k1 + 1),)], spacing=h,
                 origin=(o[0] + i0 * h[0], o[1] + j0 * h[1], o[2] + k0 * h[2]),
                 terrain=world.terrain[cols], name=f"{world.name} window")


def window_velocity(sub: World, top_distance: float, shaping: Shaping,
                    level: FlightLevel) -> np.ndarray:
    """W of a window: the full plan's W on its nodes (:func:`fm2uav.planning.planner.plan_velocity` of the world).

    The distance to the window's obstacles divided by the *world's* largest distance
    ``top_distance`` [m] (:func:`world_max_distance`), shaped, flight level imposed. Equal
    to the world's W except within a few cells of the window's sides, where obstacles
    outside the window would be nearer.
    """
    dist = distance_map(sub.occupancy, spacing=sub.spacing)
    W = np.divide(dist, top_distance, out=dist)  # normalise_distance with the world's max
    if shaping.shapes:
        W = shape_velocity(W, saturation=shaping.saturation, exponent=shaping.exponent,
                           saturation_distance=shaping.saturation_distance,
                           max_distance=top_distance)
    return flight_level_speed(W, sub, level)


def _leg(sub: World, a: np.ndarray, b: np.ndarray, top_distance: float, shaping: Shaping,
         level: FlightLevel, options: PlanOptions) -> _Leg:
    """FM² from ``a`` to ``b`` [m] on the window ``sub`` with the whole world's W scale."""
    t0 = time.perf_counter()
    W = window_velocity(sub, top_distance, shaping, level)
    t1 = time.perf_counter()
    ca, cb = sub.to_cell(a), sub.to_cell(b)
    T = fast_marching(W, [cb], spacing=sub.spacing, order=options.order, stop_at=[ca],
                      threads=options.threads)
    t2 = time.perf_counter()
    if not np.isfinite(T[ca]):
        raise PlanningError(
            f"regional plan: no connection inside the window between {np.round(a, 1).tolist()} "
            f"and {np.round(b, 1).tolist()} m; plan with storage 'full' on a coarser grid "
            "(CLI --storage full --cell-size)")
    idx = descend(T, sub.to_index(a), sub.to_index(b), spacing=sub.spacing, step=options.step)
    w = ndimage.map_coordinates(W, idx.T, order=1, mode="nearest")
    t3 = time.perf_counter()
    return _Leg(path=sub.to_world(idx), w=w, timings=(t1 - t0, t2 - t1, t3 - t2))


def _windows(world: World, top: np.ndarray, layer: np.ndarray, points: list[np.ndarray],
             stretches: list[np.ndarray], top_distance: float, shaping: Shaping,
             level: FlightLevel, options: PlanOptions) -> tuple[list[_Leg], list[int]]:
    """The full-resolution legs, receding horizon (module docstring, stage 2).

    Each window looks two stretches ahead: it plans from the current point to the waypoint
    after next, and keeps its path up to the point nearest the next waypoint, where the next
    window starts. So a waypoint only pins the discarded far half of a window's path, and the
    kept path is the window's own fine route (the last window plans to the goal).
    """
    legs, nodes = [], []
    here, k, n = points[0], 0, len(stretches)
    while True:
        final = k + 2 >= n
        target = points[n] if final else points[k + 2]
        xy = np.vstack([here[None, :2], *stretches[k:k + 2]])
        sub = _window(world, top, layer, xy, (here, target))
        nodes.append(sub.occupancy.size)
        leg = _leg(sub, here, target, top_distance, shaping, level, options)
        if final:
            legs.append(leg)
            return legs, nodes
        d = np.hypot(*(leg.path[:, :2] - points[k + 1][:2]).T)
        cut = max(1, int(np.argmin(d[:-1])))
        while cut > 1 and world.occupancy[world.to_cell(leg.path[cut])]:
            cut -= 1  # the next window starts on a free node
        legs.append(_Leg(path=leg.path[:cut + 1], w=leg.w[:cut + 1], timings=leg.timings))
        here, k = leg.path[cut], k + 1


def plan_regional(world: World, start: np.ndarray, goal: np.ndarray, *, shaping: Shaping,
                  level: FlightLevel, options: PlanOptions, t_all: float | None = None,
                  full_plan: Callable[..., Any]):
    """FM² from ``start`` to ``goal`` [m] by coarse-to-fine windows (module docstring).

    Called by :func:`fm2uav.plan` (``PlanOptions.storage``), which has checked the
    points and gives itself as ``full_plan``, the planner of the coarse stage (run
    with ``storage="full"``); returns the coarse stage's
    :class:`~fm2uav.planning.planner.Plan` carrying the fine route, with
    ``params["storage"] = "regional"`` and ``params["regional"]`` (coarse factor and
    grid, number of windows, largest window's and all windows' nodes), ``timings`` with a ``coarse`` stage, and ``W`` / ``T``
    the *coarse* stage's maps (their shape is not the world's).
    """
    t_all = time.perf_counter() if t_all is None else t_all
    layer = flight_layer(world, level.agl)  # also: the level must fit under the ceiling
    top = column_surface(world)
    t0 = time.perf_counter()
    coarse = _coarse_route(world, start, goal, shaping, level, options, full_plan)
    t_coarse = time.perf_counter() - t0
    top_distance = world_max_distance(world)
    points, stretches = _waypoints(world, layer, coarse.path[:, :2], start, goal)
    legs, nodes = _windows(world, top, layer, points, stretches, top_distance, shaping, level,
                           options)
    path = np.vstack([legs[0].path] + [lg.path[1:] for lg in legs[1:]])
    w = np.concatenate([legs[0].w] + [lg.w[1:] for lg in legs[1:]])
    t2 = time.perf_counter()
    profile = None
    if level.heights == "ground":
        profile = final_profile(world, path, level)
        # W along the flown path: the FM² path's W at the same horizontal distance
        s_fm2 = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(path[:, :2], axis=0).T))])
        s_new = np.concatenate([[0.0], np.cumsum(np.hypot(
            *np.diff(profile.path[:, :2], axis=0).T))])
        w = np.interp(s_new, s_fm2, w)
        path = profile.path
    t3 = time.perf_counter()
    length = path_length(path)
    clearance = float(surface_clearance(world, path).min())
    t4 = time.perf_counter()
    sums = np.sum([lg.timings for lg in legs], axis=0)
    timings = {
        "coarse": t_coarse,
        "velocity_map": float(sums[0]),
        "fast_marching": float(sums[1]),
        "geodesic": float(sums[2]) + (t3 - t2),
        "metrics": t4 - t3,
        "total": t4 - t_all,
    }
    params = plan_params(shaping, level, options)
    params.update(storage="regional", regional={
        "coarse_factor": round(coarse.world.spacing[0] / world.spacing[0], 3),
        "coarse_shape": list(coarse.world.shape), "windows": len(legs),
        "largest_window_nodes": int(max(nodes)), "window_nodes": int(sum(nodes))})
    return replace(coarse, path=path, w=w, length=length, clearance=clearance, timings=timings,
                   W=coarse.W, T=coarse.T, world=world, params=params, shaping=shaping,
                   level=level, profile=profile)
