"""Multirotor tracking of a planned path: a point mass with bounded speed and acceleration.

Guidance: the same carrot as the fixed-wing (:class:`.tracking.Carrot`). The
desired velocity points at the carrot with the admissible speed of the path
there (:func:`.speed_profile.speed_profile`: W, curvature ``sqrt(a_max/κ)``)
and a braking limit ``sqrt(2 a_max d_goal)`` so it stops at the goal; its
vertical part is clipped to ``[-v_descent, v_climb]`` and its horizontal part
to ``v_max``. The acceleration is ``(v_des - v) / τ`` (τ = 0.5 s) clipped to
``a_max`` — clipped steps are recorded as ``"accel"`` saturation, clipped
vertical speeds as ``"climb"`` / ``"descent"``.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ..errors import InputError
from ..geometry import arc_length, as_path3
from .airframes import Multirotor, get_airframe
from .speed_profile import speed_profile
from .tracking import Carrot, FlightLog, Tracking, TrackingOptions

__all__ = ["track_multirotor"]

_TAU = 0.5  # velocity response time constant [s]


def track_multirotor(
    path: Any,
    airframe: Multirotor | str,
    *,
    w: Any = None,
    tracking: TrackingOptions = TrackingOptions(),
) -> Tracking:
    """Fly a multirotor along ``path`` and record what happens.

    Parameters
    ----------
    path : array (N, 2|3)
        Planned path [m].
    airframe : Multirotor or preset name
    w : array (N,), optional
        W along the path in [0, 1] (speed = W v_max); default: no W limit.
    tracking : TrackingOptions
        Its ``lookahead`` is the largest carrot distance [m] (default
        ``max(v_max * 1 s, 2 m)``): the carrot is ``max(v_adm * 1 s, 1 m)``
        ahead, capped at this. Time limit: ``3 x length / mean admissible
        speed + 60``.

    Returns
    -------
    Tracking
        ``saturated``: ``"accel"``, ``"climb"``, ``"descent"``; ``states``:
        ``speed`` [m/s], ``v_ref`` [m/s].
    """
    af = get_airframe(airframe)
    if not isinstance(af, Multirotor):
        raise InputError(
            f"track_multirotor needs a multirotor airframe, got the {af.kind} {af.name!r}; "
            "use fm2uav.vehicles.track_dubins for fixed-wings"
        )
    planned = as_path3(path)
    dt = tracking.step()
    L = tracking.carrot_distance(path, max(af.max_speed * 1.0, 2.0))
    prof = speed_profile(path, af, w)
    s_plan = arc_length(planned)
    length = float(s_plan[-1])
    v_floor = 0.05 * af.max_speed  # W = 0 would never arrive: creep at 5 %
    v_adm = np.maximum(prof.v_admissible, v_floor)
    t_max = tracking.time_limit(length, float(np.mean(v_adm)))
    carrot = Carrot.along(planned, L, length, af.max_speed, dt)
    v_at = np.interp(carrot.s, prof.s, v_adm)
    a_max = af.max_accel

    pos = planned[0].copy()
    vel = np.zeros(3)
    log = FlightLog(t_max, dt, ("accel", "climb", "descent"), ("speed", "v_ref"))
    traj, prog = log.traj, log.prog
    sat_a, sat_c, sat_d = log.saturated.values()
    spd, vref = log.states.values()
    reached = False
    k = 0
    for k in range(log.n_max):
        # look ahead ~1 s at the admissible speed (>= 1 m, <= lookahead)
        idx, c = carrot.update(pos, ahead=max(float(v_at[carrot.idx]) * 1.0, 1.0))
        goal_d = float(np.linalg.norm(planned[-1] - pos))
        if (idx >= carrot.last or goal_d < 0.05) and k > 0:
            reached = True
            k -= 1
            break
        traj[k], prog[k], spd[k] = pos, carrot.s[idx], float(np.linalg.norm(vel))
        d = c - pos
        dn = float(np.linalg.norm(d))
        v_ref = min(float(v_at[idx]), math.sqrt(2.0 * a_max * goal_d))
        vref[k] = v_ref
        v_des, sat_c[k], sat_d[k] = _desired_velocity(d, dn, v_ref, af)
        acc, sat_a[k] = _acceleration(v_des, vel, a_max)
        new_vel = vel + acc * dt
        pos = pos + 0.5 * (vel + new_vel) * dt
        vel = new_vel
    return log.tracking(af, planned, k + 1, reached=reached, lookahead=L)


def _desired_velocity(d: np.ndarray, dn: float, v_ref: float, af: Multirotor) -> tuple[np.ndarray, bool, bool]:
    """Velocity [m/s] towards the carrot offset ``d`` (length ``dn`` [m]) at ``v_ref``.

    Its vertical part is clipped to ``[-max_descent_rate, max_climb_rate]``, its
    horizontal part to ``max_speed``. Returns it and whether the climb / the
    descent limit clipped it.
    """
    v_des = d / dn * v_ref if dn > 1e-12 else np.zeros(3)
    sat_c = sat_d = False
    if v_des[2] > af.max_climb_rate:
        sat_c = True
        v_des[2] = af.max_climb_rate
    elif v_des[2] < -af.max_descent_rate:
        sat_d = True
        v_des[2] = -af.max_descent_rate
    h = math.hypot(v_des[0], v_des[1])
    if h > af.max_speed:
        v_des[:2] *= af.max_speed / h
    return v_des, sat_c, sat_d


def _acceleration(v_des: np.ndarray, vel: np.ndarray, a_max: float) -> tuple[np.ndarray, bool]:
    """First-order response ``(v_des - vel) / τ`` [m/s²] clipped to ``a_max``; and whether it was clipped."""
    acc = (v_des - vel) / _TAU
    an = float(np.linalg.norm(acc))
    if an > a_max * (1 + 1e-9):
        return acc * (a_max / an), True
    return acc, False
