"""Leader–follower formation flight with FM² (thesis ch. 6, steps 1–5).

1–4. The leader's path from start to goal is planned once with FM² on the
     terrain's velocity map (shaped for its flight level when one is given).
5.   Then, every cycle of ``cycle`` seconds:

     (a, b) every UAV gets its own first potential ``W_i``: the static map of
            its flight level with the other UAVs added as obstacles (nodes
            within a safety radius impassable, the rest darkened by the
            distance to them) — only inside a small window around it;
     (c)    the leader's partial goal is the point ``leader_speed · cycle``
            further along its path; the followers' partial goals follow the
            leader's pose at that point with eqs 6.1 / 6.2, the lateral offset
            shrunk (and the column stretched) by the grey level ``B`` of the
            partial goal (:mod:`.guide`); followers at a flight level
            put their goal at that level over the terrain, the others at the
            leader's height;
     (d, e) ``T_i`` from the partial goal and gradient descent give each UAV's
            path (:func:`~fm2uav.missions.formation.local.local_path`);
     (f)    each UAV flies along its path at its speed for one cycle (:mod:`.cycles`).

The settings are a :class:`~.config.FormationConfig` and the planner's own
objects (:class:`~fm2uav.Shaping`, :class:`~fm2uav.FlightLevel`,
:class:`~fm2uav.PlanOptions`).

Safety, by construction: a UAV's path stays ``dist/2 + v_max·cycle`` away from
where the others were at the start of the cycle, and none moves more than
``v_max·cycle``; a final exact check of the synchronous motions (straight
between samples) holds a follower in place if two UAVs would still come closer
than ``dist/2`` (never needed on the scenarios tested, but it makes the bound
unconditional, because holding everyone repeats a safe state). Paths never enter
the terrain clearance band, so no point is below the ground.
"""

from __future__ import annotations

import dataclasses
import time
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ... import _validate, progress
from ...errors import InputError
from ...planning import FlightLevel, Plan, PlanOptions, Shaping, plan
from ...world import World
from .checks import min_separation, pair_distances
from .config import FormationConfig
from .cycles import CycleSettings, FlightLog, check_point, check_separation, fly_cycles, place_starts
from .guide import LeaderGuide
from .heights import Track, profile_tracks
from .local import StaticMaps
from .metrics import formation_error
from .shapes import FormationShape, formation_shape

__all__ = ["FormationResult", "fly_formation"]


