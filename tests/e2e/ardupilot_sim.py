"""A point-mass ArduPlane flying a mission file, written from the firmware's documentation.

Independent of fm2uav's own code (it reads the ``.waypoints`` file with pymavlink and
models the firmware, not the planner), for the acceptance tests of issue 24 where
ArduPilot's SITL cannot be built (the machine has no network for its submodules):

* **NAV_TAKEOFF** (Plane wiki "TAKEOFF Mode", ``Plane::do_takeoff``): the item's position
  is ignored; the aircraft holds the launch heading and climbs at ``TECS_CLMB_MAX`` until
  the item's altitude above home;
* **lateral guidance** (Plane wiki "Navigation Tuning"; Park, Deyst & How, "A New
  Nonlinear Guidance Logic for Trajectory Tracking", 2004 — ArduPilot's L1 controller):
  ``L1 = (1/π) ζ T V``, lateral acceleration ``4 ζ² V² sin(η) / L1`` towards the point
  of the leg ``L1`` ahead, limited by the bank ``g tan(ROLL_LIMIT_DEG)``; loiters with the
  same controller's circle law (PD on the radius error plus the centripetal term);
* **waypoint reached** (``WP_RADIUS`` parameter page): within
  ``min(WP_RADIUS, L1) · min(turn, 90°)/90°`` of it (the turn at it), within param2 when
  it is set, or once past the line through it perpendicular to the leg;
* **altitude** (TECS): the target slides from the previous item's altitude to the next
  one's with the progress along the leg (terrain frame: the height above the terrain
  slides), flown at most at ``TECS_CLMB_MAX`` up and ``TECS_SINK_MAX`` down;
* **NAV_LOITER_TO_ALT** (Mission Commands page): circles until the altitude, then until
  heading (within 10°) for the next waypoint;
* **DO_CHANGE_SPEED** (``Plane::do_change_speed``): type 0 sets the airspeed when it lies
  between ``AIRSPEED_MIN`` and ``AIRSPEED_MAX``, anything else is ignored;
* **RTL**: straight home; **NAV_LAND**: the glide from the previous item to the point.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Callable

import numpy as np

G = 9.80665
EARTH = 6371008.8

#: ArduPlane's defaults (ArduPlane/config.h and the parameter pages).
PLANE_DEFAULTS = {"WP_RADIUS": 90.0, "WP_LOITER_RAD": 60.0, "ROLL_LIMIT_DEG": 45.0,
                  "NAVL1_PERIOD": 17.0, "NAVL1_DAMPING": 0.75, "TECS_CLMB_MAX": 5.0,
                  "TECS_SINK_MAX": 5.0, "AIRSPEED_CRUISE": 12.0, "AIRSPEED_MIN": 9.0,
                  "AIRSPEED_MAX": 22.0}


@dataclass
class Item:
    """A mission item as read from the file."""

    seq: int
    command: int
    frame: int
    p: tuple[float, float, float, float]
    lat: float
    lon: float
    alt: float


def read_waypoints(path: Any) -> tuple[tuple[float, float, float], list[Item]]:
    """``(home lat, lon, alt), items`` of a QGC WPL 110 file, read by pymavlink."""
    from pymavlink import mavwp

    loader = mavwp.MAVWPLoader()
    loader.load(str(path))
    wps = [loader.wp(i) for i in range(loader.count())]
    home = (float(wps[0].x), float(wps[0].y), float(wps[0].z))
    items = [Item(i, int(w.command), int(w.frame), (float(w.param1), float(w.param2),
                                                    float(w.param3), float(w.param4)),
                  float(w.x), float(w.y), float(w.z)) for i, w in enumerate(wps[1:], start=1)]
    return home, items


@dataclass
class Flight:
    """What the simulated aircraft did."""

    t: list[float] = field(default_factory=list)
    pos: list[tuple[float, float, float]] = field(default_factory=list)  # north, east, AMSL
    target: list[int] = field(default_factory=list)  # index (into items) flown towards
    reached: list[tuple[int, float, str]] = field(default_factory=list)
    legs: dict[int, tuple[np.ndarray, np.ndarray]] = field(default_factory=dict)
    done: bool = False

    def array(self) -> np.ndarray:
        return np.asarray(self.pos, dtype=float)


class PlaneSim:
    """The aircraft (module docstring). ``ground(lat, lon)`` gives the terrain AMSL for
    terrain-frame items."""

    POSITION = {16, 17, 18, 19, 21, 22, 31}

    def __init__(self, home: tuple[float, float, float], items: list[Item], *,
                 heading_deg: float, params: dict[str, float] | None = None,
                 ground: Callable[[float, float], float] | None = None, dt: float = 0.1) -> None:
        self.home = home
        self.items = items
        self.prm = {**PLANE_DEFAULTS, **(params or {})}
        self.ground = ground
        self.dt = dt
        self.psi = math.radians(heading_deg)
        self.v = self.prm["AIRSPEED_CRUISE"]
        self.v_cmd = self.v

    # ------------------------------------------------------------ geometry
    def ne(self, lat: float, lon: float) -> np.ndarray:
        return np.array([math.radians(lat - self.home[0]) * EARTH,
                         math.radians(lon - self.home[1]) * EARTH
                         * math.cos(math.radians(self.home[0]))])

    def latlon(self, p: np.ndarray) -> tuple[float, float]:
        lat = self.home[0] + math.degrees(p[0] / EARTH)
        lon = self.home[1] + math.degrees(p[1] / (EARTH * math.cos(math.radians(self.home[0]))))
        return lat, lon

    def amsl(self, it: Item, at: np.ndarray | None = None) -> float:
        """The item's altitude AMSL (terrain frame: above the ground at ``at``)."""
        if it.frame in (0, 5):
            return it.alt
        if it.frame in (3, 6):
            return it.alt + self.home[2]
        if self.ground is None:
            raise ValueError("a terrain-frame item needs ground()")
        lat, lon = (it.lat, it.lon) if at is None else self.latlon(at)
        return it.alt + self.ground(lat, lon)

    def l1(self) -> float:
        return self.prm["NAVL1_DAMPING"] * self.prm["NAVL1_PERIOD"] * self.v / math.pi

    def acc_max(self) -> float:
        return G * math.tan(math.radians(self.prm["ROLL_LIMIT_DEG"]))

    # ------------------------------------------------------------ guidance
    def _vel(self) -> np.ndarray:
        return self.v * np.array([math.cos(self.psi), math.sin(self.psi)])

    def waypoint_acc(self, p: np.ndarray, a: np.ndarray, b: np.ndarray) -> float:
        """L1 lateral acceleration towards the leg a -> b (positive: turn right)."""
        vel = self._vel()
        L1 = max(self.l1(), 1.0)
        ab = b - a
        n = float(np.hypot(*ab))
        ab = ab / n if n > 1e-3 else (b - p) / max(float(np.hypot(*(b - p))), 1e-6)
        a_air = p - a
        d_a = float(np.hypot(*a_air))
        along = float(a_air @ ab)
        cross = lambda u, w: float(u[0] * w[1] - u[1] * w[0])  # noqa: E731
        if d_a > L1 and along / max(d_a, 1.0) < -0.7071:
            u = a_air / d_a
            nu = math.atan2(cross(vel, -u), float(vel @ -u))
        else:
            nu2 = math.atan2(cross(vel, ab), float(vel @ ab))
            s1 = max(-0.7071, min(0.7071, cross(a_air, ab) / L1))
            nu = math.asin(s1) + nu2
        nu = max(-math.pi / 2, min(math.pi / 2, nu))
        return 4 * self.prm["NAVL1_DAMPING"] ** 2 * self.v ** 2 / L1 * math.sin(nu)

    def loiter_acc(self, p: np.ndarray, c: np.ndarray, r: float, direction: int) -> float:
        """L1 circle law around ``c`` at radius ``r`` (direction 1: clockwise)."""
        vel = self._vel()
        T, z = self.prm["NAVL1_PERIOD"], self.prm["NAVL1_DAMPING"]
        omega = 2 * math.pi / T
        L1 = max(self.l1(), 1.0)
        a_air = p - c
        d = float(np.hypot(*a_air))
        u = a_air / d if d > 0.1 else vel / self.v
        cross = lambda a, b: float(a[0] * b[1] - a[1] * b[0])  # noqa: E731
        xv_cap = cross(u, vel)
        lv_cap = -float(vel @ u)
        nu = max(-math.pi / 2, min(math.pi / 2, math.atan2(xv_cap, lv_cap)))
        acc_cap = 4 * z * z * self.v ** 2 / L1 * math.sin(nu)
        err = d - r
        pd = err * omega * omega + (-lv_cap) * 2 * z * omega
        tangent = xv_cap * direction
        if tangent < 0:
            pd = max(pd, 0.0)
        ctr = tangent ** 2 / max(0.5 * r, r + err)
        acc_circ = direction * (pd + ctr)
        if err > 0 and direction * acc_cap < direction * acc_circ:
            return acc_cap
        return acc_circ

    # ------------------------------------------------------------ flying
    def fly(self, max_time: float = 20000.0) -> Flight:
        """Fly the mission until its end (RTL home, landing, loiter) or ``max_time`` [s]."""
        f = Flight()
        p = np.zeros(2)
        z = self.home[2]
        t = 0.0
        nav = [i for i, it in enumerate(self.items) if it.command in self.POSITION | {20}]
        prev_pt = p.copy()
        prev_alt = z
        k = 0  # index into nav
        i_item = 0  # next item to execute (DO items run when the nav item before completes)

        def run_dos(upto: int) -> None:
            nonlocal i_item
            while i_item < upto:
                it = self.items[i_item]
                if it.command == 178 and int(it.p[0]) == 0 and \
                        self.prm["AIRSPEED_MIN"] <= it.p[1] <= self.prm["AIRSPEED_MAX"]:
                    self.v_cmd = it.p[1]
                i_item += 1

        run_dos(nav[0])
        while k < len(nav) and t < max_time:
            idx = nav[k]
            it = self.items[idx]
            i_item = idx + 1
            nxt = next((self.items[j] for j in nav[k + 1:] if self.items[j].command != 20), None)
            target = self.ne(it.lat, it.lon) if it.command != 20 else np.zeros(2)
            seg_start = prev_pt.copy()
            climbed = False
            loops = 0.0
            done = False
            while not done and t < max_time:
                # speed and altitude targets
                self.v += max(-1.0 * self.dt, min(1.0 * self.dt, self.v_cmd - self.v))
                if it.command == 22:
                    acc = 0.0  # hold the launch heading
                    z_t = self.home[2] + it.alt if it.frame in (3, 6, 10, 11) else it.alt
                elif it.command in (31, 17, 18, 19):
                    r = abs(it.p[1] if it.command == 31 else it.p[2]) or self.prm["WP_LOITER_RAD"]
                    acc = self.loiter_acc(p, target, r, -1 if (it.p[1] < 0 if it.command == 31
                                                               else it.p[2] < 0) else 1)
                    z_t = self.amsl(it)
                elif it.command == 20:
                    acc = self.waypoint_acc(p, seg_start, target)
                    z_t = z
                else:
                    acc = self.waypoint_acc(p, seg_start, target)
                    ab = target - seg_start
                    n2 = float(ab @ ab)
                    prog = 1.0 if n2 < 1e-6 else min(max(float((p - seg_start) @ ab) / n2, 0), 1)
                    if it.frame in (10, 11) and self.ground is not None:
                        h_prev = prev_alt - (self.ground(*self.latlon(seg_start)))
                        z_t = self.ground(*self.latlon(p)) + h_prev + prog * (it.alt - h_prev)
                    else:
                        z_t = prev_alt + prog * (self.amsl(it) - prev_alt)
                acc = max(-self.acc_max(), min(self.acc_max(), acc))
                self.psi += acc / self.v * self.dt
                p = p + self._vel() * self.dt
                vz = max(-self.prm["TECS_SINK_MAX"], min(self.prm["TECS_CLMB_MAX"],
                                                         (z_t - z) / 2.0))
                z += vz * self.dt
                t += self.dt
                f.t.append(t)
                f.pos.append((float(p[0]), float(p[1]), float(z)))
                f.target.append(idx)
                loops += self.v * self.dt
                # completion
                if it.command == 22:
                    done = z >= z_t - 0.5
                elif it.command == 31:
                    if not climbed and abs(z - z_t) < 5.0 and loops > 2 * math.pi * 1.0:
                        climbed = True
                    if climbed and nxt is not None:
                        b = self.ne(nxt.lat, nxt.lon)
                        brg = math.atan2((b - p)[1], (b - p)[0])
                        err = (brg - self.psi + math.pi) % (2 * math.pi) - math.pi
                        inside = float(np.hypot(*(b - target))) <= r
                        done = inside or abs(math.degrees(err)) <= 10.0
                    elif climbed:
                        done = True
                elif it.command == 20:
                    done = float(np.hypot(*(p - target))) < self.prm["WP_LOITER_RAD"]
                elif it.command == 21:
                    done = float(np.hypot(*(p - target))) < 5.0 or (
                        float((p - target) @ (target - seg_start)) > 0)
                elif it.command in (17, 18, 19):
                    done = float(np.hypot(*(p - target))) <= r * 1.1
                else:  # NAV_WAYPOINT
                    ab = target - seg_start
                    if nxt is not None and nxt.command in (16, 21):
                        bc = self.ne(nxt.lat, nxt.lon) - target
                        h1, h2 = math.atan2(ab[1], ab[0]), math.atan2(bc[1], bc[0])
                        turn = abs(math.degrees((h2 - h1 + math.pi) % (2 * math.pi) - math.pi))
                    else:
                        turn = 90.0
                    acc_d = (it.p[1] if it.p[1] > 0 else
                             min(self.prm["WP_RADIUS"], self.l1()) * min(turn, 90.0) / 90.0)
                    d = float(np.hypot(*(p - target)))
                    passed = float(ab @ ab) > 1e-6 and float((p - target) @ ab) >= 0
                    if d <= acc_d or passed:
                        f.reached.append((idx, t, "reached" if d <= acc_d else "passed"))
                        done = True
            f.legs[idx] = (seg_start, target)
            if it.command == 31:
                prev_pt = p.copy() if it.p[3] > 0 else target.copy()  # xtrack: exit location
            elif it.command == 22:
                prev_pt = p.copy()
            else:
                prev_pt = target.copy() if it.command != 20 else p.copy()
            prev_alt = z if it.command in (22, 20, 31) else self.amsl(it)
            if it.command in (20, 21, 17):
                f.done = True
                break
            k += 1
            run_dos(nav[k] if k < len(nav) else len(self.items))
        return f


def cross_track(flight: Flight, sim: PlaneSim) -> dict[int, float]:
    """Largest distance of the flown track from each waypoint leg [m] (NAV_WAYPOINT targets:
    the line from where the leg started to the waypoint)."""
    pos = flight.array()[:, :2]
    tgt = np.asarray(flight.target)
    out: dict[int, float] = {}
    for idx, (a, b) in flight.legs.items():
        if sim.items[idx].command != 16:
            continue
        q = pos[tgt == idx]
        ab = b - a
        n2 = float(ab @ ab)
        if n2 < 1e-6 or not len(q):
            continue
        s = np.clip(((q - a) @ ab) / n2, 0.0, 1.0)
        out[idx] = float(np.hypot(*(q - (a + s[:, None] * ab)).T).max())
    return out
