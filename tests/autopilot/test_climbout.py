"""The fixed-wing climb-out: straight ahead to a low route (first waypoint beyond the climb
distance, never below the take-off altitude), in a loiter to a high one, refused where no
climb clears the ground."""

from __future__ import annotations

import math
from functools import lru_cache

import numpy as np
import pytest

from fm2uav import World, plan
from fm2uav.autopilot import ExportOptions, build_mission
from fm2uav.autopilot.climbout import CLIMB_CLEARANCE
from fm2uav.autopilot.firmware.ardupilot import PLANE_NAV
from fm2uav.errors import MissionError

from .mission_cases import ANCHOR


@lru_cache(maxsize=None)
def _flat_plan():
    w = World(np.zeros((240, 160), bool), spacing=10.0)  # 2.4 x 1.6 km, flat
    return plan(w, (100.0, 100.0), (2200.0, 1400.0))


def _mission(flight_alt, **kw):
    p = _flat_plan()
    opt = ExportOptions(anchor=ANCHOR, firmware="ardupilot", vehicle="fixed_wing",
                        cruise_speed=20.0, flight_alt=flight_alt, **kw)
    return build_mission(p.path, p.world, opt, w=p.w)


def _xy(m, it):
    from fm2uav.world.geo import from_lonlat

    return from_lonlat(m.world, [[it.lon, it.lat]], anchor=ANCHOR)[0]


def test_a_low_route_is_climbed_to_straight_ahead_beyond_the_climb_distance():
    m = _mission(40.0)
    co = m.info["climb_out"]
    assert co["mode"] == "straight" and co["takeoff_alt_m"] == pytest.approx(40.0, abs=0.5)
    t, first = m.items[0], next(it for it in m.items if it.command == 16)
    assert t.command == 22 and t.params[0] == 15.0
    home = m.waypoints.points_m[0, :2]
    d_t, d_1 = _xy(m, t) - home, _xy(m, first) - home
    angle = math.degrees(math.acos(d_t @ d_1 / (np.hypot(*d_t) * np.hypot(*d_1))))
    assert angle < 1.0  # the first waypoint lies ahead on the take-off course
    nav = PLANE_NAV.with_airframe(cruise=20.0)
    assert np.hypot(*d_1) >= nav.climb_distance(40.0)  # 40 m x 20 / 5 = 160 m
    assert first.alt >= t.alt - 2.0  # not below the take-off altitude
    assert math.degrees(math.atan2(d_t[0], d_t[1])) % 360 == pytest.approx(co["course_deg"],
                                                                         abs=0.1)


def test_a_high_route_is_climbed_to_in_a_loiter_over_the_start():
    m = _mission(200.0)
    co = m.info["climb_out"]
    assert co["mode"] == "loiter"
    t, lo = m.items[0], m.items[1]
    assert (t.command, lo.command) == (22, 31)
    assert t.alt == pytest.approx(PLANE_NAV.takeoff_alt) and lo.alt == pytest.approx(200.0)
    r_turn = PLANE_NAV.with_airframe(cruise=20.0).turn_radius()
    assert 1.2 * r_turn <= lo.params[1] <= 2 * r_turn  # a circle it flies, within 2 R
    assert lo.params[0] == 1.0 and lo.params[3] == 1.0  # heading required, exit xtrack
    first = next(it for it in m.items if it.command == 16)
    assert np.hypot(*(_xy(m, first) - _xy(m, lo))) > lo.params[1]  # leaves the circle
    assert co["loiter_climb_m"] == pytest.approx(150.0)
    assert m.info["flight"]["takeoff_s"] >= 150.0 / 5.0  # the climb at TECS_CLMB_MAX


def test_a_start_in_a_pit_has_no_climb_out():
    h = np.full((160, 160), 0.0)
    yy, xx = np.meshgrid(np.arange(160), np.arange(160))
    h[np.hypot(xx - 30, yy - 30) > 4] = 300.0  # a 40 m pit in a plateau 300 m up
    w = World.from_heightmap(h, 10.0, 70)
    p = plan(w, (300.0, 300.0, 20.0), (305.0, 300.0, 20.0))
    opt = ExportOptions(anchor=ANCHOR, firmware="ardupilot", vehicle="fixed_wing",
                        cruise_speed=20.0)
    with pytest.raises(MissionError, match="no fixed-wing climb-out fits the start"):
        build_mission(p.path, w, opt, w=p.w)
    assert CLIMB_CLEARANCE == 10.0
