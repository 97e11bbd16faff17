"""One flyable mission per battery: a survey split into sorties, each built and checked.

:func:`fm2uav.vehicles.sorties.split_sorties` cuts a survey that one battery cannot fly
into sorties; this module turns each into a complete mission
(:func:`build_sorties`), built by :func:`fm2uav.autopilot.build.build_mission` and so
checked by the same firmware validators as the whole mission:

1. take-off at home (the survey's start, above the take-off point);
2. the way out to the sortie's **resume point** — a point of the planned survey path,
   kept as a waypoint;
3. the survey path from there to where the sortie turns home (the next sortie's resume
   point), with its share of the camera bands (a band cut by the battery is switched
   on again where the next sortie resumes it);
4. the way home and the landing at home.

The ways out and home (:class:`HomeWays`) are the FM² **return field** of home
(:class:`fm2uav.planning.returns.ReturnField`, marched on the planner's velocity map of
the survey's world, flight level and no-fly zones: the way back from every point at
once) — or, where no field can be marched, **straight lines** at an altitude that
clears the highest surface under them by the flight level's height above ground (the
exact ground and roofs along the line, :func:`fm2uav.world.segments.surface_points`),
climbing or descending over the end points; a straight line through a no-fly zone is
refused. The split is cut with these ways' energies (flown by the power model in the
wind); each built sortie's energy and time are then its own mission's
(:func:`fm2uav.autopilot.energy.mission_energy` of its waypoints, as written), and when
one exceeds the usable battery — thinning, the take-off and the landing make a mission
cost a little more than the estimate — the split is cut again with that excess kept
aside, until every sortie fits.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..errors import InputError, PlanningError
from ..geometry import path_length

__all__ = ["HomeWays", "SortieMission", "SortieSet", "field_ways", "straight_ways",
           "build_sorties"]

#: Rebuilds of the split when a built sortie exceeds the usable battery.
MAX_ROUNDS = 5


@dataclass(frozen=True, eq=False)
class HomeWays:
    """How sorties fly between home and the survey.

    Attributes
    ----------
    kind : {"return field", "straight"}
    home : ndarray, shape (3,)
        Home in the air [m]: the survey's start, above the take-off point.
    world : World
    field : ReturnField or None
        The FM² return field of home (``kind == "return field"``).
    agl : float or None
        Height kept above the surface by straight ways [m].
    note : str
        Why this kind (said in the summary).
    """

    kind: str
    home: np.ndarray
    world: Any
    field: Any = None
    agl: float | None = None
    note: str = ""

    def paths(self, points: Any) -> list[np.ndarray]:
        """The way home from each of ``points`` [m]: (N, 3) paths from the point
        (exactly) to :attr:`home` (exactly).

        Raises
        ------
        PlanningError
            A point with no way home (cut off, or a straight line through a no-fly zone).
        """
        pts = np.atleast_2d(np.asarray(points, dtype=float))
        if self.field is not None:
            return [np.asarray(r.path, dtype=float) for r in self.field.paths(pts)]
        return [self._straight(p) for p in pts]

    def speed_share(self, path: np.ndarray) -> np.ndarray:
        """The planner's speed share W along a way (1 on straight ways)."""
        if self.field is None:
            return np.ones(len(path))
        from scipy import ndimage

        return ndimage.map_coordinates(np.asarray(self.field.W, dtype=float),
                                       self.world.to_index(path).T, order=1, mode="nearest")

    def _straight(self, p: np.ndarray) -> np.ndarray:
        from ..world.segments import surface_points

        h = self.home
        if float(np.hypot(*(p[:2] - h[:2]))) < 1e-9:
            return np.vstack([p, h])
        top = max(float(p[2]), float(h[2]))
        if self.agl is not None:
            s = surface_points(self.world, p[None, :2], h[None, :2])
            top = max(top, float(np.max(s.z)) + float(self.agl))
        path = np.array([p, [p[0], p[1], top], [h[0], h[1], top], h], dtype=float)
        keep = np.r_[True, np.any(np.abs(np.diff(path, axis=0)) > 1e-9, axis=1)]
        path = path[keep]
        if getattr(self.world, "zones", None):
            from ..world.zones import zone_violations

            bad = zone_violations(self.world, path)
            if bad:
                raise PlanningError(
                    f"the straight way home from {np.round(p, 1).tolist()} m enters the no-fly "
                    f"zone {bad[0].zone!r}: a sortie needs the return field there (plan on "
                    "the full map, planner.storage full)")
        return path


