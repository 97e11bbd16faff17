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
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from ..errors import InputError, MissionError
from ..geometry import runs
from ..missions.coverage.triggers import CameraPlan
from .geofence import as_fences, fence_statement, statement_warning
from ..world.geo import DEFAULT_ANCHOR, Anchor, amsl_known, to_lonlat
from .items import (
    CMD_DO_CHANGE_SPEED,
    CMD_DO_LAND_START,
    CMD_DO_SET_CAM_TRIGG_DIST,
    CMD_NAV_LAND,
    CMD_NAV_LOITER_UNLIM,
    CMD_NAV_RETURN_TO_LAUNCH,
    CMD_NAV_TAKEOFF,
    CMD_NAV_VTOL_LAND,
    CMD_NAV_VTOL_TAKEOFF,
    CMD_NAV_WAYPOINT,
    FRAME_RELATIVE,
    FRAME_TERRAIN,
    MissionItem,
)
from .climbout import ClimbOut, plan_climb_out
from .firmware import FIRMWARES, PROFILES, VEHICLES
from .returns import rtl_end_notes
from .firmware.navigation import AirframeNav, FixedWingNav
from .landing import landing_pattern, loiter_radius
from .placing import ItemPlacer, unit_xy
from .speeds import DEFAULT_MIN_SPEED, Speeds, plan_speeds, speed_commands  # noqa: F401 (re-exported)
from .validate import check_mission
from .waypoints import FRAMES, Waypoints, mission_waypoints, resolve_frame

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
        Lowest commanded speed [m/s]: multirotors default to 1 m/s, fixed-wing and
        VTOL speed changes need it (a margin above the stall speed); a fixed-wing's
        ``AIRSPEED_MIN`` (ArduPlane ignores a ``DO_CHANGE_SPEED`` below it).
    max_speed : float or None
        A fixed-wing's highest airspeed [m/s] (``AIRSPEED_MAX``; None: the firmware's
        default, raised to the cruise speed).
    max_bank : float or None
        A fixed-wing's bank limit [deg] (``ROLL_LIMIT_DEG``; None: the firmware's
        default): sets the turn radius the waypoints and loiters are fitted to.
    terrain : bool or None
        Write ArduPilot's terrain files (``terrain/*.DAT``) beside the mission;
        None: with every terrain-frame mission (``outputs.terrain`` / ``--terrain``).
    terrain_spacing : int or None
        Their grid spacing [m] (``TERRAIN_SPACING``; None: the planner's DEM
        resolution within [30, 100] m, :func:`fm2uav.autopilot.terrain_grid.default_spacing`).
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
        Airframe endurance [s]; None: the airframe type's default
        (:func:`fm2uav.vehicles.airframes.default_endurance`), and the summary says so.
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
    max_speed: float | None = None
    max_bank: float | None = None
    terrain: bool | None = None
    terrain_spacing: int | None = None
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
        for name in ("min_speed", "max_speed", "max_bank", "climb_rate", "descent_rate",
                     "endurance_s", "battery_wh"):
            v = getattr(self, name)
            if v is not None and not (isinstance(v, (int, float)) and math.isfinite(v) and v > 0):
                raise InputError(f"export option {name} must be a number > 0, got {v!r}")
        if self.speed_step <= 0:
            raise InputError(f"speed_step must be > 0 m/s, got {self.speed_step!r}")
        if self.min_speed is not None and self.min_speed > self.forward_speed:
            key, flag = (("hover_speed", "--hover-speed") if self.vehicle == "multirotor"
                         else ("cruise_speed", "--cruise-speed"))
            raise InputError(
                f"airframe.min_speed = {self.min_speed:g} m/s (CLI --min-speed) is above "
                f"airframe.{key} = {self.forward_speed:g} m/s ({flag}), the speed this "
                f"{self.vehicle.replace('_', '-')} flies the mission at: no commanded speed "
                f"may be below the one or above the other; allowed: min_speed <= {key}")
        if self.terrain_spacing is not None and not (
                float(self.terrain_spacing) == int(self.terrain_spacing)
                and 5 <= self.terrain_spacing <= 1000):
            raise InputError(f"terrain_spacing must be a whole number of metres in [5, 1000], "
                             f"got {self.terrain_spacing!r} (outputs.terrain_spacing / "
                             "--terrain-spacing)")
        if self.max_bank is not None and not 5.0 <= self.max_bank <= 85.0:
            raise InputError(f"max_bank must be in [5, 85] degrees, got {self.max_bank!r} "
                             "(airframe.max_bank)")
        lo, hi = self.min_speed, self.max_speed
        if lo is not None and hi is not None and lo > hi:
            raise InputError(f"min_speed {lo:g} m/s is above max_speed {hi:g} m/s "
                             "(airframe.min_speed / max_speed)")
        if self.vehicle != "multirotor" and hi is not None and self.cruise_speed > hi:
            raise InputError(f"cruise_speed {self.cruise_speed:g} m/s is above max_speed "
                             f"{hi:g} m/s (airframe.cruise_speed / max_speed)")
        if not 0 < self.land_slope_deg <= self.max_land_slope_deg:
            raise InputError(f"land_slope_deg must be in (0, {self.max_land_slope_deg:g}] "
                             f"(FW_LND_ANG), got {self.land_slope_deg!r}")

    @property
    def forward_speed(self) -> float:
        """The airframe's mission speed [m/s]: hover speed (multirotor) or cruise speed."""
        return self.hover_speed if self.vehicle == "multirotor" else self.cruise_speed

    def airframe_nav(self) -> AirframeNav:
        """The airframe's numbers a fixed-wing firmware's defaults are overlaid with."""
        return AirframeNav(cruise=self.cruise_speed, minimum=self.min_speed,
                           maximum=self.max_speed, bank_deg=self.max_bank,
                           climb_rate=self.climb_rate, sink_rate=self.descent_rate)


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
    returns : ReturnsReport or None
        The safe returns (:mod:`fm2uav.autopilot.safe_return`): ways back, point of no
        return, rally points, firmware return settings; None when not computed.
    waypoint_times : ndarray, shape (len(waypoints),), optional
        Time from the launch at which each waypoint is reached [s], on the clock of the
        flight time in ``info["flight"]`` (a fixed-wing's climb-out, legs at airspeed;
        waypoints a climb-out replaces: along its time by distance). The safe returns
        time the route on it (:func:`fm2uav.autopilot.returns.route_samples`).
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
    returns: Any = None
    waypoint_times: np.ndarray | None = None

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
                     "alt_amsl_m": round(w.home[2], 3) if w.amsl else None,
                     "source": w.home_source},
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


