"""The result of a path-tracking simulation, shared by the fixed-wing and multirotor models."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..errors import InputError
from ..geometry import as_path3, distance_to_polyline, resample_uniform, runs
from .airframes import Airframe

__all__ = ["Tracking", "TrackingOptions", "Carrot", "FlightLog"]


@dataclass(frozen=True, eq=False)
class Tracking:
    """A simulated flight along a planned path.

    Attributes
    ----------
    airframe : FixedWing or Multirotor
    planned : ndarray (N, 3)
        The planned path [m] (2D paths get z = 0).
    t : ndarray (K,)
        Time [s].
    trajectory : ndarray (K, 3)
        Flown positions [m].
    progress : ndarray (K,)
        Arc length of the projection of each flown point on the planned path [m].
    separation : ndarray (K,)
        Distance from each flown point to the planned path (polyline) [m].
    saturated : dict of str to ndarray of bool (K,)
        Per limit (``"turn"``, ``"climb"``, ``"descent"``, ``"accel"``), whether
        the command asked for more than the airframe allows at that step.
    states : dict of str to ndarray (K,)
        Model states: ``heading`` ψ [rad], ``flight_path_angle`` γ [rad],
        ``speed`` [m/s], ...
    reached : bool
        The projection reached the end of the planned path before the time limit.
    lookahead : float
        Look-ahead distance of the guidance [m].
    dt : float
        Integration step [s].
    """

    airframe: Airframe
    planned: np.ndarray = field(repr=False)
    t: np.ndarray = field(repr=False)
    trajectory: np.ndarray = field(repr=False)
    progress: np.ndarray = field(repr=False)
    separation: np.ndarray = field(repr=False)
    saturated: dict[str, np.ndarray] = field(repr=False)
    states: dict[str, np.ndarray] = field(repr=False)
    reached: bool
    lookahead: float
    dt: float

    @property
    def max_separation(self) -> float:
        """Largest distance flown → planned path [m] (the thesis' separation distance)."""
        return float(self.separation.max())

    @property
    def mean_separation(self) -> float:
        """Time-averaged distance flown → planned path [m]."""
        return float(self.separation.mean())

    @property
    def duration(self) -> float:
        """Flight time [s]."""
        return float(self.t[-1] - self.t[0])

    def saturation_intervals(self) -> list[dict[str, Any]]:
        """Where and how long each limit saturates (time and arc length along the plan)."""
        out = []
        for limit, flag in self.saturated.items():
            for i, j in runs(flag):
                out.append({
                    "limit": limit,
                    "t_from_s": round(float(self.t[i]), 3),
                    "t_to_s": round(float(self.t[j - 1] + self.dt), 3),
                    "duration_s": round(float((j - i) * self.dt), 3),
                    "s_from_m": round(float(self.progress[i]), 2),
                    "s_to_m": round(float(self.progress[j - 1]), 2),
                })
        return sorted(out, key=lambda d: d["t_from_s"])

    def saturation_time(self) -> dict[str, float]:
        """Total time [s] each limit is saturated."""
        return {k: float(np.count_nonzero(v) * self.dt) for k, v in self.saturated.items()}

    def summary(self) -> dict[str, Any]:
        """JSON-friendly numbers."""
        return {
            "reached_goal": self.reached,
            "flight_time_s": round(self.duration, 3),
            "max_separation_m": round(self.max_separation, 3),
            "mean_separation_m": round(self.mean_separation, 3),
            "lookahead_m": round(self.lookahead, 3),
            "dt_s": self.dt,
            "saturated_s": {k: round(v, 3) for k, v in self.saturation_time().items()},
            "saturation_intervals": len(self.saturation_intervals()),
        }


@dataclass(frozen=True)
class TrackingOptions:
    """How a simulated vehicle follows the planned path (both trackers and
    :func:`~fm2uav.vehicles.check_feasibility`).

    Attributes
    ----------
    lookahead : float, optional
        Carrot distance along the path [m]. Default per vehicle: the minimum
        turn radius R_min at the flown speed (at least 2 m) for a fixed-wing;
        ``max(v_max * 1 s, 2 m)`` for a multirotor (its largest carrot).
    lookahead_points : int, optional
        The thesis' ``a``: look ``a`` path points ahead (``a`` x median point
        spacing metres). Exclusive with ``lookahead``.
    dt : float
        Integration step [s], in (0, :data:`MAX_DT`]. Default 0.05.
    max_time : float, optional
        Give up after this long [s]; default ``3 x length / V + 60`` (V: the
        fixed-wing's speed, the multirotor's mean admissible speed).

    The values are checked when a tracker uses them (:meth:`step`,
    :meth:`carrot_distance`, :meth:`time_limit`).
    """

    lookahead: float | None = None
    lookahead_points: int | None = None
    dt: float = 0.05
    max_time: float | None = None

    def step(self) -> float:
        """The integration step [s] (:func:`check_dt`)."""
        return check_dt(self.dt)

    def carrot_distance(self, path: Any, default: float) -> float:
        """The look-ahead [m] along ``path`` (``default`` when neither is given)."""
        return check_lookahead(path, self.lookahead, self.lookahead_points, default)

    def time_limit(self, length: float, speed: float) -> float:
        """The simulation time limit [s] of a path ``length`` [m] flown at ``speed`` [m/s]."""
        return check_max_time(self.max_time, length, speed)


class Carrot:
    """Projection on a planned path and the look-ahead ("carrot") point.

    The path is resampled every ``ds`` metres; the projection index only moves
    forward, searched in a window of ``reach`` metres ahead of the last one, so
    a path that comes back near itself is not short-cut.
    """

    @classmethod
    def along(cls, planned: np.ndarray, lookahead: float, length: float, speed: float,
              dt: float) -> Carrot:
        """The carrot of a tracker: ``planned`` (``length`` [m]) resampled every
        ``min(0.5 m, lookahead / 8, length / 50)`` (at least 1 mm), searched as far as
        a vehicle at ``speed`` [m/s] gets in 3 steps of ``dt`` [s] plus the look-ahead."""
        ds = max(min(0.5, lookahead / 8.0, length / 50.0), 1e-3)
        return cls(planned, lookahead, ds, reach=3.0 * speed * dt + lookahead + 2 * ds)

    def __init__(self, path: np.ndarray, lookahead: float, ds: float, reach: float) -> None:
        self.pts, self.s = resample_uniform(path, ds)
        self.ds = float(self.s[1] - self.s[0]) if len(self.s) > 1 else ds
        self.n_ahead = max(int(round(lookahead / self.ds)), 1)
        self.win = max(int(math.ceil(reach / self.ds)), 2) + 1
        self.idx = 0
        self.last = len(self.pts) - 1

    def update(self, pos: np.ndarray, ahead: float | None = None) -> tuple[int, np.ndarray]:
        """Advance the projection of ``pos``; return (index, carrot point).

        ``ahead`` [m] overrides the look-ahead for this step (at most the
        constructor's, which sized the search window).
        """
        hi = min(self.idx + self.win, self.last + 1)
        seg = self.pts[self.idx : hi]
        d2 = np.einsum("ij,ij->i", seg - pos, seg - pos)
        self.idx += int(np.argmin(d2))
        n = self.n_ahead if ahead is None else min(max(int(round(ahead / self.ds)), 1), self.n_ahead)
        return self.idx, self.pts[min(self.idx + n, self.last)]


def check_lookahead(
    path: np.ndarray, lookahead: float | None, lookahead_points: int | None, default: float
) -> float:
    """Look-ahead distance [m] from metres, or from the thesis' ``a`` points ahead."""
    if lookahead is not None and lookahead_points is not None:
        raise InputError("give either lookahead (metres) or lookahead_points (a), not both")
    if lookahead_points is not None:
        if isinstance(lookahead_points, bool) or int(lookahead_points) != lookahead_points \
                or lookahead_points < 1:
            raise InputError(f"lookahead_points must be an integer >= 1, got {lookahead_points!r}")
        step = float(np.median(np.linalg.norm(np.diff(as_path3(path), axis=0), axis=1)))
        return int(lookahead_points) * step
    if lookahead is None:
        return default
    v = float(lookahead)
    if not (math.isfinite(v) and v > 0):
        raise InputError(f"lookahead must be a positive distance in metres, got {lookahead!r}")
    # beyond the path's length the carrot sits on the goal anyway: same result, bounded work
    total = float(np.sum(np.linalg.norm(np.diff(as_path3(path), axis=0), axis=1)))
    return min(v, max(total, 1.0))


#: Largest integration step [s] (a longer step skips whole manoeuvres).
MAX_DT = 10.0
#: Most integration steps a simulation may take (beyond: refused, not allocated).
MAX_STEPS = 5_000_000


def check_dt(dt: float) -> float:
    """Validate the integration step [s]: in (0, :data:`MAX_DT`]."""
    try:
        v = float(dt)
    except (TypeError, ValueError):
        raise InputError(f"dt must be a time step in seconds, got {dt!r} (CLI --dt)") from None
    if not (math.isfinite(v) and 0 < v <= MAX_DT):
        raise InputError(f"dt must be a time step in (0, {MAX_DT:g}] seconds, got {dt!r} "
                         "(CLI --dt)")
    return v


def check_steps(t_max: float, dt: float) -> int:
    """Number of integration steps for ``t_max`` [s] at ``dt`` [s] (refused beyond
    :data:`MAX_STEPS` with the step that would fit)."""
    n = t_max / dt
    if not n <= MAX_STEPS:
        raise InputError(
            f"the simulation would take {n:.3g} steps of dt = {dt:g} s for {t_max:.3g} s of "
            f"flight (limit {MAX_STEPS:.0e}); use dt >= {t_max / MAX_STEPS:.3g} s (CLI --dt)")
    return int(math.ceil(n)) + 1


def check_max_time(max_time: float | None, length: float, speed: float) -> float:
    """Simulation time limit [s]: ``max_time``, or ``3 x length / speed + 60`` if None."""
    t_max = 3.0 * length / speed + 60.0 if max_time is None else float(max_time)
    if not (math.isfinite(t_max) and t_max > 0):
        raise InputError(f"max_time must be a positive time in seconds, got {max_time!r}")
    return t_max


class FlightLog:
    """The arrays a tracker fills step by step, preallocated for the longest flight.

    ``traj`` (n_max, 3) positions [m], ``prog`` arc length of their projection on
    the plan [m], ``saturated[limit]`` the clipped steps of each of ``limits``,
    ``states[name]`` the model states; :meth:`tracking` trims them to the steps
    flown.
    """

    def __init__(self, t_max: float, dt: float, limits: tuple[str, ...],
                 states: tuple[str, ...]) -> None:
        self.dt = dt
        self.n_max = check_steps(t_max, dt)  # bounded: refused beyond MAX_STEPS
        self.traj = np.empty((self.n_max, 3))
        self.prog = np.empty(self.n_max)
        self.saturated = {k: np.zeros(self.n_max, bool) for k in limits}
        self.states = {k: np.empty(self.n_max) for k in states}

    def tracking(self, airframe: Airframe, planned: np.ndarray, n: int, *, reached: bool,
                 lookahead: float) -> Tracking:
        """The :class:`Tracking` of the first ``n`` steps."""
        flown = self.traj[:n]
        return Tracking(
            airframe=airframe,
            planned=planned,
            t=np.arange(n) * self.dt,
            trajectory=flown,
            progress=self.prog[:n],
            separation=distance_to_polyline(flown, planned),
            saturated={k: v[:n] for k, v in self.saturated.items()},
            states={k: v[:n] for k, v in self.states.items()},
            reached=reached,
            lookahead=lookahead,
            dt=self.dt,
        )
