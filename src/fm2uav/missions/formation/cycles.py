"""The re-planning cycles of a formation flight (thesis ch. 6 step 5) and its starts.

Every cycle: partial goals from the leader's pose (:class:`~.guide.LeaderGuide`),
a local FM² re-plan of every UAV with the others as obstacles
(:func:`~.local.local_path`), one cycle of flight along the re-planned paths,
holding whoever would break the separation (:func:`resolve_conflicts`).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from ... import progress
from ...errors import InputError, PlanningError, PointError
from ...geometry import arc_length, at_arc_length
from ...world import World
from .checks import segment_min_distance
from .guide import LeaderGuide
from .local import StaticMaps, local_path

__all__ = ["check_point", "place_starts", "check_separation", "resolve_conflicts",
           "resample_cycle", "FlightLog", "CycleSettings", "fly_cycles"]


def check_point(world: World, maps: StaticMaps, p: np.ndarray, what: str) -> None:
    """PointError unless ``p`` is in the map, off the terrain and its clearance band."""
    cell = world.to_cell(p, what=what)  # raises PointError outside the map
    ground = ""
    if world.terrain is not None:
        ground = f" (the ground there is at z = {float(world.ground_height(p[0], p[1])):.1f} m)"
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


def place_starts(guide: LeaderGuide, start: np.ndarray, heading: np.ndarray,
                 follower_starts: object, dist: float) -> np.ndarray:
    """Start positions (n_uav, 3) [m]: the leader's, then the followers'.

    ``follower_starts`` None: the followers' slots behind the leader's start
    (deformed by the grey level), each moved to the nearest allowed node at
    least ``dist`` from the UAVs already placed; else an (n_followers, 3)
    array [m], checked with :func:`check_point`.
    """
    maps = guide.maps
    nf = guide.shape.n_followers
    if follower_starts is None:
        slots, _ = guide.follower_goals(start, heading, None)
        starts = [start]
        for p in slots:
            starts.append(_place_start(maps, p, starts, dist))
        return np.array(starts, dtype=float)
    try:
        fs = np.asarray(follower_starts, dtype=float)
    except (TypeError, ValueError):
        raise InputError("follower_starts must be numbers, shape (n_followers, 3) [m]") from None
    if fs.shape != (nf, 3) or not np.all(np.isfinite(fs)):
        raise InputError(
            f"follower_starts must have shape ({nf}, 3) — one (x, y, z) in metres per "
            f"follower — and be finite, got shape {fs.shape}"
        )
    for j, p in enumerate(fs):
        check_point(maps.world, maps, p, f"follower {j + 1} start")
    return np.array([start] + list(fs), dtype=float)


def check_separation(pos: np.ndarray, names: tuple[str, ...], dist: float) -> None:
    """InputError if two starts are closer than ``dist / 2``."""
    bound = dist / 2.0
    n_uav = len(pos)
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


def resample_cycle(path: np.ndarray, speed: float, cycle: float, n_sub: int) -> np.ndarray:
    """Positions along ``path`` at ``n_sub + 1`` equally spaced times of one cycle.

    ``speed`` [m/s] along the path for ``cycle`` [s], stopping at its end.
    """
    s_arr = arc_length(path)
    s = np.minimum(np.linspace(0.0, speed * cycle, n_sub + 1), s_arr[-1])
    if s_arr[-1] <= 0.0:
        return np.repeat(path[:1], n_sub + 1, axis=0)
    return at_arc_length(path, s_arr, s)


def resolve_conflicts(motions: np.ndarray, bound: float) -> np.ndarray:
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


@dataclass
class FlightLog:
    """What the cycles record (appended to as the flight goes)."""

    times: list[float] = field(default_factory=list)
    samples: list[np.ndarray] = field(default_factory=list)
    cycle_start: list[float] = field(default_factory=list)
    goals: list[np.ndarray] = field(default_factory=list)
    grey: list[np.ndarray] = field(default_factory=list)
    held: list[np.ndarray] = field(default_factory=list)
    projected: list[np.ndarray] = field(default_factory=list)
    compute_s: list[float] = field(default_factory=list)
    completed: bool = False
    settled: bool = False


@dataclass(frozen=True)
class CycleSettings:
    """The fixed numbers of the cycles (resolved by the mission)."""

    cycle: float            # [s]
    speeds: np.ndarray      # (n_uav,) [m/s]
    radius: float           # safety radius around the other UAVs [m]
    n_sub: int              # samples per cycle
    bound: float            # dist / 2 [m]
    window: int             # [cells]
    order: int
    step: float
    max_cycles: int
    settle_cycles: int
    tol: float              # follower settled within this of its goal [m]


def _replan_all(maps: StaticMaps, W_stat: list[np.ndarray], pos: np.ndarray,
                goals: np.ndarray, cs: CycleSettings
                ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(a, b, d, e): every UAV re-plans in its window, the others as obstacles.

    Returns the motions (n_uav, n_sub + 1, 3), the projected and boxed-in
    masks and the goals actually planned to.
    """
    n_uav = len(pos)
    motions = np.empty((n_uav, cs.n_sub + 1, 3))
    proj = np.zeros(n_uav, dtype=bool)
    boxed = np.zeros(n_uav, dtype=bool)
    planned = goals.copy()
    for i in range(n_uav):
        others = np.delete(pos, i, axis=0)
        gaps = np.linalg.norm(others - pos[i], axis=1)
        radii = np.minimum(cs.radius, gaps - maps.half_diagonal - 1e-6)
        lp = local_path(maps, W_stat[i], pos[i], goals[i], others, radii,
                        margin=cs.window, order=cs.order, step=cs.step)
        proj[i] = lp.projected
        boxed[i] = lp.blocked
        planned[i] = lp.goal
        motions[i] = resample_cycle(lp.path, cs.speeds[i], cs.cycle, cs.n_sub)
    return motions, proj, boxed, planned