def _takeoff(geo: ItemPlacer, wps: Waypoints, opt: ExportOptions, nav: FixedWingNav | None,
             first_forced: int) -> ClimbOut:
    """The items up to the route: a takeoff to the start's altitude at the start (frame 3
    instead of 10, ArduPilot issue #20142), a fixed-wing's climb-out
    (:func:`fm2uav.autopilot.climbout.plan_climb_out`)."""
    frame = FRAME_RELATIVE if wps.frame == FRAME_TERRAIN else wps.frame
    start_xy, start_z = wps.points_m[0, :2], float(wps.points_m[0, 2])
    if wps.agl[0] < 0.5:
        raise MissionError(f"the start is {wps.agl[0]:.2f} m above the ground: a takeoff needs "
                           "a start above it (give start with agl, e.g. {x, y, agl: 30})")
    if opt.vehicle == "fixed_wing" and nav is not None:
        return plan_climb_out(geo, wps, nav, first_forced=first_forced, tolerance=opt.tolerance)
    cmd = CMD_NAV_VTOL_TAKEOFF if opt.vehicle == "vtol" else CMD_NAV_TAKEOFF
    climb = opt.climb_rate or DEFAULT_CLIMB[opt.vehicle]
    item = geo.item(cmd, frame, start_xy, start_z, label="takeoff")
    return ClimbOut([item], 1, {"mode": "vertical", "takeoff_alt_m": round(float(wps.agl[0]), 1)},
                    float(wps.agl[0]) / climb)


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


