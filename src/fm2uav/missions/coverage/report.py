"""Coverage report: the share of the area seen from a flown ground track."""

from __future__ import annotations

import numpy as np
import shapely
from shapely.geometry import Polygon

from ...errors import InputError

__all__ = ["coverage_share", "seen_region"]


def seen_region(track: np.ndarray, radius: float) -> shapely.Geometry:
    """Ground region within ``radius`` [m] of a polyline ``track`` (k, >=2) [m].

    Computed as the union of one capsule per segment, snap-rounded at
    ``radius * 1e-4`` (robust in GEOS).
    """
    xy = np.asarray(track, dtype=float)[:, :2]
    if xy.ndim != 2 or len(xy) < 1:
        raise InputError("the track must have at least one (x, y) point in metres")
    if not (np.isfinite(radius) and radius > 0):
        raise InputError(f"the coverage radius must be > 0 metres, got {radius!r}")
    # drop repeated points; a one-point track is a disc
    keep = np.r_[True, np.any(np.abs(np.diff(xy, axis=0)) > 1e-9, axis=1)]
    xy = xy[keep]
    if len(xy) == 1:
        return shapely.Point(xy[0]).buffer(radius)
    grid = _grid(radius)
    # exact vertices (simplified by < radius/10^4 only), buffered in short
    # overlapping chunks; a chunk whose buffer GEOS gets wrong is repaired with
    # make_valid, or else replaced by one capsule per segment (always valid)
    line = shapely.simplify(shapely.LineString(xy), radius * 1e-4)
    pts = shapely.get_coordinates(line)
    chunk = 24
    parts = []
    for i in range(0, len(pts) - 1, chunk):
        piece = pts[i : min(i + chunk + 1, len(pts))]
        buf = shapely.LineString(piece).buffer(radius, quad_segs=16)
        if not buf.is_valid:
            buf = shapely.make_valid(buf)
        if not buf.is_valid or buf.is_empty:
            segs = shapely.linestrings(np.stack([piece[:-1], piece[1:]], axis=1))
            buf = shapely.union_all(shapely.buffer(segs, radius, quad_segs=16), grid_size=grid)
        parts.append(buf)
    try:
        return shapely.union_all(parts, grid_size=grid)
    except shapely.errors.GEOSException:
        segs = shapely.linestrings(np.stack([pts[:-1], pts[1:]], axis=1))
        return shapely.union_all(shapely.buffer(segs, radius, quad_segs=16), grid_size=grid)


def _grid(radius: float) -> float:
    # snap-rounding overlay (robust in GEOS) at a precision far below any visual field
    return float(radius) * 1e-4


def coverage_share(area: Polygon, track: np.ndarray, radius: float) -> float:
    """Share of the area within ``radius`` of the ground track, in [0, 1].

    Parameters
    ----------
    area : shapely.Polygon
        The area to cover [m].
    track : ndarray, shape (k, 2) or (k, 3)
        Flown path [m]; only x, y are used (its ground track).
    radius : float
        Half-width of the useful visual field [m] (D/2 for bands D apart).
    """
    if area.area <= 0:
        raise InputError("the area has zero surface")
    seen = seen_region(track, radius)
    grid = _grid(radius)
    inside = shapely.intersection(shapely.set_precision(area, grid), seen, grid_size=grid)
    return float(inside.area / area.area)
