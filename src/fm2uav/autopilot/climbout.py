"""A fixed-wing climb-out the airframe can fly: from the runway to the route's altitude.

What the firmware does (:mod:`fm2uav.autopilot.firmware.flight_rules`): ArduPlane's
``NAV_TAKEOFF`` ignores the item's position, holds the launch heading and climbs
to the item's altitude at full throttle (``Plane::do_takeoff``; "The plane will
try to hold its heading during takeoff", Plane wiki "TAKEOFF Mode"), no steeper
than its climb limit (``TECS_CLMB_MAX``); only then does it turn to the next item.
PX4 climbs along the course of its take-off item. A route that starts close to
the runway, or below the take-off altitude, is overflown and flown back to (the
loops of issue 24). Two climb-outs are made:

* **straight** — the route's start altitude is within ``TKOFF_ALT`` (50 m) of
  the ground: ``NAV_TAKEOFF`` to it, along the course that points at the first
  route waypoint lying beyond the climb distance ``h V / climb`` plus that
  waypoint's turn distance; route waypoints before it are dropped (the straight
  climb replaces them, checked against the ground and the zones) and the take-off
  altitude is never above the first waypoint's;
* **loiter** — a higher route: ``NAV_TAKEOFF`` to ``TKOFF_ALT`` along the course
  toward the route, then ``NAV_LOITER_TO_ALT`` over the start (radius 1.5 turn
  radii, heading required, leaving on the tangent toward the next waypoint) up to
  the route's start altitude; the first route waypoint lies outside the circle by
  at least its turn distance. The circle is checked against the ground (at the
  take-off altitude, its lowest) and the zones.

The take-off item sits on the course at the climb distance: QGroundControl draws
the climb-out there, and the operator (or SITL's ``--home lat,lon,alt,heading``)
points the aircraft along it (:attr:`ClimbOut.info` ``course_deg``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..errors import MissionError
from .firmware.navigation import FixedWingNav
from .items import (
    CMD_NAV_LOITER_TO_ALT,
    CMD_NAV_TAKEOFF,
    FRAME_RELATIVE,
    FRAME_TERRAIN,
    MissionItem,
)
from .placing import ItemPlacer, inside_xy
from .waypoints import Waypoints

__all__ = ["CLIMB_CLEARANCE", "ClimbOut", "plan_climb_out"]

#: Lowest height [m] the climb-out (straight line or loiter circle) keeps above the DEM.
CLIMB_CLEARANCE = 10.0
#: Loiter radius of the climb, in turn radii (>= 1.2: a circle the aircraft flies; <= 2:
#: within two turn radii of the loiter point).
LOITER_TURNS = 1.5


@dataclass(frozen=True)
class ClimbOut:
    """The items from the runway to the route, and where the route resumes.

    Attributes
    ----------
    items : list of MissionItem
        ``NAV_TAKEOFF`` (and ``NAV_LOITER_TO_ALT``).
    first : int
        Index of the first route waypoint flown after them (``>= 1``).
    info : dict
        ``mode``, ``course_deg``, take-off altitude, climb distance, loiter figures,
        lowest clearance over the DEM, dropped waypoints, time.
    time_s : float
        Time from the launch to the first route waypoint's leg [s].
    warnings : list of str
    """

    items: list[MissionItem]
    first: int
    info: dict[str, Any]
    time_s: float
    warnings: list[str] = field(default_factory=list)


def _course_deg(u: np.ndarray, world: Any) -> float:
    """Bearing of the world direction ``u`` [deg from north, clockwise] (grid north)."""
    return float(math.degrees(math.atan2(u[0], u[1])) % 360.0)


def _clearance(geo: ItemPlacer, xy: np.ndarray, z: np.ndarray) -> float:
    """Lowest height of the points above the ground on the map [m] (inf off the map)."""
    inside = inside_xy(geo.world, xy)
    if not inside.any():
        return math.inf
    return float((z[inside] - geo.ground(xy[inside])).min())


def _zone_hits(world: Any, pts: np.ndarray) -> list[Any]:
    if not getattr(world, "zones", ()):
        return []
    from ..world.zones import zone_violations

    return zone_violations(world, pts)


def _first_beyond(p: np.ndarray, centre: np.ndarray, need: np.ndarray, limit: int) -> int | None:
    """First waypoint index >= 1 (and <= ``limit``) at least ``need[j]`` from ``centre``."""
    d = np.hypot(*(p[:, :2] - centre).T)
    for j in range(1, min(limit, len(p) - 1) + 1):
        if d[j] >= need[j]:
            return j
    return None


def plan_climb_out(geo: ItemPlacer, wps: Waypoints, nav: FixedWingNav, *, first_forced: int,
                   tolerance: float) -> ClimbOut:
    """The climb-out of a fixed-wing mission (module docstring).

    Parameters
    ----------
    geo : ItemPlacer
    wps : Waypoints
        The route (``points_m[0]`` is the start at its planned altitude).
    nav : FixedWingNav
        The firmware's navigation with the airframe's numbers.
    first_forced : int
        Index of the first waypoint that must be flown (a via point, a band start, a
        hold): the climb-out never drops it.
    tolerance : float
        Thinning tolerance [m]: a straight climb-out may replace route waypoints
        within ``max(tolerance, turn radius)`` of its line.

    Raises
    ------
    MissionError
        No climb-out clears the ground and the zones.
    """
    p = wps.points_m
    home = p[0, :2]
    g_home = float(geo.ground(home)[0])
    h_route = float(p[0, 2] - g_home)
    v = nav.airspeed_cruise
    r_turn = nav.turn_radius()
    route_frame = FRAME_RELATIVE if wps.frame == FRAME_TERRAIN else wps.frame
    ang = _angles(p[:, :2])
    acc = np.array([nav.turn_distance(a) for a in ang])
    limit = max(1, min(first_forced, len(p) - 1))
    if h_route <= nav.takeoff_alt + 1.0:
        straight = _straight(geo, wps, nav, h_route, acc, limit, tolerance, route_frame)
        if straight is not None:
            return straight
    return _loiter(geo, wps, nav, h_route, acc, limit, route_frame, g_home, r_turn, v)


def _angles(xy: np.ndarray) -> np.ndarray:
    from .firmware.flight_rules import turn_angles

    return turn_angles(xy)


def _straight(geo: ItemPlacer, wps: Waypoints, nav: FixedWingNav, h_route: float,
              acc: np.ndarray, limit: int, tolerance: float, frame: int) -> ClimbOut | None:
    """Take off straight to the route's altitude toward the first waypoint beyond the climb."""
    p = wps.points_m
    home = p[0, :2]
    g_home = float(geo.ground(home)[0])
    h_to = h_route
    for _ in range(4):  # the take-off altitude never above the first waypoint's
        need = nav.climb_distance(h_to) + acc
        j = _first_beyond(p, home, need, limit)
        if j is None:
            return None
        h_to_new = min(h_route, float(p[j, 2] - g_home))
        if h_to_new >= h_to - 1e-6:
            break
        h_to = h_to_new
    if h_to < 5.0:
        return None
    u = p[j, :2] - home
    dist = float(np.hypot(*u))
    u = u / dist
    # the straight line replaces the route up to waypoint j: it must stay near it
    line, z = _climb_line(home, u, g_home, h_to, nav, dist)
    dev = 0.0
    if j > 1:
        seg = p[1:j, :2] - home
        dev = float(np.abs(seg[:, 0] * u[1] - seg[:, 1] * u[0]).max())
    if dev > max(tolerance, nav.turn_radius()):
        return None
    clear = _line_clearance(geo, line, z, g_home)
    pts3 = np.column_stack([line, z])
    if clear < CLIMB_CLEARANCE or _zone_hits(geo.world, pts3):
        return None
    d_climb = nav.climb_distance(h_to)
    takeoff = geo.item(CMD_NAV_TAKEOFF, frame, home + u * d_climb, g_home + h_to,
                       label="takeoff (climb-out course)", p1=nav.takeoff_pitch_deg)
    t = h_to / nav.climb_rate + max(dist - d_climb, 0.0) / nav.airspeed_cruise
    info = {"mode": "straight", "course_deg": round(_course_deg(u, geo.world), 1),
            "takeoff_alt_m": round(h_to, 1), "climb_distance_m": round(d_climb, 1),
            "first_waypoint_m": round(dist, 1), "dropped_waypoints": j - 1,
            "min_clearance_m": round(clear, 1) if math.isfinite(clear) else None,
            "time_s": round(t, 1)}
    return ClimbOut([takeoff], j, info, t)


