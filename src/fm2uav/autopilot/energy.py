"""The energy of a built mission: its waypoints flown at their commanded speeds by the
airframe's power model, in the wind (:mod:`fm2uav.vehicles.energy`).

The power model is the mission's (``airframe.power``: a preset name, parameters, or
the file a flight-log fit wrote) or, when none is given, the class model of its
airframe type (:data:`DEFAULT_POWER`, said so in the summary). The battery is
``airframe.battery`` [Wh] or the model's. The legs are the mission's waypoints at the
commanded speeds and hold times, the take-off climb, then (``rtl``) the straight line
home at the forward speed and the descent there, or the final descent (``land``);
the wind of each leg is the field's at the leg's midpoint and height above ground.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ..vehicles.energy import check_battery, fly_legs, no_return_point
from ..vehicles.power import get_power_model

__all__ = ["DEFAULT_POWER", "mission_energy"]

#: Power model of each airframe type when the mission gives none (a VTOL in plane mode:
#: its hover phases cost several times more and are not in the figure).
DEFAULT_POWER = {"multirotor": "arducopter", "fixed_wing": "disco", "vtol": "crosswind"}


def _leg_wind(wind: Any, pts: np.ndarray, agl: np.ndarray) -> np.ndarray | None:
    if wind is None or len(pts) < 2:
        return None
    mid = 0.5 * (pts[1:] + pts[:-1])
    return np.asarray(wind.at(mid, 0.5 * (agl[1:] + agl[:-1])), dtype=float)


def mission_energy(points: Any, agl: Any, *, vehicle: str, power: Any, battery_wh: float | None,
                   reserve: float, speeds: Any, holds: Any, forward_speed: float,
                   climb_rate: float, descent_rate: float, end: str, wind: Any = None
                   ) -> dict[str, Any]:
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

    Returns
    -------
    dict
        JSON-friendly figures: ``energy_wh``, ``time_s``, ``battery_wh``, the check,
        the point of no return, the model and the wind; ``warning`` when the battery
        does not last or a leg cannot be flown in the wind.
    """
    given = power is not None
    model = get_power_model(power if given else DEFAULT_POWER.get(vehicle, "arducopter"))
    p = np.asarray(points, dtype=float)
    h = np.asarray(agl, dtype=float)
    legs_p, legs_agl = p, h
    v = np.broadcast_to(np.asarray(speeds, dtype=float), (len(p) - 1,))
    hold = np.asarray(holds, dtype=float)
    if end == "rtl" and len(p) > 1 and float(np.hypot(*(p[-1, :2] - p[0, :2]))) > 0:
        home = np.array([[p[0, 0], p[0, 1], p[-1, 2]]])
        legs_p = np.vstack([p, home])
        legs_agl = np.concatenate([h, [h[-1] + p[-1, 2] - p[0, 2] if len(h) else 0.0]])
        v = np.concatenate([v, [forward_speed]])
        hold = np.concatenate([hold, [0.0]])
    final = 0.0 if end == "loiter" else float(max(legs_agl[-1], 0.0))
    battery = float(battery_wh) if battery_wh is not None else model.battery_wh
    flight = fly_legs(legs_p, model, speed=v, climb_rate=climb_rate, descent_rate=descent_rate,
                      wind=_leg_wind(wind, legs_p, legs_agl), holds=hold,
                      takeoff_climb=float(max(h[0], 0.0)), final_descent=final)
    rep = check_battery(flight, battery_wh=battery, reserve=reserve)
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
        pw = (p[0, 0], p[0, 1], p[0, 2] - h[0])
        k, margin = no_return_point(
            p, fly_legs(p, model, speed=v[:len(p) - 1], climb_rate=climb_rate,
                        descent_rate=descent_rate, wind=_leg_wind(wind, p, h),
                        holds=hold[:len(p)], takeoff_climb=float(max(h[0], 0.0))),
            model, home=pw, speed=forward_speed, climb_rate=climb_rate,
            descent_rate=descent_rate, wind=None if wind is None else
            np.asarray(wind.at(p[:1, :2]))[0], battery_wh=battery, reserve=reserve)
        out["no_return_waypoint"] = k
        out["no_return_note"] = ("the last waypoint from which a straight flight home (in the "
                                 "wind at the start) still fits in the usable battery"
                                 + ("" if k < len(p) - 1 else ": every waypoint"))
    return out
