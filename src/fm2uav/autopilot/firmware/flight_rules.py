"""How a firmware flies a mission: speed and fixed-wing geometry rules, from its documentation.

These rules take a firmware's numbers (:mod:`fm2uav.autopilot.firmware.navigation`)
and return the :class:`~fm2uav.autopilot.firmware.profile.Problem` s of a list of
mission items; each firmware's profile lists the rules made for it
(:func:`speed_rules`, :func:`fixed_wing_rules`). Where each rule comes from:

**Speeds** (every airframe; ArduPilot ``Plane::do_change_speed`` and
``ModeAuto::do_change_speed``, PX4 navigator, MAVLink ``MAV_CMD_DO_CHANGE_SPEED``):

* ``speed-type``: param1 must be the speed type the firmware acts on for the
  airframe (airspeed 0 on a plane: ArduPlane's type 1 sets ``MIN_GROUNDSPEED``,
  not the speed flown; ground speed 1 on a multirotor);
* ``speed-range``: ArduPlane takes an airspeed only between ``AIRSPEED_MIN`` and
  ``AIRSPEED_MAX`` and ignores any other (the aircraft keeps its previous speed),
  and no fixed-wing speed may be below the airframe's minimum;
* ``no-cruise-speed`` (warning): a speed is commanded before the first waypoint —
  without one ArduPlane flies ``AIRSPEED_CRUISE`` and ArduCopter ``WPNAV_SPEED``,
  whatever the mission's time estimate assumed (fm2uav's missions always command one).

**Fixed-wing geometry** (ArduPlane ``commands_logic.cpp``, ``AP_L1_Control``; the
"Mission Commands" and "Automatic Landing" pages of the Plane wiki):

* ``fw-climb-out`` (take-off): ``NAV_TAKEOFF`` holds the launch heading and climbs
  until its altitude ("The plane will try to hold its heading during takeoff";
  ArduPlane ignores the item's position and climbs straight ahead), climbing at
  most ``TECS_CLMB_MAX``: the climb takes ``h V / climb`` metres. The next item is
  either a ``NAV_LOITER_TO_ALT`` (a climb in circles) or a waypoint **ahead** along
  the take-off course (the bearing of the take-off item, within 20°) **beyond**
  that climb distance plus its turn distance, **not lower** than the take-off
  altitude (else the aircraft overflies it at take-off altitude and comes back:
  the loops of issue 24);
* ``fw-loiter-radius``: a loiter (``NAV_LOITER_TO_ALT`` / ``NAV_LOITER_UNLIM``; 0 =
  ``WP_LOITER_RAD``) no tighter than the turn radius ``V² / (g tan ROLL_LIMIT)``;
  ``fw-loiter-exit``: the item after a ``NAV_LOITER_TO_ALT`` lies outside its circle
  (else ArduPlane leaves by altitude only, in any direction);
* ``fw-skipped-waypoint``: a waypoint counts as reached ``min(WP_RADIUS, L1)·Δψ/90°``
  before it (param2 > 0: that radius); when the aircraft is already that close to
  the *next* waypoint as it reaches one, the next is reached at once and never
  flown to (error). ``fw-short-leg`` (warning): a leg shorter than the turn onto it
  (``R tan(Δψ/2)``, ``R (1 + tan((Δψ−90°)/2))`` beyond 90°) plus the next turn
  distance is flown with an overshoot of the next waypoint;
* ``fw-landing``: a ``NAV_LAND`` glides from its approach item (the previous
  waypoint, or the tangent of a ``NAV_LOITER_TO_ALT``: ArduPlane leaves the loiter
  pointing at the touchdown) at a slope the sink limit holds at the approach speed
  (``V sin θ`` <= ``TECS_SINK_MAX``; PX4 also ``FW_LND_ANG``), over an approach no
  shorter than the turn onto it.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from typing import TYPE_CHECKING, Any

from ..items import (
    CMD_DO_CHANGE_SPEED,
    CMD_NAV_LAND,
    CMD_NAV_LOITER_TO_ALT,
    CMD_NAV_LOITER_UNLIM,
    CMD_NAV_TAKEOFF,
    CMD_NAV_WAYPOINT,
    FRAME_GLOBAL,
    FRAME_RELATIVE,
    MissionItem,
)
from .navigation import AirframeNav, FixedWingNav, SpeedCommand
from .profile import Problem

if TYPE_CHECKING:  # numpy loads with the first check, not with the firmware profiles
    import numpy as np

__all__ = ["speed_rules", "fixed_wing_rules", "local_xy", "item_amsl", "turn_angles",
           "END_TURN_DEG", "leg_speeds"]

_EARTH = 6371008.8
#: A waypoint ahead of the take-off course: within this angle of it [deg].
COURSE_TOLERANCE_DEG = 20.0
#: The first waypoint may sit this much below the take-off altitude [m] (rounding).
FALL_BACK_TOLERANCE = 2.0


def item_amsl(item: MissionItem, home_alt: float | None) -> float | None:
    """Altitude above mean sea level of a position item [m]: from its frame and param7
    (0/5 AMSL, 3/6 above home), the recorded ``alt_amsl`` in the terrain frame."""
    if item.frame in (FRAME_GLOBAL, 5):
        return item.alt
    if item.frame in (FRAME_RELATIVE, 6):
        return None if home_alt is None else item.alt + home_alt
    return item.alt_amsl


def local_xy(items: Sequence[MissionItem], lat0: float, lon0: float) -> np.ndarray:
    """East/north metres of the items' positions from ``lat0, lon0`` (local tangent plane)."""
    import numpy as np

    lat = np.radians([it.lat for it in items])
    lon = np.radians([it.lon for it in items])
    x = (lon - math.radians(lon0)) * math.cos(math.radians(lat0)) * _EARTH
    y = (lat - math.radians(lat0)) * _EARTH
    return np.column_stack([x, y])


