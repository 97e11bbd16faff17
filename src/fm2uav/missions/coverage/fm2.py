"""FM² along the zigzag at a flight level (seeds 003 §IV, thesis §5.3).

The seeds turn the best zigzag into the binary map W0 by enlarging every
stretch of it (so the path can dodge obstacles in x-y, not only in z), run
FM² over it and impose the flight level with p1/p2 (Algorithm 2). Here:

1. corridor: ``C(x, y) = max(0, 1 - dist(x, y; zigzag) / h)`` — the FM²
   velocity of the enlarged zigzag (distance to the corridor's edge,
   normalised), ``h = corridor · D`` its half-width (< D/2 so that the
   corridors of neighbouring bands never touch and the wave cannot cut
   across them);
2. flight level: :func:`fm2uav.planning.flight_level.flight_level_speed`
   (Algorithm 2 as the planner applies it, with a tolerance band of one
   vertical cell by default) on the world's FM² velocity map (normalised
   distance to the terrain/obstacles); ``level_base="uniform"`` shapes a
   constant map instead (the level is then ``level_contrast ** (p1 - p2)``
   times faster everywhere, however open the sky);
3. ``W = C · W_level`` (0 on obstacles and outside the corridor), then
   :func:`fm2uav.plan` with ``PlanOptions(speed_map=W)`` from the zigzag's first
   point to its last, both on the flight level.

Grid (``grid=``): by default (``"corridor"``) steps 1–3 run on the corridor
unrolled along the zigzag (:mod:`.grid`): arc length × offset × height, the
velocity symmetric about the zigzag (the level of the zigzag's own column
extruded across the corridor) so that the flown ground track is the zigzag
itself unless an obstacle intrudes into the corridor. Bands D apart see D/2
each side with no overlap, so any drift off a band line is coverage lost;
on the map's own grid (``grid="map"``, the seeds' W0) the geodesic drifts
1–2 m off the slanted bands and covers only 99.4–99.6 % of S1–S4 (down to
96.6 % on random polygons; docs/coverage.md has the measurements).
"""

from __future__ import annotations

import dataclasses
import math
import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from scipy.spatial import cKDTree

from ... import progress
from ...errors import InputError, PlanningError
from ...geometry import path_length
from ...planning import FlightLevel, Plan, PlanOptions, Shaping, base_velocity, shaped_velocity
from ...planning import plan as fm2_plan
from ...planning.flight_level import flight_layer, flight_level_speed
from ...world import World
from ...world.clearance import clearance_profile
from .area import as_area, check_inside_world, check_spacing
from .bands import Zigzag, zigzag
from .grid import CorridorGrid, corridor_grid
from .optimise import AngleSearch, optimise_angle
from .report import coverage_share

__all__ = ["CoveragePlan", "corridor_speed", "coverage_speed_map", "corridor_grid_speed",
           "plan_coverage", "GRIDS"]

#: Accepted values of ``grid`` in :func:`plan_coverage`.
GRIDS = ("corridor", "map")


def corridor_speed(world: World, path_xy: np.ndarray, half_width: float) -> np.ndarray:
    """FM² velocity of the enlarged zigzag on the map's columns, shape (nx, ny).

    ``max(0, 1 - d / half_width)`` with ``d`` the horizontal distance [m] from a
    column to the polyline ``path_xy`` (sampled every quarter cell).
    """
    if not (np.isfinite(half_width) and half_width > 0):
        raise InputError(f"corridor half-width must be > 0 metres, got {half_width!r}")
    dx, dy = world.spacing[0], world.spacing[1]
    step = 0.25 * min(dx, dy)
    xy = np.asarray(path_xy, dtype=float)[:, :2]
    seg = np.diff(xy, axis=0)
    lens = np.linalg.norm(seg, axis=1)
    pts = [xy[:1]]
    for p, v, ln in zip(xy[:-1], seg, lens):
        k = max(int(math.ceil(ln / step)), 1)
        pts.append(p + v * (np.arange(1, k + 1)[:, None] / k))
    dense = np.vstack(pts)
    nx, ny = world.shape[0], world.shape[1]
    gx = world.origin[0] + dx * np.arange(nx)
    gy = world.origin[1] + dy * np.arange(ny)
    X, Y = np.meshgrid(gx, gy, indexing="ij")
    d, _ = cKDTree(dense).query(np.column_stack([X.ravel(), Y.ravel()]),
                                distance_upper_bound=half_width)
    c = np.clip(1.0 - d / half_width, 0.0, 1.0)
    c[~np.isfinite(d)] = 0.0
    return c.reshape(nx, ny)