@dataclass(frozen=True, eq=False)
class FormationResult:
    """The outcome of :func:`fly_formation`.

    Attributes
    ----------
    times : ndarray, shape (n_t,)
        Sample times [s]; trajectories are straight between samples.
    positions : ndarray, shape (n_t, n_uav, 3)
        Time-stamped positions [m]; UAV 0 is the leader.
    names : tuple of str
        ``("leader", "follower 1", ...)``.
    cycle_start : ndarray, shape (n_c,)
        Start time of each cycle [s].
    partial_goals : ndarray, shape (n_c, n_uav, 3)
        Partial goal of each UAV in each cycle [m] (as requested, before any
        projection onto the reachable space).
    grey : ndarray, shape (n_c, n_followers)
        Grey level ``B`` of each follower in each cycle.
    held : ndarray of bool, shape (n_c, n_uav)
        The UAV stayed in place this cycle (safety hold or boxed in).
    projected : ndarray of bool, shape (n_c, n_uav)
        The partial goal was unreachable and moved to the nearest reachable node.
    compute_s : ndarray, shape (n_c,)
        Wall time of each re-planning cycle [s].
    min_distance : ndarray, shape (n_t,)
        Smallest distance between two UAVs at each sample [m].
    min_separation : float
        Exact smallest distance over the whole flight [m].
    shape_error : ndarray, shape (n_t,)
        Largest horizontal distance of a follower from its nominal slot [m]
        (:func:`~fm2uav.missions.formation.metrics.formation_error`).
    leader_plan : Plan
        The leader's FM² plan (steps 1–4).
    shape : FormationShape
    dist : float
        Safety distance [m].
    levels : tuple of (FlightLevel or None)
        Flight level of each UAV, None = free (followers: the leader's height).
    completed : bool
        The leader reached the goal.
    settled : bool
        After that, every follower reached its final partial goal (or, when that
        goal is unreachable, the nearest reachable node).
    timings : dict
        Wall times [s]: ``static_maps``, ``leader_plan``, ``cycles``, ``metrics``, ``total``.
    params : dict
        The mission parameters: the resolved :class:`FormationConfig` fields,
        ``levels`` (one dict or None per UAV), the :class:`~fm2uav.Shaping`
        fields, ``order``, ``step``, ``safety_radius``, ``samples_per_cycle``.
    world : World
    config : FormationConfig
        The settings flown, defaults resolved.
    tracks : tuple of Track
        Each UAV's flown trajectory (:mod:`.heights`): for a UAV with a flight
        level, its route at the final altitude profile's heights with times; every
        file written for that UAV comes from it. ``positions`` holds the same heights
        at the common sample times.
    """

    times: np.ndarray
    positions: np.ndarray
    names: tuple[str, ...]
    cycle_start: np.ndarray
    partial_goals: np.ndarray
    grey: np.ndarray
    held: np.ndarray
    projected: np.ndarray
    compute_s: np.ndarray
    min_distance: np.ndarray
    min_separation: float
    shape_error: np.ndarray
    leader_plan: Plan = field(repr=False)
    shape: FormationShape
    dist: float
    levels: tuple[FlightLevel | None, ...]
    completed: bool
    settled: bool
    timings: dict[str, float]
    params: dict[str, Any]
    world: World = field(repr=False)
    config: FormationConfig = field(default_factory=FormationConfig)
    tracks: tuple[Track, ...] = field(default=(), repr=False)

    @property
    def n_uav(self) -> int:
        """Number of UAVs (leader + followers)."""
        return int(self.positions.shape[1])

    @property
    def agl(self) -> tuple[float | None, ...]:
        """Requested height above ground of each UAV [m] (None: no flight level)."""
        return tuple(None if lv is None else lv.agl for lv in self.levels)

    @property
    def shape_error_norm(self) -> np.ndarray:
        """Shape error divided by the nominal spacing ``2·dist`` (dimensionless)."""
        return self.shape_error / (2.0 * self.dist)

    def path_lengths(self) -> np.ndarray:
        """Length flown by each UAV [m]."""
        return np.linalg.norm(np.diff(self.positions, axis=0), axis=2).sum(axis=0)

    def summary(self) -> dict[str, Any]:
        """Plain-Python summary (JSON-friendly)."""
        ms = self.compute_s * 1e3
        return {
            "uavs": list(self.names),
            "shape": self.shape.name,
            "dist_m": self.dist,
            "agl_m": [None if a is None else float(a) for a in self.agl],
            "completed": bool(self.completed),
            "settled": bool(self.settled),
            "mission_time_s": round(float(self.times[-1]), 3),
            "cycles": int(len(self.cycle_start)),
            "path_length_m": [round(float(v), 1) for v in self.path_lengths()],
            "min_separation_m": round(float(self.min_separation), 3),
            "separation_bound_m": self.dist / 2.0,
            "max_shape_error_m": round(float(self.shape_error.max()), 3),
            "final_shape_error_m": round(float(self.shape_error[-1]), 3),
            "min_grey": round(float(self.grey.min()), 3) if self.grey.size else None,
            "holds": int(self.held.sum()),
            "projected_goals": int(self.projected.sum()),
            "cycle_ms": {
                "median": round(float(np.median(ms)), 3),
                "p95": round(float(np.percentile(ms, 95)), 3),
                "max": round(float(ms.max()), 3),
            },
            "timings_s": {k: round(v, 4) for k, v in self.timings.items()},
            "params": dict(self.params),
        }


