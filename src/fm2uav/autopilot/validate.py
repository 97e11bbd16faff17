"""Mission checkers, one per autopilot firmware: what PX4 or ArduPilot would reject.

:func:`validate_mission` returns the problems of a list of
:class:`~fm2uav.autopilot.items.MissionItem` for a firmware and airframe;
:func:`check_mission` raises :class:`~fm2uav.errors.MissionError` on the first
one. Every export goes through :func:`check_mission` before a file is written.

What is checked, and where each rule comes from:

* **Both firmwares** (MAVLink ``common.xml``, QGC plan format): at least one
  item; the first navigation item is ``NAV_TAKEOFF`` (22) or
  ``NAV_VTOL_TAKEOFF`` (84) with its altitude above home; the last item is
  ``NAV_RETURN_TO_LAUNCH`` (20), ``NAV_LAND`` (21), ``NAV_VTOL_LAND`` (85) or
  ``NAV_LOITER_UNLIM`` (17); latitude/longitude/altitude of every position item
  finite and in range (and not the 0, 0 of an unset coordinate); params 1-3
  finite (param 4 may be NaN only where it is a yaw); ``DO_CHANGE_SPEED`` with a
  speed > 0 (or -1) and speed type 0/1; ``DO_SET_CAM_TRIGG_DIST`` distance >= 0
  and the camera stopped (distance 0) before the end.
* **PX4** (``MavlinkMissionManager::parse_mavlink_mission_item`` in
  ``src/modules/mavlink/mavlink_mission.cpp`` and ``FeasibilityChecker`` in
  ``src/modules/navigator/MissionFeasibility/``): position items in
  ``MAV_FRAME_GLOBAL`` (0) or ``MAV_FRAME_GLOBAL_RELATIVE_ALT`` (3) (or their
  ``_INT`` forms 5/6) only — frame 10 is ``MAV_MISSION_UNSUPPORTED_FRAME``;
  commands without a position (RTL, DO_*) in ``MAV_FRAME_MISSION`` (2);
  only the commands the feasibility checker accepts (``NAV_LOITER_TURNS`` is
  not one); VTOL items only on VTOL airframes; fixed-wing and VTOL missions
  must contain a landing (``MIS_TKO_LAND_REQ`` defaults to 2 for both); at
  most one ``DO_LAND_START``, never before an RTL item, and before the landing
  approach; a fixed-wing ``NAV_LAND`` approached from a ``NAV_WAYPOINT`` or
  ``NAV_LOITER_TO_ALT`` above it, outside that loiter's radius, with a glide
  slope no steeper than ``FW_LND_ANG`` (default 5 deg).
* **ArduPilot** (ArduPilot wiki "Mission Commands": commands handled by
  ``ArduCopter/mode_auto.cpp`` and ``ArduPlane/commands_logic.cpp``): the
  commands of the vehicle (Copter has no ``NAV_LOITER_TO_ALT``,
  ``DO_LAND_START`` or VTOL items; VTOL items need a QuadPlane); position items
  in frame 0, 3 or 10 (and 5/6/11); no ``NAV_TAKEOFF`` in the terrain frame
  (ArduPilot issue #20142: the altitude target jumps when the terrain under the
  vehicle differs from the takeoff point's).
* **generic** (``MAV_AUTOPILOT_GENERIC``): both sets of rules, so that either
  firmware accepts the mission.
* **Geofences** (``fences``, both firmwares; PX4's feasibility checker rejects a
  mission item that conflicts with a plan geofence): no position item inside an
  exclusion polygon or circle, none outside an inclusion one.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

from ..errors import InputError, MissionError
from .items import (
    CMD_DO_CHANGE_SPEED,
    CMD_DO_LAND_START,
    CMD_DO_SET_CAM_TRIGG_DIST,
    CMD_NAV_LAND,
    CMD_NAV_LOITER_TO_ALT,
    CMD_NAV_RETURN_TO_LAUNCH,
    CMD_NAV_VTOL_LAND,
    CMD_NAV_WAYPOINT,
    END_COMMANDS,
    FRAME_GLOBAL,
    FRAME_MISSION,
    FRAME_NAMES,
    FRAME_RELATIVE,
    FRAME_TERRAIN,
    TAKEOFF_COMMANDS,
    MissionItem,
    command_name,
)

__all__ = [
    "FIRMWARES",
    "VEHICLES",
    "Problem",
    "validate_mission",
    "check_mission",
    "supported_commands",
]

#: Firmware names the checkers know.
FIRMWARES = ("px4", "ardupilot", "generic")
#: Airframe kinds the checkers know.
VEHICLES = ("multirotor", "fixed_wing", "vtol")

#: Commands whose param 4 is a yaw angle, where NaN means "keep the heading".
_YAW_PARAM4 = frozenset({16, 17, 21, 22, 84, 85})

#: PX4 FeasibilityChecker::checkMissionItemValidity (the commands fm2uav may meet).
_PX4_COMMANDS = frozenset({
    16, 17, 19, 20, 21, 22, 31, 84, 85, 93, 177, 178, 179, 189, 201, 203, 205, 206,
    214, 530, 2000, 2001, 2500, 2501, 3000,
})
_PX4_POSITION_FRAMES = frozenset({0, 3, 5, 6})
#: ArduCopter mode_auto.cpp and ArduPlane commands_logic.cpp (ArduPilot wiki lists).
_ARDU_COPTER = frozenset({
    16, 17, 18, 19, 20, 21, 22, 93, 112, 114, 115, 177, 178, 179, 183, 201, 203, 205, 206,
})
_ARDU_PLANE = frozenset({
    16, 17, 18, 19, 20, 21, 22, 31, 84, 85, 93, 112, 114, 177, 178, 179, 183, 189, 201,
    203, 205, 206, 3000,
})
_ARDU_POSITION_FRAMES = frozenset({0, 3, 5, 6, 10, 11})
_VTOL_ONLY = frozenset({84, 85, 3000})

#: PX4's default maximum fixed-wing landing slope, FW_LND_ANG [deg].
PX4_FW_LND_ANG = 5.0


@dataclass(frozen=True)
class Problem:
    """One reason a firmware would reject a mission.

    Attributes
    ----------
    index : int or None
        0-based index of the offending item in the list (None: the whole mission).
    code : str
        Short identifier, e.g. ``"px4-terrain-frame"``.
    message : str
        What is wrong and how to fix it.
    """

    index: int | None
    code: str
    message: str

    def __str__(self) -> str:
        return self.message if self.index is None else f"item {self.index}: {self.message}"


def supported_commands(firmware: str, vehicle: str) -> frozenset[int]:
    """``MAV_CMD`` ids the firmware flies in a mission on that airframe."""
    _check_names(firmware, vehicle)
    if firmware == "px4":
        cmds = _PX4_COMMANDS
        return cmds if vehicle == "vtol" else cmds - _VTOL_ONLY
    if firmware == "ardupilot":
        if vehicle == "multirotor":
            return _ARDU_COPTER
        return _ARDU_PLANE if vehicle == "vtol" else _ARDU_PLANE - _VTOL_ONLY
    return supported_commands("px4", vehicle) & supported_commands("ardupilot", vehicle)


def _check_names(firmware: str, vehicle: str) -> None:
    if firmware not in FIRMWARES:
        raise InputError(f"firmware must be one of {', '.join(FIRMWARES)}, got {firmware!r} "
                         "(mission file airframe.firmware, CLI --firmware)")
    if vehicle not in VEHICLES:
        raise InputError(f"vehicle must be one of {', '.join(VEHICLES)}, got {vehicle!r} "
                         "(mission file airframe.type, CLI --vehicle)")


def _distance_m(lat1: float, lon1: float, lat2: float, lon2: float) -> float:
    """Great-circle distance [m] (haversine, mean Earth radius)."""
    r = 6371008.8
    p1, p2 = math.radians(lat1), math.radians(lat2)
    dp, dl = p2 - p1, math.radians(lon2 - lon1)
    a = math.sin(dp / 2) ** 2 + math.cos(p1) * math.cos(p2) * math.sin(dl / 2) ** 2
    return 2 * r * math.asin(min(1.0, math.sqrt(a)))


def _amsl(item: MissionItem, home_alt: float | None) -> float | None:
    """AMSL altitude of a position item from what is uploaded (frame + param 7); the
    terrain frame needs the ground, known only from the item's ``alt_amsl`` record."""
    if item.frame in (FRAME_GLOBAL, 5):
        return item.alt
    if item.frame in (FRAME_RELATIVE, 6):
        return None if home_alt is None else item.alt + home_alt
    return item.alt_amsl


