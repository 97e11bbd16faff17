"""GeoJSON export (RFC 7946): the path as a 3D LineString in WGS84.

A FeatureCollection with

* ``"path"``: LineString ``[lon, lat, alt]`` of the dense path (alt in metres
  above the world's vertical datum, normally mean sea level);
* ``"waypoints"`` (optional): LineString of the thinned mission waypoints;
* ``"start"`` and ``"goal"``: Points.

Coordinates carry 9 decimals (~0.1 mm), so a round trip is exact to 1e-7°.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import IO, Any

import numpy as np

from ..errors import InputError
from ..world.geo import Anchor, to_lonlat

__all__ = ["geojson_document", "write_geojson", "read_geojson_path"]


def _coords(geo: np.ndarray) -> list[list[float]]:
    return [[round(float(lo), 9), round(float(la), 9), round(float(al), 3)] for lo, la, al in geo]


def geojson_document(
    path_m: Any,
    world: Any,
    *,
    anchor: Anchor | None = None,
    waypoints_m: Any = None,
    properties: dict[str, Any] | None = None,
) -> dict[str, Any]:
    """FeatureCollection of a path (see the module docstring)."""
    p = np.asarray(path_m, dtype=float)
    if p.ndim != 2 or len(p) < 2:
        raise InputError(f"path must be an (N, 2|3) array with N >= 2, got shape {p.shape}")
    geo = to_lonlat(world, p, anchor=anchor)
    props = {"name": "path", "points": int(len(p)), **(properties or {})}
    feats: list[dict[str, Any]] = [
        {"type": "Feature", "properties": props,
         "geometry": {"type": "LineString", "coordinates": _coords(geo)}},
    ]
    if waypoints_m is not None:
        wgeo = to_lonlat(world, np.asarray(waypoints_m, dtype=float), anchor=anchor)
        feats.append({"type": "Feature",
                      "properties": {"name": "waypoints", "points": int(len(wgeo))},
                      "geometry": {"type": "LineString", "coordinates": _coords(wgeo)}})
    for name, row in (("start", geo[0]), ("goal", geo[-1])):
        feats.append({"type": "Feature", "properties": {"name": name},
                      "geometry": {"type": "Point", "coordinates": _coords(row[None])[0]}})
    return {"type": "FeatureCollection", "features": feats}


def write_geojson(fh: IO[str], path_m: Any, world: Any, **options: Any) -> dict[str, Any]:
    """Write :func:`geojson_document` to an open text file; returns the document."""
    doc = geojson_document(path_m, world, **options)
    json.dump(doc, fh, indent=1, allow_nan=False)
    fh.write("\n")
    return doc


def read_geojson_path(file: str | Path, name: str = "path") -> np.ndarray:
    """``(N, 3)`` lon, lat, alt of the LineString feature called ``name``."""
    file = Path(file)
    from .. import _validate as _v

    _v.input_file(file, "GeoJSON file")  # no folder / named pipe (would block)
    try:
        doc = json.loads(file.read_text())
    except (OSError, json.JSONDecodeError) as exc:
        raise InputError(f"{file}: cannot read GeoJSON: {exc}") from None
    for f in doc.get("features", []):
        if f.get("properties", {}).get("name") == name and f["geometry"]["type"] == "LineString":
            return np.asarray(f["geometry"]["coordinates"], dtype=float)
    raise InputError(f"{file}: no LineString feature named {name!r}")
