"""Dubins-airplane tracking of a planned path (thesis ch. 3, eqs 3.2–3.10).

Model (Beard & McLain's Dubins airplane, thesis eq. 3.2), constant speed V::

    ẋ = V cos ψ cos γ,   ẏ = V sin ψ cos γ,   ż = V sin γ,
    |ψ̇| <= g tan φ_max / V,   -γ_descent <= γ <= γ_climb.

Guidance (where the thesis' eqs 3.3–3.10 are ambiguous, see docs/feasibility.md):
a pure-pursuit carrot follower. The aircraft's position is projected on the
planned path (monotone progress); the carrot is the path point
``TrackingOptions.lookahead`` metres further along (the thesis' "p_{i+a}", eqs
3.5–3.6: ``TrackingOptions(lookahead_points=a)`` gives ``a`` path steps). Heading: the pure-pursuit turn rate
``ψ̇ = 2 V cosγ sin η / L_xy`` (η = bearing of the carrot minus ψ, L_xy its
horizontal distance; a carrot behind the aircraft commands the maximum rate),
the thesis' proportional law ρ = K_ψ e(ψ) with gain 2V/L. Flight-path angle:
``γ = atan2(Δz, L_xy)`` towards the carrot (the thesis' eq. 3.4 with the
carrot), the law φ = K_γ e(γ) with an instantaneous response. Unlike the
thesis ("the limitation of ρ and φ has not been considered") both commands are
clipped to the airframe's limits, and every clipped step is recorded as
saturated — without that clipping no path could be found infeasible.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ..errors import InputError
from ..geometry import arc_length, as_path3
from .airframes import Airframe, FixedWing, get_airframe
from .tracking import Carrot, FlightLog, Tracking, TrackingOptions

__all__ = ["track_dubins"]


def track_dubins(
    path: Any,
    airframe: FixedWing | str,
    *,
    speed: float | None = None,
    tracking: TrackingOptions = TrackingOptions(),
) -> Tracking:
    """Fly a fixed-wing Dubins airplane along ``path`` and record what happens.

    Parameters
    ----------
    path : array (N, 2|3)
        Planned path [m], start → goal (2D: flown at z = 0).
    airframe : FixedWing or preset name
    speed : float, optional
        Constant airspeed [m/s]; default the airframe's cruise speed. Must lie
        in [min_speed, max_speed].
    tracking : TrackingOptions
        Look-ahead (default: the minimum turn radius R_min at the flown speed,
        at least 2 m), integration step and time limit (``3 x length / V + 60``).

    Returns
    -------
    Tracking
        ``saturated`` has ``"turn"``, ``"climb"`` and ``"descent"``;
        ``states`` has ``heading``, ``flight_path_angle``, ``turn_rate``.

    Raises
    ------
    InputError
        Bad path (fewer than 2 points, NaN), airframe, speed, look-ahead or dt.
    """
    af: Airframe = get_airframe(airframe)
    if not isinstance(af, FixedWing):
        raise InputError(
            f"track_dubins needs a fixed-wing airframe, got the {af.kind} {af.name!r}; "
            "use fm2uav.vehicles.track_multirotor for multirotors"
        )
    planned = as_path3(path)
    if speed is not None:
        af = af.with_speed(speed)  # validates min <= speed <= max
    V = af.cruise_speed
    dt = tracking.step()
    R = af.turn_radius()
    L = tracking.carrot_distance(path, max(R, 2.0))
    length = float(arc_length(planned)[-1])
    t_max = tracking.time_limit(length, V)
    carrot = Carrot.along(planned, L, length, V, dt)
    rate_max = af.max_turn_rate()
    g_up, g_dn = af.max_climb, af.max_descent

    pos = planned[0].copy()
    c0 = carrot.pts[min(carrot.n_ahead, carrot.last)] - pos
    psi = math.atan2(c0[1], c0[0])
    log = FlightLog(t_max, dt, ("turn", "climb", "descent"),
                    ("heading", "flight_path_angle", "turn_rate"))
    traj, prog = log.traj, log.prog
    sat_t, sat_c, sat_d = log.saturated.values()
    heading, fpa, rate = log.states.values()
    reached = False
    k = 0
    for k in range(log.n_max):
        idx, c = carrot.update(pos)
        if idx >= carrot.last and k > 0:
            # abeam of / past the goal: the flight ends at the previous step
            # (within one step V*dt of the goal), so the overshoot is not counted
            reached = True
            k -= 1
            break
        traj[k] = pos
        prog[k] = carrot.s[idx]
        d = c - pos
        lxy = math.hypot(d[0], d[1])
        g_cmd, sat_c[k], sat_d[k] = _flight_path_command(d[2], lxy, g_up, g_dn)
        cmd, sat_t[k] = _turn_rate_command(d, lxy, psi, V, g_cmd, rate_max)
        heading[k], fpa[k], rate[k] = psi, g_cmd, cmd
        pos, psi = _integrate_step(pos, psi, cmd, g_cmd, V, dt)
    log.states["speed"] = np.full(log.n_max, V)
    return log.tracking(af, planned, k + 1, reached=reached, lookahead=L)


def _flight_path_command(dz: float, lxy: float, g_up: float, g_dn: float) -> tuple[float, bool, bool]:
    """Flight-path angle [rad] towards the carrot, clipped to ``[-g_dn, g_up]``.

    Returns the angle and whether the climb / the descent limit clipped it.
    """
    g_cmd = math.atan2(dz, lxy)
    if g_cmd > g_up:
        return g_up, True, False
    if g_cmd < -g_dn:
        return -g_dn, False, True
    return g_cmd, False, False


def _turn_rate_command(
    d: np.ndarray, lxy: float, psi: float, V: float, g_cmd: float, rate_max: float,
) -> tuple[float, bool]:
    """Pure-pursuit turn rate [rad/s] towards the carrot offset ``d`` [m], clipped to ``rate_max``.

    A carrot behind the aircraft commands the maximum rate. Returns the rate and
    whether it was clipped.
    """
    if lxy > 1e-9:
        eta = (math.atan2(d[1], d[0]) - psi + math.pi) % (2 * math.pi) - math.pi
        if abs(eta) > math.pi / 2:
            cmd = math.copysign(math.inf, eta)
        else:
            cmd = 2.0 * V * math.cos(g_cmd) * math.sin(eta) / lxy
    else:
        cmd = 0.0
    if abs(cmd) > rate_max * (1 + 1e-9):
        return math.copysign(rate_max, cmd), True
    return cmd, False


def _integrate_step(
    pos: np.ndarray, psi: float, cmd: float, g_cmd: float, V: float, dt: float,
) -> tuple[np.ndarray, float]:
    """One step of ``dt`` [s]: midpoint heading, constant flight-path angle; new position and heading."""
    pm = psi + 0.5 * cmd * dt
    cg = math.cos(g_cmd)
    pos = pos + V * dt * np.array([math.cos(pm) * cg, math.sin(pm) * cg, math.sin(g_cmd)])
    return pos, psi + cmd * dt