def field_ways(world: Any, home: Any, *, shaping: Any = None, level: Any = None) -> HomeWays:
    """:class:`HomeWays` along the FM² return field of ``home`` [m] on the planner's
    velocity map of ``world`` with ``shaping`` and the flight ``level``
    (:func:`fm2uav.planning.planner.plan_velocity`; no-fly zones are obstacles there).

    Raises
    ------
    InputError, PlanningError
        No field can be marched (home in an obstacle, a map of another shape).
    """
    from ..planning.params import PlanOptions, Shaping
    from ..planning.planner import plan_velocity
    from ..planning.returns import ReturnField

    W = plan_velocity(world, shaping if shaping is not None else Shaping(), level,
                      PlanOptions())
    h = np.asarray(home, dtype=float)
    field = ReturnField(world, W, h, name="home", level=level)
    return HomeWays("return field", h, world, field=field,
                    note="FM² return field of home on the planner's map (flight level, "
                         "obstacles and no-fly zones)")


def straight_ways(world: Any, home: Any, *, agl: float | None, note: str = "") -> HomeWays:
    """:class:`HomeWays` along straight lines, ``agl`` [m] above the highest surface under
    them (None: at the end points' altitudes, unchecked — a world without ground)."""
    return HomeWays("straight", np.asarray(home, dtype=float), world, agl=agl,
                    note=note or "straight lines clearing the surface under them by the "
                                 "flight level's height")


@dataclass(frozen=True, eq=False)
class SortieMission:
    """One sortie, built.

    Attributes
    ----------
    mission : MissionExport
        The sortie's mission (end ``land`` at home).
    files : dict
        File name → :class:`fm2uav.io.exports.ExportFile` (``sortie-01.plan``, ...).
    resume, stop : ndarray, shape (3,)
        Where the sortie joins the survey path and where it leaves it for home [m].
    survey : tuple of int
        The dense survey path's indices it flies (first, last).
    resume_waypoint : int
        Index of the resume point among the sortie's waypoints.

    Notes
    -----
    :attr:`resume_item` is the resume point's item number in the written mission (``seq``
    of the ``.waypoints`` file, home being 0).
    """

    mission: Any
    files: dict[str, Any]
    resume: np.ndarray
    stop: np.ndarray
    survey: tuple[int, int]
    resume_waypoint: int

    @property
    def resume_item(self) -> int:
        """``seq`` of the resume point's item in the written mission (home is 0): the
        waypoint labelled ``via 1``, or the take-off (1) when the sortie resumes at home."""
        for i, it in enumerate(self.mission.items):
            if it.label == "via 1":
                return i + 1
        return 1

    @property
    def energy_wh(self) -> float:
        """Energy of the sortie's mission [Wh] (:func:`~fm2uav.autopilot.energy.mission_energy`)."""
        return float(self.mission.info["energy"]["energy_wh"])

    @property
    def time_s(self) -> float:
        """Flight time of the sortie's mission in the energy model [s]."""
        return float(self.mission.info["energy"]["time_s"])


@dataclass(frozen=True, eq=False)
class SortieSet:
    """The sorties of a survey: the split (:class:`fm2uav.vehicles.sorties.SortiePlan`), the
    built missions, the ways between home and the survey, the margin the split needed and
    the rounds it took; ``whole_warnings`` (the whole mission's) are not repeated per sortie."""

    split: Any
    sorties: list[SortieMission]
    ways: HomeWays
    margin_wh: float
    rounds: int
    whole_warnings: tuple[str, ...] = ()

    def summary(self, anchor: Any = None) -> dict[str, Any]:
        """JSON-friendly figures: the split's, each sortie's mission energy and time
        (what its files fly), resume point in lon/lat, files."""
        from ..world.geo import to_lonlat

        out = self.split.summary()
        out["ways"] = {"kind": self.ways.kind, "note": self.ways.note}
        out["margin_wh"] = round(self.margin_wh, 2)
        out["rounds"] = self.rounds
        world = self.ways.world
        for s, m in zip(out["sorties"], self.sorties):
            lon, lat, alt = to_lonlat(world, np.array([m.resume]), anchor=anchor)[0]
            energy = m.mission.info["energy"]
            s.update({
                "energy_wh": energy["energy_wh"], "time_s": energy["time_s"],
                "split_energy_wh": s["energy_wh"], "split_time_s": s["time_s"],
                "ok": bool(energy["ok"]),
                "resume_m": np.round(m.resume, 2).tolist(),
                "home_from_m": np.round(m.stop, 2).tolist(),
                "resume_lon_lat_alt": [round(float(lon), 7), round(float(lat), 7),
                                       round(float(alt), 1)],
                "resume_waypoint": m.resume_waypoint, "resume_item": m.resume_item,
                "survey_path_indices": list(m.survey),
                "items": len(m.mission.items), "waypoints": len(m.mission.waypoints),
                "files": sorted(m.files),
                "warnings": [w for w in m.mission.warnings if w not in self.whole_warnings]})
        return out


