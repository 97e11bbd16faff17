"""A complete autopilot mission from a planned path: takeoff, route, speeds, camera, end.

:func:`build_mission` turns a dense path (a :class:`~fm2uav.Plan`, a route, a
coverage path, one UAV of a formation) into the list of MAVLink items every
mission file is written from, checks it with the firmware's validator
(:func:`fm2uav.autopilot.validate.check_mission`) and computes flight time and
endurance. The items, in order:

1. **Takeoff** to the start's altitude: ``NAV_VTOL_TAKEOFF`` for VTOL airframes,
   ``NAV_TAKEOFF`` otherwise (at the start for multirotors and VTOL; towards the
   second waypoint for fixed-wing, whose takeoff item gives the climb-out
   course). ArduPilot takes off above home (frame 3) even in a terrain-frame
   mission (ArduPilot issue #20142).
2. An initial ``DO_CHANGE_SPEED`` and one more wherever the planned speed
   changes (``speed_changes``; see :func:`speed_commands`).
3. The waypoints (``NAV_WAYPOINT``, yaw NaN = keep heading), with
   ``DO_SET_CAM_TRIGG_DIST`` on after each coverage band's first waypoint and
   off (distance 0) after its last.
4. The **end** (``outputs.end``): ``rtl`` (``NAV_RETURN_TO_LAUNCH``), ``land``
   (``NAV_LAND`` / ``NAV_VTOL_LAND`` at the last point; fixed-wing: a landing
   pattern ``DO_LAND_START`` + ``NAV_LOITER_TO_ALT`` + ``NAV_LAND``) or
   ``loiter`` (``NAV_LOITER_UNLIM``). ``auto``: ``land`` for multirotors and
   VTOL (every metre flown was planned; an RTL flies a straight, unchecked line
   at the firmware's return altitude), ``rtl`` for fixed-wing (a plane cannot
   land anywhere); on PX4 a fixed-wing RTL is followed by a landing pattern at
   home because PX4 rejects fixed-wing and VTOL missions without a landing
   (``MIS_TKO_LAND_REQ`` = 2) and its return mode lands through a mission
   ``DO_LAND_START``.
"""

from __future__ import annotations

import math
from collections import Counter
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..errors import InputError, MissionError
from ..geometry import runs
from ..missions.coverage.triggers import CameraPlan
from .geofence import as_fences
from ..world.geo import DEFAULT_ANCHOR, Anchor, to_lonlat
from .items import (
    CMD_DO_CHANGE_SPEED,
    CMD_DO_LAND_START,
    CMD_DO_SET_CAM_TRIGG_DIST,
    CMD_NAV_LAND,
    CMD_NAV_LOITER_TO_ALT,
    CMD_NAV_LOITER_UNLIM,
    CMD_NAV_RETURN_TO_LAUNCH,
    CMD_NAV_TAKEOFF,
    CMD_NAV_VTOL_LAND,
    CMD_NAV_VTOL_TAKEOFF,
    CMD_NAV_WAYPOINT,
    FRAME_GLOBAL,
    FRAME_RELATIVE,
    FRAME_TERRAIN,
    MissionItem,
)
from .firmware import FIRMWARES, PROFILES, VEHICLES
from .validate import check_mission
from .waypoints import FRAMES, Waypoints, ground_at, mission_waypoints, resolve_frame

__all__ = [
    "ENDS",
    "ExportOptions",
    "CameraPlan",
    "MissionExport",
    "speed_commands",
    "start_holds",
    "build_mission",
]

#: Mission ends (``outputs.end`` / ``--end``).
ENDS = ("auto", "rtl", "land", "loiter")

#: Default vertical speeds [m/s]: multirotor = ArduCopter WPNAV_SPEED_UP / _DN
#: (the ``arducopter`` preset of :mod:`fm2uav.vehicles.airframes`); fixed-wing
#: and VTOL = TECS_CLMB_MAX / TECS_SINK_MAX (ArduPlane) and FW_T_CLMB_MAX /
#: FW_T_SINK_MAX (PX4), both 5 m/s by default.
DEFAULT_CLIMB = {"multirotor": 2.5, "fixed_wing": 5.0, "vtol": 2.5}
#: Lowest commanded speed of multirotors and VTOL without ``min_speed`` [m/s] (never 0:
#: a 0 m/s DO_CHANGE_SPEED would stop the vehicle on its leg).
DEFAULT_MIN_SPEED = 1.0
DEFAULT_DESCENT = {"multirotor": 1.5, "fixed_wing": 5.0, "vtol": 1.5}


