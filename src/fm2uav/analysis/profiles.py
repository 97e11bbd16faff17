"""Turn, climb and curvature profiles along a path (TFF paper figs. 11-13).

The FM² geodesic is a polyline with sub-cell steps, so derivatives taken point
by point measure the step noise, not the path. Every profile is therefore taken
on the path resampled at a fixed arc length ``ds`` (default: the finest grid
spacing, one cell), which is also the scale at which the path is defined.

Definitions (per resampled point ``i``, angles in radians):

* heading ``psi`` — direction of the horizontal projection of segment
  ``i → i+1``, ``atan2(dy, dx)`` (the Dubins-airplane turn angle);
* climb angle ``gamma`` — flight-path angle of segment ``i → i+1``,
  ``atan2(dz, hypot(dx, dy))`` (> 0 climbing);
* turn angle — heading change between consecutive segments, wrapped to
  (-pi, pi] [rad] (per step ``ds``);
* curvature ``kappa`` — 3D Menger curvature of three consecutive points
  ``4 * area / (a b c)`` [1/m]; ``kappa_h`` the same in the horizontal plane
  (``1 / kappa_h`` is the turn radius).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..geometry import (
    arc_length,
    as_path,
    menger_curvature,
    resample_path,
    segment_angles,
    turn_angles,
)

__all__ = ["Profiles", "path_profiles"]


@dataclass(frozen=True)
class Profiles:
    """Profiles of a path resampled every ``ds`` metres.

    Attributes
    ----------
    points : ndarray, (M, 3)
        Resampled points [m].
    s : ndarray, (M,)
        Arc length of each point [m].
    heading, climb : ndarray, (M - 1,)
        Heading ``psi`` and climb angle ``gamma`` of each segment [rad].
    turn : ndarray, (M - 2,)
        Heading change at each interior point [rad per ``ds``].
    curvature, curvature_h : ndarray, (M - 2,)
        3D and horizontal curvature at each interior point [1/m].
    ds : float
        Resampling step [m].
    """

    points: np.ndarray
    s: np.ndarray
    heading: np.ndarray
    climb: np.ndarray
    turn: np.ndarray
    curvature: np.ndarray
    curvature_h: np.ndarray
    ds: float

    def summary(self) -> dict[str, float]:
        """Max and 95th percentile of |turn|, |climb| [deg], curvature [1/m], and
        the minimum horizontal turn radius [m] (from the max of ``curvature_h``)."""

        def stat(v: np.ndarray, f) -> float:
            return float(f(v)) if v.size else 0.0

        turn = np.degrees(np.abs(self.turn))
        climb = np.degrees(np.abs(self.climb))
        kh = stat(self.curvature_h, np.max)
        return {
            "turn_max_deg": stat(turn, np.max),
            "turn_p95_deg": stat(turn, lambda v: np.percentile(v, 95)),
            "climb_max_deg": stat(climb, np.max),
            "climb_p95_deg": stat(climb, lambda v: np.percentile(v, 95)),
            "curvature_max": stat(self.curvature, np.max),
            "curvature_p95": stat(self.curvature, lambda v: np.percentile(v, 95)),
            "min_turn_radius_m": (1.0 / kh) if kh > 0 else float("inf"),
        }


def path_profiles(path: np.ndarray, ds: float | None = None) -> Profiles:
    """Turn, climb and curvature profiles of a 3D (or 2D) path.

    Parameters
    ----------
    path : ndarray, (N, 3) or (N, 2)
        Points [m].
    ds : float, optional
        Resampling step [m]. Default: the median segment length times 2, at
        least 1 m — pass the grid spacing for FM² paths (e.g. ``plan.world.spacing[0]``).

    Examples
    --------
    >>> import numpy as np
    >>> t = np.linspace(0, np.pi, 200)
    >>> circle = np.stack([100 * np.cos(t), 100 * np.sin(t), 0 * t], axis=1)
    >>> pr = path_profiles(circle, ds=5.0)
    >>> round(float(np.median(pr.curvature_h)) * 100, 2)     # 1 / radius
    1.0
    """
    p = as_path(path)
    if ds is None:
        seg = np.linalg.norm(np.diff(p, axis=0), axis=1)
        ds = max(2.0 * float(np.median(seg[seg > 0])) if np.any(seg > 0) else 1.0, 1.0)
    q = resample_path(p, float(ds))
    if q.shape[1] == 2:
        q = np.concatenate([q, np.zeros((len(q), 1))], axis=1)
    heading, climb, horiz = segment_angles(q)
    turn = turn_angles(heading, horiz)
    s = arc_length(q)
    return Profiles(
        points=q,
        s=s,
        heading=heading,
        climb=climb,
        turn=turn,
        curvature=menger_curvature(q),
        curvature_h=menger_curvature(q[:, :2]),
        ds=float(ds),
    )