def _common(items: Sequence[MissionItem], home_alt: float | None) -> list[Problem]:
    out: list[Problem] = []
    if not items:
        return [Problem(None, "empty", "the mission has no items")]
    for i, it in enumerate(items):
        name = command_name(it.command)
        p = it.params
        for k in range(3):
            if not math.isfinite(p[k]):
                out.append(Problem(i, "param-nan", f"{name}: param{k + 1} is {p[k]}; "
                                   "only param4 (yaw) may be NaN"))
        if not math.isfinite(p[3]) and (it.command not in _YAW_PARAM4 or math.isinf(p[3])):
            out.append(Problem(i, "param-nan", f"{name}: param4 is {p[3]}; it is not a yaw "
                               "for this command, so it must be a number"))
        if it.has_position:
            lat, lon, alt = p[4], p[5], p[6]
            if not (math.isfinite(lat) and math.isfinite(lon)
                    and -90 <= lat <= 90 and -180 <= lon <= 180):
                out.append(Problem(i, "latlon", f"{name}: latitude/longitude ({lat}, {lon}) "
                                   "are not a valid position"))
            elif lat == 0.0 and lon == 0.0:
                out.append(Problem(i, "latlon-zero", f"{name}: latitude/longitude are 0, 0 "
                                   "(an unset coordinate)"))
            if not math.isfinite(alt):
                out.append(Problem(i, "alt", f"{name}: altitude is {alt}"))
        else:
            for k in (4, 5, 6):
                if not math.isfinite(p[k]):
                    out.append(Problem(i, "param-nan", f"{name}: param{k + 1} is {p[k]}"))
        if it.command == CMD_DO_CHANGE_SPEED:
            if p[0] not in (0.0, 1.0):
                out.append(Problem(i, "speed-type", f"{name}: speed type (param1) {p[0]:g} "
                                   "is not 0 (airspeed) or 1 (ground speed)"))
            if not (p[1] > 0 or p[1] == -1):
                out.append(Problem(i, "speed", f"{name}: speed (param2) {p[1]:g} m/s must be "
                                   "> 0 (or -1 for no change)"))
        if it.command == CMD_DO_SET_CAM_TRIGG_DIST and not p[0] >= 0:
            out.append(Problem(i, "trigger", f"{name}: trigger distance {p[0]:g} m must be >= 0"))
    nav = [i for i, it in enumerate(items) if it.has_position or it.command == 20]
    if not nav or items[nav[0]].command not in TAKEOFF_COMMANDS:
        first = items[nav[0]].name if nav else "none"
        out.append(Problem(None, "no-takeoff", "the first navigation item must be NAV_TAKEOFF "
                           f"(22) or NAV_VTOL_TAKEOFF (84), got {first}"))
    else:
        t = items[nav[0]]
        above = (t.alt if t.frame in (FRAME_RELATIVE, 6, FRAME_TERRAIN, 11)
                 else (None if home_alt is None else t.alt - home_alt))
        if above is not None and not above > 0:
            out.append(Problem(nav[0], "takeoff-alt", f"{t.name}: takeoff altitude is "
                               f"{above:.2f} m above home; it must be above home"))
    if items[-1].command not in END_COMMANDS:
        out.append(Problem(len(items) - 1, "no-end", "the mission must end with "
                           "NAV_RETURN_TO_LAUNCH (20), NAV_LAND (21), NAV_VTOL_LAND (85) or "
                           f"NAV_LOITER_UNLIM (17), not {items[-1].name}: it would end in the "
                           "air (outputs.end / --end)"))
    triggers = [it for it in items if it.command == CMD_DO_SET_CAM_TRIGG_DIST]
    if triggers and triggers[-1].params[0] != 0:
        out.append(Problem(None, "trigger-on", "the camera is still triggering at the end of "
                           "the mission: the last DO_SET_CAM_TRIGG_DIST must have distance 0"))
    return out


