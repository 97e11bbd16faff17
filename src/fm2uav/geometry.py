"""Polyline geometry shared by every layer: validation, arc length, resampling,
curvature (Menger / circumcurvature), heading, climb and turn angles, distance to
a polyline, runs of a boolean signal.

Points are world coordinates in metres, ``(N, 2)`` or ``(N, 3)``; angles are in
radians. Nothing here knows about worlds, waves or airframes.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from .errors import InputError

__all__ = [
    "as_path",
    "as_path3",
    "arc_length",
    "path_length",
    "path_lengths",
    "resample_path",
    "resample_uniform",
    "densify",
    "at_arc_length",
    "circumcurvature",
    "menger_curvature",
    "segment_angles",
    "turn_angles",
    "distance_to_polyline",
    "runs",
]


def as_path(path: Any) -> np.ndarray:
    """Validate a path ``(N, 2|3)`` [m], N >= 2, finite; return it as float (unchanged).

    Raises
    ------
    InputError
        Wrong shape, fewer than 2 points, NaN/inf.
    """
    p = np.asarray(path, dtype=float)
    if p.ndim != 2 or p.shape[1] not in (2, 3) or len(p) < 2:
        raise InputError(
            f"path must be an (N, 2) or (N, 3) array of N >= 2 points in metres, got shape {p.shape}"
        )
    if not np.all(np.isfinite(p)):
        raise InputError("path has non-finite coordinates")
    return p


def as_path3(path: Any, what: str = "path") -> np.ndarray:
    """Validate a path ``(N, 2|3)`` [m] and return it as ``(M, 3)`` float.

    2D paths get ``z = 0``. Consecutive duplicate points are dropped.

    Raises
    ------
    InputError
        Not numeric, wrong shape, fewer than 2 distinct points, NaN/inf.
    """
    try:
        p = np.asarray(path, dtype=float)
    except (TypeError, ValueError):
        raise InputError(f"{what} must be numeric points (N, 2) or (N, 3) in metres") from None
    if p.ndim != 2 or p.shape[1] not in (2, 3):
        raise InputError(
            f"{what} must have shape (N, 2) or (N, 3) (x, y[, z] in metres), got {p.shape}"
        )
    if len(p) < 2:
        raise InputError(f"{what} needs at least 2 points, got {len(p)}")
    if not np.all(np.isfinite(p)):
        r = int(np.argwhere(~np.isfinite(p))[0, 0])
        raise InputError(f"{what} has a NaN/inf coordinate at point {r}: {p[r].tolist()}")
    if p.shape[1] == 2:
        p = np.column_stack([p, np.zeros(len(p))])
    keep = np.concatenate([[True], np.linalg.norm(np.diff(p, axis=0), axis=1) > 1e-9])
    p = p[keep]
    if len(p) < 2:
        raise InputError(f"{what} has all its points at the same place {p[0].tolist()}")
    return p


def arc_length(path: np.ndarray) -> np.ndarray:
    """Cumulative arc length [m] at each point, starting at 0."""
    seg = np.linalg.norm(np.diff(path, axis=0), axis=1)
    return np.concatenate([[0.0], np.cumsum(seg)])


def path_length(path: np.ndarray) -> float:
    """Total length [m] of a polyline ``(N, d)`` (sum of its segment lengths)."""
    return float(np.sum(np.linalg.norm(np.diff(np.asarray(path, dtype=float), axis=0), axis=1)))


def path_lengths(paths: list[np.ndarray]) -> list[float]:
    """:func:`path_length` of each polyline ``(N_k, d)`` [m], the same numbers, the
    segments of all of them in a few array operations (one per axis).

    Each segment's length is ``sqrt(dx^2 + dy^2 [+ dz^2])`` summed in that order, as
    ``np.linalg.norm(..., axis=1)`` sums it, and each path's segments are added by
    ``np.sum`` (pairwise) as :func:`path_length` adds them.
    """
    if not paths:
        return []
    pts = np.concatenate([np.asarray(p, dtype=float) for p in paths])
    d = pts[1:] - pts[:-1]
    sq = d[:, 0] * d[:, 0]
    for c in range(1, pts.shape[1]):
        sq = sq + d[:, c] * d[:, c]
    seg = np.sqrt(sq)
    ends = np.cumsum([len(p) for p in paths]).tolist()
    return [float(np.sum(seg[b - n:b - 1])) if n > 1 else 0.0
            for b, n in zip(ends, (len(p) for p in paths))]


def resample_uniform(path: np.ndarray, ds: float) -> tuple[np.ndarray, np.ndarray]:
    """Points at ``ceil(length / ds)`` equal arc-length steps (<= ``ds`` [m]), both ends kept.

    Returns
    -------
    points : ndarray (M, d)
    s : ndarray (M,)
        Their arc length [m].
    """
    s = arc_length(path)
    n = max(int(np.ceil(s[-1] / ds)), 1)
    s_new = np.linspace(0.0, s[-1], n + 1)
    return at_arc_length(path, s, s_new), s_new


def at_arc_length(path: np.ndarray, s_arr: np.ndarray, s: Any) -> np.ndarray:
    """Points of a polyline ``(N, d)`` at arc length(s) ``s`` [m], linear, shape ``s.shape + (d,)``.

    ``s_arr`` is the polyline's :func:`arc_length`; ``s`` outside ``[0, L]`` gives
    the end points.
    """
    return np.stack([np.interp(s, s_arr, path[:, a]) for a in range(path.shape[1])], axis=-1)


def densify(points: np.ndarray, step: float, *, horizontal: bool = False
            ) -> tuple[np.ndarray, np.ndarray]:
    """Points every <= ``step`` [m] along a polyline, its vertices kept exactly.

    Each segment ``k`` is cut into ``n_k = max(ceil(length_k / step), 1)``
    equal pieces (``horizontal=True``: ``length_k`` is the x-y length).

    Returns
    -------
    points : ndarray, shape (M, d)
        ``p[k] + (i / n_k) (p[k+1] - p[k])`` for ``i < n_k``, then the last vertex.
    segment : ndarray of int, shape (M,)
        The segment each point lies on (the last vertex: the last segment).
    """
    p = np.asarray(points, dtype=float)
    if len(p) < 2:
        return p.copy(), np.zeros(len(p), dtype=np.int64)
    seg = np.linalg.norm(np.diff(p[:, :2] if horizontal else p, axis=0), axis=1)
    n = np.maximum(np.ceil(seg / step).astype(np.int64), 1)
    out, which = [], []
    for k in range(len(p) - 1):
        t = np.arange(n[k]) / n[k]
        out.append(p[k] + t[:, None] * (p[k + 1] - p[k]))
        which.append(np.full(n[k], k))
    out.append(p[-1:])
    which.append(np.array([len(p) - 2]))
    return np.concatenate(out), np.concatenate(which)


def resample_path(path: np.ndarray, ds: float) -> np.ndarray:
    """Points at arc-length steps of ``ds`` [m] along ``path`` (linear), both ends kept.

    The last step is shorter when the length is not a multiple of ``ds``.
    """
    p = as_path(path)
    if not (np.isfinite(ds) and ds > 0):
        raise InputError(f"ds must be a step > 0 metres, got {ds!r}")
    seg = np.linalg.norm(np.diff(p, axis=0), axis=1)
    keep = np.concatenate([[True], seg > 0])
    p = p[keep]
    s = np.concatenate([[0.0], np.cumsum(seg[seg > 0])])
    if len(p) < 2:
        return p
    n = max(int(np.ceil(s[-1] / ds - 1e-9)), 1)
    t = np.minimum(np.arange(n + 1) * ds, s[-1])
    t[-1] = s[-1]
    return at_arc_length(p, s, t)


def circumcurvature(a: np.ndarray, b: np.ndarray, c: np.ndarray) -> np.ndarray:
    """Curvature [1/m] of the circle through the points ``a[i], b[i], c[i]``.

    ``2 |(b - a) x (c - b)| / (|b - a| |c - b| |c - a|)`` (Menger curvature):
    exactly ``1/r`` for three points on a circle of radius r; 0 for collinear
    or coincident points. Arrays are (N, 2) or (N, 3) [m].
    """
    ab = b - a
    bc = c - b
    ac = c - a
    if a.shape[1] == 2:
        cross = np.abs(ab[:, 0] * bc[:, 1] - ab[:, 1] * bc[:, 0])
    else:
        cross = np.linalg.norm(np.cross(ab, bc), axis=1)
    den = np.linalg.norm(ab, axis=1) * np.linalg.norm(bc, axis=1) * np.linalg.norm(ac, axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(den > 1e-300, 2.0 * cross / np.maximum(den, 1e-300), 0.0)


def menger_curvature(points: np.ndarray) -> np.ndarray:
    """Curvature [1/m] of the circle through each three consecutive points.

    Returns ``N - 2`` values (0 for collinear points); ``points`` is (N, d).
    """
    p = np.asarray(points, dtype=float)
    return circumcurvature(p[:-2], p[1:-1], p[2:])


def segment_angles(points: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Heading, climb angle [rad] and horizontal length [m] of each segment of a 3D path.

    heading ``psi = atan2(dy, dx)``; climb ``gamma = atan2(dz, hypot(dx, dy))``
    (> 0 climbing). ``points`` is (N, 3); the arrays have N - 1 values.
    """
    d = np.diff(np.asarray(points, dtype=float), axis=0)
    heading = np.arctan2(d[:, 1], d[:, 0])
    horiz = np.hypot(d[:, 0], d[:, 1])
    climb = np.arctan2(d[:, 2], horiz)
    return heading, climb, horiz


