"""Reading and writing: path files, geo-referencing, mission exports, mission files.

Exports (all in WGS84 lon/lat; see :mod:`fm2uav.io.georef` for how worlds
without a CRS are placed on the Earth): CSV, GeoJSON, KML, QGroundControl
``.plan`` and MAVLink ``QGC WPL 110``; waypoints are thinned from the dense
path with 3D Douglas–Peucker. Mission files: :mod:`fm2uav.io.mission`.
"""

from .exports import EXPORT_FILES, ExportOptions, export_writers
from .geojson import geojson_document, read_geojson_path, write_geojson
from .georef import DEFAULT_ANCHOR, Anchor, from_lonlat, ground_height, to_lonlat
from .kml import kml_document, read_kml_path, write_kml
from .paths import read_path_csv, write_path_csv
from .qgc import plan_document, read_plan, validate_plan, write_plan
from .thin import thin_indices, thin_path
from .trajectories import (
    read_trajectories_csv,
    write_cycles_csv,
    write_formation_metrics_csv,
    write_trajectories_csv,
)
from .waypoints import Waypoints, mission_waypoints
from .wpl import read_wpl, write_wpl

__all__ = [
    "read_path_csv",
    "write_path_csv",
    "Anchor",
    "DEFAULT_ANCHOR",
    "to_lonlat",
    "from_lonlat",
    "ground_height",
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
    "export_writers",
]