# ---------------------------------------------------------------------- mission
@progress.stage()
def fly_formation(
    world: World,
    start: Any,
    goal: Any,
    *,
    config: FormationConfig = FormationConfig(),
    level: FlightLevel | None = None,
    follower_levels: FlightLevel | Sequence[FlightLevel | None] | None = None,
    shaping: Shaping = Shaping(),
    options: PlanOptions = PlanOptions(),
    follower_starts: Any = None,
) -> FormationResult:
    """Fly a leader–follower formation from ``start`` to ``goal`` with FM² (thesis ch. 6).

    Parameters
    ----------
    world : World
        3D map.
    start, goal : sequence of 3 float
        Leader's start and goal [m].
    config : FormationConfig, optional
        Shape, safety distance, speeds, cycle, clearance, grey level, window,
        cycle limits (:class:`~fm2uav.missions.formation.config.FormationConfig`).
    level : FlightLevel, optional
        Leader's flight level: its FM² map gets the flight-level shaping.
        Default None (no flight level). The thesis' formation case quotes
        p1 = 1, p2 = 0.5, with which the leader does not keep the level on our
        map (p2 < p1 lightens every other cell); ``fm2uav reproduce formation``
        runs it and p1 = 0.5, p2 = 1.5.
    follower_levels : FlightLevel or sequence of (FlightLevel or None), optional
        Followers' flight level(s): one for all or one per follower; their
        partial goals sit at that height over the terrain and their maps are
        shaped for it; None for a follower: it flies at the leader's height.
        Default: the leader's ``level`` for every follower (the thesis' case 2).
    shaping : Shaping, optional
        FM² velocity-map shaping, as in :func:`fm2uav.plan` (also applied to the
        distance to the other UAVs).
    options : PlanOptions, optional
        Fast Marching order and geodesic step [cells] of every FM² run (no
        speed map: the mission makes its own).
    follower_starts : array_like, shape (n_followers, 3), optional
        Followers' start positions [m]. Default: their slots behind the leader's
        start (deformed by the grey level); a slot in the terrain, its clearance
        band, or closer than ``dist`` to a UAV already placed is moved to the
        nearest node that is not.

    Returns
    -------
    FormationResult

    Raises
    ------
    fm2uav.InputError
        Bad settings, a 2D world, a flight level below the clearance, wrong
        shape of ``follower_starts``, or starts closer than ``dist/2`` to each other.
    fm2uav.PointError
        A start (leader's or a follower's) or the goal outside the map, inside
        the terrain or within ``clearance`` of it.
    fm2uav.UnreachableError
        The leader's goal cannot be reached from its start.

    Examples
    --------
    >>> import fm2uav
    >>> from fm2uav.missions.formation import fly_formation
    >>> sc = fm2uav.scenarios.fissure()
    >>> r = fly_formation(sc.world, sc.start, sc.goal,
    ...                   level=fm2uav.FlightLevel(agl=105.0, p2=1.5))   # doctest: +SKIP
    >>> r.min_separation >= r.dist / 2                                   # doctest: +SKIP
    True
    """
    t_all = time.perf_counter()
    start_m, goal_m = _check_world_and_points(world, start, goal)
    cfg, levels = _resolve(world, config, level, follower_levels, shaping, options)

    # ---- static maps (steps 1–2) and the leader's plan (steps 3–4)
    t0 = time.perf_counter()
    progress.step(f"velocity maps of the {len(levels)} UAVs", 0.1)
    maps = StaticMaps(world, shaping, cfg.clearance)
    check_point(world, maps, start_m, "leader start")
    check_point(world, maps, goal_m, "goal")
    W_stat = [maps.speed(lv) for lv in levels]
    t1 = time.perf_counter()
    progress.step("the leader's FM² path", 0.1)
    leader_plan, fshape, guide = _leader(world, start_m, goal_m, options, W_stat[0], maps, cfg,
                                         levels)
    t2 = time.perf_counter()

    heading0 = _start_heading(guide)
    pos = place_starts(guide, start_m, heading0, follower_starts, cfg.dist)
    names = ("leader",) + tuple(f"follower {j + 1}" for j in range(fshape.n_followers))
    check_separation(pos, names, cfg.dist)

    # ---- the cycles (step 5)
    cs = _cycle_settings(world, cfg, options, maps, guide.length)
    cfg = dataclasses.replace(cfg, max_cycles=cs.max_cycles, settle_cycles=cs.settle_cycles)
    t_loop = time.perf_counter()
    progress.step(f"flying the {len(names)} UAVs (FM² re-planning every cycle)", 0.8)
    log = fly_cycles(guide, W_stat, pos, heading0, goal_m, cs)
    t3 = time.perf_counter()
    return _result(world, log, names, guide, leader_plan, fshape, cfg, levels, shaping, options,
                   cs, timings={"static_maps": t1 - t0, "leader_plan": t2 - t1,
                                "cycles": t3 - t_loop, "total": t_all})