@dataclass(frozen=True)
class ExportOptions:
    """How a path becomes a mission (see docs/operator.md, "Missions").

    Attributes
    ----------
    tolerance : float
        Douglas–Peucker tolerance of the waypoints [m]. Default 5.
    max_points : int or None
        Cap on the number of waypoints.
    frame : {"auto", "terrain", "amsl", "relative"}
        Altitude frame (:func:`fm2uav.autopilot.waypoints.resolve_frame`).
    anchor : Anchor or None
        Placement of a world without CRS (default
        :data:`~fm2uav.world.geo.DEFAULT_ANCHOR`).
    takeoff : bool
        Must be True: every mission starts with a takeoff (kept so that mission
        files written with ``outputs.takeoff: true`` still load).
    flight_alt : float
        Altitude above home of 2D paths [m].
    cruise_speed : float
        Forward speed of fixed-wing and VTOL airframes [m/s] (``.plan``
        ``cruiseSpeed``).
    hover_speed : float
        Forward speed of multirotors [m/s] (``.plan`` ``hoverSpeed``).
    vehicle : {"multirotor", "fixed_wing", "vtol"}
    firmware : {"px4", "ardupilot", "generic"}
    end : {"auto", "rtl", "land", "loiter"}
        How the mission ends (module docstring).
    speed_changes : bool
        Write ``DO_CHANGE_SPEED`` items from the planned speed W (x the forward
        speed), quantised to ``speed_step`` with hysteresis.
    speed_step : float
        Speed quantum [m/s]. Default 1.
    speed_hysteresis : int
        Speed up only when the leg allows this many steps more (slowing down is
        immediate). Default 2.
    min_speed : float or None
        Lowest commanded speed [m/s]: multirotors default to 1 m/s, fixed-wing
        speed changes need it (a margin above the stall speed).
    loiter_radius : float
        Radius of fixed-wing loiters and of the landing pattern's loiter [m]
        (PX4 NAV_LOITER_RAD default 80 m).
    land_approach_agl : float
        Height of the fixed-wing landing approach above the touchdown [m].
    land_slope_deg : float
        Glide slope of the landing approach [deg] (PX4 rejects slopes steeper
        than FW_LND_ANG, default 5 deg).
    max_land_slope_deg : float
        The vehicle's FW_LND_ANG [deg] the validator checks against.
    climb_rate, descent_rate : float or None
        Vertical speeds for the flight time [m/s] (None: airframe defaults).
    endurance_s : float or None
        Airframe endurance [s]; None: not checked.
    reserve : float
        Share of the endurance kept in reserve. Default 0.2.
    name : str
        Mission name (KML, GeoJSON).
    power : str, MultirotorPower, FixedWingPower or None
        Power model of the energy figures (:mod:`fm2uav.autopilot.energy`; None: the
        class model of ``vehicle``).
    battery_wh : float or None
        Battery energy [Wh] (None: the power model's).
    wind : WindField or None
        The wind the energy and times are figured in (None: still air).
    """

    tolerance: float = 5.0
    max_points: int | None = None
    frame: str = "auto"
    anchor: Anchor | None = None
    takeoff: bool = True
    flight_alt: float = 30.0
    cruise_speed: float = 15.0
    hover_speed: float = 5.0
    vehicle: str = "multirotor"
    firmware: str = "px4"
    end: str = "auto"
    speed_changes: bool = False
    speed_step: float = 1.0
    speed_hysteresis: int = 2
    min_speed: float | None = None
    loiter_radius: float = 80.0
    land_approach_agl: float = 40.0
    land_slope_deg: float = 4.0
    max_land_slope_deg: float = 5.0
    climb_rate: float | None = None
    descent_rate: float | None = None
    endurance_s: float | None = None
    reserve: float = 0.2
    name: str = "fm2uav mission"
    power: Any = None
    battery_wh: float | None = None
    wind: Any = None

    def __post_init__(self) -> None:
        if self.firmware not in FIRMWARES:
            raise InputError(f"firmware must be one of {', '.join(FIRMWARES)}, got "
                             f"{self.firmware!r} (airframe.firmware / --firmware)")
        if self.vehicle not in VEHICLES:
            raise InputError(f"vehicle must be one of {', '.join(VEHICLES)}, got "
                             f"{self.vehicle!r} (airframe.type / --vehicle)")
        if self.frame not in FRAMES:
            raise InputError(f"frame must be one of {', '.join(FRAMES)}, got {self.frame!r} "
                             "(outputs.frame / --frame)")
        if self.end not in ENDS:
            raise InputError(f"end must be one of {', '.join(ENDS)}, got {self.end!r} "
                             "(outputs.end / --end)")
        if not self.takeoff:
            raise InputError("outputs.takeoff: false is not supported: PX4 and ArduPilot "
                             "missions start with a takeoff item (flown as a waypoint when the "
                             "vehicle is already in the air); remove outputs.takeoff")
        for name in ("tolerance", "flight_alt", "cruise_speed", "hover_speed", "speed_step",
                     "loiter_radius", "land_approach_agl", "land_slope_deg",
                     "max_land_slope_deg"):
            v = getattr(self, name)
            if not (isinstance(v, (int, float)) and math.isfinite(v) and v >= 0):
                raise InputError(f"export option {name} must be a number >= 0, got {v!r}")
        for name in ("min_speed", "climb_rate", "descent_rate", "endurance_s", "battery_wh"):
            v = getattr(self, name)
            if v is not None and not (isinstance(v, (int, float)) and math.isfinite(v) and v > 0):
                raise InputError(f"export option {name} must be a number > 0, got {v!r}")
        if self.speed_step <= 0:
            raise InputError(f"speed_step must be > 0 m/s, got {self.speed_step!r}")
        if not 0 < self.land_slope_deg <= self.max_land_slope_deg:
            raise InputError(f"land_slope_deg must be in (0, {self.max_land_slope_deg:g}] "
                             f"(FW_LND_ANG), got {self.land_slope_deg!r}")

    @property
    def forward_speed(self) -> float:
        """The airframe's mission speed [m/s]: hover speed (multirotor) or cruise speed."""
        return self.hover_speed if self.vehicle == "multirotor" else self.cruise_speed


