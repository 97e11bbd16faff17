"""Path helpers shared by the vehicle checks: validation, arc length, resampling,
distance to a polyline, runs of a boolean signal."""

from __future__ import annotations

from typing import Any

import numpy as np

from ..errors import InputError

__all__ = [
    "as_path3",
    "arc_length",
    "resample",
    "distance_to_polyline",
    "runs",
]


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


def resample(path: np.ndarray, ds: float) -> tuple[np.ndarray, np.ndarray]:
    """Points every ``ds`` metres of arc length (plus the exact end point).

    Returns
    -------
    points : ndarray (M, d)
    s : ndarray (M,)
        Their arc length [m].
    """
    s = arc_length(path)
    n = max(int(np.ceil(s[-1] / ds)), 1)
    s_new = np.linspace(0.0, s[-1], n + 1)
    pts = np.column_stack([np.interp(s_new, s, path[:, k]) for k in range(path.shape[1])])
    return pts, s_new


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
