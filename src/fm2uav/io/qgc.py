"""QGroundControl ``.plan`` files (JSON): writer, checker and a reader for any QGC plan.

The structure is the one QGroundControl writes and reads (its "Plan File
Format" developer documentation and ``PlanMasterController`` /
``MissionController::_loadJsonMissionFileV2`` / ``SimpleMissionItem::load``):

* top level: ``fileType`` = "Plan", ``version`` = 1, ``groundStation``,
  ``mission``, and the optional ``geoFence`` (``circles``, ``polygons``,
  ``version`` 2) and ``rallyPoints`` (``points``, ``version`` 2); fm2uav adds an
  ``fm2uav`` object (frame, home and its source, CRS and vertical reference,
  warnings), which QGroundControl ignores;
* ``mission``: ``version`` 2, ``firmwareType`` (MAV_AUTOPILOT), ``vehicleType``
  (MAV_TYPE), ``cruiseSpeed``, ``hoverSpeed``, ``globalPlanAltitudeMode``,
  ``plannedHomePosition`` ``[lat, lon, alt AMSL]`` and ``items``;
* a ``SimpleItem``: ``type``, ``command``, ``frame``, ``params`` (7 values,
  NaN written as ``null``), ``autoContinue``, ``doJumpId``; items with a
  position also ``AltitudeMode``, ``Altitude`` and ``AMSLAltAboveTerrain``
  (QGC's ``AltitudeFrame``: 1 relative, 2 absolute, 3 calculated above
  terrain, 4 terrain frame);
* a ``ComplexItem``: ``complexItemType`` (``survey``, ``CorridorScan``,
  ``StructureScan``, ``fwLandingPattern``, ...) with its own keys; survey and
  corridor scans keep the mission items they stand for in
  ``TransectStyleComplexItem.Items``.

Altitudes in the amsl frame are written as QGC's *absolute* mode (2), not as
"calculated above terrain" (3): QGC recomputes mode-3 altitudes from its own
terrain server when it loads the plan, which would replace the DEM's ground
under each waypoint with QGC's; mode 2 uploads exactly the AMSL altitude
fm2uav computed (DEM ground + AGL).

:func:`validate_plan` checks a document against these rules (used on every
file written); :func:`read_plan` reads any plan QGC writes.

The ``geoFence`` object (:func:`geofence_document`, :func:`read_geofence`) holds
``polygons`` (``{"inclusion": bool, "polygon": [[lat, lon], ...], "version": 1}``,
clockwise) and ``circles`` (``{"circle": {"center": [lat, lon], "radius": m},
"inclusion": bool, "version": 1}``), written from the fences of
:mod:`fm2uav.autopilot.geofence`.
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import IO, Any

import numpy as np

from ..errors import InputError
from ..autopilot.firmware import FIRMWARE_TYPES, VEHICLE_TYPES  # MAV_AUTOPILOT, MAV_TYPE
from ..autopilot.geofence import Fence, FenceCircle, FencePolygon, as_fences
from ..autopilot.items import FRAME_GLOBAL, FRAME_RELATIVE, FRAME_TERRAIN, MissionItem

__all__ = [
    "FIRMWARE_TYPES",
    "VEHICLE_TYPES",
    "ALTITUDE_MODES",
    "plan_document",
    "write_plan",
    "read_plan",
    "validate_plan",
    "geofence_document",
    "read_geofence",
]

#: MAV_FRAME of a position item → QGroundControl AltitudeFrame ("AltitudeMode").
ALTITUDE_MODES = {FRAME_RELATIVE: 1, FRAME_GLOBAL: 2, FRAME_TERRAIN: 4}
#: Complex items QGC writes and whether they carry their mission items.
_TRANSECT_ITEMS = ("survey", "CorridorScan")


def _json_num(v: float) -> float | None:
    return None if not math.isfinite(v) else float(v)


def _item_json(it: MissionItem, jump_id: int) -> dict[str, Any]:
    out: dict[str, Any] = {}
    if it.has_position:
        out.update({"AMSLAltAboveTerrain": None, "Altitude": float(it.alt),
                    "AltitudeMode": ALTITUDE_MODES.get(it.frame, 2)})
    out.update({
        "autoContinue": bool(it.autocontinue),
        "command": int(it.command),
        "doJumpId": int(jump_id),
        "frame": int(it.frame),
        "params": [_json_num(v) for v in it.params],
        "type": "SimpleItem",
    })
    return out


def _portable(georef: dict[str, Any] | None) -> dict[str, Any] | None:
    """The georeference with each source named by its file name (and sha256), not by the
    folder it was read from: a plan file tells the same flight wherever its mission was run
    from (the same mission file gives the same bytes on any machine, from any folder)."""
    if georef is None:
        return None
    return {**georef, "sources": [{**s, "path": Path(str(s["path"])).name}
                                  for s in georef.get("sources", ())]}


def plan_document(mission: Any) -> dict[str, Any]:
    """The ``.plan`` JSON document of a built mission (a plain dict).

    Parameters
    ----------
    mission : MissionExport
        From :func:`fm2uav.autopilot.build_mission` (items, home, airframe, fences).
    """
    opt = mission.options
    items = [_item_json(it, k + 1) for k, it in enumerate(mission.items)]
    modes = {it["AltitudeMode"] for it in items if "AltitudeMode" in it}
    info = mission.summary()
    return {
        "fileType": "Plan",
        "fm2uav": {"frame": info["frame"], "home": info["home"], "crs": info["crs"],
                   "georef": _portable(info["georef"]),
                   "vertical_reference": info["vertical_reference"],
                   "end": info["end"], "warnings": info["warnings"]},
        "geoFence": geofence_document(mission.fences),
        "groundStation": "fm2uav",
        "mission": {
            "cruiseSpeed": float(opt.cruise_speed),
            "firmwareType": FIRMWARE_TYPES[opt.firmware],
            "globalPlanAltitudeMode": modes.pop() if len(modes) == 1 else 0,
            "hoverSpeed": float(opt.hover_speed),
            "items": items,
            "plannedHomePosition": [float(v) for v in mission.home],
            "vehicleType": VEHICLE_TYPES[opt.vehicle],
            "version": 2,
        },
        "rallyPoints": {"points": [], "version": 2},
        "version": 1,
    }


def write_plan(fh: IO[str], mission: Any) -> dict[str, Any]:
    """Write a QGroundControl ``.plan`` to an open text file; returns the document.

    Coordinates keep full double precision (QGroundControl stores them the same way).
    """
    doc = plan_document(mission)
    problems = validate_plan(doc)
    if problems:  # a bug, not a user error: never write a file QGC rejects
        raise AssertionError("; ".join(problems))
    json.dump(doc, fh, indent=4, allow_nan=False)
    fh.write("\n")
    return doc


def _is_num(v: Any) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)


class _Checker:
    def __init__(self) -> None:
        self.out: list[str] = []

    def need(self, obj: Any, key: str, kind: str, where: str, optional: bool = False) -> Any:
        if not isinstance(obj, dict) or key not in obj:
            if not optional:
                self.out.append(f"{where}: missing key {key!r}")
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
            self.out.append(f"{where}.{key}: expected {kind}, got {type(v).__name__}")
            return None
        return v

    def simple_item(self, it: Any, w: str) -> None:
        self.need(it, "command", "num", w)
        self.need(it, "frame", "num", w)
        self.need(it, "autoContinue", "bool", w)
        if "doJumpId" in (it or {}) and not _is_num(it["doJumpId"]):
            self.out.append(f"{w}.doJumpId: expected num")
        if "AltitudeMode" in (it or {}) and not _is_num(it["AltitudeMode"]):
            self.out.append(f"{w}.AltitudeMode: expected num")
        params = self.need(it, "params", "list", w)
        if params is None:
            return
        if len(params) != 7:
            self.out.append(f"{w}.params must hold 7 values, got {len(params)}")
        elif not all(v is None or _is_num(v) for v in params):
            self.out.append(f"{w}.params must be numbers or null")
        elif it.get("frame") in (0, 3, 10) and not (
            _is_num(params[4]) and _is_num(params[5])
            and -90 <= params[4] <= 90 and -180 <= params[5] <= 180
        ):
            self.out.append(f"{w}.params[4:6] must be a valid latitude, longitude")

    def complex_item(self, it: Any, w: str) -> None:
        kind = self.need(it, "complexItemType", "str", w)
        if kind in _TRANSECT_ITEMS:
            ts = self.need(it, "TransectStyleComplexItem", "dict", w, optional=True)
            sub = self.need(ts, "Items", "list", f"{w}.TransectStyleComplexItem",
                            optional=True) if ts is not None else None
            for j, s in enumerate(sub or []):
                self.simple_item(s, f"{w}.TransectStyleComplexItem.Items[{j}]")


def validate_plan(doc: Any) -> list[str]:
    """Problems that would make QGroundControl reject a ``.plan`` document ([] = valid).

    Checks the keys and JSON types QGroundControl requires when it loads a
    plan file (see the module docstring), the ranges of coordinates, and for
    every SimpleItem (also those inside survey/corridor complex items) its 7
    params. ``geoFence`` and ``rallyPoints`` are optional, as in QGC.
    """
    c = _Checker()
    if not isinstance(doc, dict):
        return ["top level: expected a JSON object"]
    if c.need(doc, "fileType", "str", "top") not in (None, "Plan"):
        c.out.append("top.fileType must be 'Plan'")
    if c.need(doc, "version", "num", "top") not in (None, 1):
        c.out.append("top.version must be 1")
    fence = c.need(doc, "geoFence", "dict", "top", optional=True)
    if fence is not None:
        c.need(fence, "version", "num", "geoFence")
        for key in ("circles", "polygons"):
            for i, f in enumerate(c.need(fence, key, "list", "geoFence", optional=True) or []):
                w = f"geoFence.{key}[{i}]"
                c.need(f, "inclusion", "bool", w)
                if key == "polygons":
                    pts = c.need(f, "polygon", "list", w) or []
                    if len(pts) < 3 or not all(isinstance(p, list) and len(p) == 2
                                               and all(_is_num(v) for v in p) for p in pts):
                        c.out.append(f"{w}.polygon must hold >= 3 [lat, lon] points")
                else:
                    circ = c.need(f, "circle", "dict", w)
                    if circ is not None:
                        c.need(circ, "center", "list", f"{w}.circle")
                        c.need(circ, "radius", "num", f"{w}.circle")
    rally = c.need(doc, "rallyPoints", "dict", "top", optional=True)
    if rally is not None:
        c.need(rally, "version", "num", "rallyPoints")
        c.need(rally, "points", "list", "rallyPoints")
    m = c.need(doc, "mission", "dict", "top")
    if m is None:
        return c.out
    if c.need(m, "version", "num", "mission") not in (None, 2):
        c.out.append("mission.version must be 2")
    c.need(m, "firmwareType", "num", "mission")
    for key in ("vehicleType", "cruiseSpeed", "hoverSpeed", "globalPlanAltitudeMode"):
        if key in m and not _is_num(m[key]):
            c.out.append(f"mission.{key}: expected num")
    home = c.need(m, "plannedHomePosition", "list", "mission")
    if home is not None:
        if len(home) != 3 or not all(_is_num(v) for v in home):
            c.out.append("mission.plannedHomePosition must be [lat, lon, alt] numbers")
        elif not (-90 <= home[0] <= 90 and -180 <= home[1] <= 180):
            c.out.append(f"mission.plannedHomePosition lat/lon out of range: {home[:2]}")
    items = c.need(m, "items", "list", "mission")
    if items is not None and not items:
        c.out.append("mission.items must hold at least one item")
    for i, it in enumerate(items or []):
        w = f"mission.items[{i}]"
        kind = c.need(it, "type", "str", w)
        if kind == "SimpleItem":
            c.simple_item(it, w)
        elif kind == "ComplexItem":
            c.complex_item(it, w)
        elif kind is not None:
            c.out.append(f"{w}.type must be 'SimpleItem' or 'ComplexItem', got {kind!r}")
    return c.out


def _simple(it: dict[str, Any]) -> MissionItem:
    params = [math.nan if v is None else float(v) for v in it["params"]]
    agl = it.get("Altitude") if it.get("AltitudeMode") == 3 else None
    amsl = it.get("AMSLAltAboveTerrain")
    return MissionItem(int(it["command"]), int(it["frame"]), tuple(params),  # type: ignore[arg-type]
                       autocontinue=bool(it.get("autoContinue", True)),
                       agl=None if agl is None else float(agl),
                       alt_amsl=None if amsl is None else float(amsl))


def read_plan(file: str | Path) -> dict[str, Any]:
    """Read any ``.plan`` QGroundControl writes (or :func:`write_plan`).

    SimpleItems are read as they are. Survey and corridor-scan ComplexItems
    are expanded into the mission items QGC stored for them
    (``TransectStyleComplexItem.Items``); complex items without stored items
    (``StructureScan``, landing patterns, surveys saved without items) are
    refused, naming the item.

    Returns
    -------
    dict
        ``home`` (lat, lon, alt), ``firmware_type``, ``vehicle_type``,
        ``items`` (list of MissionItem), ``sources`` (for each item, the plan
        item it came from, e.g. ``"items[2] survey"``), ``fences``, ``rally``,
        and arrays ``command``, ``frame``, ``lat``, ``lon``, ``alt`` of the
        items (``frame`` of the first item also as ``frame0``).

    Raises
    ------
    InputError
        Not JSON, not a valid plan (the first problem named), or a complex item
        fm2uav cannot expand (named with its type and position).
    """
    file = Path(file)
    from .. import _validate as _v

    _v.input_file(file, ".plan file")  # no folder / named pipe (would block)
    try:
        doc = json.loads(file.read_text())
    except (OSError, json.JSONDecodeError, UnicodeDecodeError) as exc:
        raise InputError(f"{file}: cannot read a .plan JSON file: {exc}") from None
    problems = validate_plan(doc)
    if problems:
        raise InputError(f"{file}: not a valid QGroundControl plan: {problems[0]}")
    m = doc["mission"]
    items: list[MissionItem] = []
    sources: list[str] = []
    for i, it in enumerate(m["items"]):
        if it["type"] == "SimpleItem":
            items.append(_simple(it))
            sources.append(f"items[{i}]")
            continue
        kind = it["complexItemType"]
        sub = (it.get("TransectStyleComplexItem") or {}).get("Items")
        if kind in _TRANSECT_ITEMS and sub:
            for s in sub:
                items.append(_simple(s))
                sources.append(f"items[{i}] {kind}")
            continue
        if kind in _TRANSECT_ITEMS:
            why = ("it was saved without its mission items (TransectStyleComplexItem.Items); "
                   "open the plan in QGroundControl and save it again, which stores them")
        else:
            why = ("QGroundControl computes its mission items when it uploads the plan and does "
                   "not store them in the file; remove that item (fm2uav reads SimpleItems and "
                   "the items stored by survey and CorridorScan complex items)")
        raise InputError(
            f"{file}: mission item {i + 1} is a QGroundControl {kind!r} complex item, which "
            f"fm2uav cannot read: {why}")
    if not items:
        raise InputError(f"{file}: the plan has no mission items")
    fence = doc.get("geoFence") or {}
    return {
        "home": tuple(m["plannedHomePosition"]),
        "firmware_type": int(m["firmwareType"]),
        "vehicle_type": int(m.get("vehicleType", 0)),
        "items": items,
        "sources": sources,
        "fences": read_geofence(fence),
        "rally": [tuple(p) for p in (doc.get("rallyPoints") or {}).get("points", [])],
        "frame0": items[0].frame,
        "frame": np.array([it.frame for it in items], dtype=int),
        "command": np.array([it.command for it in items], dtype=int),
        "lat": np.array([it.lat for it in items], dtype=float),
        "lon": np.array([it.lon for it in items], dtype=float),
        "alt": np.array([it.alt for it in items], dtype=float),
    }


# ---------------------------------------------------------------- geofences
def _fence_json(f: Fence) -> dict[str, Any]:
    """The QGC ``geoFence.polygons[]`` / ``geoFence.circles[]`` entry of a fence."""
    if isinstance(f, FencePolygon):
        return {"inclusion": bool(f.inclusion),
                "polygon": [[lat, lon] for lat, lon in f.points], "version": 1}
    return {"circle": {"center": [f.center[0], f.center[1]], "radius": f.radius},
            "inclusion": bool(f.inclusion), "version": 1}


def geofence_document(fences: Any = ()) -> dict[str, Any]:
    """The ``geoFence`` object of a ``.plan`` (version 2) from
    :func:`~fm2uav.autopilot.geofence.as_fences` input."""
    fences = as_fences(fences)
    polys = [_fence_json(f) for f in fences if isinstance(f, FencePolygon)]
    circles = [_fence_json(f) for f in fences if isinstance(f, FenceCircle)]
    return {"circles": circles, "polygons": polys, "version": 2}


def read_geofence(doc: dict[str, Any]) -> list[Fence]:
    """Fences of a ``.plan``'s ``geoFence`` object (QGC version 2; [] without one)."""
    if not doc:
        return []
    out: list[Fence] = []
    for i, p in enumerate(doc.get("polygons", [])):
        out.append(FencePolygon(tuple((a, b) for a, b in p["polygon"]),
                                bool(p.get("inclusion", True)), f"polygon {i + 1}"))
    for i, c in enumerate(doc.get("circles", [])):
        circ = c["circle"]
        out.append(FenceCircle(tuple(circ["center"]), circ["radius"],
                               bool(c.get("inclusion", True)), f"circle {i + 1}"))
    return out