def _px4(items: Sequence[MissionItem], vehicle: str, home_alt: float | None,
         max_land_slope_deg: float) -> list[Problem]:
    out: list[Problem] = []
    allowed = supported_commands("px4", vehicle)
    for i, it in enumerate(items):
        if it.command not in allowed:
            why = (" (VTOL items need a VTOL airframe)" if it.command in _VTOL_ONLY else "")
            out.append(Problem(i, "px4-command", f"{it.name} is not a mission command PX4 "
                               f"accepts on a {vehicle}{why}"))
        if it.has_position and it.frame not in _PX4_POSITION_FRAMES:
            hint = ("PX4 does not fly terrain-frame mission items (mavlink_mission.cpp answers "
                    "MAV_MISSION_UNSUPPORTED_FRAME); use outputs.frame: amsl or auto "
                    "(--frame amsl), which writes AMSL altitudes from the DEM"
                    if it.frame in (FRAME_TERRAIN, 11) else "PX4 takes frames 0 and 3 only")
            out.append(Problem(i, "px4-terrain-frame" if it.frame in (10, 11) else "px4-frame",
                               f"{it.name} uses {FRAME_NAMES.get(it.frame, it.frame)}; {hint}"))
        if not it.has_position and it.frame != FRAME_MISSION:
            out.append(Problem(i, "px4-frame", f"{it.name} must use MAV_FRAME_MISSION (2) on PX4 "
                               f"(got frame {it.frame})"))
    land_start = [i for i, it in enumerate(items) if it.command == CMD_DO_LAND_START]
    lands = [i for i, it in enumerate(items) if it.command in (CMD_NAV_LAND, CMD_NAV_VTOL_LAND)]
    if len(land_start) > 1:
        out.append(Problem(land_start[1], "px4-land-start", "more than one DO_LAND_START; "
                           "PX4 allows one"))
    rtls = [i for i, it in enumerate(items) if it.command == CMD_NAV_RETURN_TO_LAUNCH]
    if land_start and any(r > land_start[0] for r in rtls):
        out.append(Problem(land_start[0], "px4-land-before-rtl", "DO_LAND_START before an "
                           "RTL item is rejected by PX4"))
    if land_start and (not lands or land_start[0] > lands[-1] - 1):
        out.append(Problem(land_start[0], "px4-land-start", "DO_LAND_START must come before "
                           "the landing approach item and its NAV_LAND"))
    if lands and lands[0] == 0:
        out.append(Problem(0, "px4-starts-landing", "the mission starts with a landing"))
    if vehicle in ("fixed_wing", "vtol") and not lands:
        out.append(Problem(None, "px4-landing-required", f"PX4 {vehicle.replace('_', '-')} "
                           "missions need a landing (MIS_TKO_LAND_REQ defaults to 2): use "
                           "outputs.end: land or rtl (--end), which add one"))
    if vehicle == "fixed_wing":
        for i in lands:
            out += _px4_fw_landing(items, i, home_alt, max_land_slope_deg)
    return out