@dataclass(frozen=True, eq=False)
class MissionExport:
    """A built mission: the items every format is written from, and its numbers.

    Attributes
    ----------
    items : list of MissionItem
        The mission after the home position, as uploaded.
    waypoints : Waypoints
        The thinned, geo-referenced route.
    options : ExportOptions
    frame : str
        Resolved altitude frame of the route.
    end : str
        Resolved end (``rtl``, ``land``, ``loiter``).
    path_m : ndarray
        The dense planned path [m].
    world : World
    warnings : list of str
    info : dict
        Summary numbers (speed changes, camera, landing, flight time, endurance).
    fences : list
        Geofences for the ``.plan`` (:mod:`fm2uav.autopilot.geofence`).
    """

    items: list[MissionItem]
    waypoints: Waypoints
    options: ExportOptions
    frame: str
    end: str
    path_m: np.ndarray
    world: Any
    warnings: list[str]
    info: dict[str, Any]
    fences: list[Any] = field(default_factory=list)

    @property
    def home(self) -> tuple[float, float, float]:
        """``(lat, lon, alt AMSL)`` of home [deg, deg, m]."""
        return self.waypoints.home

    def summary(self) -> dict[str, Any]:
        """JSON-friendly description of the mission (what ``summary.json`` records)."""
        w = self.waypoints
        cmds = Counter(it.name for it in self.items)
        crs = getattr(self.world, "crs", None)
        georef = getattr(self.world, "georef", None)
        vref = getattr(georef, "vertical", None) or getattr(self.world, "vertical_reference", None)
        return {
            "firmware": self.options.firmware,
            "vehicle": self.options.vehicle,
            "frame": {"name": self.frame, "mav_frame": w.frame,
                      "requested": self.options.frame},
            "home": {"lat": round(w.home[0], 9), "lon": round(w.home[1], 9),
                     "alt_amsl_m": round(w.home[2], 3), "source": w.home_source},
            "crs": crs,
            "georef": None if georef is None else georef.as_dict(),
            "vertical_reference": vref or ("metres above the DEM's vertical datum (normally "
                                           "mean sea level)" if crs else
                                           "anchor altitude + world z (synthetic)"),
            "end": self.end,
            "items": len(self.items),
            "waypoints": len(w),
            "commands": dict(sorted(cmds.items())),
            "waypoint_agl_m": {"min": round(float(w.agl.min()), 2),
                               "max": round(float(w.agl.max()), 2),
                               "requested": w.requested_agl},
            **self.info,
            "warnings": list(self.warnings),
        }


# ---------------------------------------------------------------- speeds
def speed_commands(leg_speeds: Any, *, current: float | None, step: float, hysteresis: int,
                   floor: float, cap: float, rounding: str = "down") -> list[tuple[int, float]]:
    """Where to change speed and to what: ``[(leg index, speed m/s), ...]``.

    Each leg's admissible speed is quantised down to a multiple of ``step``
    (never above what the leg allows), clipped to ``[floor, cap]``. The first
    leg always gets a command; later legs get one when the quantised speed is
    below the current command (slow down at once) or at least ``hysteresis``
    steps above it (speed up only for a clear gain), so noise in W does not
    produce a stream of items. ``rounding="nearest"`` (timed trajectories)
    rounds to the nearest step instead of down.
    """
    v = np.asarray(leg_speeds, dtype=float)
    out: list[tuple[int, float]] = []
    c = current
    for k, s in enumerate(v):
        n = math.floor(s / step + 1e-9) if rounding == "down" else round(s / step)
        q = min(max(n * step, floor), cap)
        if c is None or q < c - 1e-9 or q >= c + hysteresis * step - 1e-9:
            out.append((k, round(q, 6)))
            c = q
    return out


def _leg_speeds(w_dense: np.ndarray, idx: np.ndarray, vmax: float, floor: float) -> np.ndarray:
    """Slowest admissible speed W x vmax over the dense points of each leg [m/s]."""
    v = np.maximum(np.clip(w_dense, 0.0, 1.0) * vmax, floor)
    return np.array([v[a:b + 1].min() for a, b in zip(idx[:-1], idx[1:])])


def _timed_legs(times: np.ndarray, points: np.ndarray, idx: np.ndarray, floor: float
                ) -> tuple[np.ndarray, np.ndarray]:
    """Speed on each straight leg between waypoints that keeps a timed trajectory's
    timing, and the hold time at each waypoint where it waits [m/s], [s]."""
    d = np.diff(points, axis=0)
    lengths = np.hypot(d[:, 0], d[:, 1])
    dt = times[idx[1:]] - times[idx[:-1]]
    if np.any(dt <= 0):
        raise InputError("the trajectory's times must increase from waypoint to waypoint")
    holds = np.zeros(len(idx))
    speeds = lengths / dt
    slow = speeds < floor  # fly at the floor speed and wait the rest at the leg's start
    holds[:-1][slow] = dt[slow] - lengths[slow] / floor
    speeds[slow] = floor
    return speeds, holds


