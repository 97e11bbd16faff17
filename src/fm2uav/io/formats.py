"""The export formats and the names of the files they write (no exporter imported).

Read by the exporters (:mod:`fm2uav.io.exports`), the mission-file schema
(``outputs.formats``) and the output sets (:mod:`fm2uav.pipeline.outputs`), so a
mission file's formats are checked, and an output folder's names known, without
loading the exporters, the autopilot layer or the kernels.
"""

from __future__ import annotations

__all__ = ["EXPORT_FILES", "RETURN_FILES", "FORMAT_ALIASES"]

#: Export format → file name.
EXPORT_FILES = {
    "csv": "path.csv",
    "geojson": "path.geojson",
    "kml": "path.kml",
    "kmz": "path.kmz",
    "plan": "mission.plan",
    "wpl": "mission.waypoints",
}
#: Files written with the exports when the returns are computed (rally files only with
#: rally points).
RETURN_FILES = {
    "param": "mission.param",
    "returns": "returns.geojson",
    "rally": "rally.waypoints",
    "rally_txt": "rally.txt",
}
#: Other names of formats.
FORMAT_ALIASES = {"waypoints": "wpl", "qgc": "plan"}
