"""All mission exports of one plan, by format name.

:func:`export_writers` turns a plan (or any dense path on a world) into a
mapping ``file name → writer(fh)`` for the text formats, so that callers (the
CLI) decide where and how files are written (atomically, without overwriting):

=========  ===================  ===========================================
format     file                 content
=========  ===================  ===========================================
csv        ``path.csv``         dense path x, y, z [m] and W
geojson    ``path.geojson``     3D LineString lon/lat/alt + waypoints
kml        ``path.kml``         3D LineString for Google Earth
plan       ``mission.plan``     QGroundControl plan (JSON)
wpl        ``mission.waypoints`` MAVLink ``QGC WPL 110`` (tab-separated)
=========  ===================  ===========================================
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import IO, Any

import numpy as np

from ..errors import InputError
from .geojson import write_geojson
from .georef import Anchor
from .kml import write_kml
from .paths import write_path_csv
from .qgc import write_plan
from .waypoints import Waypoints, mission_waypoints
from .wpl import write_wpl

__all__ = ["EXPORT_FILES", "ExportOptions", "export_writers"]

#: Export format → file name.
EXPORT_FILES = {
    "csv": "path.csv",
    "geojson": "path.geojson",
    "kml": "path.kml",
    "plan": "mission.plan",
    "wpl": "mission.waypoints",
}


@dataclass(frozen=True)
class ExportOptions:
    """How a path becomes a mission.

    Attributes
    ----------
    tolerance : float
        Douglas–Peucker tolerance [m] for the waypoints. Default 5 m.
    max_points : int or None
        Cap on the number of waypoints.
    frame : {"auto", "relative", "terrain"}
        MAVLink altitude frame (auto: terrain for terrain-following plans).
    anchor : Anchor or None
        Placement of worlds without CRS (default :data:`~fm2uav.io.georef.DEFAULT_ANCHOR`).
    takeoff : bool
        Start the mission with NAV_TAKEOFF.
    flight_alt : float
        Altitude above home for 2D paths [m].
    cruise_speed, hover_speed : float
        [m/s], written into the ``.plan``.
    vehicle, firmware : str
        ``.plan`` vehicle and firmware types (see :mod:`fm2uav.io.qgc`).
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


def export_writers(
    plan: Any,
    formats: list[str] | tuple[str, ...],
    options: ExportOptions | None = None,
) -> tuple[dict[str, Callable[[IO[str]], Any]], Waypoints]:
    """Writers of the requested export formats for a :class:`~fm2uav.Plan`.

    Parameters
    ----------
    plan : Plan
        Uses ``plan.path``, ``plan.speed``, ``plan.world`` and ``plan.params``
        (``"agl"`` in the params marks a terrain-following plan).
    formats : sequence of str
        Keys of :data:`EXPORT_FILES`; unknown keys raise InputError.
    options : ExportOptions, optional

    Returns
    -------
    writers : dict
        File name → ``writer(fh)`` writing that file to an open text file.
    waypoints : Waypoints
        The thinned, geo-referenced waypoints (also used by the plan/WPL writers).
    """
    opt = options or ExportOptions()
    bad = [f for f in formats if f not in EXPORT_FILES]
    if bad:
        raise InputError(
            f"unknown export format {bad[0]!r}; allowed: {', '.join(EXPORT_FILES)}"
        )
    world = plan.world
    path = np.asarray(plan.path, dtype=float)
    wps = mission_waypoints(
        path, world, tolerance=opt.tolerance, frame=opt.frame,
        terrain_following="agl" in (plan.params or {}), anchor=opt.anchor,
        flight_alt=opt.flight_alt, max_points=opt.max_points, takeoff=opt.takeoff,
    )
    props = {"length_m": round(float(plan.length), 3), "frame": wps.frame,
             "waypoints": len(wps), **{k: v for k, v in (plan.params or {}).items()
                                       if isinstance(v, (int, float, str, bool))}}
    writers: dict[str, Callable[[IO[str]], Any]] = {}
    for f in formats:
        name = EXPORT_FILES[f]
        if f == "csv":
            writers[name] = lambda fh: write_path_csv(fh, path, plan.speed)
        elif f == "geojson":
            writers[name] = lambda fh: write_geojson(
                fh, path, world, anchor=opt.anchor, waypoints_m=wps.points_m,
                properties=props)
        elif f == "kml":
            writers[name] = lambda fh: write_kml(
                fh, path, world, anchor=opt.anchor, waypoints_m=wps.points_m)
        elif f == "plan":
            writers[name] = lambda fh: write_plan(
                fh, wps, cruise_speed=opt.cruise_speed, hover_speed=opt.hover_speed,
                vehicle=opt.vehicle, firmware=opt.firmware)
        elif f == "wpl":
            writers[name] = lambda fh: write_wpl(fh, wps)
    return writers, wps