# ---------------------------------------------------------------- geometry
def _unit_xy(points: np.ndarray, from_end: bool) -> np.ndarray:
    """Unit horizontal direction of arrival at the end (or of departure from the start),
    measured to the nearest waypoint more than 1 m away."""
    ref = points[-1] if from_end else points[0]
    seq = points[-2::-1] if from_end else points[1:]
    for q in seq:
        d = (ref - q)[:2] if from_end else (q - ref)[:2]
        n = float(np.hypot(d[0], d[1]))
        if n > 1.0:
            return d / n
    return np.array([1.0, 0.0])


def _inside_xy(world: Any, xy: np.ndarray) -> np.ndarray:
    b = world.bounds
    return ((xy[:, 0] >= b[0, 0]) & (xy[:, 0] <= b[0, 1]) & (xy[:, 1] >= b[1, 0])
            & (xy[:, 1] <= b[1, 1]))


class _Geo:
    """World metres → items, in the mission's altitude frame."""

    def __init__(self, world: Any, anchor: Anchor | None, wps: Waypoints) -> None:
        self.world, self.anchor, self.wps = world, anchor, wps
        self.home_amsl = wps.home[2]

    def ground(self, xy: np.ndarray) -> np.ndarray:
        return ground_at(self.world, xy)

    def item(self, command: int, frame: int, xy: np.ndarray, z_world: float, *,
             label: str, **params: float) -> MissionItem:
        """A position item at world ``xy`` and flown altitude ``z_world`` [m]."""
        lo, la, amsl = to_lonlat(self.world, [[xy[0], xy[1], z_world]], anchor=self.anchor)[0]
        g = float(self.ground(xy)[0])
        agl = z_world - g
        alt = {FRAME_GLOBAL: amsl, FRAME_RELATIVE: amsl - self.home_amsl,
               FRAME_TERRAIN: agl}[frame]
        return MissionItem.at(command, frame, float(la), float(lo), float(alt), agl=float(agl),
                              alt_amsl=float(amsl), label=label, **params)


def _landing_pattern(geo: _Geo, touchdown: np.ndarray, heading: np.ndarray, frame: int,
                     opt: ExportOptions, label: str) -> tuple[list[MissionItem], dict, list[str]]:
    """DO_LAND_START + NAV_LOITER_TO_ALT + NAV_LAND, approach along ``heading``.

    The loiter centre sits behind the touchdown along ``heading`` so that the
    tangent from its circle to the touchdown is ``approach_agl / tan(slope)``
    long; its altitude is ``approach_agl`` above the touchdown's ground.
    """
    r = float(opt.loiter_radius)
    h = float(opt.land_approach_agl)
    run = h / math.tan(math.radians(opt.land_slope_deg))
    d = math.hypot(run, r)
    centre = touchdown - heading * d
    g_td = float(geo.ground(touchdown)[0])
    f = FRAME_RELATIVE if frame == FRAME_TERRAIN else frame  # altitudes above the touchdown
    items = [
        MissionItem.do(CMD_DO_LAND_START, label=f"{label}: landing start"),
        geo.item(CMD_NAV_LOITER_TO_ALT, f, centre, g_td + h, label=f"{label}: approach loiter",
                 p1=1.0, p2=r, p4=0.0),
        geo.item(CMD_NAV_LAND, f, touchdown, g_td, label=f"{label}: touchdown"),
    ]
    warnings: list[str] = []
    s = np.linspace(0.0, run, 64)
    line = touchdown[None, :] - heading[None, :] * s[:, None]
    phi = np.linspace(0.0, 2 * math.pi, 72, endpoint=False)
    circle = centre[None, :] + r * np.column_stack([np.cos(phi), np.sin(phi)])
    pts = np.vstack([line, circle])
    info: dict[str, Any] = {"touchdown_alt_amsl_m": round(items[2].alt_amsl or 0.0, 2),
                            "approach_agl_m": h, "glide_slope_deg": opt.land_slope_deg,
                            "approach_run_m": round(run, 1), "loiter_radius_m": r}
    inside = _inside_xy(geo.world, pts)
    if not inside.all():
        warnings.append(f"{label}: the landing approach ({d:.0f} m back from the touchdown, "
                        f"{r:.0f} m loiter) leaves the map: its terrain is not checked")
    if inside.any():
        glide = np.concatenate([g_td + s * math.tan(math.radians(opt.land_slope_deg)),
                                np.full(len(circle), g_td + h)])
        clear = glide - geo.ground(pts)
        check = inside & (glide - g_td >= 10.0)
        if check.any():
            worst = float(clear[check].min())
            info["approach_min_clearance_m"] = round(worst, 1)
            if worst < 10.0:
                warnings.append(f"{label}: the landing approach passes only {worst:.1f} m above "
                                "the ground (DEM): check the landing site, or change "
                                "land_approach_agl / land_slope_deg")
    return items, info, warnings


# ---------------------------------------------------------------- building
_Event = tuple[str, float, str]  # (kind, value, label) at a dense-path index


