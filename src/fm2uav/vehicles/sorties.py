"""A survey too long for one battery, split into sorties by energy.

Every sortie takes off at home, flies straight to its resume waypoint (the first
sortie starts on the route), flies the route on to its last waypoint, flies straight
home and lands; the next sortie resumes there. With ``E_route[i]`` the energy along
the route to waypoint ``i`` (:func:`.energy.fly_legs`, in the wind), ``out[i]`` the
energy of the take-off climb and the flight from home to waypoint ``i`` and ``back[i]``
the flight from ``i`` home and the landing, a sortie over waypoints ``a .. b`` needs

``out[a] + E_route[b] − E_route[a] + back[b]  ≤  battery × (1 − reserve)``.

:func:`split_sorties` takes, from each resume point, the furthest ``b`` such that every
waypoint up to it fits with its way home (so the vehicle can turn home from anywhere on
its sortie) — greedy. :func:`even_split` is the baseline a ground station's "split
mission" gives: the fewest equal parts of the waypoint list that each fit. The greedy
split adapts each sortie to how far it is from home and how the wind treats it.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..errors import InputError, PlanningError
from .energy import _budget, fly_legs, home_legs
from .power import PowerModel

__all__ = ["Sortie", "SortiePlan", "split_sorties", "even_split", "even_parts"]


@dataclass(frozen=True)
class Sortie:
    """One flight of a split survey.

    Attributes
    ----------
    start, end : int
        The route's leg the sortie resumes on (index of its first waypoint) and the
        waypoint it flies towards when it turns home.
    out_wh, route_wh, back_wh : float
        Energy [Wh] from home to the resume point (take-off included), along the
        route, and home (landing included).
    time_s : float
        Flight time [s] of the whole sortie.
    resume, stop : ndarray, shape (3,)
        Where the sortie joins the route [m] (on the leg after waypoint ``start``) and
        where it leaves it for home (on the leg before waypoint ``end``).
    """

    start: int
    end: int
    out_wh: float
    route_wh: float
    back_wh: float
    time_s: float
    resume: np.ndarray
    stop: np.ndarray

    @property
    def energy_wh(self) -> float:
        """Energy of the whole sortie [Wh]."""
        return self.out_wh + self.route_wh + self.back_wh


@dataclass(frozen=True)
class SortiePlan:
    """The sorties of a survey and the even-split baseline.

    Attributes
    ----------
    sorties : list of Sortie
    usable_wh : float
        Battery × (1 − reserve) [Wh].
    even_sorties : int or None
        Sorties needed when the waypoint list is split into equal parts (None: no such
        split fits, a single leg is already too long).
    even_energy_wh : list of float
        The energy [Wh] of each of those equal parts (out, along, home; empty with None).
    """

    sorties: list[Sortie]
    usable_wh: float
    even_sorties: int | None
    even_energy_wh: list[float] = field(default_factory=list)

    def summary(self) -> dict[str, Any]:
        """JSON-friendly figures."""
        return {
            "count": len(self.sorties), "even_split_count": self.even_sorties,
            "even_split_energy_wh": [round(v, 2) for v in self.even_energy_wh],
            "usable_wh": round(self.usable_wh, 2),
            "sorties": [{"from_waypoint": s.start, "to_waypoint": s.end,
                         "energy_wh": round(s.energy_wh, 2), "time_s": round(s.time_s, 1),
                         "to_start_wh": round(s.out_wh, 2), "survey_wh": round(s.route_wh, 2),
                         "home_wh": round(s.back_wh, 2),
                         "resume_m": np.round(s.resume, 2).tolist(),
                         "home_from_m": np.round(s.stop, 2).tolist()} for s in self.sorties]}


def _fits(route: Any, out: np.ndarray, back: np.ndarray, a: int) -> np.ndarray:
    """Energy of the sorties ``a .. b`` for every ``b >= a``."""
    return out[a] + (route[a:] - route[a]) + back[a:]


def even_parts(route_wh: Any, out_wh: Any, back_wh: Any, usable_wh: float) -> list[float]:
    """The energy [Wh] of each part of the fewest equal parts of the waypoint list
    (consecutive parts share their junction waypoint) each of which fits in ``usable_wh``
    — ``out[a] + E_route[b] − E_route[a] + back[b]`` — ([] when not even one leg per part
    fits: a waypoint split cannot fly the survey at all)."""
    e = np.asarray(route_wh, dtype=float)
    out, back = np.asarray(out_wh, float), np.asarray(back_wh, float)
    n = len(e)
    for k in range(1, n):
        edges = np.unique(np.rint(np.linspace(0, n - 1, k + 1)).astype(int))
        parts = [float(out[a] + e[b] - e[a] + back[b]) for a, b in zip(edges[:-1], edges[1:])]
        if all(v <= usable_wh for v in parts):
            return parts
    return []


def even_split(route_wh: Any, out_wh: Any, back_wh: Any, usable_wh: float) -> int | None:
    """How many parts :func:`even_parts` needs (None: no equal split fits)."""
    return len(even_parts(route_wh, out_wh, back_wh, usable_wh)) or None


def split_sorties(points: Any, model: PowerModel, *, home: Any, battery_wh: float,
                  reserve: float = 0.2, speed: float, climb_rate: float, descent_rate: float,
                  wind: Any = None, resume_step: float = 25.0, ways: Any = None,
                  margin_wh: float = 0.0) -> SortiePlan:
    """Split the survey's waypoints into sorties that each fit in the battery.

    Parameters
    ----------
    points : array_like, shape (n, 3)
        The survey's waypoints [m], in flight order.
    model : MultirotorPower or FixedWingPower
    home : array_like, shape (3,)
        Take-off and landing point [m] (its altitude is the ground).
    battery_wh, reserve : float
        The battery [Wh] and the share of it kept.
    speed : float
        Commanded speed [m/s] (ground speed of a multirotor, airspeed of a fixed-wing).
    climb_rate, descent_rate : float
        Vertical speed limits [m/s].
    wind : WindField, optional
        The wind; the route's pieces and the flights home take it at their midpoints
        (the flights to and from home: the wind at the point where they join the route).
    resume_step : float
        A sortie may end (and the next resume) every ``resume_step`` metres along the
        route, not only at its waypoints.
    ways : callable, optional
        ``ways(points) -> (out_wh, out_s, back_wh, back_s)``, one value per point of
        ``points`` (m, 3) [m]: the energy [Wh] and time [s] from the take-off at home to
        each point (climb included) and from each point home (landing included), flown
        the way the sortie flies them (e.g. the FM² return field's paths,
        :mod:`fm2uav.autopilot.sorties`). Default: straight lines at the point's
        altitude (:func:`fm2uav.vehicles.energy.home_legs`) in the wind at the point.
    margin_wh : float
        Energy [Wh] kept aside on top of the reserve when the sorties are cut (what a
        sortie's flown mission may need more than this estimate); the summary's usable
        energy stays the battery's.

    Returns
    -------
    SortiePlan

    Raises
    ------
    PlanningError
        A leg of the route cannot be flown in the wind, or a waypoint is too far from home
        for any sortie to reach it and come back.
    """
    p = np.asarray(points, dtype=float)
    if p.ndim != 2 or p.shape[1] != 3 or len(p) < 2:
        raise InputError(f"survey waypoints must be an (n >= 2, 3) array, got {p.shape}")
    from ..geometry import densify

    usable = _budget(battery_wh, reserve)
    budget = usable - float(margin_wh)
    h = np.asarray(home, dtype=float)
    wp = p
    p, leg = densify(wp, float(resume_step), horizontal=True)
    mid = 0.5 * (p[1:] + p[:-1])
    leg_wind = None if wind is None else np.asarray(
        wind.at(mid, mid[:, 2] - h[2]), dtype=float)
    route = fly_legs(p, model, speed=float(speed), climb_rate=climb_rate,
                     descent_rate=descent_rate, wind=leg_wind)
    if not route.flyable.all():
        bad = sorted(set(leg[np.flatnonzero(~route.flyable)].tolist()))
        raise PlanningError(f"the survey cannot be flown in this wind: legs {bad[:5]} have "
                            "no headway")
    e = route.used_wh()
    t = route.elapsed()
    if ways is None:
        # the wind of the flights home: at the resume point
        home_w = None if wind is None else np.asarray(
            wind.at(p, np.maximum(p[:, 2] - h[2], 1.0)), dtype=float)
        out, out_s, back, back_s = home_legs(p, model, home=h, speed=float(speed),
                                             climb_rate=climb_rate, descent_rate=descent_rate,
                                             wind=home_w)
    else:
        out, out_s, back, back_s = (np.asarray(v, dtype=float) for v in ways(p))
    sorties: list[Sortie] = []
    a = 0
    while a < len(p) - 1:
        cost = _fits(e, out, back, a)
        if not cost[1] <= budget:
            raise PlanningError(
                f"the survey cannot be split into sorties: going on {resume_step:g} m past "
                f"{np.round(p[a], 1).tolist()} m (leg {int(leg[a])}) and flying home needs "
                f"{cost[1]:.1f} Wh, {budget:.1f} Wh are usable"
                + (f" ({usable:.1f} Wh less a {margin_wh:.1f} Wh margin)" if margin_wh else "")
                + ": a bigger battery, a lower reserve or a home closer to the survey")
        # the furthest end with every waypoint before it still within a way home: the
        # vehicle can turn home from anywhere on its sortie
        over = np.flatnonzero(cost[1:] > budget)
        b = a + (int(over[0]) if len(over) else len(cost) - 1)
        sorties.append(Sortie(int(leg[a]), int(leg[b]) + (b == len(p) - 1), float(out[a]),
                              float(e[b] - e[a]), float(back[b]),
                              float(out_s[a] + t[b] - t[a] + back_s[b]), p[a].copy(),
                              p[b].copy()))
        a = b
    on_wp = np.flatnonzero(np.r_[True, np.diff(leg) != 0])   # the waypoints among the points
    on_wp = np.unique(np.r_[on_wp, len(p) - 1])
    even = even_parts(e[on_wp], out[on_wp], back[on_wp], budget)
    return SortiePlan(sorties, usable, len(even) or None, even)