#: The turn ArduPlane assumes at a waypoint with no next leg (the mission's last position
#: item, or one followed by an RTL): ``Plane::setup_turn_angle`` ("the mission library
#: can't determine a turn angle, assume 90 degrees") [deg].
END_TURN_DEG = 90.0


def turn_angles(xy: np.ndarray) -> np.ndarray:
    """Heading change at each point of a polyline [deg] (0 at both ends)."""
    import numpy as np

    out = np.zeros(len(xy))
    if len(xy) < 3:
        return out
    d = np.diff(xy, axis=0)
    h = np.arctan2(d[:, 1], d[:, 0])
    dh = np.abs((np.diff(h) + math.pi) % (2 * math.pi) - math.pi)
    out[1:-1] = np.degrees(dh)
    return out


def leg_speeds(items: Sequence[MissionItem], nav_index: Sequence[int], default: float,
               speed_type: int) -> np.ndarray:
    """Speed in force on each leg between consecutive ``nav_index`` items [m/s]: the last
    ``DO_CHANGE_SPEED`` of ``speed_type`` before the leg's end item (``default`` before one)."""
    import numpy as np

    out = np.full(max(len(nav_index) - 1, 0), float(default))
    ends = np.asarray(nav_index[1:], dtype=int)
    for i, it in enumerate(items):
        if it.command == CMD_DO_CHANGE_SPEED and int(it.params[0]) == speed_type \
                and it.params[1] > 0:
            # a DO item runs when the nav item before it completes: from the leg after it on
            out[int(np.searchsorted(ends, i, side="right")):] = float(it.params[1])
    return out