def _px4_fw_landing(items: Sequence[MissionItem], i: int, home_alt: float | None,
                    max_slope_deg: float) -> list[Problem]:
    land = items[i]
    prev = next((items[k] for k in range(i - 1, -1, -1) if items[k].has_position), None)
    if prev is None:
        return [Problem(i, "px4-fw-approach", "NAV_LAND has no approach item before it")]
    if prev.command not in (CMD_NAV_WAYPOINT, CMD_NAV_LOITER_TO_ALT):
        return [Problem(i, "px4-fw-approach", f"NAV_LAND is approached from {prev.name}; PX4 "
                        "takes only NAV_WAYPOINT or NAV_LOITER_TO_ALT")]
    a_land, a_prev = _amsl(land, home_alt), _amsl(prev, home_alt)
    if a_land is None or a_prev is None:
        return []
    rel = a_prev - a_land
    if not rel > 0:
        return [Problem(i, "px4-fw-approach", f"the approach item is {rel:.1f} m above the "
                        "landing point; it must be above it")]
    d = _distance_m(prev.lat, prev.lon, land.lat, land.lon)
    if prev.command == CMD_NAV_LOITER_TO_ALT:
        r = abs(prev.params[1])
        if d <= r:
            return [Problem(i, "px4-fw-approach", f"the landing point is {d:.0f} m from the "
                            f"loiter centre, inside its {r:.0f} m radius")]
        d = math.sqrt(d * d - r * r)
    slope = math.degrees(math.atan2(rel, d))
    if slope > max_slope_deg + 0.1:
        return [Problem(i, "px4-fw-glide-slope", f"the landing glide slope is {slope:.1f} deg, "
                        f"steeper than FW_LND_ANG = {max_slope_deg:g} deg")]
    return []


