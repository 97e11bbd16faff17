"""Safe returns of a mission: the way back from everywhere, the point of no return, rally
points, the firmware's return made safe — or the planned return carried by the mission.

:func:`build_with_returns` builds a mission (:func:`~fm2uav.autopilot.build.build_mission`)
and then, on the plan's own map:

1. **Return fields** (:class:`~fm2uav.planning.returns.ReturnField`): one FM² march
   from home (the route's start) and one from each rally point, over the world,
   zones, limits and flight level the route was planned on.
2. **Rally points** (:mod:`~fm2uav.autopilot.rally`): the operator's, checked, and/or
   up to K chosen to bound the worst way back along the route.
3. **The way back from every point of the route**: points along the mission's legs
   (every waypoint, and every world cell between; :func:`~fm2uav.autopilot.returns.route_samples`)
   get the descent of the field whose way back is fastest: its path, length, time
   (legs at the forward speed and the climb / descent rates, then the landing
   descent, as the mission's own estimate: :func:`~fm2uav.vehicles.endurance.return_time`)
   and energy (the mission's energy model, :class:`~fm2uav.autopilot.energy.MissionPower`:
   its power model at the forward speed in the wind, the landing) — and, with an
   endurance, its share of it.
4. **The point of no return**, one figure in every budget the mission has — the usable
   battery ``battery × (1 − reserve)`` (the energy model along the legs as written and
   along the way back) and, with the airframe's endurance, the usable endurance
   ``endurance × (1 − reserve)`` (the mission's clock and the time back) — the first
   reached binds: the last point of the route from which what is spent plus what the
   way back needs stays within the budget; located between two route samples
   (:func:`~fm2uav.vehicles.endurance.first_shortfall`) and refined there by bisection
   with exact descents, so spent + way back equals the usable budget to a fraction of a
   second or a few mWh. Passed before the route's end, the mission warns (``strict``:
   refuses). The mission's energy summary then drops its straight-line point of no
   return (``no_return`` points here).
5. **The firmware's return** (:func:`~fm2uav.autopilot.returns.firmware_returns`):
   the lowest safe return altitude per firmware and airframe (``mission.param``).
   When none is safe, the mission carries a planned safe return instead, marked with
   ``DO_LAND_START`` before its landing (and, for ArduPilot, ``DO_RETURN_PATH_START``
   after the takeoff), and the parameters make the firmware's return follow the
   mission (ArduPlane ``RTL_AUTOLAND`` 4, ArduCopter failsafe action 6, PX4
   ``RTL_TYPE`` 2): a mission that ends with a landing (multirotor and VTOL by
   default) keeps it — the return continues the planned route to that landing; a
   mission that ends with an RTL (fixed-wing by default) or a loiter gets the FM² way
   back from the route's end appended and ends with a landing at home instead (an
   ArduPilot fixed-wing, which needs no landing in a mission, loiters over home: an
   automatic landing pattern needs a runway and an approach the operator chose).

The report (:class:`ReturnsReport`) is kept on the mission (``MissionExport.returns``);
its :meth:`~ReturnsReport.summary` is ``returns:`` in ``summary.json``.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from ..errors import InputError, PlanningError, UnreachableError
from ..planning.returns import ReturnField, ReturnPath
from ..vehicles.endurance import first_shortfall, return_time
from .build import MissionExport, build_mission
from .firmware import PROFILES
from .items import (
    CMD_DO_LAND_START,
    CMD_DO_RETURN_PATH_START,
    CMD_NAV_LAND,
    CMD_NAV_TAKEOFF,
    CMD_NAV_VTOL_LAND,
    CMD_NAV_VTOL_TAKEOFF,
    CMD_NAV_WAYPOINT,
    MissionItem,
)
from .params import ParamSet, param_set
from .rally import DEFAULT_AUTO_RALLY, RallyPoint, choose_rally, rally_points
from .returns import (
    RTL_WARNING,
    FirmwareReturns,
    RouteSamples,
    firmware_returns,
    route_samples,
)
from .thin import thin_path
from .validate import check_mission

__all__ = ["ReturnOptions", "ReturnsReport", "build_with_returns", "flown_plan",
           "RETURN_THIN_M", "DEFAULT_MAX_RETURNS"]

#: Douglas–Peucker tolerance of the written (and timed) return paths [m].
RETURN_THIN_M = 1.0
#: Most FM² ways back computed along a route (the spacing grows beyond it).
DEFAULT_MAX_RETURNS = 400


@dataclass(frozen=True)
class ReturnOptions:
    """What the operator asks of the returns (mission file ``rally:`` / ``returns:``, CLI
    ``--rally``, ``--rally-file``, ``--return-min-agl``, ``--strict``, ``--no-returns``).

    Attributes
    ----------
    enabled : bool
        Compute the returns at all.
    rally : tuple of (x, y[, agl])
        Rally sites given by the operator [m] (the approach height above the ground
        [m] third, default ``rally_agl``).
    auto_rally : int
        Rally points for the planner to choose (0: none).
    rally_agl : float or None
        Approach height of rally points above the ground [m]; default the height of
        the route's start above home.
    min_agl : float or None
        Lowest height above the surface of the firmware's straight return lines [m];
        default the flight level's ``min_agl``, else its cruise floor
        (``agl - tolerance``), else 30 m.
    strict : bool
        Refuse (PlanningError) a mission that passes its point of no return before
        its end.
    max_returns : int
        Most FM² ways back along the route.
    """

    enabled: bool = True
    rally: tuple[Any, ...] = ()
    auto_rally: int = 0
    rally_agl: float | None = None
    min_agl: float | None = None
    strict: bool = False
    max_returns: int = DEFAULT_MAX_RETURNS

    def __post_init__(self) -> None:
        if not 0 <= int(self.auto_rally) <= 10:
            raise InputError(f"--rally auto:K needs 1 <= K <= 10, got {self.auto_rally}")
        for name in ("rally_agl", "min_agl"):
            v = getattr(self, name)
            if v is not None and not (isinstance(v, (int, float)) and math.isfinite(v) and v >= 0):
                flag = {"rally_agl": "--rally ...,AGL", "min_agl": "--return-min-agl"}[name]
                raise InputError(f"returns {name} must be a number >= 0 m, got {v!r} ({flag})")


@dataclass(frozen=True, eq=False)
class ReturnsReport:
    """The returns of one mission (module docstring).

    Attributes
    ----------
    fields : dict of str to ReturnField
        ``"home"``, ``"rally 1"``, ... (one march each).
    rally : list of RallyPoint
    samples : RouteSamples
        Route points whose way back was planned.
    to : list of str
        Destination of each sample's way back.
    time, length : ndarray
        Its time [s] (landing included) and length [m].
    paths : list of ndarray
        Each way back as timed [m]: thinned (:data:`RETURN_THIN_M`) from the waypoints (the
        ways back written), dense between them.
    energy_wh : ndarray or None
        Energy of each way back [Wh] (the mission's energy model,
        :class:`~fm2uav.autopilot.energy.MissionPower`: power model, wind, landing).
    pnr : dict
        The point of no return (``summary()["point_of_no_return"]``).
    pnr_path : ndarray or None
        Its way back [m].
    firmware : FirmwareReturns or None
    params : ParamSet or None
        ``mission.param``.
    embedded : str
        ``""``, ``"return"`` (the planned return appended, landing at home) or
        ``"landing"`` (the route's own landing marked as the safe return).
    rally_report : dict
    warnings, notes : list of str
    """

    fields: dict[str, ReturnField]
    rally: list[RallyPoint]
    samples: RouteSamples
    to: list[str]
    time: np.ndarray
    length: np.ndarray
    paths: list[np.ndarray]
    energy_wh: np.ndarray | None
    pnr: dict[str, Any]
    pnr_path: np.ndarray | None
    firmware: FirmwareReturns | None
    params: ParamSet | None
    embedded: str
    rally_report: dict[str, Any] = field(default_factory=dict)
    warnings: list[str] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)
    speeds: dict[str, float] = field(default_factory=dict)
    endurance_s: float | None = None
    flight_w: np.ndarray | None = field(default=None, repr=False)
    flight_profile: Any = field(default=None, repr=False)

    def waypoint_paths(self) -> dict[int, np.ndarray]:
        """Waypoint index → its way back [m]."""
        return {int(w): self.paths[i] for i, w in enumerate(self.samples.waypoint) if w >= 0}

    def summary(self, world: Any = None, anchor: Any = None) -> dict[str, Any]:
        """``returns:`` of ``summary.json``."""
        s = self.samples
        share = (self.time / self.endurance_s) if self.endurance_s else None
        rows = []
        for i, w in enumerate(s.waypoint):
            if w < 0:
                continue
            row = {"waypoint": int(w), "t_mission_s": round(float(s.time[i]), 1),
                   "to": self.to[i], "length_m": round(float(self.length[i]), 1),
                   "time_s": round(float(self.time[i]), 1)}
            if share is not None:
                row["battery_share"] = round(float(share[i]), 4)
            if self.energy_wh is not None:
                row["energy_wh"] = round(float(self.energy_wh[i]), 3)
            rows.append(row)
        worst = int(np.argmax(self.time)) if len(self.time) else 0
        out: dict[str, Any] = {
            "method": "one FM² march per destination on the mission's own map (zones, limits, "
                      "flight level), a descent from every route point; time = legs at the "
                      "forward speed and the climb / descent rates, then the landing descent",
            "destinations": [
                {"name": "home", "kind": "home"},
                *[r.summary(world, anchor) if world is not None else {"name": r.name}
                  for r in self.rally]],
            "speeds": self.speeds,
            "waypoints": rows,
            "samples": {
                "count": len(s), "spacing_m": round(s.step, 2),
                "distance_m": np.round(s.distance, 1).tolist(),
                "t_mission_s": np.round(s.time, 1).tolist(),
                "to": list(self.to),
                "length_m": np.round(self.length, 1).tolist(),
                "time_s": np.round(self.time, 1).tolist(),
                **({"battery_share": np.round(share, 4).tolist()} if share is not None else {}),
                **({"energy_wh": np.round(self.energy_wh, 3).tolist()}
                   if self.energy_wh is not None else {}),
            },
            "worst": {"time_s": round(float(self.time[worst]), 1) if len(self.time) else None,
                      "distance_m": round(float(s.distance[worst]), 1) if len(s) else None,
                      "to": self.to[worst] if self.to else None},
            "energy": ("the mission's energy model (Wh): its power model in the wind, "
                       "landing included" if self.energy_wh is not None else
                       "share of the endurance at constant power (the endurance check's model)"),
            "point_of_no_return": self.pnr,
            "firmware": None if self.firmware is None else self.firmware.summary(),
            "mission_carries_safe_return": self.embedded or False,
            "warnings": list(self.warnings),
            "notes": list(self.notes),
        }
        if self.rally_report:
            out["rally_selection"] = self.rally_report
        return out


# ---------------------------------------------------------------- helpers
def _default_min_agl(level: Any) -> tuple[float, str]:
    if level is not None and level.min_agl is not None:
        return float(level.min_agl), "planner.min_agl (--min-agl)"
    if level is not None:
        return max(float(level.agl) - float(level.tolerance), 0.0), \
            "the cruise floor: planner.agl - planner.tolerance"
    return 30.0, "default 30 m (no flight level)"


def _speeds(mission: MissionExport) -> dict[str, float]:
    f = mission.info["flight"]
    return {"forward_mps": float(mission.options.forward_speed),
            "climb_mps": float(f["climb_rate_mps"]), "descent_mps": float(f["descent_rate_mps"])}


def _landing_height(world: Any, f: ReturnField) -> float:
    if world.ndim != 3:
        return 0.0
    return float(f.source[2] - world.ground_height(f.source[0], f.source[1]))


class _Backs:
    """Ways back from route points to the fastest destination, timed."""

    def __init__(self, fields: dict[str, ReturnField], speeds: dict[str, float],
                 world: Any, flight_alt: float, power: Any = None) -> None:
        self.fields, self.sp, self.world = fields, speeds, world
        self.flight_alt, self.power = flight_alt, power
        self.land = {n: (_landing_height(world, f) if world.ndim == 3 else flight_alt)
                     for n, f in fields.items()}

    def timed(self, path: np.ndarray, destination: str, *, thin: bool = False
              ) -> tuple[float, float, np.ndarray]:
        """(time, length, path) of a way back; ``thin``: the path thinned to
        :data:`RETURN_THIN_M` first (the polyline written), timed as written."""
        p = self._as3(path)
        if thin and len(p) > 2:
            p = thin_path(p, RETURN_THIN_M)
        t, L = return_time(p, speed=self.sp["forward_mps"], climb_rate=self.sp["climb_mps"],
                           descent_rate=self.sp["descent_mps"],
                           landing_height=self.land[destination])
        return t, L, p

    def _as3(self, path: Any) -> np.ndarray:
        p = np.asarray(path, dtype=float)
        if p.shape[1] == 2:
            p = np.column_stack([p, np.full(len(p), self.flight_alt)])
        return p

    def energy(self, path: Any, destination: str) -> float:
        """Energy [Wh] of a way back by the mission's energy model (``power``): at the
        forward speed in the wind, then the landing descent at the destination
        (``inf``: no way back)."""
        p = self._as3(path)
        if not len(p) or not destination:
            return math.inf
        return float(self.power.fly(p, landing=self.land[destination]).energy_wh)

    def best(self, points: np.ndarray) -> list[tuple[str, float, float, np.ndarray]]:
        """(destination, time, length, path) of each point's fastest way back (the dense
        path; :meth:`timed` with ``thin`` for the one written)."""
        nd = self.world.ndim
        pts = np.atleast_2d(points)[:, :nd]
        costs = {n: f.cost(pts) for n, f in self.fields.items()}
        names = list(costs)
        C = np.array([costs[n] for n in names])
        low = C.min(axis=0)
        out: list[tuple[str, float, float, np.ndarray]] = [
            ("", math.inf, math.inf, np.zeros((0, 3))) for _ in range(len(pts))]
        for k, n in enumerate(names):  # one batch of descents per destination
            want = np.flatnonzero(np.isfinite(low) & (C[k] <= 1.25 * low + 1e-9))
            if not len(want):
                continue
            try:
                rps = self.fields[n].paths(pts[want])
            except (UnreachableError, PlanningError):  # one by one: skip the ones that fail
                rps = []
                for i in want:
                    try:
                        rps.append(self.fields[n].path(pts[i]))
                    except (UnreachableError, PlanningError):
                        rps.append(None)
            for i, rp in zip(want, rps):
                if rp is None:
                    continue
                t, L, dense = self.timed(rp.path, n)
                if t < out[i][1]:
                    out[i] = (n, t, L, dense)
        return out


def _interp_w(W: np.ndarray, world: Any, path: np.ndarray) -> np.ndarray:
    from scipy import ndimage

    return ndimage.map_coordinates(W, world.to_index(path).T, order=1, mode="nearest")


# ---------------------------------------------------------------- embedding the safe return
def _return_end(opt: Any) -> str:
    """How the appended return ends: a landing at home, but a fixed-wing that may end
    without one (ArduPilot) loiters over home instead — an automatic landing pattern needs
    a runway and an approach the operator chose."""
    required = opt.vehicle in PROFILES[opt.firmware].landing_required
    return "loiter" if opt.vehicle == "fixed_wing" and not required else "land"


def _markers(items: list[MissionItem], models: Any) -> list[MissionItem]:
    """``items`` with DO_RETURN_PATH_START after the takeoff (ArduPilot) and DO_LAND_START
    before the final approach of a landing (unless the landing pattern has one)."""
    out = list(items)
    lands = any(it.command in (CMD_NAV_LAND, CMD_NAV_VTOL_LAND) for it in out)
    if lands and not any(it.command == CMD_DO_LAND_START for it in out):
        land = max(i for i, it in enumerate(out) if it.command in (CMD_NAV_LAND,
                                                                   CMD_NAV_VTOL_LAND))
        approach = max((i for i in range(land) if out[i].command == CMD_NAV_WAYPOINT),
                       default=land)
        out.insert(approach, MissionItem.do(CMD_DO_LAND_START, label="safe return: landing "
                                                                    "start"))
    if any(m.return_path_start for m in models):
        k = next(i for i, it in enumerate(out) if it.command in (CMD_NAV_TAKEOFF,
                                                                 CMD_NAV_VTOL_TAKEOFF))
        out.insert(k + 1, MissionItem.do(CMD_DO_RETURN_PATH_START,
                                         label="safe return: return path start"))
    return out


def _embed(mission: MissionExport, plan: Any, home: ReturnField, inputs: dict[str, Any],
           models: Any) -> tuple[MissionExport, str, str, Any, Any]:
    """The mission carrying its planned safe return (module docstring, step 5):
    (mission, kind, note, W along the flight, the flight's altitude profile)."""
    opt = mission.options
    world = mission.world
    path = np.asarray(mission.path_m, dtype=float)
    w = inputs.get("w")
    profile = inputs.get("profile")
    if inputs.get("times") is not None:
        return (mission, "", "a timed (formation) mission keeps its timing: no return appended",
                w, profile)
    if mission.end == "land":  # the route's own landing (auto for multirotor / VTOL)
        kind = "landing"
        m2 = mission
    else:  # an RTL or a loiter end: the planned way back and a landing at home
        kind = "return"
        start, end = path[0], path[-1]
        if np.hypot(*(end[:2] - start[:2])) > max(10.0, opt.tolerance):
            back = home.path(end[:world.ndim])
            ext = np.vstack([path, back.path[1:]])
            if w is not None and np.shape(w) == (len(path),):
                w = np.concatenate([np.asarray(w, dtype=float),
                                    _interp_w(np.asarray(plan.W), world, back.path[1:])])
            else:
                w = None
            if profile is not None and back.profile is not None:
                from ..planning.altitude import join_profiles

                profile = join_profiles([profile, back.profile])
            else:
                profile = None
            path = ext
        new_in = {**inputs, "w": w, "profile": profile}
        m2 = build_mission(path, world, replace(opt, end=_return_end(opt)), **new_in)
    items = _markers(m2.items, models)
    check_mission(items, opt.firmware, vehicle=opt.vehicle, home_alt=m2.waypoints.home[2],
                  max_land_slope_deg=opt.max_land_slope_deg, fences=m2.fences)
    end = "return" if kind == "return" else m2.end
    loiter = m2.end == "loiter"
    note = ("the mission carries the planned safe return: " +
            ("after the route, the FM² way back to home and " +
             ("a loiter over home (land it yourself)" if loiter else "a landing there")
             if kind == "return" else "the route's own landing at its end") +
            ("" if loiter else ", marked with DO_LAND_START") +
            (" and DO_RETURN_PATH_START after the takeoff" if any(m.return_path_start
                                                                   for m in models) else "") +
            "; " + "; ".join(m.mission_note for m in models if m.mission_note))
    return replace(m2, items=items, end=end), kind, note, w, profile


# ---------------------------------------------------------------- the point of no return
@dataclass(frozen=True, eq=False)
class _Budget:
    """One budget the point of no return is found in: the battery's usable energy [Wh] or
    the airframe's usable endurance [s]; what reaching each route sample spends of it and
    what its way back needs."""

    name: str                   # "energy" or "endurance"
    unit: str                   # "wh" or "s" (the summary's key suffix)
    usable: float
    total: float                # the battery [Wh] or the endurance [s]
    spent: np.ndarray           # on reaching each sample
    back: np.ndarray            # the way back from each sample
    spent_at: Callable[[RouteSamples], float]             # at a point of route_samples(legs=)
    back_of: Callable[[str, np.ndarray, float], float]    # (destination, path, time) of a way

    def describe(self, reserve: float) -> str:
        if self.name == "energy":
            return f"{100 * reserve:.0f} % reserve of its {self.total:.1f} Wh battery"
        return f"{100 * reserve:.0f} % reserve of its {self.total / 60:.1f} min endurance"


def _energy_budget(mission: MissionExport, samples: RouteSamples, backs: _Backs,
                   energy: np.ndarray) -> _Budget:
    """The battery budget: the energy model along the mission's legs as written (commanded
    speeds, holds, the take-off climb) and along each FM² way back."""
    from .returns import leg_speeds

    power = backs.power
    wps = mission.waypoints
    p = np.asarray(wps.points_m, dtype=float)
    speeds, holds = leg_speeds(mission.items, len(p), power.speed)
    takeoff = float(wps.agl[0])
    if len(p) > 1:
        flown = power.fly(p, speeds=speeds, holds=holds, takeoff=takeoff)
        still = power.fly(p, speeds=speeds, takeoff=takeoff)   # the legs without the holds
        used = flown.used_wh()
        travel = still.leg_energy_j / 3600.0
        hold = flown.leg_energy_j / 3600.0 - travel
    else:
        used, travel, hold = np.array([power.fly(p[:1], takeoff=takeoff).used_wh()[0]]), \
            np.zeros(0), np.zeros(0)

    def spent(rs: RouteSamples) -> np.ndarray:
        if len(p) < 2:
            return np.full(len(rs), used[0])
        k, f = rs.leg, rs.fraction
        return used[k] + f * travel[k] + np.where(f >= 1.0, hold[k], 0.0)

    return _Budget("energy", "wh", power.usable_wh, power.battery_wh, spent(samples), energy,
                   lambda rs: float(spent(rs)[0]),
                   lambda dest, path, t: backs.energy(path, dest))


def _time_budget(samples: RouteSamples, t_back: np.ndarray, endurance: float,
                 reserve: float) -> _Budget:
    """The endurance budget: the mission's clock and the time of each way back."""
    return _Budget("endurance", "s", endurance * (1.0 - reserve), endurance, samples.time,
                   t_back, lambda rs: float(rs.time[0]), lambda dest, path, t: float(t))


def _pnr_in(mission: MissionExport, samples: RouteSamples, to: list[str], backs: _Backs,
            b: _Budget, t_back: np.ndarray) -> tuple[dict[str, Any], np.ndarray | None]:
    """The point of no return in one budget (``vehicles.endurance.first_shortfall``, then a
    bisection on the straight piece of leg with exact descents)."""
    u = b.unit
    total = float(samples.distance[-1]) if len(samples) else 0.0
    base = {"computed": True, "budget": b.name, f"usable_{u}": round(b.usable, 3),
            "route_distance_m": round(total, 1)}
    hit = first_shortfall(b.spent, b.back, b.usable)
    if hit is None:
        k = int(np.argmin(b.usable - b.spent - b.back))
        return {**base, "reached": False, "passed_before_end": False,
                f"smallest_margin_{u}": round(float(b.usable - b.spent[k] - b.back[k]), 3),
                "smallest_margin_at_m": round(float(samples.distance[k]), 1)}, None
    k, _ = hit
    if k == 0:
        info = {**base, "reached": True, "passed_before_end": True, "distance_m": 0.0,
                "after_waypoint": 0, "t_mission_s": round(float(samples.time[0]), 1),
                f"spent_{u}": round(float(b.spent[0]), 3),
                "return": {"to": to[0] or None, "time_s": _r(t_back[0]),
                           f"{'energy_wh' if u == 'wh' else 'time_s'}": _r(b.back[0])},
                f"margin_{u}": _r(b.usable - b.spent[0] - b.back[0])}
        return info, None
    # bisection on the straight piece between samples k-1 and k (exact ways back)
    leg = int(samples.leg[k - 1])
    f_lo = float(samples.fraction[k - 1])
    f_hi = float(samples.fraction[k]) if int(samples.leg[k]) == leg else 1.0
    lo = (f_lo, samples.points[k - 1], float(samples.distance[k - 1]), float(samples.time[k - 1]),
          float(b.spent[k - 1]), (to[k - 1], float(t_back[k - 1]), math.nan, None))
    for _ in range(10):
        f = 0.5 * (f_lo + f_hi)
        rs = route_samples(mission, legs=[(leg, f)])
        back = backs.best(rs.points[:1])[0]
        spent = b.spent_at(rs)
        if back[3] is not None and b.usable - spent - b.back_of(back[0], back[3], back[1]) >= 0:
            f_lo = f
            lo = (f, rs.points[0], float(rs.distance[0]), float(rs.time[0]), spent, back)
        else:
            f_hi = f
    f, pt, dist, t_out, spent, back = lo
    if back[3] is None:  # the sample itself: its way back again, with the path
        back = backs.best(np.asarray(pt)[None, :])[0]
    t_b, l_b, thin = backs.timed(back[3], back[0], thin=True)  # as written
    need = b.back_of(back[0], thin, t_b)
    back = (back[0], t_b, l_b, thin)
    from ..world.geo import to_lonlat

    lo_, la_, amsl = to_lonlat(mission.world, [pt], anchor=mission.options.anchor)[0]
    wps = mission.waypoints
    ret = {"to": back[0], "time_s": round(back[1], 2), "length_m": round(back[2], 1)}
    if u == "wh":
        ret["energy_wh"] = round(need, 3)
    info = {
        **base, "reached": True,
        "passed_before_end": bool(dist < total - 1e-6),
        "distance_m": round(dist, 1), "after_waypoint": leg, "leg_fraction": round(f, 4),
        "lon": round(float(lo_), 9), "lat": round(float(la_), 9),
        "alt_amsl_m": round(float(amsl), 2),
        "point_m": [round(float(v), 2) for v in pt],
        "t_mission_s": round(t_out, 2),
        f"spent_{u}": round(spent, 3) if u == "wh" else round(t_out, 2),
        "return": ret,
        f"margin_{u}": round(b.usable - spent - need, 3),
        "waypoints": len(wps),
    }
    return info, back[3]


def _pnr(mission: MissionExport, samples: RouteSamples, t_back: np.ndarray, to: list[str],
         backs: _Backs, energy: np.ndarray, endurance: float | None, reserve: float
         ) -> tuple[dict[str, Any], np.ndarray | None, _Budget]:
    """The point of no return: the first reached of the battery's (the energy model along
    the route and the FM² ways back) and, with an endurance, the endurance's; one figure,
    saying which budget binds and where the other one lies."""
    budgets = [_energy_budget(mission, samples, backs, energy)]
    if endurance is not None:
        budgets.append(_time_budget(samples, t_back, endurance, reserve))
    found = [(b, *_pnr_in(mission, samples, to, backs, b, t_back)) for b in budgets]
    reached = [x for x in found if x[1].get("reached")]
    b, info, path = (min(reached, key=lambda x: x[1]["distance_m"]) if reached
                     else found[0])
    power = backs.power
    given = "airframe.power" if mission.options.power is not None else "class default"
    model = (f"energy model {power.model.name} ({given}) along the route and the FM² ways "
             f"back, battery {power.battery_wh:g} Wh")
    out = {**info, "reserve": reserve,
           "battery_wh": round(power.battery_wh, 3),
           **({"endurance_s": round(endurance, 1)} if endurance is not None else {}),
           "model": model + (f"; endurance {endurance / 60:.1f} min (constant power)"
                             if endurance is not None else "; no endurance given "
                             "(airframe.endurance / --endurance)")}
    others = {x[0].name: {k: v for k, v in x[1].items() if k in (
        "reached", "distance_m", "t_mission_s", f"margin_{x[0].unit}",
        f"smallest_margin_{x[0].unit}")} for x in found if x[0] is not b}
    if others:
        out["other_budgets"] = others
    return out, path, b


def _r(v: float) -> float | None:
    return round(float(v), 1) if math.isfinite(float(v)) else None


# ---------------------------------------------------------------- the whole
def build_with_returns(path_m: Any, world: Any, options: Any, returns: ReturnOptions, *,
                       plan: Any, **inputs: Any) -> MissionExport:
    """Build a mission and its safe returns (module docstring).

    Parameters
    ----------
    path_m, world, options, **inputs
        As :func:`~fm2uav.autopilot.build.build_mission` (``w``, ``agl``, ``times``,
        ``via``, ``camera``, ``fences``, ``start_hold``, ``profile``).
    returns : ReturnOptions
    plan : Plan
        The plan (or route) the path comes from: its map ``W``, level and settings
        make the return fields.

    Returns
    -------
    MissionExport
        The mission (with the planned safe return when no firmware return altitude is
        safe); its ``returns`` is the :class:`ReturnsReport` (None when the returns are
        off), its warnings include the returns'.

    Raises
    ------
    PlanningError
        ``returns.strict`` and the point of no return comes before the route's end.
    InputError
        A rally point the map refuses (named).
    """
    mission = build_mission(path_m, world, options, **inputs)
    if not returns.enabled:
        return mission
    opt = mission.options
    warnings: list[str] = []
    notes: list[str] = []
    start = np.asarray(plan.path[0], dtype=float)
    try:
        home = ReturnField.from_plan(plan, start, "home")
    except (InputError, PlanningError) as exc:
        warn = f"returns not computed: {exc}"
        return replace(mission, warnings=[*mission.warnings, warn])
    level = getattr(plan, "level", None)
    start_agl = (float(start[2] - world.ground_height(start[0], start[1])) if world.ndim == 3
                 else float(opt.flight_alt))
    agl = returns.rally_agl if returns.rally_agl is not None else start_agl
    rally = rally_points(world, returns.rally, agl=agl, reach=home)
    fields: dict[str, ReturnField] = {"home": home}
    for r in rally:
        fields[r.name] = ReturnField(world, home.W, r.point, name=r.name, level=home.level,
                                     order=home.order, step=home.step)
    rally_report: dict[str, Any] = {}
    if returns.auto_rally:
        clients = route_samples(mission, max_points=returns.max_returns).points
        chosen, flds, rally_report = choose_rally(home, clients, returns.auto_rally, agl=agl,
                                                  first=len(rally) + 1)
        if len(rally) + len(chosen) > 10:
            chosen, flds = chosen[:10 - len(rally)], flds[:10 - len(rally)]
        rally += chosen
        fields.update({f.name: f for f in flds})
        if not chosen:
            warnings.append(f"rally auto: no rally point chosen ({rally_report.get('stopped')})")
    min_agl, min_src = ((float(returns.min_agl), "returns.min_agl (--return-min-agl)")
                        if returns.min_agl is not None else _default_min_agl(level))
    if returns.min_agl is None and world.ndim == 2:
        min_agl, min_src = float(opt.flight_alt), "a 2D mission's flight altitude (flight_alt)"
    max_agl = None if level is None else level.max_agl
    models = PROFILES[opt.firmware].returns.get(opt.vehicle, ())
    fw = firmware_returns(mission, rally=rally, min_agl=min_agl, min_agl_source=min_src,
                          max_agl=max_agl)
    embedded = ""
    flight_w, flight_profile = inputs.get("w"), inputs.get("profile")
    if not fw.feasible:
        try:
            new, embedded, note, fw_w, fw_p = _embed(mission, plan, home, {**inputs}, models)
        except (UnreachableError, PlanningError) as exc:
            new, note = mission, f"the planned safe return could not be added: {exc}"
            warnings.append(note)
        if embedded:
            flight_w, flight_profile = fw_w, fw_p
        if embedded:
            mission = new
            notes.append(note)
            fw = firmware_returns(mission, rally=rally, min_agl=min_agl,
                                  min_agl_source=min_src, max_agl=max_agl)
        reasons = "; ".join(f"{r.model.label}: {', '.join(r.reasons)}" for r in fw.results
                            if not r.feasible)
        warnings.append("no firmware return altitude is safe from every point of the route "
                        f"({reasons})" + (f"; {note}" if embedded else ""))
    else:
        alt = ", ".join(f"{r.model.label} {r.altitude_m:g} m" for r in fw.results)
        notes.append(f"firmware return made safe: return altitude {alt} (mission.param) clears "
                     f"{min_agl:g} m above the surface on every straight return line")
    # the way back from every point of the final mission
    from .energy import MissionPower

    speeds = _speeds(mission)
    backs = _Backs(fields, speeds, world, float(opt.flight_alt), MissionPower.of(mission))
    samples = route_samples(mission, step=float(min(world.spacing[:2])),
                            max_points=returns.max_returns)
    best = backs.best(samples.points)
    for i in np.flatnonzero(samples.waypoint >= 0):  # written: thinned, timed as written
        if best[i][0]:
            best[i] = (best[i][0], *backs.timed(best[i][3], best[i][0], thin=True))
    to = [b[0] for b in best]
    t_back = np.array([b[1] for b in best])
    length = np.array([b[2] for b in best])
    paths = [b[3] for b in best]
    energy = np.array([backs.energy(p, d) for p, d in zip(paths, to)])
    cut = [i for i, t in enumerate(t_back) if not math.isfinite(t)]
    if cut:
        warnings.append(f"{len(cut)} route point(s) have no way back on the mission's map "
                        f"(first at {samples.distance[cut[0]]:.0f} m along the route)")
    endurance = opt.endurance_s
    pnr, pnr_path, budget = _pnr(mission, samples, t_back, to, backs, energy, endurance,
                                 opt.reserve)
    if pnr.get("passed_before_end"):
        msg = (f"point of no return {pnr['distance_m'] / 1000:.2f} km along the route (after "
               f"waypoint {pnr['after_waypoint']}, {pnr['t_mission_s'] / 60:.1f} min into the "
               f"mission): beyond it the vehicle cannot come back "
               f"{'home or to a rally point ' if rally else 'home '}within the "
               f"{budget.describe(opt.reserve)} before the route ends")
        if returns.strict:
            raise PlanningError(msg + "; refused (--strict / returns.strict): shorten the "
                                "route, add rally points (--rally auto) or give the airframe's "
                                + ("real endurance (--endurance)" if budget.name == "endurance"
                                   else "real battery and power model (--battery, --power)"))
        warnings.append(msg)
    if pnr.get("computed") and pnr.get("reached"):
        notes.append(f"point of no return: {pnr.get('distance_m', 0) / 1000:.2f} km along the "
                     f"route, {pnr.get('t_mission_s', 0) / 60:.1f} min into the mission")
    elif pnr.get("computed"):
        notes.append("no point of no return on the route: the way back from every point fits "
                     "the usable battery" + (" and endurance" if endurance is not None else ""))
    params = param_set(fw.params, header=(
        f"fm2uav return settings for {opt.firmware} {opt.vehicle}: "
        + ", ".join(r.model.label + (f" {r.altitude_m:g} m" if r.feasible else
                                     " (no safe altitude: mission-based return)")
                    for r in fw.results),
        f"checked: every straight return line >= {min_agl:g} m above the surface "
        f"({min_src})" + (f", <= {max_agl:g} m above the ground" if max_agl else ""),
        "a firmware version that does not know a name skips its line"))
    report = ReturnsReport(
        fields=fields, rally=rally, samples=samples, to=to, time=t_back, length=length,
        paths=paths, energy_wh=energy, pnr=pnr, pnr_path=pnr_path, firmware=fw, params=params,
        embedded=embedded, rally_report=rally_report, warnings=warnings, notes=notes,
        speeds=speeds, endurance_s=endurance, flight_w=flight_w, flight_profile=flight_profile)
    info = {**mission.info, "notes": list(mission.info.get("notes", [])) + notes}
    if "energy" in info:  # one point of no return: the returns' (the straight one is dropped)
        info["energy"] = {**{k: v for k, v in info["energy"].items()
                             if not k.startswith("no_return")},
                          "no_return": "point_of_no_return (FM² ways back, this energy model)"}
    kept = list(mission.warnings)
    if fw.feasible:  # the RTL line is checked now: the note says how (mission.param)
        kept = [w for w in kept if not w.startswith(RTL_WARNING)]
    return replace(mission, warnings=[*kept, *warnings], info=info, returns=report)


def flown_plan(plan: Any, mission: MissionExport) -> Any:
    """``plan`` as the mission flies it: with the planned safe return appended when the
    mission carries one (path, W along it, length, altitude profile), else ``plan``."""
    from ..geometry import path_length

    p = np.asarray(mission.path_m, dtype=float)
    if len(p) == len(plan.path) and np.array_equal(p, np.asarray(plan.path, dtype=float)):
        return plan
    rep = mission.returns
    w = rep.flight_w if rep is not None else None
    if w is None or np.shape(w) != (len(p),):
        W = np.asarray(plan.W)
        w = (_interp_w(W, plan.world, p) if W.shape == plan.world.shape
             else np.concatenate([plan.w, np.full(len(p) - len(plan.w), np.nan)]))
    profile = rep.flight_profile if rep is not None else None
    if profile is not None and len(profile.path) != len(p):
        profile = None
    return replace(plan, path=p, w=np.asarray(w, dtype=float), length=path_length(p),
                   profile=profile)
