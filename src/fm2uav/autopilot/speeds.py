"""The speeds a mission commands (``DO_CHANGE_SPEED``, 178), from the airframe's range.

Every mission commands its speed before the first waypoint: without a
``DO_CHANGE_SPEED`` ArduPlane flies its own ``AIRSPEED_CRUISE`` and ArduCopter
``WPNAV_SPEED`` (PX4 ``FW_AIRSPD_TRIM`` / ``MPC_XY_CRUISE``), whatever speed the
flight-time estimate assumed. The speeds:

* **range** ``[floor, cap]``: the cap is the airframe's forward speed (the cruise
  speed of a fixed-wing or VTOL, the multirotor's hover speed); the floor is the
  airframe's minimum speed (``airframe.min_speed``; fixed-wing: a margin above the
  stall, required for speed changes; multirotor default :data:`DEFAULT_MIN_SPEED`);
* **from W** (``speed_changes``): the thesis maps the velocity map W in [0, 1] onto
  the speed range (§3.2: "0 corresponds to the stall speed and 1 to the maximum"),
  ``v = floor + W (cap − floor)`` — never below the floor, never above the forward
  speed the user chose. W is the **obstacle-distance** map along the path
  (:meth:`fm2uav.planning.Plan.speed_share`): the flight-level shaping of a
  terrain-following plan (p1/p2) keeps the path on its level and says nothing about
  speed (taking it for a speed commanded 1 m/s for a whole route, issue 24), and the
  obstacle distances saturate at the flight level's AGL (the height the plan keeps is
  open sky: the forward speed). Speeds
  are quantised down to ``speed_step`` with a hysteresis (:func:`speed_commands`);
* **timed** trajectories (formations): the mean speed of each leg keeps the
  timing, holds where the vehicle waits;
* **type** (param1): what the firmware acts on for the airframe
  (:class:`~fm2uav.autopilot.firmware.navigation.SpeedCommand`: airspeed 0 for a
  plane — ArduPlane's type 1 sets ``MIN_GROUNDSPEED`` —, ground speed 1 for a
  multirotor).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..errors import InputError, MissionError

__all__ = ["DEFAULT_MIN_SPEED", "Speeds", "speed_commands", "w_leg_speeds", "timed_legs",
           "plan_speeds"]

#: Lowest commanded speed of multirotors without ``min_speed`` [m/s] (never 0: a 0 m/s
#: DO_CHANGE_SPEED would stop the vehicle on its leg).
DEFAULT_MIN_SPEED = 1.0


@dataclass(frozen=True)
class Speeds:
    """The speeds of a mission, leg by leg.

    Attributes
    ----------
    commanded : ndarray, shape (n - 1,)
        Speed in force on each leg between waypoints [m/s].
    changes : list of (int, float)
        ``DO_CHANGE_SPEED`` items: (leg index, speed m/s); leg 0 always has one.
    holds : ndarray, shape (n,)
        Hold time at each waypoint [s].
    timing : dict or None
        A timed trajectory's planned duration (formations).
    floor, cap : float
        The range the speeds were taken from [m/s].
    source : str
        ``"forward speed"``, ``"W"`` or ``"timing"``.
    """

    commanded: np.ndarray
    changes: list[tuple[int, float]]
    holds: np.ndarray
    timing: dict[str, Any] | None
    floor: float
    cap: float
    source: str

    def summary(self, step: float, speed_type: int) -> dict[str, Any]:
        """JSON-friendly description (``summary.json`` ``speed_changes``)."""
        return {"items": len(self.changes),
                "speeds_mps": sorted({round(v, 3) for _, v in self.changes}),
                "first_mps": round(self.changes[0][1], 3) if self.changes else None,
                "range_mps": [round(self.floor, 3), round(self.cap, 3)],
                "from": self.source, "speed_type": speed_type, "step_mps": step,
                "enabled": self.source != "forward speed"}


def speed_commands(leg_speeds: Any, *, current: float | None, step: float, hysteresis: int,
                   floor: float, cap: float, rounding: str = "down") -> list[tuple[int, float]]:
    """Where to change speed and to what: ``[(leg index, speed m/s), ...]``.

    Each leg's admissible speed is quantised down to a multiple of ``step``
    (never above what the leg allows), clipped to ``[floor, cap]``. The first
    leg always gets a command; later legs get one when the quantised speed is
    below the current command (slow down at once) or at least ``hysteresis``
    steps above it (speed up only for a clear gain), so noise in W does not
    produce a stream of items. ``rounding="nearest"`` (timed trajectories)
    rounds to the nearest step instead of down.
    """
    v = np.asarray(leg_speeds, dtype=float)
    out: list[tuple[int, float]] = []
    c = current
    for k, s in enumerate(v):
        n = math.floor(s / step + 1e-9) if rounding == "down" else round(s / step)
        q = min(max(n * step, floor), cap)
        if c is None or q < c - 1e-9 or q >= c + hysteresis * step - 1e-9:
            out.append((k, round(q, 6)))
            c = q
    return out


def w_leg_speeds(w_dense: Any, idx: Any, floor: float, cap: float) -> np.ndarray:
    """Slowest admissible speed ``floor + W (cap − floor)`` over the dense points of each
    leg between the kept indices ``idx`` [m/s]."""
    w = np.clip(np.asarray(w_dense, dtype=float), 0.0, 1.0)
    v = floor + w * (cap - floor)
    idx = np.asarray(idx, dtype=int)
    return np.array([v[a:b + 1].min() for a, b in zip(idx[:-1], idx[1:])])


def timed_legs(times: np.ndarray, points: np.ndarray, idx: np.ndarray, floor: float
               ) -> tuple[np.ndarray, np.ndarray]:
    """Speed on each straight leg between waypoints that keeps a timed trajectory's
    timing, and the hold time at each waypoint where it waits [m/s], [s]."""
    d = np.diff(points, axis=0)
    lengths = np.hypot(d[:, 0], d[:, 1])
    dt = times[idx[1:]] - times[idx[:-1]]
    if np.any(dt <= 0):
        raise InputError("the trajectory's times must increase from waypoint to waypoint")
    holds = np.zeros(len(idx))
    speeds = lengths / dt
    slow = speeds < floor  # fly at the floor speed and wait the rest at the leg's start
    holds[:-1][slow] = dt[slow] - lengths[slow] / floor
    speeds[slow] = floor
    return speeds, holds


def plan_speeds(*, indices: Any, points: Any, forward: float, floor: float | None,
                fixed_wing: bool, changes: bool, step: float, hysteresis: int,
                w: Any = None, times: Any = None, start_hold: float = 0.0) -> Speeds:
    """The speed of every leg and the ``DO_CHANGE_SPEED`` items (module docstring).

    Parameters
    ----------
    indices : array_like of int, shape (n,)
        Dense-path indices of the waypoints.
    points : array_like, shape (n, 3)
        The waypoints [m].
    forward : float
        The airframe's forward speed: the cap [m/s].
    floor : float or None
        The airframe's minimum speed [m/s] (None: :data:`DEFAULT_MIN_SPEED` for
        multirotors; fixed-wing speed changes need it).
    fixed_wing : bool
        Fixed-wing or VTOL (whose minimum is a stall margin).
    changes : bool
        Speeds from W (``speed_changes``).
    step, hysteresis
        Quantisation (:func:`speed_commands`).
    w : array_like, optional
        W along the dense path (the obstacle-distance map), for ``changes``.
    times : array_like, optional
        Time of each dense point [s]: a timed trajectory.
    start_hold : float
        With ``times``: wait at the start [s].

    Raises
    ------
    MissionError
        Fixed-wing speed changes without a minimum speed; W missing.
    """
    idx = np.asarray(indices, dtype=int)
    pts = np.asarray(points, dtype=float)
    cap = float(forward)
    lo = floor if floor is not None else (None if fixed_wing else DEFAULT_MIN_SPEED)
    if lo is not None and lo > cap:
        raise MissionError(f"the minimum speed {lo:g} m/s is above the forward speed {cap:g} "
                           "m/s (airframe.min_speed / cruise_speed / hover_speed, --min-speed)")
    holds = np.zeros(len(idx))
    timing = None
    if times is not None:
        t = np.asarray(times, dtype=float)
        f = lo or 0.5
        leg_v, holds = timed_legs(t, pts, idx, f)
        holds[0] += float(start_hold)
        ch = speed_commands(leg_v, current=None, step=step, hysteresis=0, floor=f,
                            cap=float(max(leg_v.max(), f)), rounding="nearest")
        timing = {"planned_s": round(float(t[-1] - t[0]), 2),
                  "start_hold_s": round(float(start_hold), 2)}
        source, lo_used, cap_used = "timing", f, float(max(leg_v.max(), f))
    elif changes:
        if lo is None:
            raise MissionError("fixed-wing speed changes need airframe.min_speed (a margin "
                               "above the stall speed; CLI --min-speed) so that no commanded "
                               "airspeed falls below it")
        if w is None:
            raise MissionError("speed changes need W along the path (the plan's speed map)")
        wd = np.asarray(w, dtype=float)
        if wd.shape != (idx[-1] + 1,):
            raise InputError(f"W along the path must have {idx[-1] + 1} values, got {wd.shape}")
        leg_v = w_leg_speeds(wd, idx, lo, cap)
        ch = speed_commands(leg_v, current=None, step=step, hysteresis=hysteresis, floor=lo,
                            cap=cap)
        source, lo_used, cap_used = "W", lo, cap
    else:
        ch = [(0, round(cap, 6))]
        source, lo_used, cap_used = "forward speed", (lo if lo is not None else cap), cap
    commanded = np.full(len(idx) - 1, cap)
    for k, v in ch:
        commanded[k:] = v
    return Speeds(commanded, ch, holds, timing, float(lo_used), float(cap_used), source)
