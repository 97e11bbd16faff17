"""Every mission file of a plan, from one function.

:func:`export_mission` builds the mission once (:func:`fm2uav.autopilot.build_mission`:
altitudes, takeoff, speeds, camera, end, firmware check) and returns a writer per
requested format, so that the CLI decides where and how files are written
(atomically, without overwriting) and all formats describe the same mission:

=========  =====================  ===========================================
format     file                   content
=========  =====================  ===========================================
csv        ``path.csv``           dense path x, y, z [m] and W
geojson    ``path.geojson``       3D LineString lon/lat/alt + waypoints (RFC 7946)
kml        ``path.kml``           3D path and waypoints for Google Earth
kmz        ``path.kmz``           the same KML, zipped (``doc.kml``)
plan       ``mission.plan``       QGroundControl plan (JSON), with geofences
wpl        ``mission.waypoints``  MAVLink ``QGC WPL 110`` (tab-separated)
=========  =====================  ===========================================

``waypoints`` is accepted as another name of ``wpl``.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace
from types import SimpleNamespace
from typing import IO, Any

import numpy as np

from ..errors import InputError
from ..geometry import path_length
from ..autopilot.build import CameraPlan, ExportOptions, MissionExport, build_mission, start_holds
from .geojson import write_geojson
from .kml import write_kml, write_kmz
from .paths import write_path_csv
from .qgc import write_plan
from .wpl import write_wpl

__all__ = [
    "EXPORT_FILES",
    "FORMAT_ALIASES",
    "ExportOptions",
    "ExportFile",
    "parse_formats",
    "export_mission",
    "export_formation",
    "file_prefix",
    "export_writers",
]

#: Export format → file name.
EXPORT_FILES = {
    "csv": "path.csv",
    "geojson": "path.geojson",
    "kml": "path.kml",
    "kmz": "path.kmz",
    "plan": "mission.plan",
    "wpl": "mission.waypoints",
}
#: Other names of formats.
FORMAT_ALIASES = {"waypoints": "wpl", "qgc": "plan"}
_BINARY = frozenset({"kmz"})


@dataclass(frozen=True)
class ExportFile:
    """One file to write: its name, whether it is binary, and ``write(fh)``."""

    name: str
    binary: bool
    write: Callable[[IO[Any]], Any]


def parse_formats(formats: str | Sequence[str], *, flag: str = "--format") -> list[str]:
    """Format names (comma text or a list; aliases and ``all`` resolved), in order.

    Raises
    ------
    InputError
        An unknown name (the message lists the allowed ones and names ``flag``).
    """
    names = [f.strip().lower() for f in (formats.split(",") if isinstance(formats, str)
                                         else formats) if f and f.strip()]
    if names == ["all"]:
        return list(EXPORT_FILES)
    out = []
    for n in names:
        key = FORMAT_ALIASES.get(n, n)
        if key not in EXPORT_FILES:
            raise InputError(f"{flag} {n!r} is not a known format; allowed: "
                             f"{', '.join([*EXPORT_FILES, *FORMAT_ALIASES])} or all")
        out.append(key)
    return list(dict.fromkeys(out))


def _description(m: MissionExport) -> str:
    s = m.summary()
    lines = [f"firmware {s['firmware']}, {s['vehicle']}, frame {s['frame']['name']} "
             f"(MAV_FRAME {s['frame']['mav_frame']}), end {s['end']}",
             f"home {s['home']['lat']:.7f}, {s['home']['lon']:.7f}, "
             f"{s['home']['alt_amsl_m']:.1f} m AMSL ({s['home']['source']})",
             f"CRS {s['crs']}; altitudes: {s['vertical_reference']}"]
    return "\n".join(lines + [f"warning: {w}" for w in m.warnings])


def export_mission(
    plan: Any,
    formats: Sequence[str],
    options: ExportOptions | None = None,
    *,
    agl: float | None = None,
    via: Any = (),
    camera: CameraPlan | None = None,
    fences: Any = (),
    times: Any = None,
    start_hold: float = 0.0,
    prefix: str = "",
) -> tuple[MissionExport, dict[str, ExportFile]]:
    """Build the mission of a plan and the writers of the requested files.

    Parameters
    ----------
    plan : Plan-like
        Anything with ``path``, ``world``, ``w`` (W along the path) and
        ``level`` (a :class:`~fm2uav.FlightLevel` marks a terrain-following
        plan) or ``params["agl"]``: a :class:`~fm2uav.Plan`, ``Route.plan``,
        ``CoveragePlan.plan`` (give ``agl``).
    formats : sequence of str
        Keys of :data:`EXPORT_FILES` (or aliases).
    options : ExportOptions, optional
    agl : float, optional
        Requested height above ground (default ``plan.params.get("agl")``).
    via, camera, fences, times, start_hold
        See :func:`fm2uav.autopilot.build_mission`.
    prefix : str, optional
        Put before every file name (e.g. ``"leader_"``).

    Returns
    -------
    mission : MissionExport
    files : dict
        File name → :class:`ExportFile`.

    Raises
    ------
    InputError
        Unknown format.
    MissionError
        The firmware would reject the mission.
    """
    opt = options or ExportOptions()
    keys = parse_formats(list(formats))
    params = dict(getattr(plan, "params", None) or {})
    level = getattr(plan, "level", None)
    if agl is None:
        agl = float(level.agl) if level is not None else (
            float(params["agl"]) if "agl" in params else None)
    path = np.asarray(plan.path, dtype=float)
    world = plan.world
    speed = getattr(plan, "w", None)
    if speed is None:
        speed = getattr(plan, "speed", None)
    timing = getattr(plan, "wind_timing", None)
    if timing is not None and opt.vehicle == "multirotor":
        # a multirotor is commanded ground speeds: what the safe airspeed makes good in the
        # wind (capped at the forward speed), not the airspeed share W
        speed = np.clip(timing.point_groundspeed() / opt.forward_speed, 0.0, 1.0)
    mission = build_mission(path, world, opt, w=speed, agl=agl, times=times, via=via,
                            camera=camera, fences=fences, start_hold=start_hold,
                            profile=getattr(plan, "profile", None))
    s = mission.summary()
    props = {"mission": opt.name, "length_m": round(float(getattr(plan, "length", 0.0)), 3),
             "firmware": opt.firmware, "vehicle": opt.vehicle, "frame": mission.waypoints.frame,
             "frame_name": mission.frame, "end": mission.end, "waypoints": len(mission.waypoints),
             "crs": s["crs"], "vertical_reference": s["vertical_reference"],
             "home": [s["home"]["lat"], s["home"]["lon"], s["home"]["alt_amsl_m"]],
             "home_source": s["home"]["source"], "warnings": list(mission.warnings),
             **{k: v for k, v in params.items() if isinstance(v, (int, float, str, bool))}}
    wpm = mission.waypoints.points_m
    floor = getattr(getattr(plan, "profile", None), "required", None)
    if floor is not None and np.shape(floor) != (len(path),):
        floor = None
    georef = getattr(world, "georef", None)
    if georef is not None:
        props["georef"] = georef.as_dict()
    a = opt.anchor
    writers: dict[str, Callable[[IO[Any]], Any]] = {
        "csv": lambda fh: write_path_csv(fh, path, speed, comment=georef and georef.comment(),
                                         floor=floor),
        "geojson": lambda fh: write_geojson(fh, path, world, anchor=a, waypoints_m=wpm,
                                            properties=props),
        "kml": lambda fh: write_kml(fh, path, world, anchor=a, waypoints_m=wpm, name=opt.name,
                                    description=_description(mission)),
        "kmz": lambda fh: write_kmz(fh, path, world, anchor=a, waypoints_m=wpm, name=opt.name,
                                    description=_description(mission)),
        "plan": lambda fh: write_plan(fh, mission),
        "wpl": lambda fh: write_wpl(fh, mission),
    }
    files = {}
    for k in keys:
        name = prefix + EXPORT_FILES[k]
        files[name] = ExportFile(name, k in _BINARY, writers[k])
    return mission, files


def file_prefix(name: str) -> str:
    """``"follower 1"`` → ``"follower1_"``: a vehicle's name as a file-name prefix."""
    return "".join(c for c in str(name) if c.isalnum() or c in "-_") + "_"


