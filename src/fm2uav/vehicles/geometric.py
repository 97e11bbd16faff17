"""Geometric feasibility: curvature and climb angle along a path, no simulation.

Curvature is the Menger curvature of the three points at arc lengths
``s - h``, ``s`` and ``s + h`` (exact ``1/r`` on a circle of radius r, for any
``h`` below the half circumference); the climb angle is
``atan2(Δz, Δxy)`` over ``[s - h, s + h]``. The window ``h`` defaults to
``max(R_min / 2, 2 x median point spacing)`` so that a polyline corner (whose
curvature is infinite at the vertex) is judged at the scale of the airframe's
turn: a 90° corner reads as a radius ~0.7 h.

The circle-through-three-points formula is :func:`fm2uav.geometry.circumcurvature`,
shared with the path profiles; what is specific here is the airframe-scale window.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..errors import InputError
from ..geometry import arc_length, as_path3, at_arc_length, circumcurvature, runs
from .airframes import Airframe, FixedWing, Multirotor, get_airframe

__all__ = [
    "curvature_profile",
    "climb_angle_profile",
    "GeometricCheck",
    "geometric_check",
    "default_window",
]


def _window(path: np.ndarray, window: float | None) -> float:
    if window is None:
        return float(2.0 * np.median(np.linalg.norm(np.diff(path, axis=0), axis=1)))
    w = float(window)
    if not (math.isfinite(w) and w > 0):
        raise InputError(f"window must be a positive length in metres, got {window!r}")
    return w


def default_window(path: Any, airframe: Airframe | str | None = None) -> float:
    """``max(R_min / 2, 2 x median point spacing)`` [m] (R_min at cruise / max speed)."""
    p = as_path3(path)
    w = _window(p, None)
    if airframe is not None:
        w = max(w, 0.5 * get_airframe(airframe).turn_radius())
    return w


def _at(path: np.ndarray, s: np.ndarray, q: np.ndarray) -> np.ndarray:
    return at_arc_length(path, s, np.clip(q, 0.0, s[-1]))


def curvature_profile(
    path: Any, window: float | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """Curvature [1/m] at every path point over a window ``h`` [m].

    Parameters
    ----------
    path : array (N, 2|3)
        Points [m].
    window : float, optional
        ``h`` [m]; default twice the median point spacing.

    Returns
    -------
    s : ndarray (M,)
        Arc length of the (deduplicated) points [m].
    kappa : ndarray (M,)
        Curvature [1/m]; near the ends the three points are shifted inwards.
    """
    p = as_path3(path)
    h = _window(p, window)
    s = arc_length(p)
    total = s[-1]
    h = min(h, total / 2.0)
    mid = np.clip(s, h, total - h)
    kappa = circumcurvature(_at(p, s, mid - h), _at(p, s, mid), _at(p, s, mid + h))
    return s, kappa


def climb_angle_profile(
    path: Any, window: float | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """Flight-path (climb) angle γ [rad] at every point, ``atan2(Δz, Δxy)`` over ±h.

    Returns ``(s, gamma)`` like :func:`curvature_profile`; positive = climbing.
    """
    p = as_path3(path)
    h = _window(p, window)
    s = arc_length(p)
    lo, hi = np.clip(s - h, 0, s[-1]), np.clip(s + h, 0, s[-1])
    a, c = _at(p, s, lo), _at(p, s, hi)
    d = c - a
    return s, np.arctan2(d[:, 2], np.hypot(d[:, 0], d[:, 1]))


@dataclass(frozen=True)
class GeometricCheck:
    """Result of :func:`geometric_check` (SI units; :meth:`summary` in degrees).

    Attributes
    ----------
    airframe : FixedWing or Multirotor
    window : float
        Window h of the profiles [m].
    s, curvature, climb_angle : ndarray
        Arc length [m], curvature [1/m], flight-path angle [rad] per point.
    max_curvature : float
        [1/m]; ``min_radius = 1 / max_curvature`` [m].
    turn_ok, climb_ok : ndarray of bool
        Per point: curvature <= 1/R_min; climb angle within the limits.
    violations : list of dict
        Runs of points breaking a limit: kind, s_from, s_to [m], worst value.
    feasible : bool
    reason : str
    """

    airframe: Airframe
    window: float
    s: np.ndarray = field(repr=False)
    curvature: np.ndarray = field(repr=False)
    climb_angle: np.ndarray = field(repr=False)
    max_curvature: float
    turn_ok: np.ndarray = field(repr=False)
    climb_ok: np.ndarray = field(repr=False)
    violations: list[dict[str, Any]]
    feasible: bool
    reason: str

    @property
    def min_radius(self) -> float:
        """Smallest radius of curvature along the path [m] (inf if straight)."""
        return 1.0 / self.max_curvature if self.max_curvature > 0 else math.inf

    def summary(self) -> dict[str, Any]:
        """JSON-friendly numbers (degrees for angles)."""
        return {
            "feasible": self.feasible,
            "reason": self.reason,
            "window_m": round(self.window, 3),
            "min_radius_m": round(self.min_radius, 3) if math.isfinite(self.min_radius) else None,
            "max_climb_deg": round(math.degrees(float(self.climb_angle.max())), 3),
            "max_descent_deg": round(math.degrees(float(-self.climb_angle.min())), 3),
            "violations": self.violations,
        }


def geometric_check(
    path: Any, airframe: Airframe | str, *, window: float | None = None
) -> GeometricCheck:
    """Compare the path's curvature and climb angle with the airframe's limits.

    Fixed-wing: curvature must stay <= ``1 / R_min`` (R_min at cruise speed) and
    the flight-path angle within ``[-γ_descent, γ_climb]``.
    Multirotor: it can fly any geometry by slowing down (it may hover), so the
    check is always feasible; the slow-downs show in
    :func:`fm2uav.vehicles.speed_profile.speed_profile`.

    Parameters
    ----------
    path : array (N, 2|3)
        Points [m] (at least 2, finite).
    airframe : FixedWing, Multirotor or preset name
    window : float, optional
        Window h [m]; default ``max(R_min / 2, 2 x median point spacing)``.
    """
    af = get_airframe(airframe)
    p = as_path3(path)
    h = default_window(p, af) if window is None else _window(p, window)
    s, kappa = curvature_profile(p, h)
    _, gamma = climb_angle_profile(p, h)
    kmax = float(kappa.max())
    if isinstance(af, FixedWing):
        lim = 1.0 / af.turn_radius()
        turn_ok = kappa <= lim * (1 + 1e-9)
        climb_ok = (gamma <= af.max_climb + 1e-12) & (gamma >= -af.max_descent - 1e-12)
    else:
        assert isinstance(af, Multirotor)
        turn_ok = np.ones(len(s), bool)
        climb_ok = np.ones(len(s), bool)
    violations: list[dict[str, Any]] = []
    for i, j in runs(~turn_ok):
        k = i + int(np.argmax(kappa[i:j]))
        violations.append({"kind": "turn", "s_from_m": round(float(s[i]), 2),
                           "s_to_m": round(float(s[j - 1]), 2),
                           "worst_radius_m": round(1.0 / float(kappa[k]), 3)})
    for i, j in runs(~climb_ok):
        k = i + int(np.argmax(np.abs(gamma[i:j])))
        violations.append({"kind": "climb" if gamma[k] > 0 else "descent",
                           "s_from_m": round(float(s[i]), 2), "s_to_m": round(float(s[j - 1]), 2),
                           "worst_angle_deg": round(math.degrees(float(gamma[k])), 3)})
    feasible = not violations
    if isinstance(af, Multirotor):
        reason = "a multirotor can fly any geometry by slowing down (see the speed profile)"
    elif feasible:
        reason = (f"radius of curvature >= {1 / max(kmax, 1e-300):.1f} m (limit R_min = "
                  f"{af.turn_radius():.1f} m) and flight-path angle within "
                  f"[-{math.degrees(af.max_descent):.0f}, {math.degrees(af.max_climb):.0f}] deg")
    else:
        nt = sum(v["kind"] == "turn" for v in violations)
        nc = len(violations) - nt
        parts = []
        if nt:
            parts.append(f"{nt} stretch(es) tighter than R_min = {af.turn_radius():.1f} m "
                         f"(tightest {1 / kmax:.1f} m)")
        if nc:
            parts.append(f"{nc} stretch(es) steeper than the climb/descent limits "
                         f"(steepest {math.degrees(float(np.abs(gamma).max())):.1f} deg)")
        reason = "; ".join(parts)
    return GeometricCheck(
        airframe=af, window=h, s=s, curvature=kappa, climb_angle=gamma, max_curvature=kmax,
        turn_ok=turn_ok, climb_ok=climb_ok, violations=violations, feasible=feasible,
        reason=reason,
    )