def _leader(world: World, start_m: np.ndarray, goal_m: np.ndarray, options: PlanOptions,
            W_leader: np.ndarray, maps: StaticMaps, cfg: FormationConfig,
            levels: Sequence[FlightLevel | None]) -> tuple[Any, Any, LeaderGuide]:
    """The leader's FM² plan on its static map ``W_leader``, the formation shape and the guide."""
    leader_plan = plan(world, start_m, goal_m,
                       options=dataclasses.replace(options, speed_map=W_leader))
    fshape = formation_shape(cfg.shape, cfg.n_followers)
    guide = LeaderGuide(leader_plan.path, maps, fshape, cfg.dist, cfg.grey_reference, cfg.grey,
                        levels[1:])
    return leader_plan, fshape, guide


def _start_heading(guide: LeaderGuide) -> np.ndarray:
    """The leader's horizontal unit heading at the start (+x where the path gives none)."""
    heading0 = guide.heading(0.0, np.array([1.0, 0.0]))
    if not np.all(np.isfinite(heading0)):
        heading0 = np.array([1.0, 0.0])
    return heading0


def _check_world_and_points(world: Any, start: Any, goal: Any) -> tuple[np.ndarray, np.ndarray]:
    if not isinstance(world, World):
        raise InputError(f"world must be a fm2uav.World, got {type(world).__name__}")
    if world.ndim != 3:
        raise InputError(f"formations need a 3D world (nx, ny, nz); this one is {world.ndim}D")
    return (_validate.point(start, 3, "start"), _validate.point(goal, 3, "goal"))


def _resolve(world: World, config: Any, level: Any, follower_levels: Any, shaping: Any,
             options: Any) -> tuple[FormationConfig, tuple[FlightLevel | None, ...]]:
    """Check the objects; resolve the config's defaults and every UAV's level."""
    for value, cls, name in ((config, FormationConfig, "config"), (shaping, Shaping, "shaping"),
                             (options, PlanOptions, "options")):
        if not isinstance(value, cls):
            raise InputError(f"{name} must be a {cls.__name__}, got {type(value).__name__}")
    if options.speed_map is not None:
        raise InputError("options.speed_map must be None: the formation makes its own maps")
    cfg = config.resolved(world.spacing)
    nf = cfg.n_followers
    if follower_levels is None or isinstance(follower_levels, FlightLevel):
        f_levels = [level if follower_levels is None else follower_levels] * nf
    else:
        f_levels = list(follower_levels)
        if len(f_levels) != nf:
            raise InputError(f"follower_levels must be one FlightLevel or {nf} (one per "
                             f"follower, None = the leader's height), got {len(f_levels)}")
    levels = (level, *f_levels)
    for lv in levels:
        if lv is not None and not isinstance(lv, FlightLevel):
            raise InputError(f"a flight level must be a fm2uav.FlightLevel or None, got "
                             f"{type(lv).__name__}; e.g. level=FlightLevel(agl=105.0)")
        if lv is not None and lv.agl < cfg.clearance:
            raise InputError(
                f"flight level {lv.agl:g} m is below the terrain clearance {cfg.clearance:g} m; "
                "raise the level or lower `clearance`"
            )
    return cfg, levels


#: Most re-planning cycles (incl. settling) and sub-steps per cycle of a formation flight.
MAX_CYCLES = 100_000
MAX_SUBSTEPS = 100_000