def _route(wps: Waypoints, keep: dict[int, list[_Event]], sp: Speeds, first: int,
           speed_type: int) -> list[MissionItem]:
    """The waypoints from ``first`` on (the climb-out replaced the ones before), with their
    hold times, acceptance radii and DO items; the speed of the first flown leg before them."""
    idx = wps.indices
    change_at = dict(sp.changes)
    acc = wps.acceptance if wps.acceptance is not None else np.zeros(len(wps))

    def waypoint(k: int, label: str) -> MissionItem:
        return MissionItem(CMD_NAV_WAYPOINT, wps.frame,
                           (float(sp.holds[k]), float(acc[k]), 0.0, math.nan, float(wps.lat[k]),
                            float(wps.lon[k]), float(wps.alt[k])),
                           agl=float(wps.agl[k]), alt_amsl=float(wps.alt_amsl[k]), label=label)

    items = [waypoint(0, "start (hold)")] if sp.holds[0] > 0 and first == 1 else []
    # the speed in force on the first leg flown, commanded before its waypoint
    initial = float(sp.commanded[first - 1]) if len(sp.commanded) else None
    events = [e for j in range(first) for e in keep.get(int(idx[j]), [])]
    items += _do_items(events, initial, speed_type)
    last = len(wps) - 1
    for k in range(first, last + 1):
        vias = [lab for kind, _, lab in keep.get(int(idx[k]), []) if kind == "via"]
        items.append(waypoint(k, ", ".join(vias) or f"waypoint {k}"))
        events = keep.get(int(idx[k]), [])
        if k == last:  # nothing starts at the last waypoint; a band may end there
            events = [e for e in events if e[0] == "camera_off"]
        items += _do_items(events, change_at.get(k) if k < last else None, speed_type)
    return items


