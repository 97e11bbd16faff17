"""The energy of a built mission: its waypoints flown at their commanded speeds by the
airframe's power model, in the wind (:mod:`fm2uav.vehicles.energy`).

The power model is the mission's (``airframe.power``: a preset name, parameters, or
the file a flight-log fit wrote) or, when none is given, the class model of its
airframe type (:data:`DEFAULT_POWER`, said so in the summary). The battery is
``airframe.battery`` [Wh] or the model's. The legs are the mission's waypoints at the
commanded speeds and hold times, the take-off climb, then (``rtl``) the straight line
home at the forward speed and the descent there, or the final descent (``land``);
the wind of each leg is the field's at the leg's midpoint and height above ground. A
fixed-wing flies the phases of the mission's flight time (:class:`ClimbOutClock`): its
climb-out, the legs from where it leaves, its landing pattern or its circle over home,
so that in still air the energy's time is the flight time.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from ..vehicles.energy import Flight, _budget, check_battery, fly_legs, no_return_point
from ..vehicles.power import PowerModel, get_power_model

__all__ = ["DEFAULT_POWER", "ClimbOutClock", "MissionPower", "mission_energy", "power_model"]

#: Power model of each airframe type when the mission gives none (a VTOL in plane mode:
#: its hover phases cost several times more and are not in the figure).
DEFAULT_POWER = {"multirotor": "arducopter", "fixed_wing": "disco", "vtol": "crosswind"}


def power_model(power: Any, vehicle: str) -> PowerModel:
    """The mission's power model: ``power`` (``airframe.power``) or, when None, the class
    model of the airframe type (:data:`DEFAULT_POWER`)."""
    return get_power_model(power if power is not None else DEFAULT_POWER.get(vehicle,
                                                                               "arducopter"))


@dataclass(frozen=True, eq=False)
class MissionPower:
    """The energy model of a built mission, for flights it did not write (ways home, ways
    out): its power model, battery and reserve, forward speed, climb and descent rates and
    wind (:func:`mission_energy`'s), and its world for the heights above ground the wind
    profile is read at.

    Attributes
    ----------
    model : PowerModel
    battery_wh, reserve : float
        Battery [Wh] and the share of it kept.
    speed, climb_rate, descent_rate : float
        Forward speed and vertical speed limits [m/s].
    wind : WindField or None
    world : World
    """

    model: PowerModel
    battery_wh: float
    reserve: float
    speed: float
    climb_rate: float
    descent_rate: float
    wind: Any
    world: Any

    @classmethod
    def of(cls, mission: Any) -> MissionPower:
        """The energy model of ``mission`` (a :class:`~fm2uav.autopilot.build.MissionExport`)."""
        opt = mission.options
        model = power_model(opt.power, opt.vehicle)
        flight = mission.info["flight"]
        return cls(model, float(opt.battery_wh if opt.battery_wh is not None
                                else model.battery_wh), float(opt.reserve),
                   float(opt.forward_speed), float(flight["climb_rate_mps"]),
                   float(flight["descent_rate_mps"]), opt.wind, mission.world)

    @property
    def usable_wh(self) -> float:
        """Battery × (1 − reserve) [Wh]."""
        return _budget(self.battery_wh, self.reserve)

    def agl(self, points: Any) -> np.ndarray:
        """Height above the world's ground of ``points`` [m] (a 2D world's: their z)."""
        p = np.atleast_2d(np.asarray(points, dtype=float))
        if getattr(self.world, "ndim", 3) != 3 or p.shape[1] < 3:
            return p[:, -1].copy() if p.shape[1] >= 3 else np.zeros(len(p))
        return p[:, 2] - np.asarray(self.world.ground_height(p[:, 0], p[:, 1]), dtype=float)

    def fly(self, path: Any, *, speeds: Any = None, holds: Any = None, takeoff: float = 0.0,
            landing: float = 0.0) -> Flight:
        """:func:`~fm2uav.vehicles.energy.fly_legs` along ``path`` (n, 3) [m] at ``speeds``
        (default the forward speed) in the wind at each leg's midpoint and height above
        ground, after a ``takeoff`` climb and before a ``landing`` descent [m]."""
        p = np.asarray(path, dtype=float)
        return fly_legs(p, self.model, speed=self.speed if speeds is None else speeds,
                        climb_rate=self.climb_rate, descent_rate=self.descent_rate,
                        wind=_leg_wind(self.wind, p, self.agl(p)), holds=holds,
                        takeoff_climb=max(float(takeoff), 0.0),
                        final_descent=max(float(landing), 0.0))


def _leg_wind(wind: Any, pts: np.ndarray, agl: np.ndarray) -> np.ndarray | None:
    if wind is None or len(pts) < 2:
        return None
    mid = 0.5 * (pts[1:] + pts[:-1])
    return np.asarray(wind.at(mid, 0.5 * (agl[1:] + agl[:-1])), dtype=float)


@dataclass(frozen=True)
class ClimbOutClock:
    """A fixed-wing's take-off and end as the mission's clock times them (the flight time
    of :func:`fm2uav.autopilot.build.build_mission`), for its energy to be flown on it.

    Attributes
    ----------
    first : int
        The first route waypoint flown after the climb-out (``>= 1``); the waypoints
        before it are replaced by the climb-out.
    takeoff_s : float
        The climb-out's time, from the launch to where it leaves for waypoint ``first`` [s].
    entry_m : float
        Horizontal length from where the climb-out leaves to waypoint ``first`` [m].
    end_s : float
        The landing pattern's time after the last waypoint [s] (``land`` ends).
    """

    first: int
    takeoff_s: float
    entry_m: float
    end_s: float = 0.0


def mission_energy(points: Any, agl: Any, *, vehicle: str, power: Any, battery_wh: float | None,
                   reserve: float, speeds: Any, holds: Any, forward_speed: float,
                   climb_rate: float, descent_rate: float, end: str, wind: Any = None,
                   climb_out: ClimbOutClock | None = None) -> dict[str, Any]:
    """Energy and time of the mission's flight, its battery check and point of no return.

    Parameters
    ----------
    points : array_like, shape (n, 3)
        The mission's waypoints [m] (world x, y and altitude).
    agl : array_like, shape (n,)
        Their heights above ground [m] (take-off climb, landing, wind profile).
    vehicle : str
        Airframe type (``multirotor``, ``fixed_wing``, ``vtol``).
    power : str, PowerModel or None
        The power model (None: :data:`DEFAULT_POWER` of the type).
    battery_wh : float or None
        Battery [Wh] (None: the model's).
    reserve : float
        Share of the battery kept in reserve.
    speeds : array_like, shape (n - 1,)
        Commanded speed of each leg [m/s] (ground speed of a multirotor, airspeed of
        a fixed-wing).
    holds : array_like, shape (n,)
        Hold time at each waypoint [s].
    end : str
        The mission's resolved end (``rtl``, ``land``, ``loiter``).
    wind : WindField or None
    climb_out : ClimbOutClock, optional
        A fixed-wing's climb-out and landing pattern on the mission's clock: the legs
        are flown from where the climb-out leaves (the waypoints it replaces are not),
        the take-off over the climb-out's time, a ``land`` end over the pattern's, and
        an ``rtl`` end circles home at its altitude (no descent) — the flight time's
        phases, so that in still air ``time_s`` is the mission's flight time.

    Returns
    -------
    dict
        JSON-friendly figures: ``energy_wh``, ``time_s``, ``battery_wh``, the check,
        the point of no return, the model and the wind; ``warning`` when the battery
        does not last or a leg cannot be flown in the wind. Waypoint numbers count the
        whole list (``points``).
    """
    given = power is not None
    model = power_model(power, vehicle)
    p = np.asarray(points, dtype=float)
    h = np.asarray(agl, dtype=float)
    v = np.broadcast_to(np.asarray(speeds, dtype=float), (len(p) - 1,))
    hold = np.asarray(holds, dtype=float)
    launch = p[0].copy()  # home: an rtl flies back over it
    skip, climb, climb_s, end_s = 0, float(max(h[0], 0.0)), None, None
    if climb_out is not None:  # the legs from where the climb-out leaves, at its altitude
        f = int(climb_out.first)
        skip = f - 1
        u = p[f, :2] - p[skip, :2]
        u = u / max(float(np.hypot(*u)), 1e-9)
        climb = float(max(p[f, 2] - (p[0, 2] - h[0]), 0.0))  # the runway to the route
        p = p[skip:].copy()
        h = h[skip:].copy()
        p[0] = [*(p[1, :2] - float(climb_out.entry_m) * u), p[1, 2]]
        h[0] = h[1]
        v = v[skip:]
        hold = hold[skip:].copy()
        hold[0] = 0.0  # the climb-out's time holds it
        climb_s = float(climb_out.takeoff_s)
        end_s = float(climb_out.end_s) if end == "land" else None
    legs_p, legs_agl = p, h
    if end == "rtl" and len(p) > 1 and float(np.hypot(*(p[-1, :2] - launch[:2]))) > 0:
        home = np.array([[launch[0], launch[1], p[-1, 2]]])
        legs_p = np.vstack([p, home])
        ground = launch[2] - float(np.asarray(agl, dtype=float)[0])  # the launch's
        legs_agl = np.concatenate([h, [p[-1, 2] - ground]])
        v = np.concatenate([v, [forward_speed]])
        hold = np.concatenate([hold, [0.0]])
    final = (0.0 if end == "loiter" or (climb_out is not None and end == "rtl")
             else float(max(legs_agl[-1], 0.0)))
    battery = float(battery_wh) if battery_wh is not None else model.battery_wh
    flight = fly_legs(legs_p, model, speed=v, climb_rate=climb_rate, descent_rate=descent_rate,
                      wind=_leg_wind(wind, legs_p, legs_agl), holds=hold,
                      takeoff_climb=climb, final_descent=final, takeoff_time=climb_s,
                      final_time=end_s)
    rep = check_battery(flight, battery_wh=battery, reserve=reserve)
    if skip:  # waypoints of the whole list, as the summary names them
        rep = replace(rep, reach_waypoint=int(rep.reach_waypoint) + skip,
                      waypoints=int(rep.waypoints) + skip)
    out: dict[str, Any] = {
        **rep.summary(),
        **{k: val for k, val in flight.summary().items() if k not in ("energy_wh", "time_s",
                                                                        "unflyable_legs")},
        "model": model.name,
        "model_kind": model.kind,
        "model_source": ("airframe.power" if given else
                         f"class default for a {vehicle.replace('_', '-')} (preset "
                         f"{model.name}); give airframe.power (--power) for your vehicle"),
        "hover_or_cruise_power_w": round(float(model.power(
            forward_speed if model.kind == "fixed-wing" else 0.0, 0.0)), 1),
        "wind": None if wind is None else wind.summary(),
    }
    if len(p) > 1 and flight.flyable.all():
        pw = (launch[0], launch[1], launch[2] - float(np.asarray(agl, dtype=float)[0]))
        k, margin = no_return_point(
            p, fly_legs(p, model, speed=v[:len(p) - 1], climb_rate=climb_rate,
                        descent_rate=descent_rate, wind=_leg_wind(wind, p, h),
                        holds=hold[:len(p)], takeoff_climb=climb, takeoff_time=climb_s),
            model, home=pw, speed=forward_speed, climb_rate=climb_rate,
            descent_rate=descent_rate, wind=None if wind is None else
            np.asarray(wind.at(np.asarray(pw)[None, :2]))[0], battery_wh=battery,
            reserve=reserve)
        out["no_return_waypoint"] = k + skip
        out["no_return_note"] = ("the last waypoint from which a straight flight home (in the "
                                 "wind at the start) still fits in the usable battery"
                                 + ("" if k < len(p) - 1 else ": every waypoint"))
    return out