def _cycle_settings(world: World, cfg: FormationConfig, options: PlanOptions, maps: StaticMaps,
                    length: float) -> CycleSettings:
    """The cycles' fixed numbers: safety radius, samples per cycle, cycle limits."""
    h = np.asarray(world.spacing, dtype=float)
    v_lead, v_fol, cycle = cfg.leader_speed, cfg.follower_speed, cfg.cycle
    v_max = max(v_lead, v_fol)
    bound = cfg.dist / 2.0
    max_cycles = (int(4 * np.ceil(length / (v_lead * cycle))) + 50 if cfg.max_cycles is None
                  else cfg.max_cycles)
    settle = (int(np.ceil(4 * cfg.dist / (v_fol * cycle))) + 10 if cfg.settle_cycles is None
              else cfg.settle_cycles)
    n_sub = max(2, int(np.ceil(v_max * cycle / (0.25 * float(h.min())))))
    if max_cycles + settle > MAX_CYCLES or n_sub > MAX_SUBSTEPS:
        raise InputError(
            f"the formation flight would take {max_cycles + settle} re-planning cycles of "
            f"{n_sub} sub-steps (limits {MAX_CYCLES}, {MAX_SUBSTEPS}) for a {length:.0f} m "
            f"route at {v_lead:g} m/s with cycles of {cycle:g} s on {float(h.min()):g} m cells; "
            "use a faster leader (--speed), a longer re-planning cycle (--cycle; a shorter one "
            "for fast vehicles) or a coarser grid")

    return CycleSettings(
        cycle=cycle, speeds=np.array([v_lead] + [v_fol] * cfg.n_followers),
        radius=bound + v_max * cycle + maps.half_diagonal + 1e-6,
        n_sub=n_sub,
        bound=bound, window=cfg.window, order=options.order, step=options.step,
        max_cycles=max_cycles, settle_cycles=settle, tol=0.05 * cfg.dist,
    )


def _result(world: World, log: FlightLog, names: tuple[str, ...], guide: LeaderGuide,
            leader_plan: Plan, fshape: FormationShape, cfg: FormationConfig,
            levels: tuple[FlightLevel | None, ...], shaping: Shaping, options: PlanOptions,
            cs: CycleSettings, timings: dict[str, float]) -> FormationResult:
    """Metrics of the flight and the :class:`FormationResult`; ``timings["total"]``
    holds the start time and is turned into the total."""
    t3 = time.perf_counter()
    # one truth per vehicle: the final altitude profile's heights (heights.py)
    positions, tracks = profile_tracks(world, np.asarray(log.times), np.asarray(log.samples),
                                       names, levels)
    min_d = pair_distances(positions)
    sep, _, _ = min_separation(positions)
    err = formation_error(guide.path, positions, fshape, cfg.dist)
    t4 = time.perf_counter()
    params = {
        **dataclasses.asdict(cfg),
        "levels": [None if lv is None else dataclasses.asdict(lv) for lv in levels],
        **dataclasses.asdict(shaping), "order": int(options.order), "step": float(options.step),
        "safety_radius": cs.radius, "samples_per_cycle": cs.n_sub,
    }
    nc = len(log.cycle_start)
    return FormationResult(
        times=np.asarray(log.times), positions=positions, names=names,
        cycle_start=np.asarray(log.cycle_start), partial_goals=np.asarray(log.goals),
        grey=np.asarray(log.grey).reshape(nc, fshape.n_followers), held=np.asarray(log.held),
        projected=np.asarray(log.projected), compute_s=np.asarray(log.compute_s),
        min_distance=min_d, min_separation=sep, shape_error=err, leader_plan=leader_plan,
        shape=fshape, dist=cfg.dist, levels=levels, completed=log.completed,
        settled=log.settled,
        timings={**{k: v for k, v in timings.items() if k != "total"}, "metrics": t4 - t3,
                 "total": t4 - timings["total"]},
        params=params, world=world, config=cfg, tracks=tracks,
    )