def _end(geo: ItemPlacer, wps: Waypoints, opt: ExportOptions, nav: FixedWingNav | None = None
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
            heading = -unit_xy(wps.points_m, from_end=False)
            pattern, landing, warnings = landing_pattern(
                geo, start_xy, heading, f_route, radius=opt.loiter_radius,
                approach_agl=opt.land_approach_agl, slope_deg=opt.land_slope_deg, nav=nav,
                label="home landing")
            items += pattern
        elif must_land and opt.vehicle == "vtol":
            items.append(MissionItem.do(CMD_DO_LAND_START, label="home landing start"))
            items.append(geo.item(CMD_NAV_VTOL_LAND, FRAME_RELATIVE if f_route == FRAME_TERRAIN
                                  else f_route, start_xy, float(geo.ground(start_xy)[0]),
                                  label="home landing"))
        notes, more = rtl_end_notes(geo.world, start_xy, end_xy, opt.firmware, opt.tolerance,
                                    items)
        landing.update(notes)
        warnings += more
    elif end == "land" and opt.vehicle == "fixed_wing":
        heading = unit_xy(wps.points_m, from_end=True)
        items, landing, warnings = landing_pattern(
            geo, end_xy, heading, f_route, radius=opt.loiter_radius,
            approach_agl=opt.land_approach_agl, slope_deg=opt.land_slope_deg, nav=nav,
            label="landing")
    elif end == "land":
        cmd = CMD_NAV_VTOL_LAND if opt.vehicle == "vtol" else CMD_NAV_LAND
        items.append(geo.item(cmd, f_route, end_xy, float(geo.ground(end_xy)[0]),
                              label="landing"))
    else:  # loiter
        radius = 0.0 if opt.vehicle == "multirotor" else loiter_radius(opt.loiter_radius, nav)
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


def _flight(wps: Waypoints, opt: ExportOptions, end: str, sp: Speeds, start_hold: float,
            climb_out: ClimbOut, items: list[MissionItem], nav: FixedWingNav | None,
            world: Any = None) -> tuple[dict[str, Any], str | None, np.ndarray]:
    """Flight time / endurance figures (and the endurance warning, with the point where the
    reserve is reached), and the time each waypoint is reached on that clock
    (:attr:`MissionExport.waypoint_times`).

    Multirotors and VTOL: the take-off climb at the vertical speed, the legs at the
    commanded speeds (a multirotor waits for its altitude: climbs and descents at the
    vertical speed limits), the final descent
    (:func:`fm2uav.vehicles.endurance.flight_time`). Fixed-wing: the climb-out's own
    time (take-off climb, loiter climb; :mod:`fm2uav.autopilot.climbout`), then every
    leg at its commanded airspeed (a plane does not wait for its altitude), and the
    landing pattern (to the loiter, the descent in it at the sink limit or half a
    circle to line up, the approach run) or the straight line home of an RTL
    (ArduPlane then circles home at its RTL altitude). Without ``opt.endurance_s`` the
    airframe type's default endurance is checked
    (:func:`fm2uav.vehicles.airframes.default_endurance`).
    """
    from ..vehicles.airframes import default_endurance
    from ..vehicles.endurance import FlightTime, check_endurance, flight_time
    from .energy import ClimbOutClock, mission_energy

    climb = opt.climb_rate or DEFAULT_CLIMB[opt.vehicle]
    descent = opt.descent_rate or DEFAULT_DESCENT[opt.vehicle]
    first = climb_out.first
    p = wps.points_m
    start_xy, end_xy = p[0, :2], p[-1, :2]
    fixed = opt.vehicle == "fixed_wing"
    hover = opt.vehicle == "multirotor"
    # the final descent: at the last waypoint (land), or over home after the line back (rtl:
    # from the last waypoint's altitude to the launch's ground)
    final = (0.0 if end == "loiter" or (fixed and end in ("rtl", "land")) else
             float(max(p[-1, 2] - (p[0, 2] - wps.agl[0]), 0.0)) if end == "rtl" else
             float(wps.agl[-1]))
    holds = sp.holds[first - 1:].copy()
    ft = flight_time(p[first - 1:], sp.commanded[first - 1:], climb_rate=climb,
                     descent_rate=descent, takeoff_climb=0.0 if fixed else float(wps.agl[0]),
                     final_descent=final,
                     return_distance=float(np.hypot(*(end_xy - start_xy))) if end == "rtl"
                     else 0.0, return_speed=opt.forward_speed, holds=holds, hover=hover)
    leg_time = ft.leg_time.copy()
    takeoff_s = ft.takeoff_s
    if fixed:
        # the climb-out's time runs to where it leaves for waypoint `first`
        leg_time[0] = (_entry_length(climb_out, p, first)
                       / max(float(sp.commanded[first - 1]), 1e-6) + float(holds[1]))
        takeoff_s = climb_out.time_s
    landing_s = ft.landing_s + (_pattern_time(items, nav, opt) if fixed and end == "land"
                                else 0.0)
    ft = FlightTime(leg_time=leg_time, leg_length=ft.leg_length, takeoff_s=takeoff_s,
                    takeoff_m=ft.takeoff_m if not fixed else float(wps.agl[0]),
                    landing_s=landing_s, landing_m=ft.landing_m)
    endurance_s, source = opt.endurance_s, "given (airframe.endurance / --endurance)"
    if endurance_s is None:  # the check runs by default (issue 25)
        endurance_s, source = default_endurance(opt.vehicle)
    rep = check_endurance(ft, endurance_s=endurance_s, reserve=opt.reserve)
    # the legs timed start where the climb-out leaves (waypoint ``first - 1``): the report
    # counts waypoints of the whole list, as the summary and its warning name them
    rep = replace(rep, reach_waypoint=int(rep.reach_waypoint) + first - 1,
                              waypoints=int(rep.waypoints) + first - 1)
    warning = rep.warning
    where: dict[str, Any] = {}
    if warning is not None:
        k = rep.reach_waypoint
        q = p[k] if k + 1 >= len(p) else p[k] + rep.reach_fraction * (p[k + 1] - p[k])
        where = {"reserve_reached_at_m": [round(float(v), 2) for v in q], "reach_waypoint": k}
        lon, lat, _ = to_lonlat(world, q, anchor=opt.anchor)
        where["reserve_reached_at_lonlat"] = [round(float(lon), 7), round(float(lat), 7)]
        warning += f", at lon {lon:.5f}, lat {lat:.5f}"
        if opt.endurance_s is None:
            warning += (f" (endurance: {source.split('; give')[0]}; give your vehicle's with "
                        "airframe.endurance / --endurance)")
    # the energy flies the flight time's phases (a fixed-wing's climb-out and pattern too)
    energy = mission_energy(wps.points_m, wps.agl, vehicle=opt.vehicle, power=opt.power,
                            battery_wh=opt.battery_wh, reserve=opt.reserve, speeds=sp.commanded,
                            holds=sp.holds, forward_speed=opt.forward_speed, climb_rate=climb,
                            descent_rate=descent, end=end, wind=opt.wind,
                            climb_out=ClimbOutClock(first, float(takeoff_s),
                                                    _entry_length(climb_out, p, first),
                                                    float(landing_s)) if fixed else None)
    info: dict[str, Any] = {"energy": energy, "flight": {
        **rep.summary(), "warning": warning, "endurance_source": source, **where,
        "climb_rate_mps": climb, "descent_rate_mps": descent,
        "forward_speed_mps": opt.forward_speed,
        "takeoff_s": round(float(takeoff_s), 1), "route_s": round(float(leg_time.sum()), 1),
        "end_s": round(float(landing_s), 1),
        "note": {"loiter": "loiter end: the time until the loiter starts",
                 "rtl": "rtl: the straight line home at the forward speed"
                        + (", then the descent" if not fixed else
                           " (the aircraft then circles home at its RTL altitude)"),
                 }.get(end, "")}}
    if sp.timing is not None:  # the route from leaving the start (after any start hold)
        route_t = float(leg_time.sum() + sp.holds[0] - float(start_hold))
        info["timing"] = {**sp.timing, "mission_route_s": round(route_t, 2),
                          "error_s": round(route_t - sp.timing["planned_s"], 2)}
        late = route_t - sp.timing["planned_s"]
        if late > 0.05 * sp.timing["planned_s"]:
            info["timing"]["warning"] = (
                f"timing: the mission's route takes {route_t:.0f} s, {late:.0f} s more than the "
                f"planned {sp.timing['planned_s']:.0f} s: the trajectory climbs or descends "
                f"faster than {climb:g} / {descent:g} m/s (airframe climb_rate / descent_rate)")
    return info, warning, _waypoint_times(ft, p, first)


def _waypoint_times(ft: Any, p: np.ndarray, first: int) -> np.ndarray:
    """Time [s] each waypoint of ``p`` is reached: ``ft`` times the legs from waypoint
    ``first - 1`` (where the climb-out leaves); the waypoints before it, which the
    climb-out replaces, along the take-off time by horizontal distance."""
    t = np.empty(len(p))
    t[first - 1:] = ft.elapsed()
    if first > 1:
        d = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(p[:first, :2], axis=0).T))])
        t[:first - 1] = float(ft.takeoff_s) * d[:first - 1] / max(float(d[-1]), 1e-9)
    return t


