"""Waypoint thinning: Douglas–Peucker in 2D or 3D.

A planned path has hundreds or thousands of points (half a cell apart); an
autopilot mission wants tens of waypoints. :func:`thin_path` keeps the fewest
points such that every dropped point lies within ``tolerance`` metres of the
straight segment that replaces it (Euclidean distance in x, y and z, so climbs
are kept as well as turns). Start and goal are always kept.

(The ``simplification`` package's RDP is 2D only; this one works in any dimension:
compiled splits (:mod:`._thin_kernels`) with numpy deciding the near ties, so the indices
are those of the numpy algorithm, :func:`_split_in_order`, bit for bit.)

Douglas–Peucker bounds the distance to the dense path, not the height above
the ground: the legs it keeps are checked against the world by
:func:`fm2uav.autopilot.legs.refine_legs`.
"""

from __future__ import annotations

import heapq
from typing import Any

import numpy as np

from ..errors import InputError

__all__ = ["thin_path", "thin_indices", "segment_distances"]


def segment_distances(points: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Distance [m] from each of ``points`` ``(m, d)`` to the segment ``a``–``b``."""
    ab = b - a
    L2 = float(ab @ ab)
    if L2 == 0.0:
        return np.linalg.norm(points - a, axis=1)
    t = np.clip((points - a) @ ab / L2, 0.0, 1.0)
    return np.linalg.norm(points - (a + t[:, None] * ab), axis=1)


def thin_indices(path: Any, tolerance: float, *, max_points: int | None = None) -> np.ndarray:
    """Indices of the points Douglas–Peucker keeps (sorted, first and last included).

    Parameters
    ----------
    path : array_like, shape (N, d)
        Points [m], d = 2 or 3.
    tolerance : float
        Largest allowed distance [m] of a dropped point from the kept polyline
        (>= 0; 0 keeps every point that is not exactly collinear).
    max_points : int, optional
        Stop refining once this many points are kept (>= 2); the worst
        remaining deviation is then above ``tolerance``.

    Returns
    -------
    ndarray of int
    """
    p = np.asarray(path, dtype=float)
    if p.ndim != 2 or p.shape[0] < 1 or p.shape[1] not in (2, 3):
        raise InputError(f"path must be an (N, 2) or (N, 3) array of points, got shape {p.shape}")
    if not np.all(np.isfinite(p)):
        raise InputError("path has non-finite coordinates")
    if not np.isfinite(tolerance) or tolerance < 0:
        raise InputError(f"tolerance must be a distance >= 0 m, got {tolerance!r}")
    if max_points is not None and max_points < 2:
        raise InputError(f"max_points must be >= 2, got {max_points!r}")
    n = len(p)
    if n <= 2:
        return np.arange(n)
    kept = _split_compiled(p, float(tolerance))
    if max_points is None or len(kept) <= max_points:
        return kept  # the budget is never reached: the splits' order does not matter
    return _split_in_order(p, float(tolerance), max_points)


def _split_compiled(p: np.ndarray, tolerance: float) -> np.ndarray:
    """Douglas–Peucker without a point budget: the compiled splits
    (:func:`._thin_kernels.split_all`), the segments they leave undecided decided here with
    :func:`segment_distances` — the indices of :func:`_split_in_order` without a budget."""
    from ._thin_kernels import split_all

    n = len(p)
    # C order and writeable: one compiled signature for every caller (a plan's read-only
    # path would compile a second one)
    p = np.require(p, requirements=("C", "W"))
    keep = np.zeros(n, dtype=bool)
    keep[0] = keep[-1] = True
    todo = np.zeros((n, 2), dtype=np.int64)
    todo[0] = (0, n - 1)
    n_todo = 1
    undecided = np.zeros((n, 2), dtype=np.int64)
    while n_todo:
        m = split_all(p, tolerance, keep, todo, n_todo, undecided)
        n_todo = 0
        for i, j in undecided[:m].tolist():
            d = segment_distances(p[i + 1 : j], p[i], p[j])
            k = int(np.argmax(d))
            if float(d[k]) > tolerance:
                keep[i + 1 + k] = True
                todo[n_todo], todo[n_todo + 1] = (i, i + 1 + k), (i + 1 + k, j)
                n_todo += 2
    return np.flatnonzero(keep)


def _split_in_order(p: np.ndarray, tolerance: float, max_points: int | None) -> np.ndarray:
    """Douglas–Peucker splitting the worst segment first, up to ``max_points`` points."""
    n = len(p)
    keep = np.zeros(n, dtype=bool)
    keep[0] = keep[-1] = True
    # always split the segment with the largest deviation first (a max-heap),
    # so that truncation at max_points keeps the most important points
    segments: list[tuple[float, int, int, int]] = []

    def worst(i: int, j: int) -> tuple[float, int, int, int] | None:
        if j - i < 2:
            return None
        d = segment_distances(p[i + 1 : j], p[i], p[j])
        k = int(np.argmax(d))
        return (-float(d[k]), i, j, i + 1 + k)

    first = worst(0, n - 1)
    if first is not None:
        heapq.heappush(segments, first)
    count = 2
    while segments:
        neg, i, j, k = heapq.heappop(segments)
        if -neg <= tolerance:
            break
        if max_points is not None and count >= max_points:
            break
        keep[k] = True
        count += 1
        for seg in (worst(i, k), worst(k, j)):
            if seg is not None:
                heapq.heappush(segments, seg)
    return np.flatnonzero(keep)


def thin_path(path: Any, tolerance: float, *, max_points: int | None = None) -> np.ndarray:
    """The Douglas–Peucker-thinned path ``(n, d)`` [m]; see :func:`thin_indices`.

    Examples
    --------
    >>> import numpy as np
    >>> line = np.column_stack([np.linspace(0, 100, 201), np.zeros(201), np.zeros(201)])
    >>> thin_path(line, 0.1).tolist()
    [[0.0, 0.0, 0.0], [100.0, 0.0, 0.0]]
    """
    p = np.asarray(path, dtype=float)
    return p[thin_indices(p, tolerance, max_points=max_points)]
