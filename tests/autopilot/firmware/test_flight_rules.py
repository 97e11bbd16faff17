"""The flight rules on hand-made missions: each one fires on the case its firmware page
describes (the climb-out of issue 24's SITL flight, a skipped waypoint, a speed ArduPlane
ignores, ...) and stays quiet on the mended one."""

from __future__ import annotations

import math

import pytest

from fm2uav.autopilot.firmware.navigation import AirframeNav
from fm2uav.autopilot.items import MissionItem
from fm2uav.autopilot.validate import check_mission, validate_mission
from fm2uav.errors import MissionError

HOME = (47.3977419, 8.545594, 488.0)
R_EARTH = 6371008.8


def at(cmd, east, north, alt, frame=3, **p):
    lat = HOME[0] + math.degrees(north / R_EARTH)
    lon = HOME[1] + math.degrees(east / (R_EARTH * math.cos(math.radians(HOME[0]))))
    return MissionItem.at(cmd, frame, lat, lon, alt, **p)


def speed(v, kind=0):
    return MissionItem.do(178, kind, v, -1)


def codes(items, vehicle="fixed_wing", firmware="ardupilot", **kw):
    if items[-1].command not in (20, 21, 17):
        items = [*items, MissionItem.do(20)]  # every mission ends (RTL)
    kw.setdefault("home_alt", HOME[2])
    kw.setdefault("home_latlon", HOME[:2])
    return {(p.code, p.severity) for p in validate_mission(items, firmware, vehicle=vehicle, **kw)}


def route(*xy, alt=150.0):
    return [at(16, x, y, alt) for x, y in xy]


def test_issue24_climb_out_is_refused_and_a_loiter_climb_is_not():
    # SITL: take off to 194 m, then waypoints 53 m from home at 140 m: overflown, looped back
    bad = [at(22, 0, 30, 194, p1=15), speed(22), *route((0, 53), (5, 64), (60, 140), alt=142)]
    got = codes(bad, airframe=AirframeNav(cruise=22))
    assert ("fw-climb-out", "error") in got
    msgs = [str(p) for p in validate_mission(bad, "ardupilot", vehicle="fixed_wing",
                                             home_alt=HOME[2], home_latlon=HOME[:2],
                                             airframe=AirframeNav(cruise=22))]
    assert any("overflies it and comes back" in m for m in msgs)
    assert any("below the take-off altitude" in m for m in msgs)
    # climb-out distance 194 m x 22 / 5 = 854 m + the turn distance: a waypoint 1200 m ahead
    ok = [at(22, 0, 400, 150, p1=15), speed(22), *route((0, 1200), (300, 1600), alt=150)]
    assert not {c for c in codes(ok, airframe=AirframeNav(cruise=22)) if c[1] == "error"}
    loiter = [at(22, 0, 100, 50, p1=15), at(31, 0, 0, 150, p1=1, p2=80, p4=1), speed(22),
              *route((0, 300), (200, 600))]
    assert not {c for c in codes(loiter, airframe=AirframeNav(cruise=22)) if c[1] == "error"}


def test_a_first_waypoint_off_the_take_off_course_is_refused():
    items = [at(22, 0, 300, 50, p1=15), speed(15), *route((800, 0), (1500, 0), alt=60)]
    assert ("fw-climb-out", "error") in codes(items)


def test_a_waypoint_reached_before_it_is_flown_to_is_refused_unless_its_radius_is_set():
    # ArduPlane reaches a waypoint min(WP_RADIUS, L1) x turn/90 before it: 11 m later comes the
    # next one, which is then already "reached"
    legs = [(0, 1000), (0, 1400), (0, 1411), (300, 1411)]
    items = [at(22, 0, 300, 50, p1=15), speed(22), *route(*legs)]
    assert ("fw-skipped-waypoint", "error") in codes(items, airframe=AirframeNav(cruise=22))
    fixed = [at(22, 0, 300, 50, p1=15), speed(22), at(16, 0, 1000, 150),
             at(16, 0, 1400, 150), at(16, 0, 1411, 150, p2=5), at(16, 300, 1411, 150)]
    assert codes(fixed, airframe=AirframeNav(cruise=22)) == set()
    # a leg shorter than the turn onto it is flown with an overshoot: a warning
    sharp = [at(22, 0, 300, 50, p1=15), speed(22), *route((0, 1000), (40, 1000), (40, 1500))]
    assert codes(sharp, airframe=AirframeNav(cruise=22)) == {("fw-short-leg", "warning")}