def _events(p: np.ndarray, via: Any, camera: CameraPlan | None, times: Any
            ) -> tuple[dict[int, list[_Event]], list[int]]:
    """Dense indices that must be waypoints, with what happens there."""
    n = len(p)
    keep: dict[int, list[_Event]] = {}
    via_idx = [int(i) for i in np.asarray(via, dtype=int).ravel()]
    for k, i in enumerate(via_idx):
        if not 0 <= i < n:
            raise InputError(f"via index {i} outside the path (0..{n - 1})")
        keep.setdefault(i, []).append(("via", 0.0, f"via {k + 1}"))
    if camera is not None:
        if not (math.isfinite(camera.trigger_distance) and camera.trigger_distance > 0):
            raise MissionError(f"camera trigger distance must be > 0 m, got "
                               f"{camera.trigger_distance!r}")
        for b, (a, e) in enumerate(camera.bands):
            if not 0 <= a < e < n:
                raise InputError(f"band {b + 1} indices ({a}, {e}) are not increasing inside the "
                                 f"path (0..{n - 1})")
            keep.setdefault(int(a), []).append(("camera_on", camera.trigger_distance,
                                                f"band {b + 1} start"))
            keep.setdefault(int(e), []).append(("camera_off", 0.0, f"band {b + 1} end"))
    if times is not None:  # where a timed trajectory stands still, keep both ends: a hold
        t = np.asarray(times, dtype=float)
        if t.shape != (n,) or not np.all(np.isfinite(t)) or not np.all(np.diff(t) > 0):
            raise InputError(f"times must be {n} increasing finite values [s], one per path "
                             "point")
        seg = np.linalg.norm(np.diff(p, axis=0), axis=1) / np.diff(t)
        for a, b in runs(seg < 0.1):
            if t[b] - t[a] >= 1.0:
                keep.setdefault(int(a), []).append(("hold", 0.0, "wait"))
                keep.setdefault(int(b), []).append(("hold", 0.0, "wait"))
    return keep, via_idx


@dataclass(frozen=True)
class _Speeds:
    commanded: np.ndarray  # speed in force on each leg [m/s]
    changes: list[tuple[int, float]]  # DO_CHANGE_SPEED (leg index, m/s)
    holds: np.ndarray  # hold time at each waypoint [s]
    timing: dict[str, Any] | None


def _speeds(opt: ExportOptions, wps: Waypoints, w: Any, times: Any,
            start_hold: float) -> _Speeds:
    """Commanded speed of each leg (W-based or timed) and the speed items."""
    idx = wps.indices
    vmax = opt.forward_speed
    floor = opt.min_speed if opt.min_speed is not None else (
        DEFAULT_MIN_SPEED if opt.vehicle != "fixed_wing" else None)
    holds = np.zeros(len(idx))
    changes: list[tuple[int, float]] = []
    timing = None
    if times is not None:
        t = np.asarray(times, dtype=float)
        lo = floor or 0.5
        leg_v, holds = _timed_legs(t, wps.points_m, idx, lo)
        holds[0] += float(start_hold)
        changes = speed_commands(leg_v, current=None, step=opt.speed_step, hysteresis=0,
                                 floor=lo, cap=float(max(leg_v.max(), lo)), rounding="nearest")
        timing = {"planned_s": round(float(t[-1] - t[0]), 2),
                  "start_hold_s": round(float(start_hold), 2)}
    elif opt.speed_changes:
        if floor is None:
            raise MissionError("fixed-wing speed changes need airframe.min_speed (a margin "
                               "above the stall speed; CLI --min-speed) so that no commanded "
                               "airspeed falls below it")
        if w is None:
            raise MissionError("speed changes need W along the path (the plan's speed profile)")
        wd = np.asarray(w, dtype=float)
        if wd.shape != (idx[-1] + 1,):
            raise InputError(f"W along the path must have {idx[-1] + 1} values, got {wd.shape}")
        leg_v = _leg_speeds(wd, idx, vmax, floor)
        changes = speed_commands(leg_v, current=None, step=opt.speed_step,
                                 hysteresis=opt.speed_hysteresis, floor=floor, cap=vmax)
    commanded = np.full(len(idx) - 1, vmax)
    for k, v in changes:
        commanded[k:] = v
    return _Speeds(commanded, changes, holds, timing)


def _takeoff(geo: _Geo, wps: Waypoints, opt: ExportOptions) -> MissionItem:
    """The takeoff item to the start's altitude (frame 3 instead of 10, issue #20142)."""
    frame = FRAME_RELATIVE if wps.frame == FRAME_TERRAIN else wps.frame
    start_xy, start_z = wps.points_m[0, :2], float(wps.points_m[0, 2])
    if wps.agl[0] < 0.5:
        raise MissionError(f"the start is {wps.agl[0]:.2f} m above the ground: a takeoff needs "
                           "a start above it (give start with agl, e.g. {x, y, agl: 30})")
    if opt.vehicle == "vtol":
        return geo.item(CMD_NAV_VTOL_TAKEOFF, frame, start_xy, start_z, label="takeoff")
    if opt.vehicle == "fixed_wing":  # the item's position gives the climb-out course
        leg = wps.points_m[1, :2] - start_xy
        n = max(float(np.hypot(*leg)), 1e-9)
        target = start_xy + leg / n * min(200.0, 0.5 * n)
        return geo.item(CMD_NAV_TAKEOFF, frame, target, start_z,
                        label="takeoff (climb-out course)", p1=15.0)
    return geo.item(CMD_NAV_TAKEOFF, frame, start_xy, start_z, label="takeoff")