def _ardupilot(items: Sequence[MissionItem], vehicle: str) -> list[Problem]:
    out: list[Problem] = []
    allowed = supported_commands("ardupilot", vehicle)
    kind = {"multirotor": "Copter", "fixed_wing": "Plane", "vtol": "QuadPlane"}[vehicle]
    for i, it in enumerate(items):
        if it.command not in allowed:
            out.append(Problem(i, "ardupilot-command", f"{it.name} is not a mission command "
                               f"ArduPilot {kind} flies"))
        if it.has_position and it.frame not in _ARDU_POSITION_FRAMES:
            out.append(Problem(i, "ardupilot-frame", f"{it.name} uses frame {it.frame}; "
                               "ArduPilot missions take frames 0, 3 and 10"))
        if it.command in TAKEOFF_COMMANDS and it.frame in (FRAME_TERRAIN, 11):
            out.append(Problem(i, "ardupilot-terrain-takeoff", f"{it.name} in the terrain "
                               "frame: ArduPilot's altitude target jumps when the terrain "
                               "under the vehicle differs from the takeoff point's (ArduPilot "
                               "issue #20142); write the takeoff above home (frame 3)"))
    return out


def _fence_problems(items: Sequence[MissionItem], fences: Sequence[Any]) -> list[Problem]:
    from shapely.geometry import Point, Polygon

    from .geofence import FenceCircle, FencePolygon

    out: list[Problem] = []
    for f in fences:
        if not isinstance(f, (FencePolygon, FenceCircle)):
            continue
        poly = (Polygon([(lon, lat) for lat, lon in f.points]) if isinstance(f, FencePolygon)
                else None)
        what = f"{'inclusion' if f.inclusion else 'exclusion'} fence {f.name!r}"
        for i, it in enumerate(items):
            if not it.has_position:
                continue
            if poly is not None:
                inside = poly.covers(Point(it.lon, it.lat))
            else:
                inside = _distance_m(it.lat, it.lon, *f.center) <= f.radius
            if f.inclusion and not inside:
                out.append(Problem(i, "fence-outside", f"{it.name} lies outside the {what}"))
            elif not f.inclusion and inside:
                out.append(Problem(i, "fence-inside", f"{it.name} lies inside the {what}"))
    return out


def validate_mission(
    items: Sequence[MissionItem],
    firmware: str,
    *,
    vehicle: str = "multirotor",
    home_alt: float | None = None,
    max_land_slope_deg: float = PX4_FW_LND_ANG,
    fences: Sequence[Any] = (),
) -> list[Problem]:
    """Problems that would make ``firmware`` reject or misfly the mission ([] = none).

    Parameters
    ----------
    items : sequence of MissionItem
        The mission after the home position (as uploaded).
    firmware : {"px4", "ardupilot", "generic"}
    vehicle : {"multirotor", "fixed_wing", "vtol"}, optional
    home_alt : float, optional
        Home altitude above mean sea level [m]; needed to compare relative and
        absolute altitudes (takeoff above home, fixed-wing glide slope).
    max_land_slope_deg : float, optional
        PX4 ``FW_LND_ANG`` [deg] (default 5, PX4's default).
    fences : sequence of FencePolygon / FenceCircle, optional
        The plan's geofences.

    Returns
    -------
    list of Problem
    """
    _check_names(firmware, vehicle)
    items = list(items)
    out = _common(items, home_alt)
    if firmware in ("px4", "generic"):
        out += _px4(items, vehicle, home_alt, max_land_slope_deg)
    if firmware in ("ardupilot", "generic"):
        out += _ardupilot(items, vehicle)
    if fences:
        out += _fence_problems(items, list(fences))
    return out


def check_mission(items: Sequence[MissionItem], firmware: str, **options: object) -> None:
    """Raise :class:`~fm2uav.errors.MissionError` naming the first problem (see
    :func:`validate_mission` for ``options``)."""
    problems = validate_mission(items, firmware, **options)  # type: ignore[arg-type]
    if problems:
        more = f" (+{len(problems) - 1} more)" if len(problems) > 1 else ""
        raise MissionError(f"{firmware} would reject this mission: {problems[0]}{more}")

