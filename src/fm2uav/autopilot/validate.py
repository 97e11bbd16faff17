"""Mission checkers: what PX4 or ArduPilot would reject, from the firmware profiles.

:func:`validate_mission` returns the problems of a list of
:class:`~fm2uav.autopilot.items.MissionItem` for a firmware and airframe;
:func:`check_mission` raises :class:`~fm2uav.errors.MissionError` on the first
one. Every export goes through :func:`check_mission` before a file is written.

What is checked, and where each rule comes from:

* **Every firmware** (MAVLink ``common.xml``, QGC plan format; here): at least one
  item; the first navigation item is ``NAV_TAKEOFF`` (22) or
  ``NAV_VTOL_TAKEOFF`` (84) with its altitude above home; the last item is
  ``NAV_RETURN_TO_LAUNCH`` (20), ``NAV_LAND`` (21), ``NAV_VTOL_LAND`` (85) or
  ``NAV_LOITER_UNLIM`` (17); latitude/longitude/altitude of every position item
  finite and in range (and not the 0, 0 of an unset coordinate); params 1-3
  finite (param 4 may be NaN only where it is a yaw); ``DO_CHANGE_SPEED`` with a
  speed > 0 (or -1) and speed type 0/1; ``DO_SET_CAM_TRIGG_DIST`` distance >= 0
  and the camera stopped (distance 0) before the end.
* **The firmware's own rules** (its :class:`~fm2uav.autopilot.firmware.FirmwareProfile`
  ``rules``): PX4 in :mod:`fm2uav.autopilot.firmware.px4`, ArduPilot in
  :mod:`fm2uav.autopilot.firmware.ardupilot`; **generic**
  (``MAV_AUTOPILOT_GENERIC``): both sets of rules, so that either firmware
  accepts the mission.
* **Geofences** (``fences``, both firmwares; PX4's feasibility checker rejects a
  mission item that conflicts with a plan geofence): no position item inside an
  exclusion polygon or circle, none outside an inclusion one.
* **How the firmware flies it** (:mod:`fm2uav.autopilot.firmware.flight_rules`, in
  each profile's ``rules``): the speed commands (type, range, a cruise speed
  before the first waypoint) and a fixed-wing's climb-out, loiters, waypoint
  spacing and landing approach, from the firmware's navigation numbers with the
  airframe's own laid over them (``airframe``).

A problem is an ``error`` (the firmware rejects or misflies the mission: the export
stops) or a ``warning`` (it flies it with the deviation the message says:
:func:`check_mission` returns them for the summary).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

from ..errors import MissionError
from .firmware import (
    FIRMWARES,
    VEHICLES,
    Problem,
    check_vehicle,
    firmware_profile,
    supported_commands,
)
from .firmware.navigation import AirframeNav
from .firmware.px4 import FW_LND_ANG as PX4_FW_LND_ANG
from .items import (
    CMD_DO_CHANGE_SPEED,
    CMD_DO_SET_CAM_TRIGG_DIST,
    END_COMMANDS,
    FRAME_RELATIVE,
    FRAME_TERRAIN,
    TAKEOFF_COMMANDS,
    MissionItem,
    command_name,
    distance_m,
)

__all__ = [
    "FIRMWARES",
    "VEHICLES",
    "PX4_FW_LND_ANG",
    "Problem",
    "validate_mission",
    "check_mission",
    "supported_commands",
]

#: Commands whose param 4 is a yaw angle, where NaN means "keep the heading".
_YAW_PARAM4 = frozenset({16, 17, 21, 22, 84, 85})


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
                inside = distance_m(it.lat, it.lon, *f.center) <= f.radius
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
    home_latlon: tuple[float, float] | None = None,
    airframe: AirframeNav | None = None,
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
    home_latlon : (float, float), optional
        Home latitude, longitude [deg]: where a fixed-wing take-off starts.
    airframe : AirframeNav, optional
        The airframe's speeds, bank, climb and sink, laid over the firmware's defaults.

    Returns
    -------
    list of Problem
    """
    profile = firmware_profile(firmware)
    check_vehicle(vehicle)
    items = list(items)
    out = _common(items, home_alt)
    for rule in profile.rules:
        out += rule(items, vehicle, home_alt=home_alt, max_land_slope_deg=max_land_slope_deg,
                    home_latlon=home_latlon, airframe=airframe)
    if fences:
        out += _fence_problems(items, list(fences))
    return out


def check_mission(items: Sequence[MissionItem], firmware: str, **options: object
                  ) -> list[Problem]:
    """Raise :class:`~fm2uav.errors.MissionError` naming the first error (see
    :func:`validate_mission` for ``options``); return the warnings."""
    problems = validate_mission(items, firmware, **options)  # type: ignore[arg-type]
    errors = [p for p in problems if p.is_error]
    if errors:
        more = f" (+{len(errors) - 1} more)" if len(errors) > 1 else ""
        raise MissionError(f"{firmware} would reject or misfly this mission: {errors[0]}{more}")
    return [p for p in problems if not p.is_error]