# ---------------------------------------------------------------- speeds
def speed_rules(commands: Mapping[str, SpeedCommand], nav: FixedWingNav | None,
                label: str) -> Callable[..., list[Problem]]:
    """The speed rule of a firmware (module docstring): ``rule(items, vehicle, **kw)``."""

    def rule(items: Sequence[MissionItem], vehicle: str, *,
             airframe: AirframeNav | None = None, **_: Any) -> list[Problem]:
        cmd = commands.get(vehicle)
        if cmd is None:
            return []
        out: list[Problem] = []
        fixed = vehicle in ("fixed_wing", "vtol") and nav is not None
        n = nav.for_airframe(airframe) if fixed else None
        speeds = [(i, it) for i, it in enumerate(items) if it.command == CMD_DO_CHANGE_SPEED]
        for i, it in speeds:
            kind, v = int(it.params[0]), float(it.params[1])
            if kind not in (cmd.accepted or (cmd.speed_type,)):
                what = "airspeed (0)" if cmd.speed_type == 0 else "ground speed (1)"
                out.append(Problem(i, "speed-type", f"DO_CHANGE_SPEED speed type {kind}: "
                                   f"{label} takes the {what} on a {vehicle.replace('_', '-')}"
                                   f"{': ' + cmd.other_type if cmd.other_type else ''}"))
            elif n is not None and v > 0 and not (n.airspeed_min - 1e-6 <= v
                                                  <= n.airspeed_max + 1e-6):
                why = (f"{label} ignores an airspeed outside {n.param('airspeed_min')} "
                       f"{n.airspeed_min:g} .. {n.param('airspeed_max')} {n.airspeed_max:g} "
                       "m/s and keeps flying its previous speed"
                       if cmd.ignored_outside else
                       f"it is outside the airframe's range {n.airspeed_min:g} .. "
                       f"{n.airspeed_max:g} m/s")
                out.append(Problem(i, "speed-range", f"DO_CHANGE_SPEED {v:g} m/s: {why} "
                                   "(airframe.min_speed / max_speed, --min-speed)"))
        nav_items = [i for i, it in enumerate(items) if it.has_position]
        first_wp = next((i for i in nav_items if items[i].command == CMD_NAV_WAYPOINT), None)
        ok = cmd.accepted or (cmd.speed_type,)
        if first_wp is not None and not any(i < first_wp and int(it.params[0]) in ok
                                            and it.params[1] > 0 for i, it in speeds):
            out.append(Problem(first_wp, "no-cruise-speed", "no DO_CHANGE_SPEED before the "
                               f"first waypoint: {label} flies {cmd.default}, not the speed the "
                               "mission's flight time assumes", "warning"))
        return out

    rule.__name__ = rule.__qualname__ = f"speed_rules[{label}]"
    return rule


# ---------------------------------------------------------------- fixed-wing geometry
def fixed_wing_rules(nav: FixedWingNav, label: str) -> Callable[..., list[Problem]]:
    """The fixed-wing geometry rule of a firmware (module docstring)."""

    def rule(items: Sequence[MissionItem], vehicle: str, *, home_alt: float | None = None,
             home_latlon: tuple[float, float] | None = None,
             airframe: AirframeNav | None = None, **_: Any) -> list[Problem]:
        if vehicle not in ("fixed_wing", "vtol"):
            return []
        n = nav.for_airframe(airframe)
        nav_idx = [i for i, it in enumerate(items) if it.has_position]
        if len(nav_idx) < 2:
            return []
        pos = [items[i] for i in nav_idx]
        xy = local_xy(pos, pos[0].lat, pos[0].lon)
        speeds = leg_speeds(items, nav_idx, n.airspeed_cruise, 0)
        out: list[Problem] = []
        if vehicle == "fixed_wing" and items[nav_idx[0]].command == CMD_NAV_TAKEOFF:
            launch = (xy[0] if home_latlon is None else
                      local_xy([MissionItem.at(CMD_NAV_WAYPOINT, FRAME_GLOBAL, home_latlon[0],
                                               home_latlon[1], 0.0)], pos[0].lat, pos[0].lon)[0])
            out += _climb_out(items, nav_idx, xy, launch, speeds, n, home_alt, label)
        out += _loiters(items, nav_idx, xy, speeds, n, label)
        out += _legs(items, nav_idx, xy, speeds, n, label)
        out += _landings(items, nav_idx, xy, speeds, n, home_alt, label)
        return out

    rule.__name__ = rule.__qualname__ = f"fixed_wing_rules[{label}]"
    return rule