def coverage_speed_map(
    world: World,
    zz: Zigzag,
    level: FlightLevel,
    *,
    corridor: float = 0.25,
    level_contrast: float = 0.5,
    level_base: str = "world",
    shaping: Shaping | None = None,
) -> np.ndarray:
    """Velocity map W of the coverage FM² (corridor × flight level), shape of the world.

    Parameters
    ----------
    world : World
        3D map with terrain.
    zz : Zigzag
        The zigzag to follow.
    level : FlightLevel
        The flight level (``agl`` [m], ``p1``/``p2``, seeds: 0.5 and 1.3). Its
        band is widened to at least one vertical cell (:func:`coverage_level`)
        so that the clarified layer stays face-connected where the ground slopes.
    corridor : float
        Corridor half-width as a share of D, in (0, 0.5). Default 0.25.
    level_contrast : float
        Value in (0, 1) of the uniform map shaped with ``level_base="uniform"``.
    level_base : {"world", "uniform"}
        Map the flight level is imposed on: ``"world"`` (default) the
        planner's FM² velocity of the world (normalised distance to the
        terrain and obstacles, :func:`fm2uav.planning.base_velocity`), shaped
        exactly as ``plan(level=...)`` does (capped Algorithm 2); ``"uniform"``
        a constant ``level_contrast`` on the free nodes, which gives the level
        the same contrast everywhere however far the obstacles are.
    shaping : Shaping, optional
        Shaping of the world's map with ``level_base="world"`` (e.g.
        ``saturation_distance`` in metres); default the unshaped distance map.
    """
    if world.ndim != 3:
        raise InputError("coverage FM² needs a 3D world with terrain")
    h = _corridor_half_width(world, zz, corridor, level_contrast, level_base)
    cell = min(world.spacing[0], world.spacing[1])
    if level_base == "world":
        base = _base(world, shaping)  # the planner's FM² map: distance to obstacles
    else:
        base = np.where(world.occupancy, 0.0, float(level_contrast))
    c = corridor_speed(world, zz.path(step=cell / 2.0), h)
    return flight_level_speed(base, world, coverage_level(level, world)) * c[:, :, None]


def coverage_level(level: FlightLevel, world: World) -> FlightLevel:
    """The flight level the coverage FM² imposes: ``level`` with its band at least
    one vertical cell of ``world`` (a one-cell layer breaks where the ground slopes).

    Raises
    ------
    InputError
        ``level`` is not a :class:`~fm2uav.FlightLevel`.
    """
    if not isinstance(level, FlightLevel):
        raise InputError(f"level must be a fm2uav.FlightLevel, got {type(level).__name__}; "
                         "e.g. level=FlightLevel(agl=100.0)")
    dz = float(world.spacing[2])
    return level if level.band >= dz else dataclasses.replace(level, band=dz)


