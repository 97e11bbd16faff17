"""Leader–follower formation flight with FM² (thesis ch. 6, steps 1–5).

1–4. The leader's path from start to goal is planned once with FM² on the
     terrain's velocity map (shaped for a flight level when ``agl`` is given).
5.   Then, every cycle of ``cycle`` seconds:

     (a, b) every UAV gets its own first potential ``W_i``: the static map of
            its flight level with the other UAVs added as obstacles (nodes
            within a safety radius impassable, the rest darkened by the
            distance to them) — only inside a small window around it;
     (c)    the leader's partial goal is the point ``leader_speed · cycle``
            further along its path; the followers' partial goals follow the
            leader's pose at that point with eqs 6.1 / 6.2, the lateral offset
            shrunk (and the column stretched) by the grey level ``B`` of the
            partial goal (see :func:`grey_levels`); followers at a flight level
            put their goal at that level over the terrain, the others at the
            leader's height;
     (d, e) ``T_i`` from the partial goal and gradient descent give each UAV's
            path (:func:`~fm2uav.missions.formation.local.local_path`);
     (f)    each UAV flies along its path at its speed for one cycle.

Safety, by construction: a UAV's path stays ``dist/2 + v_max·cycle`` away from
where the others were at the start of the cycle, and none moves more than
``v_max·cycle``; a final exact check of the synchronous motions (straight
between samples) holds a follower in place if two UAVs would still come closer
than ``dist/2`` (never needed on the scenarios tested, but it makes the bound
unconditional, because holding everyone repeats a safe state). Paths never enter
the terrain clearance band, so no point is below the ground.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ...errors import InputError, PlanningError, PointError
from ...planning import Plan, plan
from ...world import World
from .checks import min_separation, pair_distances, segment_min_distance
from .local import StaticMaps, local_path
from .metrics import arc_length, formation_error, path_heading
from .shapes import FormationShape, formation_shape, slot_offsets, slot_positions

__all__ = ["FormationResult", "fly_formation", "grey_levels", "GREY_MODES"]

#: How the grey level ``B`` of a follower is measured (see :func:`grey_levels`).
GREY_MODES = ("goal", "follower")


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
    agl : tuple of (float or None)
        Flight level of each UAV [m above ground], None = free.
    completed : bool
        The leader reached the goal.
    settled : bool
        After that, every follower reached its final partial goal (or, when that
        goal is unreachable, the nearest reachable node).
    timings : dict
        Wall times [s]: ``static_maps``, ``leader_plan``, ``cycles``, ``metrics``, ``total``.
    params : dict
        The mission parameters.
    world : World
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
    agl: tuple[float | None, ...]
    completed: bool
    settled: bool
    timings: dict[str, float]
    params: dict[str, Any]
    world: World = field(repr=False)

    @property
    def n_uav(self) -> int:
        """Number of UAVs (leader + followers)."""
        return int(self.positions.shape[1])

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


# ---------------------------------------------------------------------- helpers
def _as_point(p: Any, what: str) -> np.ndarray:
    try:
        arr = np.asarray(p, dtype=float).reshape(-1)
    except (TypeError, ValueError):
        raise InputError(f"{what} must be 3 coordinates (x, y, z) in metres, got {p!r}") from None
    if arr.size != 3 or not np.all(np.isfinite(arr)):
        raise InputError(f"{what} must be 3 finite coordinates (x, y, z) in metres, got {p!r}")
    return arr


def _positive(value: Any, what: str, unit: str) -> float:
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise InputError(f"{what} must be a number [{unit}], got {value!r}") from None
    if not (np.isfinite(v) and v > 0):
        raise InputError(f"{what} must be finite and > 0 [{unit}], got {value!r}")
    return v


def _check_point(world: World, maps: StaticMaps, p: np.ndarray, what: str) -> None:
    """PointError unless ``p`` is in the map, off the terrain and its clearance band."""
    cell = world.to_cell(p, what=what)  # raises PointError outside the map
    ground = ""
    if world.terrain is not None:
        ground = f" (the ground there is at z = {float(world.terrain[cell[0], cell[1]]):.1f} m)"
    if world.occupancy[cell]:
        raise PointError(
            f"{what} {np.round(p, 2).tolist()} m is inside the terrain{ground}; "
            f"move it into free space"
        )
    if not maps.allowed[cell]:
        raise PointError(
            f"{what} {np.round(p, 2).tolist()} m is closer than the clearance "
            f"{maps.clearance:g} m to the terrain{ground}; move it higher/away or "
            f"lower `clearance`"
        )


def grey_levels(
    maps: StaticMaps,
    shape: FormationShape,
    leader_goal: np.ndarray,
    heading: np.ndarray,
    dist: float,
    reference: float,
    *,
    mode: str = "goal",
    followers: np.ndarray | None = None,
    candidates: int = 41,
) -> np.ndarray:
    """Grey level ``B`` in [0, 1] of every follower (the shrink factor of eqs 6.1/6.2).

    The thesis deforms the formation in the leader's horizontal plane only
    ("the distances are only modified in the plane x–y"), so the grey level is
    measured there: the horizontal clearance ``c`` (distance to the terrain in
    the same height layer, :func:`~fm2uav.missions.formation.local.horizontal_clearance`)
    at the leader's height, saturated at ``reference``: ``B = min(1, c / reference)``
    — the grey level of a saturated ``W``. Followers on a flight level then
    take their height from the terrain under their deformed slot.

    Parameters
    ----------
    maps : StaticMaps
    shape : FormationShape
    leader_goal : ndarray, shape (3,)
        The leader's pose (position [m]) the slots follow.
    heading : ndarray, shape (2,)
        The leader's unit direction in the x–y plane.
    dist : float
        Safety distance [m].
    reference : float
        Clearance [m] at which ``B = 1`` (default of the mission: ``2·dist``,
        the nominal lateral offset).
    mode : {"goal", "follower"}
        ``"goal"`` (default): the largest ``B`` (of ``candidates`` values)
        whose deformed partial goal has ``c >= B·reference`` — a self-consistent
        grey level *of the partial goal* (thesis step 5c); it depends on the
        leader's pose only, so it cannot oscillate. ``"follower"``: the literal
        wording of eqs 6.1/6.2, ``c`` at the follower's current position
        ``followers`` (n, 3) [m] (taken at the leader's height).

    Returns
    -------
    ndarray, shape (n_followers,)
    """
    n = shape.n_followers
    z = float(leader_goal[2])
    if mode == "follower":
        pts = np.array(followers, dtype=float)
        pts[:, 2] = z
        return np.clip(maps.horizontal_clearance_at(pts) / reference, 0.0, 1.0)
    B = np.linspace(1.0, 0.0, candidates)
    grey = np.repeat(B[:, None], n, axis=1)                   # (m, n)
    xy = _clip_xy(maps, slot_positions(leader_goal[:2], heading, slot_offsets(shape, grey), dist))
    pts = np.concatenate([xy, np.full(xy.shape[:-1] + (1,), z)], axis=-1)
    c = maps.horizontal_clearance_at(pts)                     # (m, n)
    ok = c >= grey * reference - 1e-9
    return B[np.argmax(ok, axis=0)]                           # largest consistent B


def _clip_xy(maps: StaticMaps, xy: np.ndarray) -> np.ndarray:
    lo = maps.origin[:2]
    hi = lo + (maps.shape[:2] - 1) * maps.spacing[:2]
    return np.clip(xy, lo, hi)


def _resample(path: np.ndarray, speed: float, cycle: float, n_sub: int) -> np.ndarray:
    """Positions along ``path`` at ``n_sub + 1`` equally spaced times of one cycle."""
    s_arr = arc_length(path)
    s = np.minimum(np.linspace(0.0, speed * cycle, n_sub + 1), s_arr[-1])
    if s_arr[-1] <= 0.0:
        return np.repeat(path[:1], n_sub + 1, axis=0)
    return np.stack([np.interp(s, s_arr, path[:, a]) for a in range(3)], axis=-1)


def _resolve_conflicts(motions: np.ndarray, bound: float) -> np.ndarray:
    """Hold UAVs (lowest priority first) until no two come closer than ``bound``.

    ``motions`` (n_uav, n_sub + 1, 3) is modified in place; returns the held mask.
    Terminates: every round holds one more UAV and holding all repeats the
    (safe) positions at the start of the cycle.
    """
    n = motions.shape[0]
    held = np.zeros(n, dtype=bool)
    i_idx, k_idx = np.triu_indices(n, 1)
    while True:
        rel = motions[i_idx] - motions[k_idx]              # (pairs, n_sub + 1, 3)
        dmin = segment_min_distance(np.moveaxis(rel, 1, 0)).min(axis=0)
        bad = np.flatnonzero(dmin < bound)
        if bad.size == 0:
            return held
        p = bad[np.argmin(dmin[bad])]
        a, b = int(i_idx[p]), int(k_idx[p])
        victim = b if not held[b] else a                    # higher index = lower priority
        if held[victim]:  # both already held: cannot happen from a safe start state
            raise PlanningError(
                f"UAVs {a} and {b} are closer than {bound:g} m while both hold position; "
                "the starting positions violate the safety distance"
            )
        motions[victim] = motions[victim, :1]
        held[victim] = True


# ---------------------------------------------------------------------- mission
def fly_formation(
    world: World,
    start: Any,
    goal: Any,
    *,
    n_followers: int = 2,
    shape: str = "triangle",
    dist: float = 60.0,
    leader_speed: float = 10.0,
    follower_speed: float | None = None,
    cycle: float = 1.0,
    follower_starts: Any = None,
    agl: float | None = None,
    follower_agl: float | Any | None = None,
    p1: float = 0.5,
    p2: float = 1.5,
    agl_mode: str = "capped",
    saturation: float = 1.0,
    exponent: float = 1.0,
    method: str = "edt",
    walls: bool = False,
    clearance: float | None = None,
    grey: str = "goal",
    grey_reference: float | None = None,
    window: int = 6,
    order: int = 2,
    step: float = 0.5,
    max_cycles: int | None = None,
    settle_cycles: int | None = None,
) -> FormationResult:
    """Fly a leader–follower formation from ``start`` to ``goal`` with FM² (thesis ch. 6).

    Parameters
    ----------
    world : World
        3D map.
    start, goal : sequence of 3 float
        Leader's start and goal [m].
    n_followers : int, optional
        Number of followers. Default 2 (the thesis' triangle of three UAVs).
    shape : {"triangle", "v", "line"}, optional
        Nominal formation (:func:`~fm2uav.missions.formation.shapes.formation_shape`).
    dist : float, optional
        Safety distance [m]: no two UAVs ever come closer than ``dist/2``; the
        nominal triangle puts the followers ``2·dist`` behind and ``2·dist`` to
        each side of the leader. Default 60 m (4 cells of the thesis' map: the
        UAVs are 8 cells apart).
    leader_speed : float, optional
        Leader's speed [m/s]. Default 10.
    follower_speed : float, optional
        Followers' top speed [m/s]; default ``1.5 · leader_speed`` so that they
        can catch up after a deformation.
    cycle : float, optional
        Re-planning period [s]. Default 1.
    follower_starts : array_like, shape (n_followers, 3), optional
        Followers' start positions [m]. Default: their slots behind the leader's
        start (deformed by the grey level); a slot in the terrain, its clearance
        band, or closer than ``dist`` to a UAV already placed is moved to the
        nearest node that is not.
    agl : float, optional
        Leader's flight level [m above ground]: its FM² map gets the flight-level
        shaping with ``p1``, ``p2``. Default None (no flight level).
    follower_agl : float or sequence, optional
        Followers' flight level(s) [m above ground]: their partial goals sit at
        this height over the terrain and their maps are shaped for it. Default:
        the leader's ``agl`` (the thesis' case 2); None with ``agl`` None means
        followers fly at the leader's height.
    p1, p2 : float, optional
        Flight-level exponents (thesis Algorithm 2). Defaults 0.5 and 1.5 (those
        of :func:`fm2uav.plan`). The thesis' formation case quotes p1 = 1,
        p2 = 0.5, with which the leader does not keep the level on our map
        (p2 < p1 lightens every other cell); ``fm2uav reproduce formation``
        runs both.
    agl_mode : {"capped", "literal"}, optional
        Reading of Algorithm 2 (:func:`fm2uav.planning.flight_level.flight_level_speed`).
    saturation, exponent, method, walls : optional
        FM² velocity-map shaping, as in :func:`fm2uav.plan`.
    clearance : float, optional
        Nodes closer than this to the terrain are impassable for every UAV [m].
        Default ``2 · max(spacing)``, which keeps every path point above the
        interpolated ground.
    grey : {"goal", "follower"}, optional
        Where the grey level is measured (:func:`grey_levels`). Default "goal".
    grey_reference : float, optional
        Horizontal clearance [m] at which ``B = 1`` (:func:`grey_levels`);
        default ``2 · dist`` (the nominal lateral offset).
    window : int, optional
        Local re-planning window padding [cells]. Default 6.
    order : {1, 2}, optional
        Fast Marching order. Default 2.
    step : float, optional
        Geodesic step [cells]. Default 0.5.
    max_cycles : int, optional
        Safety stop. Default ``4 · (leader path length / (leader_speed · cycle)) + 50``.
    settle_cycles : int, optional
        Cycles allowed after the leader's arrival for the followers to reach
        their final slots. Default ``ceil(4·dist / (follower_speed · cycle)) + 10``.

    Returns
    -------
    FormationResult

    Raises
    ------
    fm2uav.InputError
        Bad parameters, a 2D world, wrong shape of ``follower_starts``, or starts
        closer than ``dist/2`` to each other.
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
    >>> r = fly_formation(sc.world, sc.start, sc.goal, agl=105.0)  # doctest: +SKIP
    >>> r.min_separation >= r.dist / 2                              # doctest: +SKIP
    True
    """
    t_all = time.perf_counter()
    if not isinstance(world, World):
        raise InputError(f"world must be a fm2uav.World, got {type(world).__name__}")
    if world.ndim != 3:
        raise InputError(f"formations need a 3D world (nx, ny, nz); this one is {world.ndim}D")
    start_m = _as_point(start, "start")
    goal_m = _as_point(goal, "goal")
    dist = _positive(dist, "dist", "m")
    v_lead = _positive(leader_speed, "leader_speed", "m/s")
    v_fol = 1.5 * v_lead if follower_speed is None else _positive(
        follower_speed, "follower_speed", "m/s")
    cycle = _positive(cycle, "cycle", "s")
    fshape = formation_shape(shape, n_followers)
    nf = fshape.n_followers
    n_uav = nf + 1
    h = np.asarray(world.spacing, dtype=float)
    clearance = 2.0 * float(h.max()) if clearance is None else _positive(
        clearance, "clearance", "m")
    reference = 2.0 * dist if grey_reference is None else _positive(
        grey_reference, "grey_reference", "m")
    if grey not in GREY_MODES:
        raise InputError(f"grey must be one of {', '.join(GREY_MODES)}, got {grey!r}")
    if isinstance(window, bool) or not isinstance(window, (int, np.integer)) or window < 1:
        raise InputError(f"window must be an integer >= 1 (cells), got {window!r}")
    if agl is not None:
        agl = _positive(agl, "agl", "m")
    if follower_agl is None:
        f_agl: list[float | None] = [agl] * nf
    else:
        arr = np.atleast_1d(np.asarray(follower_agl, dtype=float))
        if arr.size == 1:
            arr = np.repeat(arr, nf)
        if arr.shape != (nf,):
            raise InputError(
                f"follower_agl must be one height or {nf} heights [m], got {follower_agl!r}")
        f_agl = [_positive(a, "follower_agl", "m") for a in arr]
    agls = (agl, *f_agl)
    for a in agls:
        if a is not None and a < clearance:
            raise InputError(
                f"flight level {a:g} m is below the terrain clearance {clearance:g} m; "
                "raise the level or lower `clearance`"
            )

    # ---- static maps (steps 1–2) and the leader's plan (steps 3–4)
    t0 = time.perf_counter()
    maps = StaticMaps(world, saturation=saturation, exponent=exponent, method=method,
                      walls=walls, clearance=clearance, p1=p1, p2=p2, agl_mode=agl_mode)
    _check_point(world, maps, start_m, "leader start")
    _check_point(world, maps, goal_m, "goal")
    W_stat = [maps.speed(a) for a in agls]
    t1 = time.perf_counter()
    leader_plan = plan(world, start_m, goal_m, speed_map=W_stat[0], order=order, step=step)
    gpath = leader_plan.path
    s_arr = arc_length(gpath)
    L = float(s_arr[-1])
    t2 = time.perf_counter()

    def heading_at(s: float, previous: np.ndarray) -> np.ndarray:
        hd = path_heading(gpath, s_arr, s, dist)
        return previous if not np.all(np.isfinite(hd)) else hd

    def goal_z_fn(leader_z: float):
        def goal_z(xy: np.ndarray) -> np.ndarray:
            z = np.empty(xy.shape[:-1])
            for j, a in enumerate(f_agl):
                z[..., j] = leader_z if a is None else maps.level_z(a, xy[..., j, :])
            return z
        return goal_z

    def follower_goals(leader_goal: np.ndarray, heading: np.ndarray,
                       current: np.ndarray | None) -> tuple[np.ndarray, np.ndarray]:
        gz = goal_z_fn(float(leader_goal[2]))
        B = grey_levels(maps, fshape, leader_goal, heading, dist, reference,
                        mode=grey if current is not None else "goal", followers=current)
        xy = _clip_xy(maps, slot_positions(leader_goal[:2], heading,
                                           slot_offsets(fshape, B), dist))
        z = gz(xy[None])[0]
        return np.concatenate([xy, z[:, None]], axis=1), B

    heading0 = heading_at(0.0, np.array([1.0, 0.0]))
    if not np.all(np.isfinite(heading0)):
        heading0 = np.array([1.0, 0.0])

    # ---- followers' starts
    if follower_starts is None:
        slots, _ = follower_goals(start_m, heading0, None)
        starts = [start_m]
        for p in slots:
            starts.append(_place_start(maps, p, starts, dist))
    else:
        try:
            fs = np.asarray(follower_starts, dtype=float)
        except (TypeError, ValueError):
            raise InputError(
                "follower_starts must be numbers, shape (n_followers, 3) [m]") from None
        if fs.shape != (nf, 3) or not np.all(np.isfinite(fs)):
            raise InputError(
                f"follower_starts must have shape ({nf}, 3) — one (x, y, z) in metres per "
                f"follower — and be finite, got shape {fs.shape}"
            )
        for j, p in enumerate(fs):
            _check_point(world, maps, p, f"follower {j + 1} start")
        starts = [start_m] + list(fs)
    pos = np.array(starts, dtype=float)
    names = ("leader",) + tuple(f"follower {j + 1}" for j in range(nf))
    bound = dist / 2.0
    for a in range(n_uav):
        for b in range(a + 1, n_uav):
            d = float(np.linalg.norm(pos[a] - pos[b]))
            if d < bound:
                raise InputError(
                    f"the starts of the {names[a]} {np.round(pos[a], 1).tolist()} m and the "
                    f"{names[b]} {np.round(pos[b], 1).tolist()} m overlap: they are {d:.1f} m "
                    f"apart, less than dist/2 = {bound:g} m; place them at least {bound:g} m "
                    f"apart (nominally 2·dist = {2 * dist:g} m)"
                )

    # ---- the cycles (step 5)
    v_max = max(v_lead, v_fol)
    speeds = np.array([v_lead] + [v_fol] * nf)
    radius = bound + v_max * cycle + maps.half_diagonal + 1e-6
    n_sub = max(2, int(np.ceil(v_max * cycle / (0.25 * float(h.min())))))
    if max_cycles is None:
        max_cycles = int(4 * np.ceil(L / (v_lead * cycle))) + 50
    if settle_cycles is None:
        settle_cycles = int(np.ceil(4 * dist / (v_fol * cycle))) + 10
    tol = 0.05 * dist
    times = [0.0]
    samples = [pos.copy()]
    rec_start, rec_goals, rec_grey, rec_held, rec_proj, rec_cpu = [], [], [], [], [], []
    s_ref = 0.0
    heading = heading0
    completed = settled = False
    after = 0
    t_loop = time.perf_counter()
    for c in range(int(max_cycles)):
        tc = time.perf_counter()
        t_now = c * cycle
        # (c) partial goals: the leader's along its path, the followers' from its pose
        s_goal = min(s_ref + v_lead * cycle, L)
        g_lead = _interp_path(gpath, s_arr, s_goal)
        heading = heading_at(s_goal, heading)
        f_goals, B = follower_goals(g_lead, heading, pos[1:])
        goals = np.vstack([g_lead[None], f_goals])
        # (a, b, d, e) every UAV re-plans in its window, the others as obstacles
        motions = np.empty((n_uav, n_sub + 1, 3))
        proj = np.zeros(n_uav, dtype=bool)
        boxed = np.zeros(n_uav, dtype=bool)
        planned = goals.copy()
        for i in range(n_uav):
            others = np.delete(pos, i, axis=0)
            gaps = np.linalg.norm(others - pos[i], axis=1)
            radii = np.minimum(radius, gaps - maps.half_diagonal - 1e-6)
            lp = local_path(maps, W_stat[i], pos[i], goals[i], others, radii,
                            margin=window, order=order, step=step)
            proj[i] = lp.projected
            boxed[i] = lp.blocked
            planned[i] = lp.goal
            motions[i] = _resample(lp.path, speeds[i], cycle, n_sub)
        # (f) fly one cycle, holding whoever would break the separation
        held = _resolve_conflicts(motions, bound) | boxed
        pos = motions[:, -1, :].copy()
        for m in range(1, n_sub + 1):
            times.append(t_now + cycle * m / n_sub)
            samples.append(motions[:, m, :])
        rec_start.append(t_now)
        rec_goals.append(goals)
        rec_grey.append(B)
        rec_held.append(held)
        rec_proj.append(proj)
        # leader's progress along its path
        s_ref = _progress(gpath, s_arr, pos[0], s_ref, s_goal)
        rec_cpu.append(time.perf_counter() - tc)
        if s_goal >= L and np.linalg.norm(pos[0] - goal_m) <= 1e-6 * max(1.0, L):
            completed = True
            f_err = np.linalg.norm(pos[1:] - planned[1:], axis=1)
            if np.all(f_err <= tol):
                settled = True
                break
            after += 1
            if after > settle_cycles:
                break
    t3 = time.perf_counter()

    positions = np.asarray(samples)
    times_arr = np.asarray(times)
    min_d = pair_distances(positions)
    sep, _, _ = min_separation(positions)
    err = formation_error(gpath, positions, fshape, dist)
    t4 = time.perf_counter()
    params = {
        "n_followers": nf, "shape": fshape.name, "dist": dist, "leader_speed": v_lead,
        "follower_speed": v_fol, "cycle": cycle, "agl": agl, "follower_agl": f_agl,
        "p1": float(p1), "p2": float(p2), "agl_mode": agl_mode, "saturation": float(saturation),
        "exponent": float(exponent), "method": method, "walls": bool(walls),
        "clearance": clearance, "grey": grey, "grey_reference": reference,
        "window": int(window), "order": int(order), "step": float(step),
        "safety_radius": radius, "samples_per_cycle": n_sub,
    }
    return FormationResult(
        times=times_arr, positions=positions, names=names,
        cycle_start=np.asarray(rec_start), partial_goals=np.asarray(rec_goals),
        grey=np.asarray(rec_grey).reshape(len(rec_start), nf), held=np.asarray(rec_held),
        projected=np.asarray(rec_proj), compute_s=np.asarray(rec_cpu),
        min_distance=min_d, min_separation=sep, shape_error=err, leader_plan=leader_plan,
        shape=fshape, dist=dist, agl=agls, completed=completed, settled=settled,
        timings={"static_maps": t1 - t0, "leader_plan": t2 - t1, "cycles": t3 - t_loop,
                 "metrics": t4 - t3, "total": t4 - t_all},
        params=params, world=world,
    )


def _interp_path(path: np.ndarray, s_arr: np.ndarray, s: float) -> np.ndarray:
    return np.array([np.interp(s, s_arr, path[:, a]) for a in range(path.shape[1])])


def _progress(path: np.ndarray, s_arr: np.ndarray, p: np.ndarray, s_ref: float,
              s_goal: float) -> float:
    """Arc length of the leader's projection on its path, never decreasing."""
    lo = int(np.searchsorted(s_arr, s_ref - (s_goal - s_ref), side="left"))
    hi = int(np.searchsorted(s_arr, s_goal + (s_goal - s_ref), side="right"))
    lo, hi = max(lo - 1, 0), min(hi + 1, len(s_arr) - 1)
    a, b = path[lo:hi], path[lo + 1:hi + 1]
    if len(a) == 0:
        return s_ref
    d = b - a
    dd = (d * d).sum(axis=1)
    t = np.clip(((p - a) * d).sum(axis=1) / np.where(dd > 0, dd, 1.0), 0.0, 1.0)
    q = a + t[:, None] * d
    k = int(np.argmin(((q - p) ** 2).sum(axis=1)))
    s = s_arr[lo + k] + t[k] * np.sqrt(dd[k])
    return float(max(s_ref, min(s, s_goal)))


def _place_start(maps: StaticMaps, p: np.ndarray, placed: list[np.ndarray],
                 spacing: float) -> np.ndarray:
    """Default follower start: ``p`` if allowed and ``spacing`` away from the UAVs
    already placed, else the nearest allowed node that is (growing search box)."""
    world = maps.world
    p = np.clip(np.asarray(p, dtype=float), world.bounds[:, 0], world.bounds[:, 1])
    others = np.asarray(placed, dtype=float).reshape(-1, 3)

    def far_enough(q: np.ndarray) -> np.ndarray:
        if not len(others):
            return np.ones(len(q), dtype=bool)
        d = np.linalg.norm(q[:, None, :] - others[None, :, :], axis=2)
        return np.all(d >= spacing, axis=1)

    cell = np.asarray(world.to_cell(p, what="follower start"))
    if maps.allowed[tuple(cell)] and far_enough(p[None])[0]:
        return p
    shape = maps.shape
    r = 1
    while True:
        lo = np.maximum(cell - r, 0)
        hi = np.minimum(cell + r + 1, shape)
        sub = maps.allowed[tuple(slice(int(a), int(b)) for a, b in zip(lo, hi))]
        pts = maps.origin + (np.argwhere(sub) + lo) * maps.spacing
        pts = pts[far_enough(pts)] if len(pts) else pts
        if len(pts):
            return pts[int(np.argmin(((pts - p) ** 2).sum(axis=1)))]
        if np.all(lo == 0) and np.all(hi == shape):
            raise PointError(
                f"no free place for a follower start near {np.round(p, 1).tolist()} m at least "
                f"{spacing:g} m from the other UAVs; pass follower_starts explicitly"
            )
        r *= 2