def fly_cycles(guide: LeaderGuide, W_stat: list[np.ndarray], pos: np.ndarray,
               heading: np.ndarray, goal: np.ndarray, cs: CycleSettings) -> FlightLog:
    """Fly the cycles from the start positions ``pos`` until the formation settles
    at the leader's ``goal`` (or ``max_cycles`` / ``settle_cycles`` run out)."""
    maps, L = guide.maps, guide.length
    log = FlightLog(times=[0.0], samples=[pos.copy()])
    s_ref = 0.0
    after = 0
    # cycles the leader needs at its speed (the followers then settle: a few more)
    expected = max(1, int(np.ceil(L / max(cs.speeds[0] * cs.cycle, 1e-9))))
    for c in range(int(cs.max_cycles)):
        progress.count(min(c, expected), expected, "cycles")
        tc = time.perf_counter()
        t_now = c * cs.cycle
        # (c) partial goals: the leader's along its path, the followers' from its pose
        s_goal = min(s_ref + cs.speeds[0] * cs.cycle, L)
        g_lead = guide.point(s_goal)
        heading = guide.heading(s_goal, heading)
        f_goals, B = guide.follower_goals(g_lead, heading, pos[1:])
        goals = np.vstack([g_lead[None], f_goals])
        motions, proj, boxed, planned = _replan_all(maps, W_stat, pos, goals, cs)
        # (f) fly one cycle, holding whoever would break the separation
        held = resolve_conflicts(motions, cs.bound) | boxed
        pos = motions[:, -1, :].copy()
        for m in range(1, cs.n_sub + 1):
            log.times.append(t_now + cs.cycle * m / cs.n_sub)
            log.samples.append(motions[:, m, :])
        log.cycle_start.append(t_now)
        log.goals.append(goals)
        log.grey.append(B)
        log.held.append(held)
        log.projected.append(proj)
        # leader's progress along its path
        s_ref = guide.progress(pos[0], s_ref, s_goal)
        log.compute_s.append(time.perf_counter() - tc)
        if s_goal >= L and np.linalg.norm(pos[0] - goal) <= 1e-6 * max(1.0, L):
            log.completed = True
            f_err = np.linalg.norm(pos[1:] - planned[1:], axis=1)
            if np.all(f_err <= cs.tol):
                log.settled = True
                break
            after += 1
            if after > cs.settle_cycles:
                break
    return log