def _nearest(path: np.ndarray, lo: int, hi: int, q: np.ndarray) -> int:
    """Index in ``path[lo:hi + 1]`` nearest (horizontally) to ``q``."""
    seg = path[lo:hi + 1, :2]
    return lo + int(np.argmin(np.hypot(*(seg - q[:2]).T)))


def _way_costs(ways: HomeWays, power: Any, ground: float):
    """``ways(points)`` for :func:`~fm2uav.vehicles.sorties.split_sorties`: the energy [Wh]
    and time [s] out (take-off climb at home, the way reversed) and home (the way, the
    landing), flown by the mission's energy model
    (:class:`~fm2uav.autopilot.energy.MissionPower`)."""

    def cost(points: Any) -> tuple[np.ndarray, ...]:
        pts = np.asarray(points, dtype=float)
        res = np.zeros((4, len(pts)))
        for k, path in enumerate(ways.paths(pts)):
            height = float(path[-1, 2]) - ground
            out = power.fly(path[::-1], takeoff=height)
            back = power.fly(path, landing=height)
            res[:, k] = out.energy_wh, out.time_s, back.energy_wh, back.time_s
        return tuple(res)

    return cost


def _sortie_plan(plan: Any, ways: HomeWays, ia: int, ib: int) -> tuple[Any, np.ndarray, int]:
    """A Plan-like of one sortie: the way out, the survey path ``ia .. ib``, the way home
    (repeated points dropped); with where each point of the survey piece went
    (``index[j]``: survey point ``ia + j``) and the length of the way out."""
    dense = np.asarray(plan.path, dtype=float)
    out_way, home_way = ways.paths(dense[[ia, ib]])
    out_way = out_way[::-1]
    survey = dense[ia:ib + 1]
    path = np.vstack([out_way[:-1], survey, home_way[1:]])
    w = np.concatenate([ways.speed_share(out_way)[:-1], np.asarray(plan.w, float)[ia:ib + 1],
                        ways.speed_share(home_way)[1:]])
    keep = np.r_[True, np.any(np.abs(np.diff(path, axis=0)) > 1e-9, axis=1)]
    new = np.cumsum(keep) - 1
    path = path[keep]
    i0 = len(out_way) - 1
    sp = dataclasses.replace(plan, path=path, w=np.clip(w[keep], 0.0, 1.0),
                             length=path_length(path), profile=None, wind_timing=None)
    return sp, new[i0:i0 + len(survey)], i0


def _camera(camera: Any, ia: int, ib: int, index: np.ndarray) -> Any:
    """The camera bands of the survey path ``ia .. ib`` re-indexed on a sortie's path
    (``index``: :func:`_sortie_plan`); a band cut at a sortie's end is resumed by the next."""
    if camera is None:
        return None
    bands = []
    for a, e in camera.bands:
        lo, hi = max(int(a), ia), min(int(e), ib)
        if lo < hi:
            bands.append((int(index[lo - ia]), int(index[hi - ia])))
    return dataclasses.replace(camera, bands=tuple(bands))


def _build(plan: Any, options: Any, **inputs: Any) -> tuple[Any, dict[str, Any]]:
    """The default sortie builder: the mission alone, no files."""
    from .build import build_mission

    return build_mission(plan.path, plan.world, options, w=plan.w, **inputs), {}


