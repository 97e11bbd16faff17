"""Lengths of lon/lat polylines on the WGS84 ellipsoid, as an independent check measures them.

A written line is what an operator (or a check) measures: the sum, segment by segment, of
the geodesic distance on the WGS84 ellipsoid (``pyproj.Geod.inv``, Karney's algorithm) —
combined, on lines with an altitude, with the altitude change of the segment
(``hypot(geodesic, dz)``). That is not the planner's path length in the map's metres: the
written line is thinned, its coordinates rounded, and a projected map's metres differ from
the ellipsoid's by the projection's scale factor (up to 0.5 %, ``world.geo``).
"""

from __future__ import annotations

from collections.abc import Sequence
from functools import lru_cache
from typing import Any

import numpy as np

__all__ = ["lonlat_line_lengths"]


@lru_cache(maxsize=1)
def _wgs84() -> Any:
    from pyproj import Geod

    return Geod(ellps="WGS84")


def lonlat_line_lengths(lines: Sequence[Any]) -> np.ndarray:
    """Length [m] of each polyline of ``[lon, lat]`` or ``[lon, lat, alt]`` positions.

    Parameters
    ----------
    lines : sequence of array_like, each shape (n_i, 2) or (n_i, 3)
        Longitude and latitude [degrees, WGS84] and optionally altitude [m] per point;
        every line with the same number of columns.

    Returns
    -------
    ndarray, shape (len(lines),)
        The sum over each line's segments of the WGS84 geodesic distance [m], or of
        ``hypot(geodesic, altitude change)`` with an altitude column; 0 for a line of
        fewer than two points.

    Examples
    --------
    >>> lonlat_line_lengths([[[0.0, 0.0], [0.0, 1.0]], [[0.0, 0.0, 0.0], [0.0, 0.0, 30.0]]])
    Traceback (most recent call last):
    ...
    ValueError: every line needs the same columns (lon, lat[, alt]); got 2 and 3
    >>> lonlat_line_lengths([[[0.0, 0.0], [0.0, 1.0]], [[5.0, 45.0]]]).round(3)
    array([110574.389,      0.   ])
    """
    arrays = [np.asarray(line, dtype=float).reshape(len(line), -1) for line in lines]
    if not arrays:
        return np.zeros(0)
    cols = {a.shape[1] for a in arrays}
    if len(cols) > 1 or not cols <= {2, 3}:
        raise ValueError("every line needs the same columns (lon, lat[, alt]); got "
                         + " and ".join(str(c) for c in sorted(cols)))
    counts = np.array([len(a) for a in arrays])
    out = np.zeros(len(arrays))
    if counts.max() < 2:
        return out
    pts = np.concatenate(arrays)
    a, b = pts[:-1], pts[1:]
    _, _, d = _wgs84().inv(a[:, 0], a[:, 1], b[:, 0], b[:, 1])
    d = np.asarray(d, dtype=float)
    if pts.shape[1] == 3:
        d = np.hypot(d, b[:, 2] - a[:, 2])
    first = np.cumsum(counts) - counts  # each line's first point = its first segment
    long = counts >= 2
    # a line's segments are first .. first + n - 2; the one after it joins two lines
    segs = np.zeros(len(d) + 1)
    segs[:-1] = d
    bounds = np.column_stack([first[long], first[long] + counts[long] - 1]).ravel()
    out[long] = np.add.reduceat(segs, bounds)[::2]
    return out