def turn_angles(heading: np.ndarray, horiz: np.ndarray) -> np.ndarray:
    """Heading change [rad] between consecutive segments, wrapped to (-pi, pi].

    A segment with no horizontal motion (``horiz`` < 1e-9 m) has no heading:
    the turn next to it is 0. Returns ``len(heading) - 1`` values.
    """
    turn = (np.diff(heading) + np.pi) % (2 * np.pi) - np.pi
    still = (horiz[1:] < 1e-9) | (horiz[:-1] < 1e-9)
    return np.where(still, 0.0, turn)


def distance_to_polyline(points: np.ndarray, path: np.ndarray, chunk: int = 256) -> np.ndarray:
    """Exact Euclidean distance [m] from each point to the polyline ``path``."""
    pts = np.atleast_2d(np.asarray(points, dtype=float))
    a = path[:-1]
    ab = np.diff(path, axis=0)
    ab2 = np.maximum(np.einsum("ij,ij->i", ab, ab), 1e-300)
    out = np.empty(len(pts))
    for i0 in range(0, len(pts), chunk):
        q = pts[i0 : i0 + chunk]
        ap = q[:, None, :] - a[None, :, :]
        t = np.clip(np.einsum("pij,ij->pi", ap, ab) / ab2, 0.0, 1.0)
        d = ap - t[:, :, None] * ab[None, :, :]
        out[i0 : i0 + chunk] = np.sqrt(np.einsum("pij,pij->pi", d, d).min(axis=1))
    return out


def runs(flag: np.ndarray) -> list[tuple[int, int]]:
    """Half-open index ranges ``[i, j)`` where the bool array ``flag`` is True."""
    f = np.asarray(flag, dtype=bool).astype(np.int8)
    d = np.diff(np.concatenate([[0], f, [0]]))
    starts = np.flatnonzero(d == 1)
    ends = np.flatnonzero(d == -1)
    return [(int(a), int(b)) for a, b in zip(starts, ends)]