def _line_clearance(geo: ItemPlacer, line: np.ndarray, z: np.ndarray, g_home: float) -> float:
    """Lowest height of a take-off climb above the ground once it is ``CLIMB_CLEARANCE``
    above the runway [m] (inf off the map; -inf when the ground rises above the climb
    before that: the runway ends in a slope)."""
    inside = inside_xy(geo.world, line)
    if not inside.any():
        return math.inf
    g = geo.ground(line[inside])
    zi = z[inside]
    early = (zi - g_home) < CLIMB_CLEARANCE
    if np.any(g[early] > zi[early] + 1e-6):
        return -math.inf
    late = ~early
    return float((zi - g)[late].min()) if late.any() else math.inf


def _climb_line(home: np.ndarray, u: np.ndarray, g_home: float, h_to: float,
                nav: FixedWingNav, length: float | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Points and altitudes of a straight take-off climb along ``u`` [m] (level at the
    take-off altitude beyond the climb distance, up to ``length``)."""
    d = max(nav.climb_distance(h_to) if length is None else length, 1.0)
    s = np.linspace(0.0, d, 120)
    z = g_home + np.minimum(h_to, s * nav.climb_rate / nav.airspeed_cruise)
    return home + s[:, None] * u, z


def _circle(centre: np.ndarray, r: float) -> np.ndarray:
    phi = np.linspace(0.0, 2 * math.pi, 96, endpoint=False)
    return centre + r * np.column_stack([np.cos(phi), np.sin(phi)])


def _loiter(geo: ItemPlacer, wps: Waypoints, nav: FixedWingNav, h_route: float,
            acc: np.ndarray, limit: int, frame: int, g_home: float, r_turn: float,
            v: float) -> ClimbOut:
    """Take off to TKOFF_ALT (higher where the ground around needs it), then climb in a
    loiter to the route: over the start, or where the take-off climb ends; along the
    course toward the route, else the course (every 30°) that clears the ground best."""
    p = wps.points_m
    home = p[0, :2]
    r = float(math.ceil(LOITER_TURNS * r_turn))
    need_j = r + np.maximum(acc, r_turn)
    j0 = _first_beyond(p, home, need_j, limit) or limit
    toward = p[j0, :2] - home
    base = math.atan2(toward[1], toward[0])
    best = None
    for k in range(12):
        a = base + math.radians(30.0 * k)
        u = np.array([math.cos(a), math.sin(a)])
        for at_end in (False, True):
            h_to = min(h_route, nav.takeoff_alt)
            for _ in range(3):  # raise the take-off altitude until the circle clears
                centre = home + u * nav.climb_distance(h_to) if at_end else home
                ring = _circle(centre, r)
                inside = inside_xy(geo.world, ring)
                top = float(geo.ground(ring[inside]).max()) if inside.any() else g_home
                h_need = top - g_home + CLIMB_CLEARANCE
                if h_need <= h_to + 1e-6 or h_to >= h_route:
                    break
                h_to = min(h_route, max(h_to, h_need))
            ring = _circle(centre, r)
            c_ring = _clearance(geo, ring, np.full(len(ring), g_home + h_to))
            line, z_line = _climb_line(home, u, g_home, h_to, nav)
            c_line = _line_clearance(geo, line, z_line, g_home)
            clear = min(c_ring, c_line)
            hits = _zone_hits(geo.world, np.vstack([
                np.column_stack([ring, np.full(len(ring), g_home + h_to)]),
                np.column_stack([line, z_line])]))
            ok = clear >= CLIMB_CLEARANCE and not hits
            score = (ok, k == 0, clear)
            if best is None or score > best[0]:
                best = (score, u, centre, h_to, clear, hits)
        if best is not None and best[0][0] and best[0][1]:
            break  # the course toward the route works: take it
    assert best is not None
    (ok, _, _), u, centre, h_to, clear, hits = best
    if not ok:
        if hits:
            raise MissionError(
                f"no fixed-wing climb-out fits the start: every {r:.0f} m climb-out loiter "
                f"around it enters {hits[0].zone!r}; move the start away from the zone")
        raise MissionError(
            f"no fixed-wing climb-out fits the start: the best take-off climb and {r:.0f} m "
            f"loiter pass {clear:.0f} m above the ground (at least {CLIMB_CLEARANCE:g} m "
            "needed); start over open ground, or lower the cruise speed "
            "(airframe.cruise_speed) for a tighter turn")
    warnings: list[str] = []
    j = _first_beyond(p, centre, need_j, limit)
    if j is None:
        j = limit
        warnings.append(f"the route's first waypoints lie within the {r:.0f} m climb-out loiter: "
                        "the aircraft leaves the loiter toward a waypoint close to its circle")
    # climb to the route, but never above its first waypoint (no dive onto it)
    h_loiter = max(h_to, min(h_route, float(p[j, 2] - g_home)))
    d_climb = nav.climb_distance(h_to)
    takeoff = geo.item(CMD_NAV_TAKEOFF, frame, home + u * d_climb, g_home + h_to,
                       label="takeoff (climb-out course)", p1=nav.takeoff_pitch_deg)
    loiter = geo.item(CMD_NAV_LOITER_TO_ALT, frame, centre, g_home + h_loiter,
                      label="climb-out loiter", p1=1.0, p2=r, p4=1.0)
    climb = max(h_loiter - h_to, 0.0)
    back = max(float(np.hypot(*(home + u * d_climb - centre))) - r, 0.0)
    # take-off climb, to the circle, the climb in circles, on average half a circle to the
    # exit heading
    t = (h_to / nav.climb_rate + back / v + climb / nav.climb_rate + math.pi * r / v)
    info = {"mode": "loiter", "course_deg": round(_course_deg(u, geo.world), 1),
            "takeoff_alt_m": round(h_to, 1), "climb_distance_m": round(d_climb, 1),
            "loiter_radius_m": r, "loiter_alt_m": round(h_loiter, 1),
            "loiter_centre_m": [round(float(c), 2) for c in centre],
            "loiter_climb_m": round(climb, 1), "dropped_waypoints": j - 1,
            "min_clearance_m": round(clear, 1) if math.isfinite(clear) else None,
            "time_s": round(t, 1)}
    return ClimbOut([takeoff, loiter], j, info, t, warnings)
