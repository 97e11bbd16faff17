"""File formats: path files, geo-referencing, mission exports, mission files.

Exports (all in WGS84 lon/lat; see :func:`fm2uav.world.geo.to_lonlat` for how worlds
without a CRS are placed on the Earth): CSV, GeoJSON, KML/KMZ, QGroundControl
``.plan`` and MAVLink ``QGC WPL 110``, all written by :func:`export_mission`
from one mission built by :mod:`fm2uav.autopilot` (MAVLink items, firmware
checks, leg checks, geofences). Mission files: :mod:`fm2uav.io.mission`.
Readers and writers only: they take items and points and compute nothing.

The mission names of :mod:`fm2uav.autopilot` (``build_mission``,
``ExportOptions``, ``MissionItem``, ``validate_mission``, ...) live there; they
are re-exported here so that code written before the autopilot layer keeps working.
"""

from typing import TYPE_CHECKING

from .._lazy import lazy_names

if TYPE_CHECKING:  # loaded on first attribute access (PEP 562), see __getattr__
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
    from .geojson import geojson_document, read_geojson_path, write_geojson
    from .kml import kml_document, read_kml_path, write_kml, write_kmz
    from .paths import read_path_csv, write_path_csv
    from .qgc import geofence_document, plan_document, read_plan, validate_plan, write_plan
    from .trajectories import (
        read_trajectories_csv,
        write_cycles_csv,
        write_formation_metrics_csv,
        write_trajectories_csv,
    )
    from .wpl import read_wpl, write_wpl

    # the mission itself lives in fm2uav.autopilot (re-exported for existing code)
    from ..autopilot import (
        CameraPlan,
        FenceCircle,
        FencePolygon,
        MissionExport,
        MissionItem,
        Problem,
        Waypoints,
        build_mission,
        check_mission,
        fences_from_world,
        mission_waypoints,
        resolve_frame,
        speed_commands,
        thin_indices,
        thin_path,
        validate_mission,
    )

#: Where each public name lives (relative to this package). ``import fm2uav.io.outdir``
#: (every command's output set) loads none of them: the writers and the mission builder
#: (numpy, numba, shapely, pyproj) are imported on first access.
_LAZY_NAMES = {
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
    "geojson_document": ".geojson",
    "read_geojson_path": ".geojson",
    "write_geojson": ".geojson",
    "kml_document": ".kml",
    "read_kml_path": ".kml",
    "write_kml": ".kml",
    "write_kmz": ".kml",
    "read_path_csv": ".paths",
    "write_path_csv": ".paths",
    "geofence_document": ".qgc",
    "plan_document": ".qgc",
    "read_plan": ".qgc",
    "validate_plan": ".qgc",
    "write_plan": ".qgc",
    "read_trajectories_csv": ".trajectories",
    "write_cycles_csv": ".trajectories",
    "write_formation_metrics_csv": ".trajectories",
    "write_trajectories_csv": ".trajectories",
    "read_wpl": ".wpl",
    "write_wpl": ".wpl",
    "CameraPlan": "..autopilot",
    "FenceCircle": "..autopilot",
    "FencePolygon": "..autopilot",
    "MissionExport": "..autopilot",
    "MissionItem": "..autopilot",
    "Problem": "..autopilot",
    "Waypoints": "..autopilot",
    "build_mission": "..autopilot",
    "check_mission": "..autopilot",
    "fences_from_world": "..autopilot",
    "mission_waypoints": "..autopilot",
    "resolve_frame": "..autopilot",
    "speed_commands": "..autopilot",
    "thin_indices": "..autopilot",
    "thin_path": "..autopilot",
    "validate_mission": "..autopilot",
}


__getattr__, __dir__ = lazy_names(__name__, _LAZY_NAMES)

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
