"""Energy [Wh] and time [min] of a flight along waypoints, in a wind.

Each leg between two waypoints is flown straight at a steady state (accelerations
and turns are not modelled). The wind ``w`` is horizontal, constant along a leg
(sample a field at the legs' midpoints). With ``u`` the leg's horizontal unit vector,
``L`` its horizontal length and ``dz`` its height change:

* **ground speed commanded** (a multirotor: ArduCopter's ``WPNAV_SPEED`` and PX4's
  ``MPC_XY_CRUISE`` are ground speeds): the leg takes
  ``t = max(L / v, dz⁺ / v_climb, dz⁻ / v_descent)`` as in still air, the air
  velocity is ``(L/t) u − w``; when its size exceeds the airframe's largest airspeed
  (:meth:`~.power.MultirotorPower.max_airspeed`) the vehicle flies at that airspeed
  and the ground speed drops to what it then makes good;
* **airspeed held** (a fixed-wing: ``AIRSPEED_CRUISE``, TECS): the ground speed ``g``
  along the leg solves ``|g u − w|² + (g s)² = V²`` (``s = dz / L``, the climb
  following the line), ``g = (u·w + sqrt((u·w)² − (1 + s²)(|w|² − V²))) / (1 + s²)``.

A leg the vehicle cannot make good against the wind (no positive ground speed) is
*not flyable*: its time and energy are infinite and :class:`Flight` lists it, it is
never averaged away. The power at each leg's airspeed and climb rate comes from the
airframe's :mod:`.power` model; the energy is power × time. The take-off climb and
the final descent are vertical legs (a fixed-wing flies them at its airspeed and
the climb / sink rate), holds are hovered (loitered) in the wind.

:func:`check_battery` compares the energy with the battery kept ``reserve`` in
reserve, and :func:`no_return_point` adds, at each waypoint, the energy of flying
straight home against the same wind: the last waypoint from which the vehicle still
gets home within the usable energy.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Literal

import numpy as np

from .._validate import non_negative, positive
from ..errors import InputError
from .power import FixedWingPower, PowerModel

__all__ = ["Flight", "BatteryReport", "fly_legs", "check_battery", "home_legs",
           "no_return_point", "ground_speed_at_airspeed"]

_J_PER_WH = 3600.0


def ground_speed_at_airspeed(u: Any, wind: Any, airspeed: Any, slope: Any = 0.0) -> np.ndarray:
    """Ground speed [m/s] along unit directions ``u`` flown at ``airspeed`` in ``wind``.

    Parameters
    ----------
    u : array_like, shape (..., 2)
        Horizontal unit vectors of the track.
    wind : array_like, shape (..., 2)
        Horizontal wind [m/s] (the velocity of the air, towards where it blows).
    airspeed : array_like
        True airspeed [m/s].
    slope : array_like
        ``dz / L`` of the track (climb along the line).

    Returns
    -------
    ndarray
        The horizontal ground speed; ``nan`` where the vehicle cannot make headway.

    Examples
    --------
    >>> float(ground_speed_at_airspeed([1.0, 0.0], [-4.0, 0.0], 10.0))   # headwind
    6.0
    >>> float(ground_speed_at_airspeed([1.0, 0.0], [0.0, 6.0], 10.0))    # crosswind
    8.0
    """
    u = np.asarray(u, dtype=float)
    w = np.asarray(wind, dtype=float)
    va = np.asarray(airspeed, dtype=float)
    a = 1.0 + np.asarray(slope, dtype=float) ** 2
    b = np.sum(u * w, axis=-1)
    c = np.sum(w * w, axis=-1) - va * va
    disc = b * b - a * c
    with np.errstate(invalid="ignore"):
        g = (b + np.sqrt(disc)) / a
    return np.where((disc >= 0) & (g > 0), g, np.nan)


@dataclass(frozen=True)
class Flight:
    """A flight leg by leg, with its power and energy.

    Attributes
    ----------
    leg_length : ndarray, shape (n - 1,)
        3D length of each leg [m].
    leg_time : ndarray, shape (n - 1,)
        Duration of each leg [s] (holds included; ``inf``: not flyable).
    groundspeed, airspeed, climb : ndarray, shape (n - 1,)
        Horizontal ground speed, airspeed and climb rate on each leg [m/s].
    power : ndarray, shape (n - 1,)
        Electrical power on each leg [W].
    leg_energy_j : ndarray, shape (n - 1,)
        Energy of each leg [J] (holds included).
    flyable : ndarray of bool, shape (n - 1,)
        The vehicle makes good the leg against the wind.
    takeoff_s, takeoff_j, landing_s, landing_j : float
        Time [s] and energy [J] of the take-off climb and the final descent.
    """

    leg_length: np.ndarray
    leg_time: np.ndarray
    groundspeed: np.ndarray
    airspeed: np.ndarray
    climb: np.ndarray
    power: np.ndarray
    leg_energy_j: np.ndarray
    flyable: np.ndarray
    takeoff_s: float = 0.0
    takeoff_j: float = 0.0
    landing_s: float = 0.0
    landing_j: float = 0.0

    @property
    def time_s(self) -> float:
        """Total flight time [s] (``inf`` when a leg is not flyable)."""
        return float(self.takeoff_s + self.leg_time.sum() + self.landing_s)

    @property
    def energy_wh(self) -> float:
        """Total energy [Wh] (``inf`` when a leg is not flyable)."""
        return float(self.takeoff_j + self.leg_energy_j.sum() + self.landing_j) / _J_PER_WH

    @property
    def distance_m(self) -> float:
        """Length of the waypoint legs [m] (take-off and landing not counted)."""
        return float(self.leg_length.sum())

    def elapsed(self) -> np.ndarray:
        """Time [s] at which each waypoint is reached (take-off included)."""
        return self.takeoff_s + np.concatenate([[0.0], np.cumsum(self.leg_time)])

    def used_wh(self) -> np.ndarray:
        """Energy [Wh] used when each waypoint is reached (take-off included)."""
        return (self.takeoff_j + np.concatenate([[0.0], np.cumsum(self.leg_energy_j)])
                ) / _J_PER_WH

    def summary(self) -> dict[str, Any]:
        """JSON-friendly numbers (``None`` for an infinite total)."""
        def fin(x: float, nd: int) -> float | None:
            return round(x, nd) if np.isfinite(x) else None
        ok = self.flyable
        return {
            "energy_wh": fin(self.energy_wh, 2),
            "time_s": fin(self.time_s, 1),
            "mean_power_w": fin(self.energy_wh * _J_PER_WH / self.time_s, 1)
            if self.time_s > 0 else None,
            "groundspeed_mps": [fin(float(self.groundspeed[ok].min()), 2),
                                fin(float(self.groundspeed[ok].max()), 2)] if ok.any() else None,
            "airspeed_mps": [fin(float(self.airspeed[ok].min()), 2),
                             fin(float(self.airspeed[ok].max()), 2)] if ok.any() else None,
            "unflyable_legs": np.flatnonzero(~ok).tolist(),
        }


def _wind_legs(wind: Any, n: int) -> np.ndarray:
    if wind is None:
        return np.zeros((n, 2))
    w = np.asarray(wind, dtype=float)
    if w.shape == (2,):
        w = np.broadcast_to(w, (n, 2))
    if w.shape != (n, 2) or not np.all(np.isfinite(w)):
        raise InputError(f"wind must be a finite (u, v) vector [m/s] or one per leg, shape "
                         f"({n}, 2); got shape {w.shape}")
    return w


def fly_legs(
    points: Any,
    model: PowerModel,
    *,
    speed: Any,
    climb_rate: float,
    descent_rate: float,
    wind: Any = None,
    holds: Any = None,
    takeoff_climb: float = 0.0,
    final_descent: float = 0.0,
    hold: Literal["ground", "air"] | None = None,
    takeoff_time: float | None = None,
    final_time: float | None = None,
) -> Flight:
    """Time, power and energy of each leg between ``points`` flown in ``wind``.

    Parameters
    ----------
    points : array_like, shape (n, 3)
        Waypoints [m] (x east, y north, altitude).
    model : MultirotorPower or FixedWingPower
        The airframe's power model (:mod:`.power`).
    speed : float or array_like, shape (n - 1,)
        Commanded speed on each leg [m/s]: a ground speed or an airspeed (``hold``).
    climb_rate, descent_rate : float
        Vertical speed limits [m/s] (> 0).
    wind : array_like, shape (2,) or (n - 1, 2), optional
        Horizontal wind (u east, v north) [m/s] on each leg; default still air.
    holds : array_like, shape (n,), optional
        Hold time at each waypoint [s].
    takeoff_climb, final_descent : float
        Heights [m] of the vertical take-off climb and of the final descent.
    hold : {"ground", "air"}, optional
        What ``speed`` is: a ground speed (default for a multirotor) or an airspeed
        (default for a fixed-wing).
    takeoff_time, final_time : float, optional
        Durations [s] of the take-off climb and of the final descent when they are not
        flown at the climb / descent rate (a fixed-wing's climb-out, its landing pattern:
        the height spread over the time, at the first leg's airspeed). Default: the
        height over the rate.

    Returns
    -------
    Flight
    """
    p = np.asarray(points, dtype=float)
    if p.ndim != 2 or p.shape[1] != 3 or len(p) < 1 or not np.all(np.isfinite(p)):
        raise InputError(f"points must be a finite (n, 3) array, got shape {np.shape(points)}")
    up = positive(climb_rate, "climb_rate", unit="m/s")
    down = positive(descent_rate, "descent_rate", unit="m/s")
    fixed = isinstance(model, FixedWingPower)
    mode = hold or ("air" if fixed else "ground")
    if mode not in ("ground", "air"):
        raise InputError(f"hold must be 'ground' or 'air', got {hold!r}")
    d = np.diff(p, axis=0)
    n = len(d)
    horiz = np.hypot(d[:, 0], d[:, 1])
    dz = d[:, 2]
    v = np.broadcast_to(np.asarray(speed, dtype=float), (n,)).copy()
    if n and not (np.all(np.isfinite(v)) and np.all(v > 0)):
        raise InputError("leg speeds must be finite and > 0 m/s")
    w = _wind_legs(wind, n)
    moving = horiz > 1e-9
    u = np.zeros((n, 2))
    u[moving] = d[moving, :2] / horiz[moving, None]
    slope = np.where(moving, dz / np.where(moving, horiz, 1.0), 0.0)
    vertical_t = np.maximum(np.maximum(dz, 0) / up, np.maximum(-dz, 0) / down)
    if mode == "air":
        g = ground_speed_at_airspeed(u, w, v, slope)
        t = np.where(moving, horiz / np.where(np.isfinite(g), g, 1.0), vertical_t)
        ok = ~moving | np.isfinite(g)
        air = v.copy()
        vz = np.where(moving, slope * np.nan_to_num(g), np.sign(dz) * np.where(dz > 0, up, down))
    else:
        t = np.maximum(horiz / v, vertical_t)
        g = np.where(t > 0, horiz / np.where(t > 0, t, 1.0), 0.0)
        air_vec = g[:, None] * u - w
        air = np.hypot(air_vec[:, 0], air_vec[:, 1])
        cap = model.max_airspeed() if hasattr(model, "max_airspeed") else np.inf
        over = air > cap
        ok = np.ones(n, dtype=bool)
        if np.any(over):
            g2 = ground_speed_at_airspeed(u[over], w[over], cap)
            still = ~moving[over]  # holding a vertical line against a wind above the cap
            g2 = np.where(still, np.nan, g2)
            ok[over] = np.isfinite(g2)
            t_over = np.maximum(horiz[over] / np.where(np.isfinite(g2), g2, 1.0),
                                vertical_t[over])
            t[over] = t_over
            g[over] = np.where(np.isfinite(g2), horiz[over] / np.where(t_over > 0, t_over, 1.0),
                               np.nan)
            air[over] = np.where(np.isfinite(g2), np.hypot(*(g[over][:, None] * u[over]
                                                            - w[over]).T), cap)
        vz = np.where(t > 0, dz / np.where(t > 0, t, 1.0), 0.0)
    t = np.where(ok, t, np.inf)
    if holds is not None:
        h = np.asarray(holds, dtype=float)
        if h.shape != (len(p),) or np.any(h < 0) or not np.all(np.isfinite(h)):
            raise InputError(f"holds must be {len(p)} times >= 0 s")
    else:
        h = np.zeros(len(p))
    air_ok = np.where(ok, air, v if fixed else 0.0)
    pw = model.power(np.maximum(air_ok, 1e-6) if fixed else air_ok, np.where(ok, vz, 0.0))
    # holds: hovered in the wind (a multirotor's airspeed is the wind's speed) or
    # loitered at the airspeed
    wind_at_wp = np.vstack([w[:1], w]) if n else np.zeros((len(p), 2))
    hold_air = (np.broadcast_to(v[:1] if n else [1.0], len(p)) if fixed
                else np.hypot(wind_at_wp[:, 0], wind_at_wp[:, 1]))
    # (no holds: no hover power to weigh, the zeros it would give)
    hold_j = h * model.power(hold_air, 0.0) if np.any(h) else np.zeros(len(p))
    energy = np.where(ok, pw * t, np.inf) + hold_j[1:]
    t = t + h[1:]
    # vertical take-off and final descent
    v0 = float(v[0]) if n else 1.0
    climb, desc = max(float(takeoff_climb), 0.0), max(float(final_descent), 0.0)
    air_v = v0 if fixed else 0.0
    t_up = climb / up if takeoff_time is None else non_negative(
        takeoff_time, "takeoff_time", unit="s")
    t_dn = desc / down if final_time is None else non_negative(final_time, "final_time", unit="s")
    vz_up = up if takeoff_time is None else (climb / t_up if t_up > 0 else 0.0)
    vz_dn = down if final_time is None else (desc / t_dn if t_dn > 0 else 0.0)
    e_up = float(model.power(air_v, vz_up)) * t_up + float(hold_j[0])
    e_dn = float(model.power(air_v, -vz_dn)) * t_dn
    return Flight(leg_length=np.hypot(horiz, dz), leg_time=t, groundspeed=g,
                  airspeed=air, climb=vz, power=pw, leg_energy_j=energy, flyable=ok,
                  takeoff_s=t_up + float(h[0]), takeoff_j=e_up, landing_s=t_dn, landing_j=e_dn)


@dataclass(frozen=True)
class BatteryReport:
    """A flight's energy against the battery.

    Attributes
    ----------
    energy_wh, time_s, distance_m : float
        The whole flight [Wh], [s], [m] (``inf`` energy/time: a leg not flyable).
    battery_wh : float
        Battery energy [Wh].
    reserve : float
        Share kept in reserve.
    usable_wh : float
        ``battery × (1 − reserve)`` [Wh].
    ok : bool
        Every leg flyable and the energy within the usable energy.
    reach_m : float
        Distance along the waypoint legs at which the usable energy runs out [m].
    reach_waypoint : int
        Last waypoint reached within the usable energy.
    waypoints : int
        Number of waypoints.
    unflyable : list of int
        Legs (index of their first waypoint) the vehicle cannot make good in the wind.
    """

    energy_wh: float
    time_s: float
    distance_m: float
    battery_wh: float
    reserve: float
    usable_wh: float
    ok: bool
    reach_m: float
    reach_waypoint: int
    waypoints: int
    unflyable: list[int]

    @property
    def warning(self) -> str | None:
        """One line saying what fails, or None when the battery lasts."""
        if self.unflyable:
            legs = ", ".join(f"{k}→{k + 1}" for k in self.unflyable[:5])
            return (f"wind: the vehicle cannot make headway on {len(self.unflyable)} leg(s) "
                    f"({legs}{', ...' if len(self.unflyable) > 5 else ''}); the wind there "
                    "is stronger than its airspeed: fly another day or another route")
        if self.ok:
            return None
        return (f"battery: the flight needs {self.energy_wh:.1f} Wh ({self.time_s / 60:.1f} "
                f"min) but {self.battery_wh:.0f} Wh with a {100 * self.reserve:.0f} % reserve "
                f"leaves {self.usable_wh:.1f} Wh: the vehicle gets {self.reach_m / 1000:.2f} km "
                f"along (waypoint {self.reach_waypoint} of {self.waypoints - 1}) before it eats "
                "into the reserve")

    def summary(self) -> dict[str, Any]:
        """JSON-friendly numbers."""
        def fin(x: float, nd: int) -> float | None:
            return round(x, nd) if np.isfinite(x) else None
        return {"energy_wh": fin(self.energy_wh, 2), "time_s": fin(self.time_s, 1),
                "battery_wh": self.battery_wh, "reserve": self.reserve,
                "usable_wh": round(self.usable_wh, 2), "ok": self.ok,
                "reach_m": round(self.reach_m, 1), "reach_waypoint": self.reach_waypoint,
                "unflyable_legs": self.unflyable, "warning": self.warning}


def _budget(battery_wh: float, reserve: float) -> float:
    r = float(reserve)
    if not (0.0 <= r < 1.0):
        raise InputError(f"reserve must be a share in [0, 1) (e.g. 0.2 for 20 %), got {reserve!r}")
    return positive(battery_wh, "battery energy", unit="Wh") * (1.0 - r)


def check_battery(flight: Flight, *, battery_wh: float, reserve: float = 0.2) -> BatteryReport:
    """Compare a :class:`Flight`'s energy with a battery [Wh] kept ``reserve`` in reserve.

    Raises
    ------
    InputError
        Battery not > 0 or reserve outside [0, 1).
    """
    usable = _budget(battery_wh, reserve)
    n = len(flight.leg_time) + 1
    bad = np.flatnonzero(~flight.flyable).tolist()
    used = flight.used_wh()
    ok = not bad and flight.energy_wh <= usable
    if ok:
        k, reach = n - 1, flight.distance_m
    else:
        k = max(int(np.searchsorted(used, usable, side="right")) - 1, 0)
        k = min(k, n - 1)
        reach = float(np.sum(flight.leg_length[:k]))
        if k < n - 1 and used[k] <= usable and np.isfinite(flight.leg_energy_j[k]) \
                and flight.leg_energy_j[k] > 0:
            reach += float(flight.leg_length[k]) * min(
                (usable - used[k]) * _J_PER_WH / flight.leg_energy_j[k], 1.0)
    return BatteryReport(flight.energy_wh, flight.time_s, flight.distance_m, float(battery_wh),
                         float(reserve), usable, ok, reach, k, n, bad)


def home_legs(points: Any, model: PowerModel, *, home: Any, speed: float, climb_rate: float,
              descent_rate: float, wind: Any = None
              ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """``(out_wh, out_s, back_wh, back_s)`` at every waypoint: take-off at ``home``, climb to
    the waypoint's altitude, fly straight to it; and the flight straight back at its
    altitude, descent and landing at ``home`` (``wind``: (u, v) [m/s], one or one per
    waypoint)."""
    p = np.asarray(points, dtype=float)
    h = np.asarray(home, dtype=float)
    n = len(p)
    top = np.column_stack([np.full(n, h[0]), np.full(n, h[1]), p[:, 2]])
    w = None if wind is None else np.broadcast_to(np.asarray(wind, dtype=float), (n, 2))
    # one flight through top_0, p_0, top_1, p_1, ...: the even legs are the ones wanted
    go_path = np.empty((2 * n, 3))
    go_path[0::2], go_path[1::2] = top, p
    back_path = np.empty((2 * n, 3))
    back_path[0::2], back_path[1::2] = p, top
    leg_w = None if w is None else np.repeat(w, 2, axis=0)[:-1]
    kw = dict(speed=speed, climb_rate=climb_rate, descent_rate=descent_rate, wind=leg_w)
    go = fly_legs(go_path, model, **kw)
    back = fly_legs(back_path, model, **kw)
    height = np.maximum(p[:, 2] - h[2], 0.0)
    fixed = model.kind == "fixed-wing"
    air = float(speed) if fixed else 0.0
    t_up, t_dn = height / climb_rate, height / descent_rate
    e_up = float(model.power(air, climb_rate)) * t_up
    e_dn = float(model.power(air, -descent_rate)) * t_dn
    return ((go.leg_energy_j[0::2] + e_up) / 3600.0, go.leg_time[0::2] + t_up,
            (back.leg_energy_j[0::2] + e_dn) / 3600.0, back.leg_time[0::2] + t_dn)


def no_return_point(points: Any, flight: Flight, model: PowerModel, *, home: Any,
                    speed: float, climb_rate: float, descent_rate: float, wind: Any = None,
                    battery_wh: float, reserve: float = 0.2) -> tuple[int, np.ndarray]:
    """The point of no return: the last waypoint from which a straight flight home still fits.

    At waypoint ``i`` the energy used so far (:meth:`Flight.used_wh`) plus the energy of
    flying straight to above ``home`` at the waypoint's altitude and descending there
    (in the same constant ``wind``) is compared with the usable energy.

    Parameters
    ----------
    points : array_like, shape (n, 3)
        The waypoints ``flight`` was flown along [m].
    home : array_like, shape (3,)
        Home [m] (its altitude is the ground the final descent reaches).
    speed : float
        Speed of the way home [m/s] (ground or air, as for the flight).
    wind : array_like, shape (2,), optional
        Constant wind on the way home [m/s].

    Returns
    -------
    (k, margin_wh)
        ``k`` the waypoint before the first with a negative margin (−1: none has one;
        ``n − 1``: all do), and the margin
        ``usable − used − home`` [Wh] at every waypoint (``-inf`` where the way home
        cannot be flown in the wind).
    """
    from .endurance import first_shortfall

    usable = _budget(battery_wh, reserve)
    back = home_legs(points, model, home=home, speed=speed, climb_rate=climb_rate,
                     descent_rate=descent_rate, wind=wind)[2]
    used = flight.used_wh()
    margin = usable - used - back
    margin = np.where(np.isfinite(margin), margin, -np.inf)
    hit = first_shortfall(used, back, usable)  # the returns layer's rule, on waypoints
    return (hit[0] - 1 if hit is not None else len(margin) - 1), margin
