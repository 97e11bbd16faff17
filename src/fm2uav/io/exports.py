"""Every mission file of a plan, from one function.

:func:`export_mission` builds the mission once (:func:`fm2uav.autopilot.build_mission`:
altitudes, takeoff, speeds, camera, end, firmware check) and returns a writer per
requested format, so that the CLI decides where and how files are written
(atomically, without overwriting) and all formats describe the same mission:

=========  =====================  ===========================================
format     file                   content
=========  =====================  ===========================================
csv        ``path.csv``           dense path x, y, z [m] and the speed share W
                                 (obstacle distances, :meth:`fm2uav.Plan.speed_share`)
geojson    ``path.geojson``       3D LineString lon/lat/alt + waypoints (RFC 7946)
kml        ``path.kml``           3D path and waypoints for Google Earth
kmz        ``path.kmz``           the same KML, zipped (``doc.kml``)
plan       ``mission.plan``       QGroundControl plan (JSON), with geofences
wpl        ``mission.waypoints``  MAVLink ``QGC WPL 110`` (tab-separated)
=========  =====================  ===========================================

``waypoints`` is accepted as another name of ``wpl``.

With ``returns`` (:class:`~fm2uav.autopilot.safe_return.ReturnOptions`) the mission is
built with its safe returns (:func:`fm2uav.autopilot.safe_return.build_with_returns`)
and every export comes with the return files (:data:`RETURN_FILES`):
``mission.param`` (the firmware's return settings, :mod:`fm2uav.io.params`),
``returns.geojson`` (the ways back, the point of no return, :mod:`fm2uav.io.returns`)
and, with rally points, ``rally.waypoints`` and ``rally.txt`` (:mod:`fm2uav.io.rally`).
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
from .formats import EXPORT_FILES, FORMAT_ALIASES, RETURN_FILES
from .terrain_dat import terrain_files
from .wpl import write_wpl

__all__ = [
    "EXPORT_FILES",
    "RETURN_FILES",
    "FORMAT_ALIASES",
    "ExportOptions",
    "ExportFile",
    "parse_formats",
    "export_mission",
    "export_formation",
    "file_prefix",
    "export_writers",
    "terrain_export",
    "TERRAIN_LOAD",
    "TERRAIN_WITHOUT",
]

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
             + ("altitude above sea level unknown" if s["home"]["alt_amsl_m"] is None
                else f"{s['home']['alt_amsl_m']:.1f} m AMSL") + f" ({s['home']['source']})",
             f"CRS {s['crs']}; altitudes: {s['vertical_reference']}"]
    return "\n".join(lines + [f"warning: {w}" for w in m.warnings]
                     + [f"note: {n}" for n in m.info.get("notes", [])])


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
    returns: Any = None,
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
    returns : ReturnOptions, optional
        Build the mission with its safe returns and add the return files (module
        docstring).

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
    if hasattr(plan, "speed_share"):  # the obstacle-distance W, not a flight level's shaping
        try:
            speed = plan.speed_share()
        except InputError:  # a regional plan: no world-sized map to read it from
            if opt.speed_changes:
                raise
    timing = getattr(plan, "wind_timing", None)
    if timing is not None and opt.vehicle == "multirotor":
        # a multirotor is commanded ground speeds: what the safe airspeed makes good in the
        # wind (capped at the forward speed), not the airspeed share W
        speed = np.clip(timing.point_groundspeed() / opt.forward_speed, 0.0, 1.0)
    inputs = dict(w=speed, agl=agl, times=times, via=via, camera=camera, fences=fences,
                  start_hold=start_hold, profile=getattr(plan, "profile", None))
    if returns is not None:
        from ..autopilot.safe_return import build_with_returns

        mission = build_with_returns(path, world, opt, returns, plan=plan, **inputs)
        path = np.asarray(mission.path_m, dtype=float)  # with a planned safe return appended
        if speed is not None and np.shape(speed) != (len(path),):
            speed = None
    else:
        mission = build_mission(path, world, opt, **inputs)
    s = mission.summary()
    props = {"mission": opt.name, "length_m": round(float(getattr(plan, "length", 0.0)), 3),
             "firmware": opt.firmware, "vehicle": opt.vehicle, "frame": mission.waypoints.frame,
             "frame_name": mission.frame, "end": mission.end, "waypoints": len(mission.waypoints),
             "crs": s["crs"], "vertical_reference": s["vertical_reference"],
             "home": [s["home"]["lat"], s["home"]["lon"], s["home"]["alt_amsl_m"]],
             "home_source": s["home"]["source"], "warnings": list(mission.warnings),
             "notes": list(mission.info.get("notes", [])),
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
    if keys and getattr(mission, "returns", None) is not None:
        files.update(_return_files(mission, prefix))
    if opt.terrain if opt.terrain is not None else mission.frame == "terrain":
        files.update(terrain_export(world, [mission], [path], opt))
    return mission, files


def _return_files(mission: MissionExport, prefix: str) -> dict[str, ExportFile]:
    """The return files of a mission built with its returns (module docstring)."""
    from .params import write_params
    from .rally import write_rally_txt, write_rally_waypoints
    from .returns import write_returns

    rep = mission.returns
    writers: dict[str, Callable[[IO[Any]], Any]] = {
        "returns": lambda fh: write_returns(fh, mission)}
    if rep.params is not None:
        writers["param"] = lambda fh: write_params(fh, rep.params)
    if rep.rally:
        writers["rally"] = lambda fh: write_rally_waypoints(fh, mission)
        writers["rally_txt"] = lambda fh: write_rally_txt(fh, mission)
    return {prefix + RETURN_FILES[k]: ExportFile(prefix + RETURN_FILES[k], False, w)
            for k, w in writers.items()}


#: What a terrain folder is for (summary line): how to load it, what happens without it.
TERRAIN_LOAD = ("copy terrain/*.DAT to the SD card's APM/terrain/ folder (SITL: the terrain/ "
                "folder of its working directory) and set TERRAIN_ENABLE=1, TERRAIN_SPACING="
                "{spacing} (terrain/terrain.param)")
TERRAIN_WITHOUT = ("without them ArduPilot does not arm a terrain-frame mission (\"PreArm: "
                   "waiting for terrain data\") unless a ground station serves the terrain, and "
                   "with TERRAIN_ENABLE=0 not at all (\"PreArm: terrain disabled\")")


def terrain_export(world: Any, missions: Sequence[MissionExport], paths: Sequence[Any],
                   options: ExportOptions) -> dict[str, ExportFile]:
    """ArduPilot's terrain files of missions flown on one world: the blocks around their
    homes, items and paths (:func:`fm2uav.autopilot.terrain_grid.mission_terrain`), one
    ``terrain/NxxEyyy.DAT`` per degree and ``terrain/terrain.param``; each mission's
    ``info["terrain"]`` says what they hold and how to load them."""
    from ..autopilot.terrain_grid import mission_terrain

    items = [it for m in missions for it in m.items]
    path = np.vstack([np.asarray(p, dtype=float)[:, :3] if np.shape(p)[1] >= 3 else
                      np.column_stack([p, np.zeros(len(p))]) for p in paths])
    grid = mission_terrain(world, home_latlon=missions[0].home[:2], items=items, path_m=path,
                           anchor=options.anchor, spacing=options.terrain_spacing)
    info = {**grid.info, "folder": "terrain/",
            "load": TERRAIN_LOAD.format(spacing=grid.spacing), "without": TERRAIN_WITHOUT}
    for m in missions:
        m.info["terrain"] = info
    files = {f"terrain/{name}": ExportFile(f"terrain/{name}", True, write)
             for name, write in terrain_files(grid).items()}
    params = ("# ArduPilot parameters for the terrain files of this folder (fm2uav)\n"
              f"TERRAIN_ENABLE 1\nTERRAIN_SPACING {grid.spacing}\n")
    files["terrain/terrain.param"] = ExportFile("terrain/terrain.param", False,
                                                lambda fh: fh.write(params))
    return files


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
    tracks = tuple(getattr(result, "tracks", ()) or ())
    for i, name in enumerate(result.names):
        # the UAV's track: its final heights with times (one truth for all its files)
        tr = tracks[i] if i < len(tracks) else None
        path = np.asarray(result.positions[:, i] if tr is None else tr.path, dtype=float)
        times = result.times if tr is None else tr.times
        track = SimpleNamespace(path=path, world=world, w=None, level=None, params={},
                                length=path_length(path),
                                profile=None if tr is None else tr.profile)
        agl = result.agl[i] if i < len(result.agl) else None
        m, f = export_mission(track, formats, replace(opt, name=f"{opt.name} — {name}",
                                                      terrain=False),
                              agl=agl, times=times, start_hold=float(holds[i]),
                              prefix=file_prefix(name), fences=fences)
        missions[name] = m
        files.update(f)
    ms = list(missions.values())
    if opt.terrain if opt.terrain is not None else any(m.frame == "terrain" for m in ms):
        # one terrain folder for every vehicle: the blocks around all their paths
        files.update(terrain_export(world, ms, [np.asarray(m.path_m, dtype=float) for m in ms],
                                    opt))
    return missions, files


def export_writers(plan: Any, formats: Sequence[str], options: ExportOptions | None = None,
                   **kwargs: Any) -> tuple[dict[str, Callable[[IO[Any]], Any]], Any]:
    """``(file name → writer(fh), waypoints)``: :func:`export_mission` in the older
    two-value form (binary formats need a binary file)."""
    mission, files = export_mission(plan, formats, options, **kwargs)
    return {n: f.write for n, f in files.items()}, mission.waypoints
