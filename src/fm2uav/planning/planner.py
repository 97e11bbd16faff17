"""The FM² planner: velocity map → arrival times from the goal → geodesic.

Thesis §2.2: (1) the binary map W0; (2) a wave from every obstacle gives the
velocity map W (distance to obstacles, rescaled to [0, 1], then shaped by the
saturation α and exponent β); (3) a wave from the goal over W gives the arrival
times T, stopped as soon as the start is reached; (4) gradient descent on T from
the start gives the path.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from scipy import ndimage

from .. import _validate
from .. import progress
from ..eikonal.fmm import fast_marching
from ..eikonal.velocity import normalised_distance, shape_velocity
from ..errors import InputError, PlanningError, PointError, UnreachableError
from ..geometry import path_lengths
from ..world import World
from ..world.clearance import min_surface_clearances
from ..world.zones import check_points_allowed, zone_violations
from .altitude import AltitudeProfile, final_profile, height_figures
from .flight_level import flight_level_speed
from .geodesic import descend, drop_ties, reaches_any
from .params import FlightLevel, PlanOptions, Shaping, plan_params
from .wind import PathTiming, WindOptions, descend_track, path_timing, wind_times
from .regional import check_full_grid, plan_regional, use_regional

__all__ = ["Plan", "plan", "base_velocity", "shaped_velocity", "max_distance", "plan_params"]


@dataclass(frozen=True, eq=False)
class Plan:
    """The result of :func:`plan`.

    Attributes
    ----------
    path : ndarray, shape (N, ndim)
        Path from start to goal in world coordinates [m]; ``path[0]`` is the
        start and ``path[-1]`` the goal, exactly.
    w : ndarray, shape (N,)
        W interpolated (linearly) at each path point: the admissible speed as a
        share of the maximum, in [0, 1] (dimensionless; m/s only with an airframe).
    length : float
        Path length [m].
    clearance : float
        Smallest distance from a path point to the terrain/building surface [m]
        (continuous: :func:`fm2uav.world.clearance.surface_clearance`; not to
        grid nodes, not to no-fly zones; ``inf`` on a 2D map without obstacles).
    timings : dict of str to float
        Wall time of each stage [s]: ``velocity_map``, ``fast_marching``,
        ``geodesic``, ``metrics``, ``total`` (a regional plan adds ``coarse`` and
        sums its windows' stages).
    W : ndarray
        The velocity map used (after saturation/exponent and any flight-level
        shaping), same shape as the world. A regional plan
        (``params["storage"] == "regional"``, :mod:`fm2uav.planning.regional`) has no
        world-sized map: ``W`` and ``T`` are then its coarse stage's.
    T : ndarray
        Arrival times [s·(1/W)] of the wave from the goal; ``inf`` where not
        reached before the start was frozen.
    world : World
        The map planned on.
    params : dict
        The planner parameters, flat and JSON-friendly (:func:`plan_params`):
        the fields of ``shaping``, ``options`` (without the speed map) and, with
        a flight level, of ``level``; plus ``custom_speed_map``.
    shaping : Shaping
        The shaping of W used (ignored with a custom speed map).
    level : FlightLevel or None
        The flight level imposed, None without one.
    profile : AltitudeProfile or None
        With a flight level on a 3D world: the final altitude profile that set
        the heights of ``path`` (climb-out, cruise at ``agl`` above the
        continuous ground, descent; :mod:`fm2uav.planning.altitude`).
    wind_timing : PathTiming or None
        Planned in a wind (``plan(..., wind=WindOptions(...))``): the safe airspeed,
        ground speed, heading and time along ``path`` in that wind
        (:mod:`fm2uav.planning.wind`); ``T`` is then in seconds.
    """

    path: np.ndarray
    w: np.ndarray
    length: float
    clearance: float
    timings: dict[str, float]
    W: np.ndarray = field(repr=False)
    T: np.ndarray = field(repr=False)
    world: World = field(repr=False)
    params: dict[str, Any] = field(default_factory=dict)
    shaping: Shaping = field(default_factory=Shaping)
    level: FlightLevel | None = None
    profile: AltitudeProfile | None = field(default=None, repr=False)
    wind_timing: PathTiming | None = field(default=None, repr=False)

    @property
    def phase(self) -> np.ndarray | None:
        """``"climb-out"`` / ``"cruise"`` / ``"descent"`` per path point (None without a profile)."""
        return None if self.profile is None else self.profile.phase

    def speed_share(self) -> np.ndarray:
        """The admissible speed share along the path from the obstacle distances alone [0, 1].

        ``w`` is the map the plan marched on, which for a terrain-following plan
        includes the flight-level shaping (p1/p2 keep the path on its level; they say
        nothing about speed). The speed share of a terrain-following plan is
        ``min(d / d_sat, 1) ** β`` of the distance ``d`` to the nearest obstacle,
        interpolated at the path's final points, with ``d_sat`` the flight level's
        ``agl`` (or the shaping's saturation distance, α · max d, when nearer): the
        height above ground the plan was asked to keep is open sky, full speed;
        closer to the terrain or the buildings (slopes, ridges, roofs) the vehicle
        slows down. Plans without a flight level, and plans on a custom speed map,
        return ``w``.

        Raises
        ------
        InputError
            A regional plan (no world-sized map to read it from).
        """
        if self.level is None or self.params.get("custom_speed_map"):
            return self.w
        if self.params.get("storage") == "regional":
            raise InputError("a regional plan keeps no world-sized velocity map to read the "
                             "speeds from: export it without speed changes "
                             "(outputs.speed_changes: false, --no-speed-changes)")
        sh = self.shaping
        top = max_distance(self.world, sh)
        d_sat = sh.saturation_distance if sh.saturation_distance is not None else \
            sh.saturation * top
        d_sat = min(float(d_sat), float(self.level.agl))
        W = shape_velocity(base_velocity(self.world, method=sh.method, walls=sh.walls),
                           exponent=sh.exponent, saturation_distance=d_sat, max_distance=top)
        idx = self.world.to_index(self.path)
        return ndimage.map_coordinates(W, idx.T, order=1, mode="nearest")

    def height_above_ground(self) -> np.ndarray | None:
        """``z - World.ground_height(x, y)`` [m] at every path point (None for 2D)."""
        if self.path.shape[1] != 3:
            return None
        return self.path[:, 2] - np.asarray(
            self.world.ground_height(self.path[:, 0], self.path[:, 1]), dtype=float)

    @property
    def start(self) -> np.ndarray:
        """Start point [m]."""
        return self.path[0]

    @property
    def goal(self) -> np.ndarray:
        """Goal point [m]."""
        return self.path[-1]

    def lonlat(self, anchor: Any = None) -> np.ndarray:
        """Path as WGS84 ``(lon [deg], lat [deg], alt [m])`` rows.

        A geo-referenced world (``world.crs`` set, e.g. ``World.from_dem``) uses
        its CRS; a world without one is placed at ``anchor`` (default
        ``DEFAULT_ANCHOR``, as the exports do). See :func:`fm2uav.world.geo.to_lonlat`.
        """
        from ..world.geo import to_lonlat

        return to_lonlat(self.world, self.path, anchor=anchor)

    def summary(self) -> dict[str, Any]:
        """Plain-Python summary (JSON-friendly) of the plan's numbers."""
        return {
            "start_m": [round(float(v), 3) for v in self.start],
            "goal_m": [round(float(v), 3) for v in self.goal],
            "points": int(len(self.path)),
            "length_m": round(float(self.length), 3),
            "clearance_m": float(self.clearance) if np.isfinite(self.clearance) else None,
            "min_w": round(float(self.w.min()), 6),
            "params": dict(self.params),
            "timings_s": {k: round(v, 6) for k, v in self.timings.items()},
            **self._height_summary(),
        }

    def _height_summary(self) -> dict[str, Any]:
        h = self.height_above_ground()
        if h is None:
            return {}
        req = None if self.level is None else self.level.agl
        out: dict[str, Any] = {"height_above_ground": {"path": height_figures(h, req,
                                                                               points=self.path)}}
        if self.profile is not None:
            c = self.profile.cruise
            if c.any():
                idx = np.flatnonzero(c)
                out["height_above_ground"]["cruise"] = height_figures(h[c], req,
                                                                      points=self.path[c])
                out["cruise_points"] = [int(idx[0]), int(idx[-1])]
            out["altitude_profile"] = self.profile.summary()
        return out


def base_velocity(world: World, *, method: str = "edt", walls: bool = False,
                  threads: int | None = None) -> np.ndarray:
    """Normalised velocity map of a world before shaping, cached on the world.

    ``d / max(d)`` with ``d`` the distance to the nearest obstacle; cached in
    ``world._cache`` because it depends only on the (immutable) occupancy, so
    sweeps over saturation/exponent pay the distance transform once. The
    normaliser ``max(d)`` [m] is cached next to it (:func:`max_distance`).
    ``threads``: of the distance transform (:func:`fm2uav.eikonal.distance_map`; the
    values do not depend on it).
    """
    key = ("base_velocity", method, bool(walls))
    cached = world._cache.get(key)
    if cached is None:
        check_full_grid(world)  # a clear error rather than running out of memory
        cached, scale = normalised_distance(world.occupancy, spacing=world.spacing,
                                            method=method, walls=walls, threads=threads)
        cached.setflags(write=False)
        world._cache[key] = cached
        world._cache[("max_distance", method, bool(walls))] = scale
    return cached


def max_distance(world: World, shaping: Shaping = Shaping()) -> float:
    """The distance [m] :func:`base_velocity` normalises by: the largest distance
    from a node to an obstacle (``inf`` on a map without obstacles); cached."""
    key = ("max_distance", shaping.method, bool(shaping.walls))
    if key not in world._cache:
        base_velocity(world, method=shaping.method, walls=shaping.walls)
    return world._cache[key]


def shaped_velocity(world: World, shaping: Shaping = Shaping(),
                    threads: int | None = None) -> np.ndarray:
    """The FM² velocity map W of a world shaped by ``shaping`` (0 on obstacles).

    The cached :func:`base_velocity` itself (read-only) when there is nothing
    to shape, else a new array: ``min(d / d_sat, 1) ** exponent``. ``threads``: of
    the distance transform, as :func:`base_velocity`'s.
    """
    W = base_velocity(world, method=shaping.method, walls=shaping.walls, threads=threads)
    if not shaping.shapes:
        return W
    top = max_distance(world, shaping) if shaping.saturation_distance is not None else None
    return shape_velocity(W, saturation=shaping.saturation, exponent=shaping.exponent,
                          saturation_distance=shaping.saturation_distance, max_distance=top)


def _check_free(world: World, point: np.ndarray, what: str) -> tuple[int, ...]:
    # World.to_cell validates "inside the map" with a clear message and uses the
    # same nearest-node rule as the geodesic
    cell = world.to_cell(point, what=what)
    if world.occupancy[cell]:
        hint = ""
        if world.terrain is not None and world.ndim == 3:
            ground = world.ground_height(point[0], point[1])
            hint = f" (the ground there is at z = {ground:.1f} m; raise the {what} above it)"
        raise PointError(
            f"{what} {np.round(point, 3).tolist()} m is inside an obstacle (node {list(cell)})"
            f"{hint}; move the {what} to free space"
        )
    return cell


@progress.stage()
def plan(
    world: World,
    start: Any,
    goal: Any,
    *,
    shaping: Shaping = Shaping(),
    level: FlightLevel | None = None,
    options: PlanOptions = PlanOptions(),
    wind: WindOptions | None = None,
) -> Plan:
    """Plan a path from ``start`` to ``goal`` with Fast Marching Square.

    Parameters
    ----------
    world : World
        The map (occupancy True = obstacle).
    start, goal : sequence of float
        World coordinates [m].
    shaping : Shaping, optional
        How W is made from the obstacles: saturation α (or a saturation
        distance in metres), exponent β, distance method, walls. Default
        ``Shaping()`` (W = d / max d).
    level : FlightLevel, optional
        Impose a flight level ``level.agl`` metres above the ground (thesis
        Algorithm 2, see :mod:`fm2uav.planning.flight_level`). Default None.
    options : PlanOptions, optional
        Fast Marching order, geodesic step [cells], a custom speed map
        (which replaces the shaping and the flight level: the hook for extra
        shaping such as other UAVs), and the storage: a terrain world too big
        for one full 3D grid is planned coarse-to-fine by
        :func:`fm2uav.planning.regional.plan_regional` (``storage="auto"``).
        Default ``PlanOptions()``.
    wind : WindOptions, optional
        Plan the time-optimal route in a wind field at the safe airspeed
        ``W × wind.airspeed`` (:mod:`fm2uav.planning.wind`): nodes where the wind is
        at least that airspeed are refused. Needs the full grid (not regional).
        Default None (still air).

    Returns
    -------
    Plan

    Raises
    ------
    fm2uav.PlanningError
        Start or goal outside the map or inside an obstacle.
    fm2uav.UnreachableError
        No free connection between start and goal.
    fm2uav.InputError
        Bad parameter values (the objects check themselves; here: wrong type).

    Examples
    --------
    >>> import numpy as np
    >>> from fm2uav import World, plan
    >>> occ = np.zeros((40, 30), bool); occ[18:22, 0:20] = True
    >>> p = plan(World(occ, spacing=1.0), (5.0, 5.0), (35.0, 5.0))
    >>> bool(p.path[:, 1].max() > 20)   # goes around the wall
    True
    >>> from fm2uav import Shaping
    >>> q = plan(World(occ, spacing=1.0), (5.0, 5.0), (35.0, 5.0), shaping=Shaping(exponent=2.0))
    >>> bool(q.clearance >= p.clearance)  # a darker map keeps further from the wall
    True
    """
    t_all = time.perf_counter()
    if not isinstance(world, World):
        raise InputError(f"world must be a fm2uav.World, got {type(world).__name__}")
    _check_objects(shaping, level, options)
    start_m = _validate.point(start, world.ndim, "start")
    goal_m = _validate.point(goal, world.ndim, "goal")
    if world.zones:  # name the zone rather than "inside an obstacle"
        check_points_allowed(world, {"start": start_m, "goal": goal_m})
    start_cell = _check_free(world, start_m, "start")
    goal_cell = _check_free(world, goal_m, "goal")
    _check_work(world, start_m, goal_m, start_cell, goal_cell, options)
    regional = use_regional(world, shaping, level, options)
    if wind is not None and not isinstance(wind, WindOptions):
        raise InputError(f"wind must be a fm2uav.planning.wind.WindOptions, got "
                         f"{type(wind).__name__}")
    if wind is not None and regional:
        raise InputError("planning in a wind needs the full grid, and this map is planned "
                         "regionally (too big for one grid): use a coarser cell_size "
                         "(--cell-size) or planner.storage: full")
    if regional:  # too big for one full grid
        return plan_regional(world, start_m, goal_m, shaping=shaping, level=level,
                             options=options, t_all=t_all, full_plan=plan)

    t0 = time.perf_counter()
    progress.step("velocity map W", 0.3)
    W = plan_velocity(world, shaping, level, options)
    t1 = time.perf_counter()
    if W[start_cell] <= 0 or W[goal_cell] <= 0:
        which = "start" if W[start_cell] <= 0 else "goal"
        raise PointError(
            f"the velocity map is 0 at the {which} node; move the {which} away from obstacles"
        )
    progress.step("arrival times T (Fast Marching)", 0.45)
    if wind is not None:
        T, track, refused = wind_times(world, W, goal_cell, start_cell, wind,
                                       order=options.order)
        t2 = time.perf_counter()
        return trace_plan(world, W, T, start_m, goal_m, shaping, level, options,
                          (t_all, t0, t1, t2), wind=wind, track=track, refused=refused)
    T = fast_marching(W, [goal_cell], spacing=world.spacing, order=options.order,
                      stop_at=[start_cell], threads=options.threads)
    # the nodes of the start's time that the queue froze before it are dropped: the field
    # is then a function of the times alone, which plan_many rebuilds from one whole march
    drop_ties(T, start_cell)
    t2 = time.perf_counter()
    return trace_plan(world, W, T, start_m, goal_m, shaping, level, options,
                      (t_all, t0, t1, t2))


#: Most geodesic steps a plan may take (step * min cell each, along the straight line
#: between start and goal): beyond it the request is refused, not run for hours.
MAX_PATH_STEPS = 5_000_000


def _check_work(world: World, start_m: np.ndarray, goal_m: np.ndarray,
                start_cell: tuple[int, ...], goal_cell: tuple[int, ...],
                options: PlanOptions) -> None:
    """Refuse start == goal and requests whose descent would take absurdly many steps."""
    if start_cell == goal_cell:
        raise PointError(
            f"start {np.round(start_m, 3).tolist()} m and goal {np.round(goal_m, 3).tolist()} m "
            f"fall on the same grid node {list(start_cell)}: there is nothing to plan; give a "
            "goal at least one cell away (mission file start/goal; CLI --start/--goal)")
    h = float(np.min(world.spacing))
    steps = float(np.linalg.norm(goal_m - start_m)) / (float(options.step) * h)
    if steps > MAX_PATH_STEPS:
        raise InputError(
            f"the path would take at least {steps:.3g} geodesic steps of {options.step:g} x "
            f"{h:g} m (limit {MAX_PATH_STEPS:.0e}): the step or the smallest cell is far too "
            "small for this distance; raise planner.step (CLI --step, default 0.5 cells) or "
            "use a coarser, less anisotropic grid (world.dz / --dz, world.cell_size / "
            "--cell-size)")


def plan_velocity(world: World, shaping: Shaping, level: FlightLevel | None,
                  options: PlanOptions) -> np.ndarray:
    """The velocity map W that :func:`plan` marches on (shaped, flight level, or custom).

    Returns
    -------
    ndarray
        W in [0, 1] per node (read-only when it is the world's cached base map).
    """
    if options.speed_map is None:
        # 0 on obstacles already (distance 0); the cached base map is read-only
        # and used as is when there is nothing to shape
        W = shaped_velocity(world, shaping, threads=options.threads)
        if level is not None:
            W = flight_level_speed(W, world, level)
    else:
        W = options.speed_map
        if W.shape != world.shape:
            raise InputError(
                f"speed_map has shape {W.shape} but the world is {world.shape}; "
                "give one speed per node"
            )
    return W


def unreachable_error(start_m: np.ndarray, goal_m: np.ndarray) -> UnreachableError:
    """The error of a start the wave from the goal never reached (points in metres)."""
    return UnreachableError(
        f"the goal {np.round(goal_m, 3).tolist()} m cannot be reached from the start "
        f"{np.round(start_m, 3).tolist()} m: no free connection between them; move one "
        "of them into the other's free region or clear the separating obstacles")


def stuck_error(start_m: np.ndarray, goal_m: np.ndarray, shaping: Shaping,
                exc: Exception) -> PlanningError:
    """The error of a descent stuck on a reached start (``exc``: the descent's own)."""
    return PlanningError(
        f"no path could be traced from the start {np.round(start_m, 3).tolist()} m to the "
        f"goal {np.round(goal_m, 3).tolist()} m although the goal is reachable: W is too "
        f"small along the only passage (exponent {shaping.exponent:g}); lower "
        "planner.exponent (CLI --exponent), raise planner.saturation (--saturation) or use "
        f"a finer grid ({exc})")


def trace_plan(world: World, W: np.ndarray, T: np.ndarray, start_m: np.ndarray,
               goal_m: np.ndarray, shaping: Shaping, level: FlightLevel | None,
               options: PlanOptions, marks: tuple[float, float, float, float], *,
               wind: WindOptions | None = None, track: np.ndarray | None = None,
               refused: np.ndarray | None = None) -> Plan:
    """Descend ``T`` from the start, set the final heights and measure: the end of :func:`plan`.

    Shared with :class:`fm2uav.planning.session.Planner`, which keeps ``W`` and ``T``
    between re-plans. ``marks`` = perf-counter times (start, before W, after W,
    after the march) for the timings. In a wind (``wind``), the path follows the
    march's ground ``track`` (:func:`fm2uav.planning.wind.descend_track`).
    """
    start_cell = world.to_cell(start_m, what="start")
    if not np.isfinite(T[start_cell]) and wind is not None:
        raise UnreachableError(
            f"the goal {np.round(goal_m, 3).tolist()} m cannot be reached from the start "
            f"{np.round(start_m, 3).tolist()} m in this wind ({wind.field.describe()}): "
            f"{int(refused.sum()) if refused is not None else 0} nodes where the wind is at "
            "least the safe airspeed W x airspeed are refused and close every way; fly "
            "faster (--cruise-speed / --hover-speed), lower the saturation, or fly another day")
    if not np.isfinite(T[start_cell]):
        raise unreachable_error(start_m, goal_m)
    # descend() never enters nodes with T = inf; obstacles have W = 0, hence
    # T = inf, unless a custom speed map gave them a speed: only then pass the
    # mask (it costs a copy of T, ~1 s on a 40M-node map).
    blocked = world.occupancy if reaches_any(T, world.occupancy) else None
    progress.step("path (geodesic descent)", 0.6)
    try:
        if track is not None:
            path_idx = descend_track(T, track, world.to_index(start_m), world.to_index(goal_m),
                                     spacing=world.spacing, blocked=world.occupancy,
                                     step=options.step)
        else:
            path_idx = descend(
                T,
                world.to_index(start_m),
                world.to_index(goal_m),
                spacing=world.spacing,
                blocked=blocked,
                step=options.step,
            )
    except PlanningError as exc:  # "descent ... stuck": T reached the start, W too dark
        raise stuck_error(start_m, goal_m, shaping, exc) from None
    return finish_plan(world, W, T, path_idx, shaping, level, options, marks, wind=wind,
                       refused=refused)


def finish_plan(world: World, W: np.ndarray, T: np.ndarray, path_idx: np.ndarray,
                shaping: Shaping, level: FlightLevel | None, options: PlanOptions,
                marks: tuple[float, float, float, float], *, wind: WindOptions | None = None,
                refused: np.ndarray | None = None) -> Plan:
    """The :class:`Plan` of a descended path: :func:`finish_plans` of one path.

    Raises
    ------
    PlanningError
        No altitude profile meets the flight level's limits; the path enters a zone (a bug).
    """
    out = finish_plans(world, W, T, [path_idx], shaping, level, options, marks, wind=wind,
                       refused=refused)[0]
    if isinstance(out, PlanningError):
        raise out
    return out


def finish_plans(world: World, W: np.ndarray, T: np.ndarray, paths_idx: list[np.ndarray],
                 shaping: Shaping, level: FlightLevel | None, options: PlanOptions,
                 marks: tuple[float, float, float, float], *,
                 wind: WindOptions | None = None, refused: np.ndarray | None = None
                 ) -> list[Plan | PlanningError]:
    """The :class:`Plan` of each descended path: final heights, zone check, W, length, clearance.

    The end of :func:`trace_plan` (one path) and of
    :func:`fm2uav.planning.many.plan_many` (every route of a wave): one routine for the
    altitude profile and the figures of every path. W along the paths and their
    clearances are read for all the paths at once (the same numbers as path by path).

    Parameters
    ----------
    paths_idx : list of ndarray, shape (N, ndim)
        The descents in index coordinates [cells], start first, goal last.
    marks : tuple of 4 float
        Perf-counter times (start, before W, after W, after the march) for the timings
        (with several paths, the batch's: ``geodesic`` and ``metrics`` cover every path).

    Returns
    -------
    list
        Per path its :class:`Plan`, or the :class:`~fm2uav.errors.PlanningError` it
        raised (no altitude profile meets the flight level's limits; the path enters a
        zone: a bug).
    """
    t_all, t0, t1, t2 = marks
    finals: list[tuple[np.ndarray, np.ndarray, AltitudeProfile | None] | PlanningError] = []
    heights = level is not None and level.heights == "ground" and world.ndim == 3
    if heights:
        progress.step("heights above the ground", 1.0)
    lens = [len(q) for q in paths_idx]
    ends = np.cumsum(lens)[:-1] if lens else []
    in_world = np.split(world.to_world(np.concatenate(paths_idx)), ends) if lens else []
    for path, path_idx in zip(in_world, paths_idx):  # world.to_world of each, in one call
        profile = None
        try:
            if heights:
                # heights from the continuous ground along the FM² route (issue 13); with a
                # custom speed map (route legs re-use the first leg's W) the level still
                # sets them
                profile = final_profile(world, path, level)
                path = profile.path
                path_idx = world.to_index(path)
            if world.zones:
                bad = zone_violations(world, path)
                if bad:  # the zone nodes are obstacles: this is a bug, never a user error
                    raise PlanningError(
                        f"the planned path enters {bad[0].zone!r} at "
                        f"{np.round(bad[0].point, 1).tolist()} m; please report this (the "
                        "zones were rasterised too thinly)")
        except PlanningError as exc:
            finals.append(exc)
            continue
        finals.append((path, path_idx, profile))
    t3 = time.perf_counter()
    done = [f for f in finals if not isinstance(f, PlanningError)]
    if done:
        ends = np.cumsum([len(f[0]) for f in done])[:-1]
        w_all = np.split(ndimage.map_coordinates(
            W, np.concatenate([f[1] for f in done]).T, order=1, mode="nearest"), ends)
        clear_all = min_surface_clearances(world, [f[0] for f in done])
        lengths = path_lengths([f[0] for f in done])
    t4 = time.perf_counter()
    timings = {
        "velocity_map": t1 - t0,
        "fast_marching": t2 - t1,
        "geodesic": t3 - t2,
        "metrics": t4 - t3,
        "total": t4 - t_all,
    }
    base_params = plan_params(shaping, level, options)
    out: list[Plan | PlanningError] = []
    k = 0
    for f in finals:
        if isinstance(f, PlanningError):
            out.append(f)
            continue
        path, _, profile = f
        w, clearance, length = w_all[k], float(clear_all[k]), lengths[k]
        k += 1
        params = dict(base_params)
        timing = None
        if wind is not None:
            timing = path_timing(world, path, w, wind)
            params["wind"] = {**wind.summary(), "refused_nodes": int(refused.sum())
                              if refused is not None else 0, **timing.summary()}
        out.append(Plan(
            path=path,
            w=w,
            length=length,
            clearance=clearance,
            timings=dict(timings),
            W=W,
            T=T,
            world=world,
            params=params,
            shaping=shaping,
            level=level if options.speed_map is None else None,
            profile=profile,
            wind_timing=timing,
        ))
    return out


def _check_objects(shaping: Any, level: Any, options: Any) -> None:
    """InputError unless the parameter objects have the right types (one spelling)."""
    for value, cls, name, example in (
        (shaping, Shaping, "shaping", "shaping=Shaping(exponent=2.0)"),
        (options, PlanOptions, "options", "options=PlanOptions(order=1)"),
    ):
        if not isinstance(value, cls):
            raise InputError(f"{name} must be a fm2uav.{cls.__name__}, got "
                             f"{type(value).__name__}; e.g. {example}")
    if level is not None and not isinstance(level, FlightLevel):
        raise InputError(f"level must be a fm2uav.FlightLevel or None, got "
                         f"{type(level).__name__}; e.g. level=FlightLevel(agl=150.0)")