def test_loiters_tighter_than_the_turn_radius_and_exits_inside_them_are_refused():
    tight = [at(22, 0, 100, 50, p1=15), at(31, 0, 0, 150, p1=1, p2=30, p4=1), speed(22),
             *route((0, 400), (200, 800))]
    assert ("fw-loiter-radius", "error") in codes(tight, airframe=AirframeNav(cruise=22))
    inside = [at(22, 0, 100, 50, p1=15), at(31, 0, 0, 150, p1=1, p2=80, p4=1), speed(22),
              *route((0, 50), (200, 800))]
    assert ("fw-loiter-exit", "error") in codes(inside, airframe=AirframeNav(cruise=22))


def test_speeds_arduplane_ignores_or_takes_for_something_else_are_refused():
    base = [at(22, 0, 100, 50, p1=15), at(31, 0, 0, 150, p1=1, p2=80, p4=1)]
    tail = route((0, 400), (200, 800))
    assert ("speed-type", "error") in codes([*base, speed(15, kind=1), *tail])
    assert ("speed-range", "error") in codes([*base, speed(30), *tail])  # AIRSPEED_MAX 22
    assert ("speed-range", "error") in codes([*base, speed(8), *tail])  # AIRSPEED_MIN 9
    assert ("speed-range", "error") not in codes([*base, speed(30), *tail],
                                                 airframe=AirframeNav(cruise=30))
    assert ("no-cruise-speed", "warning") in codes([*base, *tail])
    # ArduCopter takes types 0 and 1 as the horizontal speed, 2/3 are climb / descent
    copter = [at(22, 0, 0, 30), speed(5, kind=0), *route((0, 100), alt=30)]
    assert codes(copter, vehicle="multirotor") == set()
    copter[1] = speed(5, kind=2)
    assert ("speed-type", "error") in codes(copter, vehicle="multirotor")


def test_a_landing_glide_the_sink_limit_cannot_hold_is_refused():
    items = [at(22, 0, 100, 50, p1=15), at(31, 0, 0, 150, p1=1, p2=80, p4=1), speed(22),
             *route((0, 600), (0, 1500)), MissionItem.do(189),
             at(31, 0, 2000, 200, p1=1, p2=80), at(21, 0, 2400, 0)]
    # 200 m over a 392 m tangent: 27 deg, ArduPlane sinks at most asin(5/22) = 13 deg
    assert ("fw-landing", "error") in codes(items, airframe=AirframeNav(cruise=22))
    items[-2] = at(31, 0, 800, 40, p1=1, p2=80)
    assert ("fw-landing", "error") not in codes(items, airframe=AirframeNav(cruise=22))


def test_check_mission_raises_on_errors_and_returns_warnings():
    items = [at(22, 0, 100, 50, p1=15), at(31, 0, 0, 150, p1=1, p2=80, p4=1),
             *route((0, 400), (200, 800))]
    items.append(MissionItem.do(20))
    warnings = check_mission(items, "ardupilot", vehicle="fixed_wing", home_alt=HOME[2],
                             home_latlon=HOME[:2])
    assert [w.code for w in warnings] == ["no-cruise-speed"]
    with pytest.raises(MissionError, match="ardupilot would reject or misfly.*speed-range|"
                                           "ignores an airspeed"):
        check_mission([*items[:2], speed(40), *items[2:]], "ardupilot", vehicle="fixed_wing",
                      home_alt=HOME[2], home_latlon=HOME[:2])