def build_sorties(mission: Any, plan: Any, *, ways: HomeWays, camera: Any = None,
                  fences: Any = (), agl: float | None = None, build: Any = None,
                  name: str = "sortie-{k:02d}", resume_step: float = 25.0) -> SortieSet | None:
    """Split a built survey mission by battery and build one mission per sortie.

    Parameters
    ----------
    mission : MissionExport
        The whole survey's mission (its options: airframe, power model, battery, reserve,
        wind, firmware).
    plan : Plan
        The survey's dense planned path (``CoveragePlan.plan``): each sortie flies a piece of
        it.
    ways : HomeWays
        How sorties fly between home and the survey (:func:`field_ways`,
        :func:`straight_ways`); ``ways.home`` is ``plan.path[0]``.
    camera : CameraPlan, optional
        The survey's camera bands (dense indices of ``plan.path``).
    fences : sequence, optional
        Geofences written into each ``.plan``.
    agl : float, optional
        Requested height above ground (terrain following).
    build : callable, optional
        ``build(plan, options, agl=, via=, camera=, fences=) -> (MissionExport, files)``:
        builds a sortie's mission (and its files, e.g. with
        :func:`fm2uav.io.exports.export_mission`); default
        :func:`~fm2uav.autopilot.build.build_mission`, no files. Of the files, the
        mission and path files (``mission.plan``, ``path.kml``, ...) are kept, renamed
        after the sortie (``sortie-01.plan``, ``sortie-01.kml``).
    name : str
        File stem of sortie ``k`` (1-based).
    resume_step : float
        Where sorties may end along the route [m] (:func:`~fm2uav.vehicles.sorties.split_sorties`).

    Returns
    -------
    SortieSet or None
        None when one battery flies the whole mission.

    Raises
    ------
    PlanningError
        The survey cannot be split (a point too far from home), a way home cannot be
        found, or a sortie still exceeds the battery after :data:`MAX_ROUNDS` cuts.
    MissionError
        The firmware would reject a sortie's mission.
    """
    from ..vehicles.sorties import split_sorties
    from .energy import MissionPower

    energy = mission.info.get("energy") or {}
    if energy.get("ok", True):
        return None
    opt = mission.options
    dense = np.asarray(plan.path, dtype=float)
    if not np.allclose(dense[0], ways.home):
        raise InputError("the sorties' home must be the survey path's first point")
    wps = mission.waypoints
    p = np.asarray(wps.points_m, dtype=float)
    ground = float(p[0, 2] - wps.agl[0])
    power = MissionPower.of(mission)
    cost = _way_costs(ways, power, ground)
    cached: dict[bytes, tuple[np.ndarray, ...]] = {}

    def ways_cost(points: Any) -> tuple[np.ndarray, ...]:  # the same points every round
        key = np.ascontiguousarray(points).tobytes()
        if key not in cached:
            cached[key] = cost(points)
        return cached[key]

    sopt = dataclasses.replace(opt, end="land")
    idx = np.asarray(wps.indices, dtype=int)
    margin = 0.0
    for rounds in range(1, MAX_ROUNDS + 1):
        split = split_sorties(p, power.model, home=[p[0, 0], p[0, 1], ground],
                              battery_wh=power.battery_wh, reserve=power.reserve,
                              speed=power.speed, climb_rate=power.climb_rate,
                              descent_rate=power.descent_rate, wind=power.wind,
                              resume_step=resume_step, ways=ways_cost, margin_wh=margin)
        n = len(split.sorties)
        built: list[SortieMission] = []
        ia = 0
        for k, s in enumerate(split.sorties, 1):
            last = k == n
            ib = len(dense) - 1 if last else _nearest(
                dense, int(idx[max(s.end - 1, 0)]), int(idx[s.end]), s.stop)
            ib = max(ib, ia + 1)
            sp, index, _ = _sortie_plan(plan, ways, ia, ib)
            label = name.format(k=k)
            m, files = (build or _build)(
                sp, dataclasses.replace(sopt, name=f"{opt.name}, sortie {k} of {n}"),
                agl=agl, via=[int(index[0]), int(index[-1])],
                camera=_camera(camera, ia, ib, index), fences=fences)
            renamed = {}
            for fname, f in files.items():
                stem, _, ext = fname.rpartition(".")
                if stem not in ("mission", "path"):
                    continue  # terrain and return files belong to the whole mission
                new = f"{label}.{ext}"
                renamed[new] = dataclasses.replace(f, name=new)
            built.append(SortieMission(m, renamed, dense[ia].copy(), dense[ib].copy(), (ia, ib),
                                       int(m.info["via_waypoints"][0])))
            ia = ib
        usable = split.usable_wh
        over = max(sm.energy_wh - usable for sm in built)
        if over <= 0:
            return SortieSet(split, built, ways, margin, rounds, tuple(mission.warnings))
        margin += over + 0.002 * usable
    raise PlanningError(
        f"a sortie still needs {over:.1f} Wh more than the {usable:.1f} Wh usable after "
        f"{MAX_ROUNDS} cuts of the survey: a bigger battery or a lower reserve")
