"""The area to cover: parsing and validation of a polygon (shapely).

An area is one valid polygon in world metres, possibly non-convex and with
holes. Everything a user can get wrong (empty, self-intersecting, degenerate,
several parts, outside the map, a band spacing that is not positive or larger
than the area) raises :class:`fm2uav.InputError` with what, where and how to fix.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np
import shapely
from shapely.geometry import MultiPolygon, Polygon, shape
from shapely.validation import explain_validity

from ...errors import InputError

__all__ = ["as_area", "read_area", "load_area", "check_spacing", "check_inside_world", "exterior_edges"]

#: Largest number of bands accepted (guards against D given in the wrong unit).
MAX_BANDS = 5000


def _from_geojson(obj: dict) -> Any:
    kind = obj.get("type")
    if kind == "FeatureCollection":
        feats = obj.get("features") or []
        polys = [f for f in feats if (f.get("geometry") or {}).get("type") in ("Polygon", "MultiPolygon")]
        if len(polys) != 1:
            raise InputError(
                f"the GeoJSON FeatureCollection has {len(polys)} polygon features; give exactly "
                "one area to cover (split the file, or cover each area separately)"
            )
        return shape(polys[0]["geometry"])
    if kind == "Feature":
        if not obj.get("geometry"):
            raise InputError("the GeoJSON Feature has no geometry; give a Polygon")
        return shape(obj["geometry"])
    if kind in ("Polygon", "MultiPolygon"):
        return shape(obj)
    raise InputError(
        f"GeoJSON of type {kind!r} is not an area; give a Polygon (or a Feature holding one)"
    )


def as_area(area: Any) -> Polygon:
    """Validate an area and return it as a shapely :class:`Polygon` [m].

    Parameters
    ----------
    area : Polygon, MultiPolygon with one part, GeoJSON-like dict, or (k, 2) vertices
        The surface to cover, in world metres (x, y). Holes are allowed.

    Raises
    ------
    InputError
        Empty, not a polygon, several parts, self-intersecting / invalid,
        degenerate (zero area), or non-finite coordinates.
    """
    if isinstance(area, dict):
        geom = _from_geojson(area)
    elif isinstance(area, (Polygon, MultiPolygon)):
        geom = area
    elif isinstance(area, shapely.Geometry):
        raise InputError(
            f"the area must be a polygon, got a {area.geom_type}; give a closed ring of "
            "at least 3 vertices"
        )
    else:
        try:
            pts = np.asarray(area, dtype=float)
        except (TypeError, ValueError):
            raise InputError(
                f"the area must be a shapely Polygon, a GeoJSON dict or (k, 2) vertices in "
                f"metres, got {type(area).__name__}"
            ) from None
        if pts.size == 0:
            raise InputError("the area is empty: give at least 3 vertices (x, y) in metres")
        if pts.ndim != 2 or pts.shape[1] != 2:
            raise InputError(
                f"area vertices must be a (k, 2) array of (x, y) metres, got shape {pts.shape}"
            )
        if len(pts) < 3:
            raise InputError(
                f"the area has only {len(pts)} vertices; a polygon needs at least 3"
            )
        if not np.all(np.isfinite(pts)):
            raise InputError("the area has NaN/inf coordinates; give finite metres")
        geom = Polygon(pts)
    if geom.is_empty:
        raise InputError("the area is empty: give a polygon with at least 3 vertices")
    if isinstance(geom, MultiPolygon):
        if len(geom.geoms) != 1:
            raise InputError(
                f"the area has {len(geom.geoms)} separate parts; a zigzag covers one connected "
                "polygon — cover each part separately (or join them)"
            )
        geom = geom.geoms[0]
    coords = np.asarray(geom.exterior.coords)
    if not np.all(np.isfinite(coords)):
        raise InputError("the area has NaN/inf coordinates; give finite metres")
    if len(np.unique(np.round(coords, 9), axis=0)) < 3:
        raise InputError(
            "the area is degenerate: its exterior has fewer than 3 distinct vertices"
        )
    scale = max(float(np.ptp(coords[:, 0])), float(np.ptp(coords[:, 1])), 1e-300)
    centred = coords - coords.mean(axis=0)
    if np.linalg.svd(centred, compute_uv=False)[-1] <= 1e-9 * scale * np.sqrt(len(coords)):
        raise InputError(
            "the area is degenerate: all its vertices lie on one line (zero area); give a "
            "polygon that encloses a surface"
        )
    if not geom.is_valid:
        why = explain_validity(geom)
        raise InputError(
            f"the area is not a valid polygon: {why}; fix the ring (no self-intersections, "
            "holes strictly inside, vertices in order), e.g. with shapely.make_valid"
        )
    if geom.area <= 1e-9 * scale * scale:
        raise InputError(
            f"the area is degenerate: zero area ({geom.area:.3g} m²); give a polygon that "
            "encloses a surface"
        )
    return shapely.normalize(geom)


def load_area(file: str | Path, world: Any = None, *, crs: Any = None) -> tuple[Polygon, Any]:
    """Read an area from a vector file into the world's CRS and validate it.

    Any vector file :func:`fm2uav.world.vectors.read_vectors` reads works
    (GeoJSON — lon/lat per RFC 7946 unless it declares a CRS —, GeoPackage,
    Shapefile, KML/KMZ). On a geo-referenced world (``world.crs``) the polygon
    is reprojected into the world's metres; on a world without a CRS (the
    built-in synthetic maps) a file without a declared CRS is read in the
    map's metres, and one that looks like lon/lat is refused.

    Parameters
    ----------
    file : path
        The area file: exactly one polygon (holes allowed).
    world : World, optional
        The map (its ``crs``); ``None`` reads the file in its own coordinates.
    crs : optional
        CRS of a file that declares none (CLI ``--crs``).

    Returns
    -------
    (Polygon, SourceFile)
        The area in world metres and where it came from (path, SHA-256, CRS rule).

    Raises
    ------
    InputError
        Missing file, no single polygon, invalid polygon.
    WorldError
        Unreadable file, coordinates that do not fit the CRS, lon/lat on a map
        without a CRS.
    """
    from ...world.vectors import read_vectors

    file = Path(file)
    if not file.exists():
        raise InputError(f"area file {file} does not exist")
    target = getattr(world, "crs", None) if world is not None else None
    data = read_vectors(file, target_crs=target, crs=crs, role="area", repair=False)
    if len(data.geometries) != 1:
        skipped = (f" (left out: {', '.join(f'{n} {k}' for k, n in data.skipped.items())})"
                   if data.skipped else "")
        raise InputError(
            f"the area file {file} has {len(data.geometries)} polygon features{skipped}; give "
            "exactly one area to cover (split the file, or cover each area separately)")
    return as_area(data.geometries[0]), data.source


def read_area(file: str | Path, world: Any = None, *, crs: Any = None) -> Polygon:
    """Read an area from a vector file and validate it (see :func:`load_area`).

    Raises
    ------
    InputError
        Missing file, no single polygon, invalid polygon.
    """
    return load_area(file, world, crs=crs)[0]


def check_spacing(area: Polygon, spacing: float) -> float:
    """Validate the band spacing D [m] against the area.

    Raises
    ------
    InputError
        D not finite or <= 0; D larger than the area (its diameter: one
        camera footprint would cover it all); or so small that more than
        :data:`MAX_BANDS` bands are needed (probably a unit mistake).
    """
    try:
        d = float(spacing)
    except (TypeError, ValueError):
        raise InputError(f"the band spacing D must be a number of metres, got {spacing!r}") from None
    if not math.isfinite(d) or d <= 0:
        raise InputError(f"the band spacing D must be > 0 metres, got {spacing!r}")
    hull = np.asarray(area.convex_hull.exterior.coords)
    diff = hull[:, None, :] - hull[None, :, :]
    diameter = float(np.sqrt((diff**2).sum(-1)).max())
    if d > diameter:
        raise InputError(
            f"the band spacing D = {d:g} m is larger than the area (its widest extent is "
            f"{diameter:.1f} m): a single pass already covers it; use D <= {diameter:.1f} m"
        )
    if diameter / d > MAX_BANDS:
        raise InputError(
            f"the band spacing D = {d:g} m needs more than {MAX_BANDS} bands over an area "
            f"{diameter:.1f} m wide; is D in metres? use a larger spacing"
        )
    return d


def check_inside_world(area: Polygon, world: Any, *, margin: float = 0.0) -> None:
    """Raise InputError unless the area (grown by ``margin`` [m]) lies in the map's x-y extent."""
    b = np.asarray(world.bounds, dtype=float)
    box = shapely.box(b[0, 0], b[1, 0], b[0, 1], b[1, 1])
    if not area.intersects(box):
        x0, y0, x1, y1 = area.bounds
        raise InputError(
            f"the area (x in [{x0:.1f}, {x1:.1f}], y in [{y0:.1f}, {y1:.1f}] m) lies outside the "
            f"map (x in [{b[0, 0]:g}, {b[0, 1]:g}], y in [{b[1, 0]:g}, {b[1, 1]:g}] m); "
            "check the area's coordinates and CRS (--area / world.crs, --crs) or widen the map "
            "to cover it (world.bbox, CLI --bbox W,S,E,N)"
        )
    grown = area.buffer(margin) if margin > 0 else area
    outside = grown.difference(box)
    if outside.area > 1e-6 * max(area.area, 1.0):
        c = outside.representative_point()
        what = "the area" if margin <= 0 else f"the area plus the {margin:g} m turn margin"
        raise InputError(
            f"{what} leaves the map by {outside.area:.0f} m², e.g. at ({c.x:.1f}, {c.y:.1f}) m "
            f"(map x in [{b[0, 0]:g}, {b[0, 1]:g}], y in [{b[1, 0]:g}, {b[1, 1]:g}] m); move or "
            "shrink the area, or use a larger map"
        )


def exterior_edges(area: Polygon) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Edges ``a -> b`` of the exterior ring as four contiguous float arrays [m].

    Holes never change a strip's along-band extent (the exterior boundary is
    part of the area), so the cost needs the exterior only.
    """
    xy = np.asarray(area.exterior.coords, dtype=float)
    a, b = xy[:-1], xy[1:]
    return (np.ascontiguousarray(a[:, 0]), np.ascontiguousarray(a[:, 1]),
            np.ascontiguousarray(b[:, 0]), np.ascontiguousarray(b[:, 1]))
