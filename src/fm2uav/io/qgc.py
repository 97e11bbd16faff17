"""QGroundControl ``.plan`` files (JSON).

The structure is the one QGroundControl writes and reads (its "Plan File
Format" developer documentation and ``PlanMasterController`` /
``MissionController::_loadJsonMissionFileV2`` / ``MissionItem::load``):

* top level: ``fileType`` = "Plan", ``version`` = 1, ``groundStation``,
  objects ``mission``, ``geoFence`` (``circles``, ``polygons``, ``version`` 2),
  ``rallyPoints`` (``points``, ``version`` 2);
* ``mission``: ``version`` 2, ``firmwareType`` (MAV_AUTOPILOT), ``vehicleType``
  (MAV_TYPE), ``cruiseSpeed``, ``hoverSpeed``, ``globalPlanAltitudeMode``,
  ``plannedHomePosition`` ``[lat, lon, alt AMSL]`` and ``items``;
* each ``SimpleItem``: ``type``, ``command``, ``frame``, ``params`` (7 values,
  NaN written as ``null``), ``autoContinue``, ``doJumpId``, ``Altitude``,
  ``AltitudeMode`` and ``AMSLAltAboveTerrain``.

:func:`validate_plan` checks exactly these keys and types and is used by the
tests on every file we write.
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import IO, Any

import numpy as np

from ..errors import InputError
from .waypoints import (
    CMD_NAV_TAKEOFF,
    CMD_NAV_WAYPOINT,
    FRAME_RELATIVE,
    FRAME_TERRAIN,
    Waypoints,
)

__all__ = [
    "FIRMWARE_TYPES",
    "VEHICLE_TYPES",
    "plan_document",
    "write_plan",
    "read_plan",
    "validate_plan",
]

#: Autopilot firmware name → MAV_AUTOPILOT.
FIRMWARE_TYPES = {"generic": 0, "ardupilot": 3, "px4": 12}
#: Airframe kind → MAV_TYPE.
VEHICLE_TYPES = {"fixed_wing": 1, "multirotor": 2, "vtol": 22}
#: QGroundControl's AltitudeMode enum for the MAVLink frames we write.
_ALT_MODE = {FRAME_RELATIVE: 1, FRAME_TERRAIN: 4}


def _item(seq: int, command: int, frame: int, lat: float, lon: float, alt: float,
          param1: float = 0.0) -> dict[str, Any]:
    return {
        "AMSLAltAboveTerrain": None,
        "Altitude": float(alt),
        "AltitudeMode": _ALT_MODE[frame],
        "autoContinue": True,
        "command": int(command),
        "doJumpId": int(seq),
        "frame": int(frame),
        "params": [float(param1), 0, 0, None, float(lat), float(lon), float(alt)],
        "type": "SimpleItem",
    }


def plan_document(
    wps: Waypoints,
    *,
    cruise_speed: float = 15.0,
    hover_speed: float = 5.0,
    vehicle: str = "multirotor",
    firmware: str = "px4",
) -> dict[str, Any]:
    """The ``.plan`` JSON document of a set of waypoints (a plain dict).

    Parameters
    ----------
    wps : Waypoints
        From :func:`fm2uav.io.mission_waypoints`.
    cruise_speed, hover_speed : float, optional
        Fixed-wing cruise and multirotor hover speeds [m/s].
    vehicle : {"multirotor", "fixed_wing", "vtol"}, optional
    firmware : {"px4", "ardupilot", "generic"}, optional
    """
    if wps.frame not in _ALT_MODE:
        raise InputError(f"a .plan needs frame 3 (relative) or 10 (terrain), got {wps.frame}")
    if vehicle not in VEHICLE_TYPES:
        raise InputError(f"vehicle must be one of {sorted(VEHICLE_TYPES)}, got {vehicle!r}")
    if firmware not in FIRMWARE_TYPES:
        raise InputError(f"firmware must be one of {sorted(FIRMWARE_TYPES)}, got {firmware!r}")
    items = []
    seq = 1
    if wps.takeoff:
        items.append(_item(seq, CMD_NAV_TAKEOFF, wps.frame, wps.lat[0], wps.lon[0], wps.alt[0]))
        seq += 1
    for lat, lon, alt in zip(wps.lat, wps.lon, wps.alt):
        items.append(_item(seq, CMD_NAV_WAYPOINT, wps.frame, lat, lon, alt))
        seq += 1
    return {
        "fileType": "Plan",
        "geoFence": {"circles": [], "polygons": [], "version": 2},
        "groundStation": "QGroundControl",
        "mission": {
            "cruiseSpeed": float(cruise_speed),
            "firmwareType": FIRMWARE_TYPES[firmware],
            "globalPlanAltitudeMode": _ALT_MODE[wps.frame],
            "hoverSpeed": float(hover_speed),
            "items": items,
            "plannedHomePosition": [float(v) for v in wps.home],
            "vehicleType": VEHICLE_TYPES[vehicle],
            "version": 2,
        },
        "rallyPoints": {"points": [], "version": 2},
        "version": 1,
    }


def write_plan(fh: IO[str], wps: Waypoints, **options: Any) -> dict[str, Any]:
    """Write a QGroundControl ``.plan`` to an open text file; returns the document.

    ``options`` are those of :func:`plan_document`. Coordinates keep full
    double precision (QGroundControl stores them the same way).
    """
    doc = plan_document(wps, **options)
    problems = validate_plan(doc)
    if problems:  # a bug, not a user error: never write a file QGC rejects
        raise AssertionError("; ".join(problems))
    json.dump(doc, fh, indent=4, allow_nan=False)
    fh.write("\n")
    return doc


def _is_num(v: Any) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)


def validate_plan(doc: Any) -> list[str]:
    """Problems that would make QGroundControl reject a ``.plan`` document ([] = valid).

    Checks the keys and JSON types QGroundControl requires when it loads a
    plan file (see the module docstring), plus the ranges of coordinates and
    that every item is a SimpleItem with 7 params.
    """
    out: list[str] = []

    def need(obj: Any, key: str, kind: Any, where: str) -> Any:
        if not isinstance(obj, dict) or key not in obj:
            out.append(f"{where}: missing key {key!r}")
            return None
        v = obj[key]
        ok = {
            "str": isinstance(v, str),
            "num": _is_num(v),
            "bool": isinstance(v, bool),
            "list": isinstance(v, list),
            "dict": isinstance(v, dict),
        }[kind]
        if not ok:
            out.append(f"{where}.{key}: expected {kind}, got {type(v).__name__}")
            return None
        return v

    if not isinstance(doc, dict):
        return ["top level: expected a JSON object"]
    if need(doc, "fileType", "str", "top") not in (None, "Plan"):
        out.append("top.fileType must be 'Plan'")
    if need(doc, "version", "num", "top") not in (None, 1):
        out.append("top.version must be 1")
    need(doc, "groundStation", "str", "top")
    fence = need(doc, "geoFence", "dict", "top")
    if fence is not None:
        need(fence, "version", "num", "geoFence")
        need(fence, "circles", "list", "geoFence")
        need(fence, "polygons", "list", "geoFence")
    rally = need(doc, "rallyPoints", "dict", "top")
    if rally is not None:
        need(rally, "version", "num", "rallyPoints")
        need(rally, "points", "list", "rallyPoints")
    m = need(doc, "mission", "dict", "top")
    if m is None:
        return out
    if need(m, "version", "num", "mission") not in (None, 2):
        out.append("mission.version must be 2")
    need(m, "firmwareType", "num", "mission")
    for key in ("vehicleType", "cruiseSpeed", "hoverSpeed", "globalPlanAltitudeMode"):
        if key in m and not _is_num(m[key]):
            out.append(f"mission.{key}: expected num")
    home = need(m, "plannedHomePosition", "list", "mission")
    if home is not None:
        if len(home) != 3 or not all(_is_num(v) for v in home):
            out.append("mission.plannedHomePosition must be [lat, lon, alt] numbers")
        elif not (-90 <= home[0] <= 90 and -180 <= home[1] <= 180):
            out.append(f"mission.plannedHomePosition lat/lon out of range: {home[:2]}")
    items = need(m, "items", "list", "mission")
    if items is not None and not items:
        out.append("mission.items must hold at least one item")
    for i, it in enumerate(items or []):
        w = f"mission.items[{i}]"
        if need(it, "type", "str", w) not in (None, "SimpleItem"):
            out.append(f"{w}.type must be 'SimpleItem'")
        need(it, "command", "num", w)
        need(it, "frame", "num", w)
        need(it, "autoContinue", "bool", w)
        if "doJumpId" in (it or {}) and not _is_num(it["doJumpId"]):
            out.append(f"{w}.doJumpId: expected num")
        if "AltitudeMode" in (it or {}) and not _is_num(it["AltitudeMode"]):
            out.append(f"{w}.AltitudeMode: expected num")
        params = need(it, "params", "list", w)
        if params is not None:
            if len(params) != 7:
                out.append(f"{w}.params must hold 7 values, got {len(params)}")
            elif not all(v is None or _is_num(v) for v in params):
                out.append(f"{w}.params must be numbers or null")
            elif it.get("frame") in (0, 3, 10) and not (
                _is_num(params[4]) and _is_num(params[5])
                and -90 <= params[4] <= 90 and -180 <= params[5] <= 180
            ):
                out.append(f"{w}.params[4:6] must be a valid latitude, longitude")
    return out


def read_plan(file: str | Path) -> dict[str, Any]:
    """Read a ``.plan`` written by :func:`write_plan` (or QGroundControl).

    Returns
    -------
    dict
        ``home`` (lat, lon, alt), ``frame`` (of the first item), and arrays
        ``command``, ``lat``, ``lon``, ``alt`` of the mission items.

    Raises
    ------
    InputError
        Not JSON, or not a valid plan (the first problem is named).
    """
    file = Path(file)
    try:
        doc = json.loads(file.read_text())
    except (OSError, json.JSONDecodeError) as exc:
        raise InputError(f"{file}: cannot read a .plan JSON file: {exc}") from None
    problems = validate_plan(doc)
    if problems:
        raise InputError(f"{file}: not a valid QGroundControl plan: {problems[0]}")
    items = doc["mission"]["items"]
    return {
        "home": tuple(doc["mission"]["plannedHomePosition"]),
        "frame": int(items[0]["frame"]),
        "command": np.array([it["command"] for it in items], dtype=int),
        "lat": np.array([it["params"][4] for it in items], dtype=float),
        "lon": np.array([it["params"][5] for it in items], dtype=float),
        "alt": np.array([it["params"][6] for it in items], dtype=float),
    }