def _climb_out(items: Sequence[MissionItem], nav_idx: Sequence[int], xy: np.ndarray,
               launch: np.ndarray, speeds: np.ndarray, n: FixedWingNav,
               home_alt: float | None, label: str) -> list[Problem]:
    """The take-off climbs straight ahead from the launch (home) along the course to the
    take-off item's position (ArduPlane holds the launch heading: the operator points the
    aircraft along the course the item shows)."""
    import numpy as np

    t = items[nav_idx[0]]
    nxt = items[nav_idx[1]]
    h_to = t.alt if t.frame in (FRAME_RELATIVE, 6, 10, 11) else (
        None if home_alt is None else t.alt - home_alt)
    if h_to is None:
        return []
    v = float(speeds[0]) if len(speeds) else n.airspeed_cruise
    if nxt.command == CMD_NAV_LOITER_TO_ALT:
        return []  # a climb in circles: its radius and exit are the loiter rules
    if nxt.command not in (CMD_NAV_WAYPOINT,):
        return []
    d = xy[1] - launch
    dist = float(np.hypot(*d))
    need = n.climb_distance(h_to, v) + n.turn_distance(90.0, v)
    out: list[Problem] = []
    course = xy[0] - launch
    if float(np.hypot(*course)) > 1.0 and dist > 1.0:
        ang = math.degrees(math.acos(max(-1.0, min(1.0, float(np.dot(course, d)) /
                                                   (float(np.hypot(*course)) * dist)))))
        if ang > COURSE_TOLERANCE_DEG:
            out.append(Problem(nav_idx[1], "fw-climb-out", f"the first waypoint lies {ang:.0f}° "
                               f"off the take-off course: {label} climbs straight ahead on the "
                               "launch heading to the take-off altitude before it turns; put "
                               "the first waypoint ahead, or climb in a NAV_LOITER_TO_ALT"))
    if dist < need - 1e-6:
        out.append(Problem(nav_idx[1], "fw-climb-out", f"the first waypoint is {dist:.0f} m from "
                           f"the launch, but climbing {h_to:.0f} m at {n.climb_rate:g} m/s "
                           f"({n.param('climb_rate')}) and {v:g} m/s takes "
                           f"{n.climb_distance(h_to, v):.0f} m plus {n.turn_distance(90, v):.0f} "
                           f"m to turn: {label} overflies it and comes back; climb in a "
                           "NAV_LOITER_TO_ALT or put the first waypoint further ahead"))
    a_to = item_amsl(t, home_alt)
    a_1 = item_amsl(nxt, home_alt)
    if a_to is not None and a_1 is not None and a_1 < a_to - FALL_BACK_TOLERANCE:
        out.append(Problem(nav_idx[1], "fw-climb-out", f"the first waypoint is {a_to - a_1:.0f} "
                           "m below the take-off altitude: the climb-out falls back before the "
                           "route; take off to the route's altitude"))
    return out


def _loiters(items: Sequence[MissionItem], nav_idx: Sequence[int], xy: np.ndarray,
             speeds: np.ndarray, n: FixedWingNav, label: str) -> list[Problem]:
    import numpy as np

    out: list[Problem] = []
    for k, i in enumerate(nav_idx):
        it = items[i]
        if it.command == CMD_NAV_LOITER_TO_ALT:
            r = abs(it.params[1])
        elif it.command == CMD_NAV_LOITER_UNLIM:
            r = abs(it.params[2])
        else:
            continue
        v = float(speeds[k - 1]) if k > 0 and len(speeds) else n.airspeed_cruise
        r_eff = r if r > 0 else n.loiter_radius
        rt = n.turn_radius(v)
        if r_eff < rt - 0.5:
            out.append(Problem(i, "fw-loiter-radius", f"{it.name}: a {r_eff:.0f} m loiter at "
                               f"{v:g} m/s is tighter than the turn radius {rt:.0f} m "
                               f"({n.param('bank_limit_deg')} {n.bank_limit_deg:g}°): {label} "
                               "flies a wider circle than the mission's"))
        if it.command == CMD_NAV_LOITER_TO_ALT and k + 1 < len(nav_idx):
            d = float(np.hypot(*(xy[k + 1] - xy[k])))
            if d < r_eff + 1.0:
                out.append(Problem(nav_idx[k + 1], "fw-loiter-exit", f"{items[nav_idx[k + 1]].name} "
                                   f"is {d:.0f} m from the loiter centre, inside its {r_eff:.0f} "
                                   f"m circle: {label} leaves the loiter by altitude only, in "
                                   "whatever direction it then flies"))
    return out


