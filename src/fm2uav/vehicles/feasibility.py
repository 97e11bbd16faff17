"""Can this airframe fly this path? The feasibility report.

:func:`check_feasibility` runs the three checks and gives one verdict:

1. tracking simulation (:func:`.track_dubins` for fixed-wings,
   :func:`.track_multirotor` for multirotors) — the thesis' check: the flown
   ("feasible") path must reach the goal, stay within ``tolerance`` metres of
   the planned path (the separation distance) and, with a world, never enter
   an obstacle node nor leave the map;
2. geometric check (:func:`.geometric_check`): curvature vs 1/R_min and
   climb angle vs the limits, no simulation — reported, not part of the verdict
   (a polyline corner fails it and yet may be flown within tolerance);
3. admissible-speed profile (:func:`.speed_profile`) from W and curvature.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..world.clearance import clearance_profile
from ..errors import InputError
from ..world import World
from ..geometry import as_path3
from .airframes import Airframe, FixedWing, get_airframe
from .dubins_airplane import track_dubins
from .geometric import GeometricCheck, geometric_check
from .multirotor import track_multirotor
from .speed_profile import SpeedProfile, speed_profile
from .tracking import Tracking, TrackingOptions

__all__ = ["DEFAULT_TOLERANCE", "MAX_TOLERANCE", "FeasibilityReport", "check_feasibility",
           "collision_check"]

#: Default largest admissible separation flown ↔ planned [m]: about the
#: horizontal accuracy of a GNSS-guided small UAV plus margin.
DEFAULT_TOLERANCE = 5.0


def collision_check(world: World, points: np.ndarray) -> dict[str, Any]:
    """Whether points [m] (3D; 2D worlds use x, y) leave the map or hit an obstacle node.

    Returns a dict: ``outside`` and ``inside_obstacle`` (counts), ``first`` (index
    of the first offending point or None), ``min_clearance_m``.
    """
    pts = np.asarray(points, dtype=float)[:, : world.ndim]
    inside = np.atleast_1d(world.contains(pts))
    idx = np.floor(world.to_index(pts) + 0.5).astype(np.int64)
    idx = np.clip(idx, 0, np.asarray(world.shape) - 1)
    hit = world.occupancy[tuple(idx.T)] & inside
    bad = ~inside | hit
    clr = clearance_profile(world, pts)
    return {
        "outside": int(np.count_nonzero(~inside)),
        "inside_obstacle": int(np.count_nonzero(hit)),
        "first": int(np.flatnonzero(bad)[0]) if bad.any() else None,
        "min_clearance_m": float(clr.min()),
    }


@dataclass(frozen=True, eq=False)
class FeasibilityReport:
    """Result of :func:`check_feasibility`.

    Attributes
    ----------
    airframe : FixedWing or Multirotor
    tracking : Tracking
        The simulated flight (trajectory, separation, saturations).
    geometric : GeometricCheck
    speed : SpeedProfile
    tolerance : float
        Largest admissible separation [m].
    collision : dict or None
        :func:`collision_check` of the flown trajectory (None without world).
    feasible : bool
        The verdict (tracking-based, see the module doc).
    reasons : list of str
        Why (every failed condition, or what held).
    """

    airframe: Airframe
    tracking: Tracking
    geometric: GeometricCheck
    speed: SpeedProfile
    tolerance: float
    collision: dict[str, Any] | None
    feasible: bool
    reasons: list[str] = field(default_factory=list)

    @property
    def reason(self) -> str:
        """The reasons as one sentence."""
        return "; ".join(self.reasons)

    def summary(self) -> dict[str, Any]:
        """JSON-friendly report (angles in degrees)."""
        return {
            "feasible": self.feasible,
            "reason": self.reason,
            "airframe": self.airframe.summary(),
            "tolerance_m": self.tolerance,
            "tracking": self.tracking.summary(),
            "saturation_intervals": self.tracking.saturation_intervals(),
            "geometric": self.geometric.summary(),
            "speed_profile": self.speed.summary(),
            "collision": self.collision,
        }

    def summary_rows(self, airframe: Airframe | None = None) -> dict[str, str]:
        """The verdict as printable ``{label: text}`` rows (what ``fm2uav check`` prints).

        ``airframe`` is the airframe as asked (default :attr:`airframe`); a
        fixed-wing adds its minimum turn radius at the simulated cruise speed.
        """
        af = self.airframe if airframe is None else airframe
        tr, geo = self.tracking, self.geometric
        sat = ", ".join(f"{k} {v:.1f} s" for k, v in tr.saturation_time().items()) or "none"
        rows = {
            "verdict": "FEASIBLE" if self.feasible else "INFEASIBLE",
            "reason": self.reason,
            "airframe": f"{af.name} ({af.kind})",
            "separation max / mean [m]": f"{tr.max_separation:.2f} / {tr.mean_separation:.2f}",
            "limits saturated": sat,
            "geometric check": ("ok" if geo.feasible else "violated") + f": {geo.reason}",
            "min radius of curvature [m]": (f"{geo.min_radius:.1f}"
                                            if math.isfinite(geo.min_radius) else "inf"),
            "max climb / descent [deg]": (f"{np.degrees(geo.climb_angle.max()):.1f} / "
                                          f"{np.degrees(-geo.climb_angle.min()):.1f}"),
        }
        if getattr(af, "kind", "") == "fixed-wing":
            rows["R_min [m]"] = f"{af.turn_radius(self.airframe.cruise_speed):.1f}"
        return rows


#: Largest tracking tolerance [m] (a larger one accepts any path).
MAX_TOLERANCE = 10_000.0


def check_feasibility(
    path: Any,
    airframe: Airframe | str,
    *,
    world: World | None = None,
    w: Any = None,
    tolerance: float = DEFAULT_TOLERANCE,
    speed: float | None = None,
    tracking: TrackingOptions = TrackingOptions(),
    window: float | None = None,
) -> FeasibilityReport:
    """Check whether ``airframe`` can fly ``path``.

    Parameters
    ----------
    path : array (N, 2|3)
        Planned path [m], start → goal (e.g. ``Plan.path`` or a CSV read with
        :func:`fm2uav.io.read_path_csv`).
    airframe : FixedWing, Multirotor or preset name (see ``AIRFRAMES``)
    world : World, optional
        Also check that the flown trajectory stays in free space.
    w : array (N,), optional
        W along the path (``Plan.w``), for the admissible-speed profile.
    tolerance : float
        Largest admissible separation flown ↔ planned [m]. Default 5.
    speed : float, optional
        Fixed-wing airspeed [m/s] (default cruise).
    tracking : TrackingOptions
        Carrot distance [m] or the thesis' ``a`` points, simulation step [s] and
        time limit of the tracker (see :func:`track_dubins`, :func:`track_multirotor`).
    window : float, optional
        Window of the geometric profiles [m].

    Returns
    -------
    FeasibilityReport

    Raises
    ------
    InputError
        Unknown airframe, bad path (< 2 points, NaN), negative speed or tolerance.
    """
    af = get_airframe(airframe)
    from .. import _validate

    # above 10 km any path "keeps within tolerance": a typo, never a check
    tol = _validate.in_range(tolerance, "tolerance", 0.0, MAX_TOLERANCE, low_open=True,
                             unit="m", where=(None, "--tolerance"))
    raw = np.asarray(path, dtype=float) if not isinstance(path, np.ndarray) else path
    as_path3(raw)  # validate once, with the user's view of the path
    if world is not None and not isinstance(world, World):
        raise InputError(f"world must be a fm2uav.World, got {type(world).__name__}")
    if world is not None and raw.shape[1] != world.ndim:
        raise InputError(
            f"the path has {raw.shape[1]} coordinates per point but the world is {world.ndim}D"
        )
    af, tr = _fly(raw, af, w=w, speed=speed, tracking=tracking)
    geo = geometric_check(raw, af, window=window)
    prof = speed_profile(raw, af, w, window=window)
    ok, reasons, col = _verdict(tr, tol, world)
    return FeasibilityReport(
        airframe=af, tracking=tr, geometric=geo, speed=prof, tolerance=tol, collision=col,
        feasible=ok, reasons=reasons,
    )


def _fly(raw: np.ndarray, af: Airframe, *, w: Any, speed: float | None,
         tracking: TrackingOptions) -> tuple[Airframe, Tracking]:
    """Fly ``raw`` with the tracker of ``af``'s kind; the airframe flown (at ``speed``) and its tracking."""
    if isinstance(af, FixedWing):
        if speed is not None:
            af = af.with_speed(speed)
        return af, track_dubins(raw, af, tracking=tracking)
    if speed is not None:
        raise InputError(f"speed= (CLI --speed) applies to fixed-wings; the {af.name} is a "
                         "multirotor, which flies the planned W profile up to its max_speed; "
                         "remove it")
    return af, track_multirotor(raw, af, w=w, tracking=tracking)