def export_formation(
    result: Any,
    formats: Sequence[str],
    options: ExportOptions | None = None,
    *,
    fences: Any = (),
) -> tuple[dict[str, MissionExport], dict[str, ExportFile]]:
    """One mission per vehicle of a formation flight, each following its own timing.

    Every UAV's simulated trajectory (``result.positions[:, i]`` at
    ``result.times``) becomes a mission (files prefixed with the UAV's name
    without spaces, :func:`file_prefix`: ``leader_``, ``follower1_``, ...): its
    waypoints, a ``DO_CHANGE_SPEED`` per leg with the simulated mean speed
    (0.1 m/s steps), holds where it waited, and a hold at its start so that all
    vehicles leave their start points together: vehicles armed and started at
    the same moment climb to their start altitudes at ``climb_rate``, and the
    ones with less to climb wait for the others. The summary of each records
    the planned and the mission's route time (``timing``).

    Parameters
    ----------
    result : FormationResult
        From :func:`fm2uav.missions.formation.fly_formation`.
    formats : sequence of str
    options : ExportOptions, optional
        Shared by all vehicles (firmware, airframe, frame, end, ...).
    fences : optional
        Geofences written into every vehicle's ``.plan`` and checked against its
        waypoints (as :func:`export_mission` ``fences``), e.g. the no-fly zones of
        :func:`fm2uav.autopilot.geofence.zone_fences`.
    """
    opt = options or ExportOptions()
    opt = replace(opt, speed_step=min(opt.speed_step, 0.1))
    world = result.world
    holds = start_holds(result.positions[0], world, opt)
    missions: dict[str, MissionExport] = {}
    files: dict[str, ExportFile] = {}
    for i, name in enumerate(result.names):
        path = np.asarray(result.positions[:, i], dtype=float)
        track = SimpleNamespace(path=path, world=world, w=None, level=None, params={},
                                length=path_length(path))
        agl = result.agl[i] if i < len(result.agl) else None
        m, f = export_mission(track, formats, replace(opt, name=f"{opt.name} — {name}"),
                              agl=agl, times=result.times, start_hold=float(holds[i]),
                              prefix=file_prefix(name), fences=fences)
        missions[name] = m
        files.update(f)
    return missions, files


def export_writers(plan: Any, formats: Sequence[str], options: ExportOptions | None = None,
                   **kwargs: Any) -> tuple[dict[str, Callable[[IO[Any]], Any]], Any]:
    """``(file name → writer(fh), waypoints)``: :func:`export_mission` in the older
    two-value form (binary formats need a binary file)."""
    mission, files = export_mission(plan, formats, options, **kwargs)
    return {n: f.write for n, f in files.items()}, mission.waypoints