def _legs(items: Sequence[MissionItem], nav_idx: Sequence[int], xy: np.ndarray,
          speeds: np.ndarray, n: FixedWingNav, label: str) -> list[Problem]:
    """Waypoint after waypoint: skipped waypoints (error) and overshoots (warning)."""
    import numpy as np

    out: list[Problem] = []
    ang = turn_angles(xy)
    ang[-1] = END_TURN_DEG  # no next leg: the firmware assumes a 90° turn
    for k in range(1, len(nav_idx) - 1):
        i, j = nav_idx[k], nav_idx[k + 1]
        a, b = items[i], items[j]
        if a.command != CMD_NAV_WAYPOINT or b.command != CMD_NAV_WAYPOINT:
            continue
        v = float(speeds[k])
        L = float(np.hypot(*(xy[k + 1] - xy[k])))
        acc_a = n.turn_distance(ang[k], v, a.params[1])
        acc_b = n.turn_distance(ang[k + 1], v, b.params[1])
        # where the aircraft is when it reaches waypoint a: acc_a before it on its leg in
        d_in = xy[k] - xy[k - 1]
        u_in = d_in / max(float(np.hypot(*d_in)), 1e-9)
        at = xy[k] - u_in * min(acc_a, float(np.hypot(*d_in)))
        gap = float(np.hypot(*(xy[k + 1] - at)))
        if gap <= acc_b + 1e-6:
            out.append(Problem(j, "fw-skipped-waypoint", f"{b.name} is {L:.0f} m after the "
                               f"previous waypoint: {label} reaches the previous one "
                               f"{acc_a:.0f} m before it, already within {acc_b:.0f} m of this "
                               f"one ({n.param('acceptance_radius')} / L1 at {v:g} m/s), so it "
                               "never flies to it"))
            continue
        turn_on = n.turn_on_distance(ang[k], v)
        need = turn_on + acc_b
        if L < need - 1e-6:
            out.append(Problem(j, "fw-short-leg", f"the {L:.0f} m leg to {b.name} is shorter than "
                               f"the {need:.0f} m {label} flies on it ({turn_on:.0f} m to turn "
                               f"{ang[k]:.0f}° onto it at a {n.turn_radius(v):.0f} m radius, "
                               f"{v:g} m/s, and {acc_b:.0f} m of turn distance before the "
                               "waypoint): it reaches the waypoint before it is on the leg, "
                               "off its line by up to about a turn radius", "warning"))
    return out


def _landings(items: Sequence[MissionItem], nav_idx: Sequence[int], xy: np.ndarray,
              speeds: np.ndarray, n: FixedWingNav, home_alt: float | None,
              label: str) -> list[Problem]:
    import numpy as np

    out: list[Problem] = []
    for k, i in enumerate(nav_idx):
        land = items[i]
        if land.command != CMD_NAV_LAND or k == 0:
            continue
        prev = items[nav_idx[k - 1]]
        v = float(speeds[k - 1]) if len(speeds) else n.airspeed_cruise
        d = float(np.hypot(*(xy[k] - xy[k - 1])))
        if prev.command == CMD_NAV_LOITER_TO_ALT:
            r = abs(prev.params[1]) or n.loiter_radius
            if d <= r:
                continue  # the PX4 rule names it (landing inside the loiter)
            run = math.sqrt(d * d - r * r)
        elif prev.command == CMD_NAV_WAYPOINT:
            run = d
            if k >= 2:
                turn = turn_angles(xy[k - 2:k + 1])[1]
                need = n.turn_on_distance(turn, v) + n.turn_distance(turn, v)
                if run < need:
                    out.append(Problem(i, "fw-landing", f"the landing approach is {run:.0f} m "
                                       f"long, shorter than the {need:.0f} m {label} needs to "
                                       f"turn {turn:.0f}° onto it: it reaches the runway off "
                                       "its line"))
        else:
            continue
        a_land, a_prev = item_amsl(land, home_alt), item_amsl(prev, home_alt)
        if a_land is None or a_prev is None or run <= 0:
            continue
        slope = math.degrees(math.atan2(a_prev - a_land, run))
        lim = n.max_glide_deg(v)
        if slope > lim + 0.1:
            out.append(Problem(i, "fw-landing", f"the landing glide slope is {slope:.1f}°, steeper "
                               f"than the {lim:.1f}° {label} can hold at {v:g} m/s "
                               f"({n.param('sink_rate')} {n.sink_rate:g} m/s"
                               f"{', FW_LND_ANG' if n.landing_slope_max_deg is not None else ''})"
                               ": lengthen the approach (land_slope_deg)"))
    return out