def _verdict(tr: Tracking, tol: float, world: World | None,
             ) -> tuple[bool, list[str], dict[str, Any] | None]:
    """Feasible or not, the reasons (one sentence each) and the collision check of the trajectory."""
    reasons: list[str] = []
    ok = True
    if not tr.reached:
        ok = False
        reasons.append(f"did not reach the goal within {tr.duration:.0f} s (it cannot follow the "
                       "path: it circles or drifts away)")
    if tr.max_separation > tol:
        ok = False
        i = int(np.argmax(tr.separation))
        reasons.append(
            f"strays {tr.max_separation:.2f} m from the planned path (tolerance {tol:g} m) at "
            f"{tr.progress[i]:.0f} m along it"
        )
    col = None
    if world is not None:
        col = collision_check(world, tr.trajectory)
        if col["first"] is not None:
            ok = False
            p = tr.trajectory[col["first"]]
            what = "leaves the map" if col["outside"] else "enters an obstacle"
            reasons.append(f"the flown trajectory {what} at {np.round(p, 1).tolist()} m "
                           f"(t = {tr.t[col['first']]:.1f} s)")
    sat = tr.saturation_time()
    if ok:
        msg = (f"flown within {tr.max_separation:.2f} m of the planned path (tolerance {tol:g} m, "
               f"mean {tr.mean_separation:.2f} m) and reached the goal")
        if col is not None:
            msg += f", min clearance {col['min_clearance_m']:.1f} m"
        reasons.append(msg)
    busy = {k: v for k, v in sat.items() if v > 0}
    if busy:
        reasons.append("limits saturated " + ", ".join(f"{k} {v:.1f} s" for k, v in busy.items()))
    return ok, reasons, col