def _do_items(events: list[_Event], change: float | None, speed_type: float
              ) -> list[MissionItem]:
    """Camera and speed items after a waypoint (camera off before on, speed last)."""
    out = []
    for kind, value, label in sorted(events, key=lambda e: e[0] != "camera_off"):
        if kind == "camera_on":
            out.append(MissionItem.do(CMD_DO_SET_CAM_TRIGG_DIST, value, 0.0, 1.0, 0.0,
                                      label=f"{label}: camera on"))
        elif kind == "camera_off":
            out.append(MissionItem.do(CMD_DO_SET_CAM_TRIGG_DIST, 0.0, 0.0, 0.0, 0.0,
                                      label=f"{label}: camera off"))
    if change is not None:
        out.append(MissionItem.do(CMD_DO_CHANGE_SPEED, speed_type, change, -1.0, 0.0,
                                  label="speed change"))
    return out


def _route(wps: Waypoints, keep: dict[int, list[_Event]], sp: _Speeds,
           opt: ExportOptions) -> list[MissionItem]:
    """The waypoints after the takeoff, with their hold times and DO items."""
    idx = wps.indices
    change_at = dict(sp.changes)
    speed_type = 1.0 if opt.vehicle == "multirotor" else 0.0

    def waypoint(k: int, label: str) -> MissionItem:
        return MissionItem(CMD_NAV_WAYPOINT, wps.frame,
                           (float(sp.holds[k]), 0.0, 0.0, math.nan, float(wps.lat[k]),
                            float(wps.lon[k]), float(wps.alt[k])),
                           agl=float(wps.agl[k]), alt_amsl=float(wps.alt_amsl[k]), label=label)

    items = [waypoint(0, "start (hold)")] if sp.holds[0] > 0 else []
    items += _do_items(keep.get(int(idx[0]), []), change_at.get(0), speed_type)
    last = len(wps) - 1
    for k in range(1, last + 1):
        vias = [lab for kind, _, lab in keep.get(int(idx[k]), []) if kind == "via"]
        items.append(waypoint(k, ", ".join(vias) or f"waypoint {k}"))
        events = keep.get(int(idx[k]), [])
        if k == last:  # nothing starts at the last waypoint; a band may end there
            events = [e for e in events if e[0] == "camera_off"]
        items += _do_items(events, change_at.get(k) if k < last else None, speed_type)
    return items


def _end(geo: _Geo, wps: Waypoints, opt: ExportOptions
         ) -> tuple[str, list[MissionItem], dict[str, Any], list[str]]:
    """(resolved end, items, landing figures, warnings)."""
    end = opt.end if opt.end != "auto" else ("rtl" if opt.vehicle == "fixed_wing" else "land")
    start_xy = wps.points_m[0, :2]
    end_xy, end_z = wps.points_m[-1, :2], float(wps.points_m[-1, 2])
    f_route = wps.frame
    items: list[MissionItem] = []
    landing: dict[str, Any] = {}
    warnings: list[str] = []
    if end == "rtl":
        items.append(MissionItem.do(CMD_NAV_RETURN_TO_LAUNCH, label="return to launch"))
        must_land = opt.vehicle in PROFILES[opt.firmware].landing_required
        if must_land and opt.vehicle == "fixed_wing":
            heading = -_unit_xy(wps.points_m, from_end=False)
            pattern, landing, warnings = _landing_pattern(geo, start_xy, heading, f_route, opt,
                                                          "home landing")
            items += pattern
        elif must_land and opt.vehicle == "vtol":
            items.append(MissionItem.do(CMD_DO_LAND_START, label="home landing start"))
            items.append(geo.item(CMD_NAV_VTOL_LAND, FRAME_RELATIVE if f_route == FRAME_TERRAIN
                                  else f_route, start_xy, float(geo.ground(start_xy)[0]),
                                  label="home landing"))
        if len(items) > 1:
            landing["note"] = ("PX4 needs a landing in fixed-wing and VTOL missions "
                               "(MIS_TKO_LAND_REQ = 2): the RTL item is followed by a landing at "
                               "home, which PX4's return mode uses through DO_LAND_START")
        line = start_xy[None, :] + np.linspace(0, 1, 50)[:, None] * (end_xy - start_xy)[None, :]
        inside = _inside_xy(geo.world, line)
        rise = (float((geo.ground(line[inside]) - geo.ground(start_xy)[0]).max())
                if inside.any() else float("nan"))
        back = float(np.hypot(*(end_xy - start_xy)))
        landing["rtl_straight_line_m"] = round(back, 1)
        landing["rtl_max_ground_above_home_m"] = None if not np.isfinite(rise) else round(rise, 1)
        if back > max(10.0, opt.tolerance):  # the route did not come back home itself
            rises = (f" — the ground under it rises {rise:.0f} m above home"
                     if np.isfinite(rise) and rise > 0 else "")
            warnings.append("RTL flies a straight line home at the firmware's return altitude "
                            "(PX4 RTL_RETURN_ALT, ArduPilot RTL_ALT / ALT_HOLD_RTL); fm2uav "
                            f"neither plans nor checks it{rises}; use return: true (--return) "
                            "for a planned way back")
    elif end == "land" and opt.vehicle == "fixed_wing":
        heading = _unit_xy(wps.points_m, from_end=True)
        items, landing, warnings = _landing_pattern(geo, end_xy, heading, f_route, opt, "landing")
    elif end == "land":
        cmd = CMD_NAV_VTOL_LAND if opt.vehicle == "vtol" else CMD_NAV_LAND
        items.append(geo.item(cmd, f_route, end_xy, float(geo.ground(end_xy)[0]),
                              label="landing"))
    else:  # loiter
        radius = 0.0 if opt.vehicle == "multirotor" else float(opt.loiter_radius)
        items.append(geo.item(CMD_NAV_LOITER_UNLIM, f_route, end_xy, end_z,
                              label="loiter at the end", p3=radius))
    return end, items, landing, warnings


