"""Reading and writing: path files, geo-referencing, mission exports, mission files.

Exports (all in WGS84 lon/lat; see :func:`fm2uav.world.geo.to_lonlat` for how worlds
without a CRS are placed on the Earth): CSV, GeoJSON, KML/KMZ, QGroundControl
``.plan`` and MAVLink ``QGC WPL 110``, all written by :func:`export_mission`
from one list of MAVLink items (:mod:`fm2uav.io.build`: takeoff, waypoints
thinned with 3D Douglas–Peucker, speeds, camera triggers, RTL/land/loiter),
checked per firmware (:mod:`fm2uav.io.validate`). Mission files:
:mod:`fm2uav.io.mission`.
"""

import importlib
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:  # loaded on first attribute access (PEP 562), see __getattr__
    from .build import CameraPlan, MissionExport, build_mission, speed_commands
    from .exports import (
        EXPORT_FILES,
        ExportFile,
        ExportOptions,
        export_formation,
        export_mission,
        export_writers,
        parse_formats,
    )
    from ..world.geo import DEFAULT_ANCHOR, Anchor, from_lonlat, to_lonlat  # the one conversion
    from .geofence import FenceCircle, FencePolygon, fences_from_world, geofence_document
    from .items import MissionItem
    from .validate import Problem, check_mission, validate_mission
    from .geojson import geojson_document, read_geojson_path, write_geojson
    from .kml import kml_document, read_kml_path, write_kml, write_kmz
    from .paths import read_path_csv, write_path_csv
    from .qgc import plan_document, read_plan, validate_plan, write_plan
    from .thin import thin_indices, thin_path
    from .trajectories import (
        read_trajectories_csv,
        write_cycles_csv,
        write_formation_metrics_csv,
        write_trajectories_csv,
    )
    from .waypoints import Waypoints, mission_waypoints, resolve_frame
    from .wpl import read_wpl, write_wpl

#: Where each public name lives (relative to this package). ``import fm2uav.io.outdir``
#: (every command's output set) loads none of them: the writers and the mission builder
#: (numpy, numba, shapely, pyproj) are imported on first access.
_LAZY_NAMES = {
    "CameraPlan": ".build",
    "MissionExport": ".build",
    "build_mission": ".build",
    "speed_commands": ".build",
    "EXPORT_FILES": ".exports",
    "ExportFile": ".exports",
    "ExportOptions": ".exports",
    "export_formation": ".exports",
    "export_mission": ".exports",
    "export_writers": ".exports",
    "parse_formats": ".exports",
    "DEFAULT_ANCHOR": "..world.geo",
    "Anchor": "..world.geo",
    "from_lonlat": "..world.geo",
    "to_lonlat": "..world.geo",
    "FenceCircle": ".geofence",
    "FencePolygon": ".geofence",
    "fences_from_world": ".geofence",
    "geofence_document": ".geofence",
    "MissionItem": ".items",
    "Problem": ".validate",
    "check_mission": ".validate",
    "validate_mission": ".validate",
    "geojson_document": ".geojson",
    "read_geojson_path": ".geojson",
    "write_geojson": ".geojson",
    "kml_document": ".kml",
    "read_kml_path": ".kml",
    "write_kml": ".kml",
    "write_kmz": ".kml",
    "read_path_csv": ".paths",
    "write_path_csv": ".paths",
    "plan_document": ".qgc",
    "read_plan": ".qgc",
    "validate_plan": ".qgc",
    "write_plan": ".qgc",
    "thin_indices": ".thin",
    "thin_path": ".thin",
    "read_trajectories_csv": ".trajectories",
    "write_cycles_csv": ".trajectories",
    "write_formation_metrics_csv": ".trajectories",
    "write_trajectories_csv": ".trajectories",
    "Waypoints": ".waypoints",
    "mission_waypoints": ".waypoints",
    "resolve_frame": ".waypoints",
    "read_wpl": ".wpl",
    "write_wpl": ".wpl",
}


def __getattr__(name: str) -> Any:
    if name in _LAZY_NAMES:
        value = getattr(importlib.import_module(_LAZY_NAMES[name], __name__), name)
        globals()[name] = value  # later accesses skip __getattr__
        return value
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_LAZY_NAMES))


__all__ = [
    "read_path_csv",
    "write_path_csv",
    "Anchor",
    "DEFAULT_ANCHOR",
    "to_lonlat",
    "from_lonlat",
    "thin_path",
    "thin_indices",
    "Waypoints",
    "mission_waypoints",
    "geojson_document",
    "write_geojson",
    "read_geojson_path",
    "kml_document",
    "write_kml",
    "read_kml_path",
    "plan_document",
    "write_plan",
    "read_plan",
    "validate_plan",
    "write_wpl",
    "read_wpl",
    "write_trajectories_csv",
    "read_trajectories_csv",
    "write_formation_metrics_csv",
    "write_cycles_csv",
    "EXPORT_FILES",
    "ExportOptions",
    "ExportFile",
    "export_mission",
    "export_formation",
    "export_writers",
    "parse_formats",
    "build_mission",
    "MissionExport",
    "CameraPlan",
    "speed_commands",
    "MissionItem",
    "validate_mission",
    "check_mission",
    "Problem",
    "FencePolygon",
    "FenceCircle",
    "fences_from_world",
    "geofence_document",
    "resolve_frame",
    "write_kmz",
]
