"""Similarity of two paths: discrete Fréchet distance and area between curves.

The two measures of the curvature study (seed 004, §1 and §3.3): the
discrete Fréchet distance (Eiter & Mannila's coupling of the vertices,
Alt & Godau ref. [19]) and the area enclosed between two curves that share
their end points (the first curve followed by the second one reversed is a
closed polygon; its area is the area between them).
"""

from __future__ import annotations

from typing import Any

import numpy as np
import shapely
from shapely.geometry import LineString

from .._numba import njit
from ..errors import InputError

__all__ = ["frechet_distance", "area_between_curves"]


@njit(cache=True, nogil=True)
def _frechet_kernel(P, Q):
    n, m = P.shape[0], Q.shape[0]
    d = P.shape[1]
    row = np.empty(m)
    for i in range(n):
        prev_diag = 0.0  # ca[i-1, j-1]
        for j in range(m):
            s = 0.0
            for k in range(d):
                t = P[i, k] - Q[j, k]
                s += t * t
            c = np.sqrt(s)
            if i == 0 and j == 0:
                v = c
            elif i == 0:
                v = max(row[j - 1], c)
            elif j == 0:
                v = max(row[0], c)
            else:
                best = min(row[j], prev_diag, row[j - 1])  # up, diagonal, left
                v = max(best, c)
            prev_diag = row[j] if i > 0 else 0.0
            row[j] = v
    return row[m - 1]


def _as_curve(c: Any, what: str) -> np.ndarray:
    try:
        arr = np.asarray(c, dtype=np.float64)
    except (TypeError, ValueError):
        raise InputError(f"{what} must be an (N, d) array of points, got {type(c).__name__}") from None
    if arr.ndim != 2 or arr.shape[0] < 1 or arr.shape[1] < 1:
        raise InputError(f"{what} must be an (N, d) array of points with N >= 1, got shape {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise InputError(f"{what} has non-finite coordinates")
    return np.require(arr, requirements=("C", "W"))  # one compiled signature for any caller



def _as_curves(P: Any, Q: Any) -> tuple[np.ndarray, np.ndarray]:
    """The two curves ``P``, ``Q`` of a comparison as (N, d) float arrays (:func:`_as_curve`)."""
    return _as_curve(P, "P"), _as_curve(Q, "Q")


def frechet_distance(P: Any, Q: Any) -> float:
    """Discrete Fréchet distance between two polylines (compiled, O(N·M)).

    The smallest, over all monotone couplings of the vertices of ``P`` and
    ``Q`` (both walked forward from their first point, each step advancing
    one or both), of the largest distance between coupled vertices.

    Parameters
    ----------
    P, Q : array_like, shape (N, d) and (M, d)
        Points [m], same dimension ``d``.

    Returns
    -------
    float
        Distance [m].

    Examples
    --------
    >>> frechet_distance([[0, 0], [1, 0], [2, 0]], [[0, 1], [2, 1]])
    1.4142135623730951
    """
    p, q = _as_curves(P, Q)
    if p.shape[1] != q.shape[1]:
        raise InputError(f"P and Q must have the same dimension, got {p.shape[1]} and {q.shape[1]}")
    return float(_frechet_kernel(p, q))


@njit(cache=True)
def _winding(ring, x, y):
    """Winding number of the closed polyline ``ring`` (last == first) around (x, y)."""
    w = 0
    for i in range(ring.shape[0] - 1):
        x0, y0 = ring[i, 0], ring[i, 1]
        x1, y1 = ring[i + 1, 0], ring[i + 1, 1]
        cross = (x1 - x0) * (y - y0) - (x - x0) * (y1 - y0)
        if y0 <= y:
            if y1 > y and cross > 0:
                w += 1
        elif y1 <= y and cross < 0:
            w -= 1
    return w


@njit(cache=True)
def _wound_area(ring, areas, xy):
    """Sum, in order, of the ``areas`` [m²] of the faces with a positive area whose inner
    point ``xy[i]`` the closed polyline ``ring`` winds around."""
    total = 0.0
    for i in range(areas.shape[0]):
        if areas[i] > 0.0 and _winding(ring, xy[i, 0], xy[i, 1]) != 0:
            total += areas[i]
    return total


def area_between_curves(P: Any, Q: Any) -> float:
    """Area enclosed between two 2D curves with common end points [m²].

    As in the seed (§3.3): ``P`` followed by ``Q`` reversed is a closed
    polygon. Where the curves cross, it is self-intersecting; its area is
    taken as the area of the set of points it winds around (non-zero winding
    number), so every lobe between the curves counts positively, once. If the
    end points differ, the two closing segments bound the polygon.

    Parameters
    ----------
    P, Q : array_like, shape (N, 2) and (M, 2)
        Points [m].

    Returns
    -------
    float
        Area [m²]; 0 for identical curves.

    Examples
    --------
    >>> area_between_curves([[0, 0], [1, 1], [2, 0]], [[0, 0], [2, 0]])
    1.0
    """
    p, q = _as_curves(P, Q)
    if p.shape[1] != 2 or q.shape[1] != 2:
        raise InputError("area_between_curves needs 2D curves (N, 2)")
    ring = np.concatenate([p, q[::-1], p[:1]])
    keep = np.ones(len(ring), dtype=bool)
    keep[1:] = np.any(np.diff(ring, axis=0) != 0.0, axis=1)
    ring = np.ascontiguousarray(ring[keep])
    if len(ring) < 4:
        return 0.0
    noded = shapely.node(LineString(ring))
    faces = shapely.get_parts(shapely.polygonize(shapely.get_parts(noded)))
    if len(faces) == 0:
        return 0.0
    # the faces' areas, then the inner points (representative_point) of those with a
    # positive area, in one call each; the faces the polygon winds around summed in order
    areas = np.asarray(shapely.area(faces), dtype=np.float64)
    keep = areas > 0.0
    if not keep.any():
        return 0.0
    pts = shapely.point_on_surface(faces[keep])
    xy = np.column_stack([shapely.get_x(pts), shapely.get_y(pts)])
    return float(_wound_area(ring, np.ascontiguousarray(areas[keep]), xy))
