"""Flight time, distance and endurance of a mission: does the battery last?

The mission is flown leg by leg between its waypoints. A leg of horizontal
length ``L`` and height change ``dz`` at commanded speed ``v`` takes, for a
vehicle that can hover (``hover=True``),

``t = max(L / v, dz / v_climb, -dz / v_descent)``

(the horizontal and vertical motions run at the same time, each limited by its
own speed: a multirotor's ``WPNAV_SPEED`` / ``WPNAV_SPEED_UP`` /
``WPNAV_SPEED_DN``), and for a fixed-wing (``hover=False``), which flies on at its
airspeed whether or not it has reached the leg's altitude, ``t = sqrt(L² + dz²) / v``.
Hold times add to the leg they end. The take-off climb (home → first waypoint)
and the final descent are vertical legs; a return to launch adds the straight
line home at cruise speed and the descent there.

:func:`check_endurance` compares the total with the usable endurance,
``endurance × (1 − reserve)``, and, when it does not last, says how far along
the route the vehicle gets before it eats into the reserve.

The way back from a point of the route (:func:`return_time`) is timed the same
way, leg by leg of the return path at the forward speed, plus the final descent at
the destination; :func:`first_shortfall` finds where the time flown plus the time
back first exceeds the usable endurance: the point of no return.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from .._validate import positive
from ..errors import InputError

__all__ = ["FlightTime", "EnduranceReport", "flight_time", "check_endurance", "return_time",
           "first_shortfall"]


@dataclass(frozen=True)
class FlightTime:
    """Time and distance of a flight, leg by leg.

    Attributes
    ----------
    leg_time : ndarray, shape (n - 1,)
        Duration of each leg between waypoints [s] (holds included).
    leg_length : ndarray, shape (n - 1,)
        3D length of each leg [m].
    takeoff_s, takeoff_m : float
        Take-off climb [s] and its height [m].
    landing_s, landing_m : float
        Return to launch and final descent [s], and their distance [m].
    """

    leg_time: np.ndarray
    leg_length: np.ndarray
    takeoff_s: float
    takeoff_m: float
    landing_s: float
    landing_m: float

    @property
    def time_s(self) -> float:
        """Total flight time [s]."""
        return float(self.takeoff_s + self.leg_time.sum() + self.landing_s)

    @property
    def distance_m(self) -> float:
        """Total distance flown [m]."""
        return float(self.takeoff_m + self.leg_length.sum() + self.landing_m)

    def elapsed(self) -> np.ndarray:
        """Time [s] at which each waypoint is reached (take-off included)."""
        return self.takeoff_s + np.concatenate([[0.0], np.cumsum(self.leg_time)])


def flight_time(
    points: Any,
    speeds: Any,
    *,
    climb_rate: float,
    descent_rate: float,
    takeoff_climb: float = 0.0,
    final_descent: float = 0.0,
    return_distance: float = 0.0,
    return_speed: float | None = None,
    holds: Any = None,
    hover: bool = True,
) -> FlightTime:
    """Leg-by-leg flight time of waypoints flown at the given speeds.

    Parameters
    ----------
    points : array_like, shape (n, 3)
        Waypoints [m] (x, y, altitude).
    speeds : float or array_like, shape (n - 1,)
        Commanded horizontal speed on each leg [m/s].
    climb_rate, descent_rate : float
        Vertical speed limits [m/s] (> 0).
    takeoff_climb : float, optional
        Height climbed from home to the first waypoint [m].
    final_descent : float, optional
        Height of the final descent to the ground [m].
    return_distance : float, optional
        Straight-line distance of a return to launch [m], flown at
        ``return_speed`` (default: the last leg's speed).
    holds : array_like, shape (n,), optional
        Hold time at each waypoint [s].
    hover : bool, optional
        The vehicle waits for its altitude (multirotor); False: a fixed-wing flying
        each leg at its airspeed.
    """
    p = np.asarray(points, dtype=float)
    if p.ndim != 2 or p.shape[1] != 3 or len(p) < 1 or not np.all(np.isfinite(p)):
        raise InputError(f"points must be a finite (n, 3) array, got shape {p.shape}")
    up = positive(climb_rate, "climb_rate [m/s]")
    down = positive(descent_rate, "descent_rate [m/s]")
    d = np.diff(p, axis=0)
    horiz = np.hypot(d[:, 0], d[:, 1])
    v = np.broadcast_to(np.asarray(speeds, dtype=float), horiz.shape)
    if v.size and not (np.all(np.isfinite(v)) and np.all(v > 0)):
        raise InputError("leg speeds must be finite and > 0 m/s")
    if not len(d):
        t = np.zeros(0)
    elif hover:
        t = np.maximum.reduce([horiz / np.where(v > 0, v, 1.0), np.maximum(d[:, 2], 0) / up,
                               np.maximum(-d[:, 2], 0) / down])
    else:
        t = np.hypot(horiz, d[:, 2]) / np.where(v > 0, v, 1.0)
    if holds is not None:
        h = np.asarray(holds, dtype=float)
        if h.shape != (len(p),) or np.any(h < 0) or not np.all(np.isfinite(h)):
            raise InputError(f"holds must be {len(p)} times >= 0 s")
        t = t + h[1:]
        takeoff_hold = float(h[0])
    else:
        takeoff_hold = 0.0
    rs = return_speed if return_speed is not None else (float(v[-1]) if v.size else 1.0)
    ret = (float(return_distance) / positive(rs, "return speed [m/s]") if return_distance
           else 0.0)
    climb, descent = max(float(takeoff_climb), 0.0), max(float(final_descent), 0.0)
    return FlightTime(
        leg_time=t, leg_length=np.linalg.norm(d, axis=1),
        takeoff_s=climb / up + takeoff_hold, takeoff_m=climb,
        landing_s=ret + descent / down, landing_m=descent + float(return_distance),
    )


@dataclass(frozen=True)
class EnduranceReport:
    """A flight time against the airframe's endurance.

    Attributes
    ----------
    time_s, distance_m : float
        The whole flight [s], [m].
    endurance_s : float or None
        The airframe's endurance [s] (None: not given, nothing checked).
    reserve : float
        Share of the endurance kept in reserve.
    usable_s : float or None
        ``endurance × (1 − reserve)`` [s].
    ok : bool
        The flight fits in the usable endurance (True when not checked).
    reach_m : float
        Distance along the flight at which the usable endurance runs out [m]
        (the whole distance when it lasts).
    reach_waypoint : int
        Last waypoint reached within the usable endurance (index).
    waypoints : int
        Number of waypoints.
    reach_fraction : float
        Share of the leg after ``reach_waypoint`` flown when the usable endurance runs
        out (0 when it runs out during the take-off climb or lasts), so that the point
        is ``p[k] + reach_fraction (p[k + 1] - p[k])``.
    """

    time_s: float
    distance_m: float
    endurance_s: float | None
    reserve: float
    usable_s: float | None
    ok: bool
    reach_m: float
    reach_waypoint: int
    waypoints: int
    reach_fraction: float = 0.0

    @property
    def warning(self) -> str | None:
        """One line saying how far the vehicle gets, or None when it lasts."""
        if self.ok or self.endurance_s is None or self.usable_s is None:
            return None
        return (f"endurance: the flight needs {self.time_s / 60:.1f} min ({self.distance_m / 1000:.2f}"
                f" km) but {self.endurance_s / 60:.1f} min endurance with a "
                f"{100 * self.reserve:.0f} % reserve leaves {self.usable_s / 60:.1f} min: the "
                f"vehicle gets {self.reach_m / 1000:.2f} km along the flight (waypoint "
                f"{self.reach_waypoint} of {self.waypoints - 1}) before it eats into the reserve")

    def summary(self) -> dict[str, Any]:
        """JSON-friendly numbers."""
        return {
            "flight_time_s": round(self.time_s, 1),
            "flight_distance_m": round(self.distance_m, 1),
            "endurance_s": None if self.endurance_s is None else round(self.endurance_s, 1),
            "reserve": self.reserve,
            "usable_s": None if self.usable_s is None else round(self.usable_s, 1),
            "ok": self.ok,
            "reach_m": round(self.reach_m, 1),
            "reach_waypoint": self.reach_waypoint,
            "warning": self.warning,
        }


def check_endurance(ft: FlightTime, *, endurance_s: float | None, reserve: float = 0.2
                    ) -> EnduranceReport:
    """Compare a :class:`FlightTime` with an endurance [s] kept ``reserve`` in reserve.

    Raises
    ------
    InputError
        Endurance not > 0 or reserve outside [0, 1).
    """
    r = float(reserve)
    if not (0.0 <= r < 1.0):
        raise InputError(f"reserve must be a share in [0, 1) (e.g. 0.2 for 20 %), got {reserve!r}")
    n = len(ft.leg_time) + 1
    if endurance_s is None:
        return EnduranceReport(ft.time_s, ft.distance_m, None, r, None, True, ft.distance_m,
                               n - 1, n)
    usable = positive(endurance_s, "endurance [s]") * (1.0 - r)
    ok = ft.time_s <= usable
    if ok:
        return EnduranceReport(ft.time_s, ft.distance_m, float(endurance_s), r, usable, True,
                               ft.distance_m, n - 1, n)
    t_wp = ft.elapsed()
    if usable <= t_wp[0]:
        frac = usable / t_wp[0] if t_wp[0] > 0 else 0.0
        return EnduranceReport(ft.time_s, ft.distance_m, float(endurance_s), r, usable, False,
                               frac * ft.takeoff_m, 0, n)
    k = min(int(np.searchsorted(t_wp, usable, side="right") - 1), n - 1)
    reach = ft.takeoff_m + float(np.sum(ft.leg_length[:k]))
    frac = 0.0
    if k < n - 1 and ft.leg_time[k] > 0:
        frac = min((usable - t_wp[k]) / ft.leg_time[k], 1.0)
        reach += ft.leg_length[k] * frac
    return EnduranceReport(ft.time_s, ft.distance_m, float(endurance_s), r, usable, False,
                           float(reach), k, n, float(frac))


def return_time(path: Any, *, speed: float, climb_rate: float, descent_rate: float,
                landing_height: float = 0.0) -> tuple[float, float]:
    """``(time [s], 3D length [m])`` of flying ``path`` home and landing.

    Each segment takes ``max(L / speed, dz / climb, -dz / descent)`` (as the
    mission's legs, :func:`flight_time`); the final descent of ``landing_height``
    [m] at ``descent_rate`` is added (the vehicle is on the ground at the end).

    Parameters
    ----------
    path : array_like, shape (n, 3)
        The way back [m], from the point to over the destination.
    speed : float
        Forward speed [m/s] (the airframe's: RTL flies at its cruise speed).
    climb_rate, descent_rate : float
        Vertical speed limits [m/s].
    landing_height : float
        Height of the destination point above its ground [m].
    """
    p = np.asarray(path, dtype=float)
    if p.ndim != 2 or len(p) < 1:
        raise InputError(f"path must be an (n, 2|3) array, got shape {p.shape}")
    if p.shape[1] == 2:
        p = np.column_stack([p, np.zeros(len(p))])
    ft = flight_time(p, speed, climb_rate=climb_rate, descent_rate=descent_rate,
                     final_descent=max(float(landing_height), 0.0))
    return ft.time_s, float(ft.leg_length.sum())


def first_shortfall(t_out: Any, t_back: Any, usable: float) -> tuple[int, float] | None:
    """Where ``t_out + t_back`` first exceeds ``usable``, between samples ``k - 1`` and ``k``.

    Parameters
    ----------
    t_out : array_like, shape (m,)
        Time flown to each sample of the route [s] (increasing).
    t_back : array_like, shape (m,)
        Time back home from each sample [s] (``inf``: no way back).
    usable : float
        Usable endurance [s].

    Returns
    -------
    (k, f) or None
        The first sample ``k`` over the budget and the fraction ``f`` in [0, 1] of the
        interval ``k - 1 → k`` where the margin ``usable - t_out - t_back`` crosses 0
        (linear between the samples); ``k = 0`` when the first sample is already over;
        None when every sample is within the budget.

    Examples
    --------
    >>> first_shortfall([0, 10, 20], [5, 15, 25], 30.0)
    (2, 0.25)
    """
    out = np.asarray(t_out, dtype=float)
    back = np.asarray(t_back, dtype=float)
    margin = float(usable) - out - back
    bad = np.flatnonzero(~(margin >= 0))
    if not len(bad):
        return None
    k = int(bad[0])
    if k == 0:
        return 0, 0.0
    a, b = margin[k - 1], margin[k]
    f = 1.0 if not np.isfinite(b) else float(a / (a - b)) if a != b else 1.0
    return k, min(max(f, 0.0), 1.0)