def _entry_length(climb_out: ClimbOut, p: np.ndarray, first: int) -> float:
    """Horizontal length from where the climb-out ends to the first flown waypoint [m]."""
    info = climb_out.info
    d = float(np.hypot(*(p[first, :2] - p[0, :2])))
    if info.get("mode") == "loiter":
        r = float(info["loiter_radius_m"])
        return math.sqrt(max(d * d - r * r, 0.0))
    if info.get("mode") == "straight":
        return 0.0  # the climb-out's time runs to the waypoint
    return float(np.hypot(*(p[first, :2] - p[first - 1, :2])))


def _pattern_time(items: list[MissionItem], nav: FixedWingNav | None,
                  opt: ExportOptions) -> float:
    """Time of a fixed-wing landing pattern after the route [s]: to the loiter, the
    descent in it at the sink limit (at least half a circle to line up), the approach run."""
    from .firmware.flight_rules import local_xy

    k = next((i for i, it in enumerate(items) if it.command == CMD_DO_LAND_START), None)
    if k is None or nav is None:
        return 0.0
    seq = [it for it in items[k:] if it.has_position]
    before = next((it for it in reversed(items[:k]) if it.has_position), None)
    if len(seq) < 2 or before is None:
        return 0.0
    loiter, land = seq[0], seq[-1]
    xy = local_xy([before, loiter, land], loiter.lat, loiter.lon)
    v = opt.forward_speed
    r = abs(loiter.params[1]) or nav.loiter_radius
    d_in = max(float(np.hypot(*(xy[1] - xy[0]))) - r, 0.0)
    drop = max((before.alt_amsl or 0.0) - (loiter.alt_amsl or 0.0), 0.0)
    run = math.sqrt(max(float(np.hypot(*(xy[2] - xy[1]))) ** 2 - r * r, 0.0))
    return d_in / v + max(drop / nav.sink_rate, math.pi * r / v) + run / v


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