def start_holds(starts: Any, world: Any, options: ExportOptions) -> np.ndarray:
    """Wait at each vehicle's start [s] so that vehicles armed together leave together.

    Each vehicle climbs from the ground (:meth:`World.ground_height`) to its
    start ``starts[i]`` [m] at ``options.climb_rate`` (default
    :data:`DEFAULT_CLIMB` of the airframe); the ones with less to climb wait for
    the one with most.
    """
    climb = options.climb_rate or DEFAULT_CLIMB[options.vehicle]
    starts = np.asarray(starts, dtype=float)
    ground = np.asarray([world.ground_height(x, y) for x, y in starts[:, :2]], dtype=float)
    climb_s = (starts[:, 2] - ground) / climb
    return float(climb_s.max()) - climb_s


def _flight(wps: Waypoints, opt: ExportOptions, end: str, sp: _Speeds, start_hold: float
            ) -> tuple[dict[str, Any], str | None]:
    """Flight time / endurance figures (and the endurance warning)."""
    from ..vehicles.endurance import check_endurance, flight_time
    from .energy import mission_energy

    climb = opt.climb_rate or DEFAULT_CLIMB[opt.vehicle]
    descent = opt.descent_rate or DEFAULT_DESCENT[opt.vehicle]
    start_xy, end_xy = wps.points_m[0, :2], wps.points_m[-1, :2]
    ft = flight_time(wps.points_m, sp.commanded, climb_rate=climb, descent_rate=descent,
                     takeoff_climb=float(wps.agl[0]),
                     final_descent=0.0 if end == "loiter" else float(wps.agl[-1]),
                     return_distance=float(np.hypot(*(end_xy - start_xy))) if end == "rtl"
                     else 0.0, return_speed=opt.forward_speed, holds=sp.holds)
    rep = check_endurance(ft, endurance_s=opt.endurance_s, reserve=opt.reserve)
    energy = mission_energy(wps.points_m, wps.agl, vehicle=opt.vehicle, power=opt.power,
                            battery_wh=opt.battery_wh, reserve=opt.reserve, speeds=sp.commanded,
                            holds=sp.holds, forward_speed=opt.forward_speed, climb_rate=climb,
                            descent_rate=descent, end=end, wind=opt.wind)
    info: dict[str, Any] = {"energy": energy, "flight": {
        **rep.summary(), "climb_rate_mps": climb, "descent_rate_mps": descent,
        "forward_speed_mps": opt.forward_speed,
        "note": {"loiter": "loiter end: the time until the loiter starts",
                 "rtl": "rtl: the straight line home at the forward speed, then the descent"
                 }.get(end, "")}}
    if sp.timing is not None:  # the route from leaving the start (after any start hold)
        route_t = float(ft.leg_time.sum() + sp.holds[0] - float(start_hold))
        info["timing"] = {**sp.timing, "mission_route_s": round(route_t, 2),
                          "error_s": round(route_t - sp.timing["planned_s"], 2)}
        late = route_t - sp.timing["planned_s"]
        if late > 0.05 * sp.timing["planned_s"]:
            info["timing"]["warning"] = (
                f"timing: the mission's route takes {route_t:.0f} s, {late:.0f} s more than the "
                f"planned {sp.timing['planned_s']:.0f} s: the trajectory climbs or descends "
                f"faster than {climb:g} / {descent:g} m/s (airframe climb_rate / descent_rate)")
    return info, rep.warning


def _snap(profile: Any, frame: str) -> bool | float:
    """How waypoints get the requested AGL: without a final profile, within a vertical
    cell (FM²'s grid bias); with one, the path's own heights — except in the terrain
    frame, where the autopilot follows the ground itself and cruise points within the
    profile's tolerance carry the request."""
    if profile is None:
        return True
    if frame == "terrain":
        return float(getattr(getattr(profile, "level", None), "tolerance", 2.0))
    return False