def corridor_grid_speed(
    grid: CorridorGrid,
    level: FlightLevel,
    *,
    level_contrast: float = 0.5,
    level_base: str = "world",
    shaping: Shaping | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """Velocity map W of the coverage FM² on a corridor grid, and the flight layer.

    ``W[i, j, k] = C(ρ_j) · L[i, k]`` with ``C(ρ) = 1 - |ρ| / h`` and ``L`` the
    flight-level speed of the zigzag's own column (Algorithm 2 on the
    vertical curtain ρ = 0, base map and options as :func:`coverage_speed_map`),
    0 on the grid's obstacles and outside the map.

    Returns
    -------
    W : ndarray, shape of ``grid.world``
    layer : ndarray of int, shape (nσ,)
        Flight-level layer of the curtain [cells].
    """
    _check_level_options(level_contrast, level_base)
    gw = grid.world
    c = grid.centre
    occ = gw.occupancy
    if level_base == "world":
        base = grid.sample(_base(grid.map, shaping))[:, c:c + 1, :]
        base[occ[:, c:c + 1, :]] = 0.0
    else:
        base = np.where(occ[:, c:c + 1, :], 0.0, float(level_contrast))
    curtain = World(occ[:, c:c + 1, :], spacing=gw.spacing,
                    origin=(gw.origin[0], 0.0, gw.origin[2]))
    speed = flight_level_speed(base, curtain, coverage_level(level, gw))
    cw = np.clip(1.0 - np.abs(grid.offsets) / grid.half_width, 0.0, 1.0)
    W = cw[None, :, None] * speed
    W[occ] = 0.0
    W[~grid.inside] = 0.0
    return W, flight_layer(curtain, level.agl)[:, 0]


def _base(world: World, shaping: Shaping | None) -> np.ndarray:
    """The world's FM² map: unshaped distance map, or shaped by ``shaping``."""
    return base_velocity(world) if shaping is None else shaped_velocity(world, shaping)


def _check_level_options(level_contrast: float, level_base: str) -> None:
    if not (0 < level_contrast < 1):
        raise InputError(f"level_contrast must be in (0, 1), got {level_contrast!r}")
    if level_base not in ("world", "uniform"):
        raise InputError(f"level_base must be 'world' or 'uniform', got {level_base!r}")


def _corridor_half_width(world: World, zz: Zigzag, corridor: float, level_contrast: float,
                         level_base: str) -> float:
    """Validate the corridor options; return the half-width h = corridor · D [m]."""
    if not (0 < corridor < 0.5):
        raise InputError(f"corridor must be a share of D in (0, 0.5), got {corridor!r}")
    _check_level_options(level_contrast, level_base)
    cell = min(world.spacing[0], world.spacing[1])
    h = corridor * zz.spacing
    if h < 1.0 * cell:
        raise InputError(
            f"the corridor half-width {h:g} m (corridor {corridor:g} x D = {zz.spacing:g} m) is "
            f"under one cell ({cell:g} m): the bands are too close for this grid; use "
            f"D >= {cell / corridor:g} m or a finer map"
        )
    return h


@dataclass(frozen=True, eq=False)
class CoveragePlan:
    """Result of :func:`plan_coverage`.

    Attributes
    ----------
    zigzag : Zigzag
        The bands flown.
    search : AngleSearch or None
        The steering-angle search (None when the angle was given).
    plan : fm2uav.Plan
        The FM² path along the bands (``plan.path`` is (N, 3) [m]).
    coverage : float
        Share of the area within D/2 of the FM² path's ground track.
    zigzag_coverage : float
        Same for the ideal zigzag (should be 1).
    agl_error : ndarray
        Height above the ground minus ``agl`` along the path [m].
    timings : dict
        Wall times [s]: ``angle``, ``zigzag``, ``speed_map`` (corridor grid
        included), ``fm2``, ``report``, ``total``.
    params : dict
        Settings: ``spacing_m``, the fields of :attr:`level` (``agl``, ``p1``,
        ``p2``, ``band``, ...), ``corridor``, ``level_contrast``,
        ``level_base``, ``search``, ``order``, ``step``, ``grid``.
    level : FlightLevel or None
        The flight level flown (band widened as :func:`coverage_level` says).
    grid : CorridorGrid or None
        The corridor grid FM² ran on (None with ``grid="map"``).
    grid_plan : fm2uav.Plan or None
        The FM² result on that grid, in its metres ``(σ, ρ, z)``, with the
        exact W and T (None with ``grid="map"``).

    Notes
    -----
    ``plan`` is always expressed on the map: ``plan.world`` is the map,
    ``plan.path`` in map metres, ``plan.clearance`` measured on the map. With
    ``grid="corridor"`` its ``W`` and ``T`` are those of :attr:`grid_plan`
    resampled linearly onto the map's nodes (0 / inf outside the grid), for
    display; :attr:`grid_plan` holds the arrays FM² used.
    """

    zigzag: Zigzag
    search: AngleSearch | None
    plan: Any
    coverage: float
    zigzag_coverage: float
    agl_error: np.ndarray = field(repr=False)
    timings: dict[str, float] = field(default_factory=dict)
    params: dict[str, Any] = field(default_factory=dict)
    level: FlightLevel | None = None
    grid: CorridorGrid | None = field(default=None, repr=False)
    grid_plan: Any = field(default=None, repr=False)

    @property
    def path(self) -> np.ndarray:
        """(N, 3) FM² path [m]."""
        return self.plan.path

    def summary(self) -> dict[str, Any]:
        """JSON-friendly numbers."""
        e = np.abs(self.agl_error)
        out = {
            "angle_deg": round(self.zigzag.angle_deg, 4),
            "bands": self.zigzag.n_bands,
            "extra_bands": list(self.zigzag.extra_bands),
            "zigzag_cost_m": round(self.zigzag.cost, 3),
            "path_length_m": round(float(self.plan.length), 3),
            "coverage": round(self.coverage, 6),
            "zigzag_coverage": round(self.zigzag_coverage, 6),
            "agl_error_mean_abs_m": round(float(e.mean()), 3),
            "agl_error_max_abs_m": round(float(e.max()), 3),
            "timings_s": {k: round(v, 6) for k, v in self.timings.items()},
            "params": dict(self.params),
        }
        if self.search is not None:
            out["search"] = {"method": self.search.method, "evaluations": self.search.evaluations,
                             **{k: round(v, 4) for k, v in self.search.stats().items()}}
        return out


def _on_level(world: World, xy: np.ndarray, layer: np.ndarray, what: str) -> np.ndarray:
    if not world.contains(np.r_[xy, world.origin[2]]):
        raise InputError(f"the zigzag {what} {np.round(xy, 1).tolist()} m is outside the map")
    i, j = (int(v) for v in np.round(world.to_index(np.r_[xy, world.origin[2]])[:2]))
    z = world.origin[2] + layer[i, j] * world.spacing[2]
    return np.r_[xy, z]


def _checked_level(world: World, grid: str, level: FlightLevel, options: PlanOptions
                   ) -> FlightLevel:
    """The coverage flight level (:func:`coverage_level`) once ``grid``, ``world`` and
    ``options`` are checked.

    Raises
    ------
    InputError
        Unknown grid, not a 3D world, options with a speed map.
    """
    if grid not in GRIDS:
        raise InputError(f"grid must be one of {', '.join(GRIDS)}, got {grid!r}")
    if not isinstance(world, World) or world.ndim != 3:
        raise InputError("plan_coverage needs a 3D fm2uav.World with terrain")
    level = coverage_level(level, world)
    if not isinstance(options, PlanOptions) or options.speed_map is not None:
        raise InputError("options must be a fm2uav.PlanOptions without speed_map (the coverage "
                         "FM² makes its own speed map), e.g. options=PlanOptions(order=1)")
    return level


def _steering(poly: Any, d: float, angle: float | None, search: str,
              search_options: dict[str, Any] | None, seed: Any
              ) -> tuple[float, AngleSearch | None]:
    """``(angle [rad], search)``: the given ``angle`` (no search), else the result of the
    steering-angle search ``search`` over ``poly`` at spacing ``d`` [m] (the DEs seeded
    with ``seed`` unless ``search_options`` has one)."""
    if angle is not None:
        return angle, None
    opts = dict(search_options or {})
    if search.lower() in ("de", "scipy-de"):
        opts.setdefault("seed", seed)
    found = optimise_angle(poly, d, method=search, **opts)
    return found.angle, found


def _zigzag_in_map(world: World, poly: Any, d: float, angle: float) -> tuple[Zigzag, np.ndarray]:
    """The zigzag over ``poly`` at spacing ``d`` [m] and ``angle`` [rad], and its ideal path,
    checked to stay in the map."""
    zz = zigzag(poly, d, angle)
    ideal = zz.path()
    _check_zigzag_in_map(world, ideal, d)
    return zz, ideal


@progress.stage()
def plan_coverage(
    world: World,
    area,
    spacing: float,
    *,
    level: FlightLevel,
    angle: float | None = None,
    search: str = "de",
    search_options: dict[str, Any] | None = None,
    seed: int | np.random.Generator = 0,
    corridor: float = 0.25,
    level_contrast: float = 0.5,
    level_base: str = "world",
    options: PlanOptions = PlanOptions(),
    grid: str = "corridor",
    shaping: Shaping | None = None,
) -> CoveragePlan:
    """Coverage path: best zigzag over ``area``, then FM² along it at a flight level.

    Parameters
    ----------
    world : World
        3D map with terrain (e.g. ``fm2uav.scenarios.coverage.coverage_world()``).
    area : Polygon, GeoJSON dict or (k, 2) vertices
        Area to cover [m] (inside the map).
    spacing : float
        Band spacing D [m] (see :mod:`.camera` to derive it from a camera).
    level : FlightLevel
        The flight level (``agl`` [m] above the ground; seeds: p1 = 0.5,
        p2 = 1.3 at level 10, the FlightLevel defaults). Its band is widened
        to at least one vertical cell (:func:`coverage_level`).
    angle : float, optional
        Steering angle [rad]; default: searched with ``search``.
    search : {"de", "sweep", "scipy-de"}
        Angle search (default the seeds' DE).
    search_options : dict, optional
        Extra keywords for the search (e.g. ``bounds_deg=(0, 180)``).
    seed : int or Generator
        Seed of the DE.
    corridor, level_contrast, level_base
        See :func:`coverage_speed_map`.
    options : PlanOptions, optional
        Fast Marching order and geodesic step of the FM² run (its speed map
        must be None: the coverage builds its own).
    grid : {"corridor", "map"}
        Grid FM² runs on: ``"corridor"`` (default) the corridor unrolled
        along the zigzag, with a velocity symmetric about it (the flown ground
        track is the zigzag unless an obstacle intrudes, :mod:`.grid`);
        ``"map"`` the map's own grid, as the seeds (the path drifts 1–2 m off
        the bands and leaves slivers uncovered between them).
        With no-fly zones (``world.zones``) whose footprint the corridor meets,
        the coverage is flown as an FM² route around them instead
        (:mod:`.zones`; ``params["grid"] == "route"``).
    shaping : Shaping, optional
        Shaping of the world's FM² map (e.g. ``saturation_distance`` [m]);
        default the unshaped distance map (the seeds').

    Returns
    -------
    CoveragePlan

    Raises
    ------
    InputError
        Bad area, spacing, objects, or the zigzag leaves the map.
    fm2uav.PlanningError
        The flight level leaves the map; the corridor is cut (unreachable); a
        path point falls in an obstacle node of the map (only possible on the
        band grid over very steep relief at a low level: use ``grid="map"``).
    """
    t0 = time.perf_counter()
    level = _checked_level(world, grid, level, options)
    poly = as_area(area)
    d = check_spacing(poly, spacing)
    check_inside_world(poly, world)
    progress.step("steering angle of the bands" + (f" ({search})" if angle is None else ""), 0.3)
    angle, found = _steering(poly, d, angle, search, search_options, seed)
    t1 = time.perf_counter()
    progress.step("zigzag bands", 0.05)
    zz, ideal = _zigzag_in_map(world, poly, d, angle)
    t2 = time.perf_counter()
    if not (0 < corridor < 0.5):
        raise InputError(f"corridor must be a share of D in (0, 0.5), got {corridor!r}")
    progress.step("FM² along the bands", 0.5)
    fm, grid, cg, grid_plan, t3 = _fly_zigzag(
        world, zz, ideal, d, level, grid, corridor, options,
        dict(level_contrast=level_contrast, level_base=level_base, shaping=shaping))
    _check_free(world, fm.path)
    fm = with_flown_heights(world, fm, level)
    t4 = time.perf_counter()
    progress.step("coverage and heights above the ground", 0.15)
    cov, zcov, err = _report(world, poly, fm.path, ideal, d, level)
    t5 = time.perf_counter()
    return CoveragePlan(
        zigzag=zz, search=found, plan=fm, coverage=cov, zigzag_coverage=zcov, agl_error=err,
        timings=_timings(t0, t1, t2, t3, t4, t5),
        params={"spacing_m": d, **dataclasses.asdict(level), "corridor": float(corridor),
                "level_contrast": float(level_contrast), "level_base": level_base,
                "search": None if found is None else found.method,
                "order": int(options.order), "step": float(options.step), "grid": grid},
        level=level, grid=cg, grid_plan=grid_plan,
    )


def _report(world: World, poly: Any, path: np.ndarray, ideal: np.ndarray, d: float,
            level: FlightLevel) -> tuple[float, float, np.ndarray]:
    """Coverage shares (within ``d / 2`` [m]) of the flown ``path`` and of the ``ideal``
    zigzag, and the path's height above the ground minus ``level.agl`` [m]."""
    cov = coverage_share(poly, path, d / 2.0)
    zcov = coverage_share(poly, ideal, d / 2.0)
    return cov, zcov, path[:, 2] - world.ground_height(path[:, 0], path[:, 1]) - level.agl


def _timings(*t: float) -> dict[str, float]:
    """Wall times [s] of the steps between the clock readings ``t`` of
    :func:`plan_coverage` (and the total)."""
    steps = ("angle", "zigzag", "speed_map", "fm2", "report")
    return {**{k: t[i + 1] - t[i] for i, k in enumerate(steps)}, "total": t[-1] - t[0]}


def with_flown_heights(world: World, fm: Plan, level: FlightLevel) -> Plan:
    """The coverage plan with its heights set from the continuous ground (issue 13).

    The coverage FM² runs on its own speed map, so :func:`fm2uav.plan` sets no
    final altitude profile; the route found is kept horizontally and its heights
    become ground (source DEM, bilinear) + ``level.agl`` within the airframe's
    climb/descent limits (:func:`fm2uav.planning.altitude.final_profile`), as for
    every other plan. ``level.heights == "fm2"`` keeps the flight layer's own
    heights (the seeds' measurement); a plan that has a profile is returned as is.
    """
    if level.heights != "ground" or fm.profile is not None:
        return fm
    from scipy import ndimage

    from ...planning.altitude import final_profile
    from ...world.clearance import surface_clearance

    profile = final_profile(world, fm.path, level)
    path = profile.path
    w = ndimage.map_coordinates(fm.W, world.to_index(path).T, order=1, mode="nearest")
    return dataclasses.replace(fm, path=path, w=w, length=path_length(path),
                               clearance=float(surface_clearance(world, path).min()),
                               level=level, profile=profile)


def _check_zigzag_in_map(world: World, ideal: np.ndarray, d: float) -> None:
    """InputError if the zigzag (its turns reach D/2 beyond the bands) leaves the map."""
    b = world.bounds
    out = ((ideal[:, 0] < b[0, 0]) | (ideal[:, 0] > b[0, 1]) | (ideal[:, 1] < b[1, 0])
           | (ideal[:, 1] > b[1, 1]))
    if out.any():
        p = ideal[np.argmax(out)]
        raise InputError(
            f"the zigzag (turns reach D/2 = {d / 2:g} m beyond the bands) leaves the map at "
            f"({p[0]:.1f}, {p[1]:.1f}) m; keep the area at least D/2 from the map's edge or "
            "use a smaller D"
        )


def _fly_zigzag(world: World, zz: Zigzag, ideal: np.ndarray, d: float, level: FlightLevel,
                grid: str, corridor: float, options: PlanOptions, opts: dict[str, Any]
                ) -> tuple[Plan, str, CorridorGrid | None, Plan | None, float]:
    """FM² along the zigzag on the chosen grid (or a route around no-fly zones).

    Returns the plan on the map, the grid actually used (``"route"`` when zones
    cut the corridor), the corridor grid and its own plan (corridor grid only)
    and the time the speed map was ready (:func:`time.perf_counter`).
    """
    from .zones import meets_zones, plan_zone_route

    if meets_zones(world, ideal, corridor * d):  # no-fly zones cut the corridor: a route
        t3 = time.perf_counter()
        route = plan_zone_route(world, ideal, d, level, shaping=opts["shaping"], options=options)
        return route.plan, "route", None, None, t3
    if grid == "corridor":
        cg = corridor_grid(world, zz, corridor * d)
        W, layer = corridor_grid_speed(cg, level, **opts)
        gw = cg.world
        z = gw.origin[2] + layer[[0, -1]] * gw.spacing[2]
        start = np.array([0.0, 0.0, z[0]])
        goal = np.array([gw.origin[0] + (gw.shape[0] - 1) * gw.spacing[0], 0.0, z[1]])
        t3 = time.perf_counter()
        grid_plan = fm2_plan(gw, start, goal, options=dataclasses.replace(options, speed_map=W))
        return _on_map(cg, grid_plan), grid, cg, grid_plan, t3
    W = coverage_speed_map(world, zz, level, corridor=corridor, **opts)
    layer = flight_layer(world, level.agl)
    start = _on_level(world, zz.start, layer, "start")
    goal = _on_level(world, zz.goal, layer, "end")
    t3 = time.perf_counter()
    fm = fm2_plan(world, start, goal, options=dataclasses.replace(options, speed_map=W))
    return fm, grid, None, None, t3


def _on_map(cg: CorridorGrid, fm: Plan) -> Plan:
    """The corridor-grid FM² plan expressed on the map (path mapped back, W/T resampled)."""
    path = cg.to_map(fm.path)
    world = cg.map
    return Plan(
        path=path, w=fm.w, length=path_length(path),
        clearance=float(clearance_profile(world, path).min()),
        timings=dict(fm.timings), W=cg.to_map_nodes(fm.W, 0.0),
        T=cg.to_map_nodes(fm.T, np.inf), world=world,
        params={**fm.params, "grid": "corridor"}, shaping=fm.shaping, level=fm.level,
    )


def _check_free(world: World, path: np.ndarray) -> None:
    """Raise PlanningError if a path point's nearest map node is an obstacle."""
    idx = np.clip(np.floor(world.to_index(path) + 0.5).astype(np.int64), 0,
                  np.asarray(world.shape) - 1)
    hit = world.occupancy[tuple(idx.T)]
    if hit.any():
        p = path[np.argmax(hit)]
        raise PlanningError(
            f"the coverage path enters an obstacle node of the map at "
            f"({p[0]:.1f}, {p[1]:.1f}, {p[2]:.1f}) m; raise agl or plan with grid='map'"
        )