def _flat(world: Any) -> bool:
    """True when the world's ground is one flat level (buildings without a DEM)."""
    t = getattr(world, "terrain", None)
    return t is None or float(np.ptp(t)) == 0.0


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
    if getattr(world, "crs", None) and not amsl_known(world):
        warnings.append(
            "buildings without a DEM or a ground elevation: the ground's altitude above sea "
            f"level is unknown, so the mission is written in frame {frame} "
            f"({'MAVLink 3, altitudes above home' if frame == 'relative' else 'MAVLink 10'}) "
            "and assumes the ground is flat at the take-off's height everywhere; give "
            "world.ground_elevation (--ground-elevation) or world.dem (--dem) for altitudes "
            "above sea level")
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
                          has_terrain=has_terrain, amsl=amsl_known(world))
    warnings = _world_warnings(world, opt, frame, has_terrain)
    keep, via_idx = _events(p, via, camera, times)
    required = getattr(profile, "required", None)
    if required is not None and np.shape(required) != (len(p),):
        required = None  # a profile of another sampling than the path: no floor to compare
    fw = PROFILES[opt.firmware]
    nav = (fw.fixed_wing_nav.for_airframe(opt.airframe_nav())
           if opt.vehicle != "multirotor" and fw.fixed_wing_nav is not None else None)
    wps = mission_waypoints(p, world, frame=frame, agl=agl, tolerance=opt.tolerance,
                            anchor=opt.anchor, flight_alt=opt.flight_alt,
                            max_points=opt.max_points, keep=sorted(keep),
                            snap=_snap(profile, frame), required=required, turns=nav)
    geo = ItemPlacer(world, opt.anchor, wps)
    forced = [k for k in range(1, len(wps)) if int(wps.indices[k]) in keep]
    climb_out = _takeoff(geo, wps, opt, nav, forced[0] if forced else len(wps) - 1)
    sp = plan_speeds(indices=wps.indices, points=wps.points_m, forward=opt.forward_speed,
                     floor=opt.min_speed, fixed_wing=opt.vehicle != "multirotor",
                     changes=opt.speed_changes, step=opt.speed_step,
                     hysteresis=opt.speed_hysteresis, w=w, times=times, start_hold=start_hold)
    speed_type = fw.change_speed[opt.vehicle].speed_type
    end, end_items, landing, end_warnings = _end(geo, wps, opt, nav)
    items = [*climb_out.items, *_route(wps, keep, sp, climb_out.first, speed_type), *end_items]
    warnings += climb_out.warnings + end_warnings
    fence_list = as_fences(fences)
    flight_warnings = check_mission(
        items, opt.firmware, vehicle=opt.vehicle, home_alt=wps.home[2],
        home_latlon=wps.home[:2], max_land_slope_deg=opt.max_land_slope_deg,
        fences=fence_list, airframe=opt.airframe_nav())
    warnings += [str(w_) for w_ in flight_warnings]
    info, endurance_warning, waypoint_times = _flight(wps, opt, end, sp, start_hold, climb_out,
                                                     items, nav, world)
    if endurance_warning:
        warnings.append(endurance_warning)
    if info["energy"]["warning"]:
        warnings.append(info["energy"]["warning"])
    if "warning" in info.get("timing", {}):
        warnings.append(info["timing"]["warning"])
    info["speed_changes"] = sp.summary(opt.speed_step, speed_type)
    if opt.vehicle != "multirotor":
        info["climb_out"] = climb_out.info
    if nav is not None:
        info["navigation"] = {**nav.summary(), **({"turns": wps.turns} if wps.turns else {})}
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
    statement = fence_statement(
        getattr(world, "zones", ()), fence_list, firmware=opt.firmware,
        home_amsl=wps.home[2] if wps.amsl else None,
        flat_ground=getattr(world, "ground", None) is None and _flat(world))
    if statement is not None:
        info["geofence"] = statement
        line = statement_warning(statement)
        if line:
            warnings.append(line)
    return MissionExport(items=items, waypoints=wps, options=opt, frame=frame, end=end,
                         path_m=p, world=world, warnings=warnings, info=info,
                         fences=fence_list, waypoint_times=waypoint_times)