def _world_warnings(world: Any, opt: ExportOptions, frame: str, has_terrain: bool) -> list[str]:
    """Warnings about the world the mission is built on (no CRS: made-up relief; no terrain map)."""
    warnings: list[str] = []
    if not getattr(world, "crs", None):
        a = opt.anchor or DEFAULT_ANCHOR
        warnings.append("synthetic world without CRS: its relief is made up and placed at the "
                        f"anchor lon {a.lon:g}, lat {a.lat:g}, alt {a.alt:g} m (world.anchor / "
                        "--anchor): it is not the real terrain there, so the altitudes do not "
                        "clear the real ground — do not fly this mission as it is")
    if frame == "terrain" and not has_terrain:
        warnings.append("frame terrain on a world without a terrain map: altitudes are above "
                        "the world's flat ground")
    return warnings


def build_mission(
    path_m: Any,
    world: Any,
    options: ExportOptions | None = None,
    *,
    w: Any = None,
    agl: float | None = None,
    times: Any = None,
    via: Any = (),
    camera: CameraPlan | None = None,
    fences: Any = (),
    start_hold: float = 0.0,
    profile: Any = None,
) -> MissionExport:
    """Build and check the mission of a dense path (see the module docstring).

    Parameters
    ----------
    path_m : array_like, shape (N, 2|3)
        Dense planned path [m].
    world : World
    options : ExportOptions, optional
    w : array_like, shape (N,), optional
        W along the path (``Plan.w``), for speed changes.
    agl : float, optional
        Requested height above ground of a terrain-following plan [m].
    times : array_like, shape (N,), optional
        Time of each path point [s] (a formation UAV's trajectory): the speed
        items then make the mission follow this timing (mean speed per leg, hold
        times where the vehicle waits).
    via : sequence of int, optional
        Dense indices of via points (kept as waypoints, labelled).
    camera : CameraPlan, optional
        Coverage bands and trigger distance.
    fences : sequence of FencePolygon / FenceCircle, optional
        Geofences written into the ``.plan``.
    start_hold : float, optional
        With ``times``: wait this long [s] at the start after the takeoff (to
        leave the start at the same moment as other vehicles).
    profile : AltitudeProfile, optional
        The plan's final altitude profile (``Plan.profile``): the path's heights
        are then used as they are (terrain frame: the request where the profile
        is within its tolerance of it), and its ``required`` floor checks the legs.

    Raises
    ------
    MissionError
        The firmware would reject the mission (the validator's first problem),
        or the request cannot be met (e.g. fixed-wing speed changes without
        ``min_speed``).
    """
    opt = options or ExportOptions()
    p = np.asarray(path_m, dtype=float)
    has_terrain = getattr(world, "terrain", None) is not None
    frame = resolve_frame(opt.frame, opt.firmware, terrain_following=agl is not None,
                          has_terrain=has_terrain)
    warnings = _world_warnings(world, opt, frame, has_terrain)
    keep, via_idx = _events(p, via, camera, times)
    required = getattr(profile, "required", None)
    if required is not None and np.shape(required) != (len(p),):
        required = None  # a profile of another sampling than the path: no floor to compare
    wps = mission_waypoints(p, world, frame=frame, agl=agl, tolerance=opt.tolerance,
                            anchor=opt.anchor, flight_alt=opt.flight_alt,
                            max_points=opt.max_points, keep=sorted(keep),
                            snap=_snap(profile, frame), required=required)
    geo = _Geo(world, opt.anchor, wps)
    sp = _speeds(opt, wps, w, times, start_hold)
    end, end_items, landing, end_warnings = _end(geo, wps, opt)
    items = [_takeoff(geo, wps, opt), *_route(wps, keep, sp, opt), *end_items]
    warnings += end_warnings
    fence_list = as_fences(fences)
    check_mission(items, opt.firmware, vehicle=opt.vehicle, home_alt=wps.home[2],
                  max_land_slope_deg=opt.max_land_slope_deg, fences=fence_list)
    info, endurance_warning = _flight(wps, opt, end, sp, start_hold)
    if endurance_warning:
        warnings.append(endurance_warning)
    if info["energy"]["warning"]:
        warnings.append(info["energy"]["warning"])
    if "warning" in info.get("timing", {}):
        warnings.append(info["timing"]["warning"])
    info["speed_changes"] = {"items": len(sp.changes),
                             "speeds_mps": sorted({round(v, 3) for _, v in sp.changes}),
                             "step_mps": opt.speed_step,
                             "enabled": bool(opt.speed_changes or times is not None)}
    if camera is not None:
        info["camera"] = {**camera.info, "trigger_distance_m": round(camera.trigger_distance, 3),
                          "bands": len(camera.bands),
                          "trigger_items": sum(1 for it in items
                                               if it.command == CMD_DO_SET_CAM_TRIGG_DIST)}
    if landing:
        info["landing"] = landing
    if wps.legs is not None:
        info["legs"] = wps.legs
    if via_idx:
        info["via_waypoints"] = [int(np.searchsorted(wps.indices, i)) for i in via_idx]
    return MissionExport(items=items, waypoints=wps, options=opt, frame=frame, end=end,
                         path_m=p, world=world, warnings=warnings, info=info,
                         fences=fence_list)
