"""The energy of a built mission: its waypoints, speeds and end flown by the power model."""

from __future__ import annotations

import numpy as np
import pytest

from fm2uav.autopilot import ExportOptions, build_mission
from fm2uav.autopilot.energy import DEFAULT_POWER, mission_energy
from fm2uav.vehicles.energy import fly_legs
from fm2uav.vehicles.power import POWER_MODELS
from fm2uav.world.wind import WindField

from .mission_cases import ANCHOR, hill, hill_tff

LINE = np.array([[0, 0, 60], [1000, 0, 60], [2000, 0, 90]], float)
AGL = np.array([60.0, 60.0, 90.0])


def _energy(**kw):
    base = dict(vehicle="multirotor", power=None, battery_wh=None, reserve=0.2, speeds=8.0,
                holds=np.zeros(3), forward_speed=8.0, climb_rate=2.5, descent_rate=1.5,
                end="land")
    return mission_energy(LINE, AGL, **{**base, **kw})


def test_land_end_is_the_legs_plus_takeoff_and_final_descent():
    e = _energy()
    f = fly_legs(LINE, POWER_MODELS["arducopter"], speed=8.0, climb_rate=2.5,
                 descent_rate=1.5, takeoff_climb=60.0, final_descent=90.0)
    assert e["energy_wh"] == pytest.approx(round(f.energy_wh, 2))
    assert e["time_s"] == pytest.approx(round(f.time_s, 1))
    assert e["battery_wh"] == 74.0 and e["ok"] and e["warning"] is None
    assert e["model"] == DEFAULT_POWER["multirotor"] and "class default" in e["model_source"]
    assert e["no_return_waypoint"] == 2


def test_rtl_adds_the_way_home_and_a_headwind_home_costs_more():
    land = _energy()
    rtl = _energy(end="rtl")
    assert rtl["time_s"] > land["time_s"] + 2000 / 8.0 - 1
    west = WindField.constant(6.0, 270.0)  # blows east: tail out, head home
    windy = _energy(end="rtl", wind=west)
    assert windy["energy_wh"] > rtl["energy_wh"]
    assert windy["wind"]["from_deg"] == 270.0


def test_a_small_battery_and_a_gale_are_warned():
    small = _energy(battery_wh=10.0)
    assert not small["ok"] and small["warning"].startswith("battery: the flight needs")
    gale = _energy(wind=WindField.constant(30.0, 90.0))
    assert gale["energy_wh"] is None and "cannot make headway" in gale["warning"]
    assert "no_return_waypoint" not in gale


def test_fixed_wing_default_and_given_models():
    e = _energy(vehicle="fixed_wing", speeds=15.0, forward_speed=15.0)
    assert e["model"] == "disco" and e["model_kind"] == "fixed-wing"
    given = _energy(vehicle="fixed_wing", speeds=15.0, forward_speed=15.0, power="crosswind",
                    battery_wh=222.0)
    assert given["model"] == "crosswind" and given["model_source"] == "airframe.power"
    assert given["energy_wh"] > e["energy_wh"]  # 4.5 kg against 0.94 kg


def test_build_mission_reports_the_energy_and_warns():
    p = hill_tff()
    m = build_mission(p.path, hill(), ExportOptions(anchor=ANCHOR, battery_wh=0.5), agl=60.0)
    s = m.summary()
    assert s["energy"]["model"] == "arducopter" and s["energy"]["battery_wh"] == 0.5
    assert any(w.startswith("battery:") for w in s["warnings"])
    calm = build_mission(p.path, hill(), ExportOptions(anchor=ANCHOR), agl=60.0).summary()
    assert calm["energy"]["ok"] and calm["energy"]["wind"] is None
    # the same legs as the flight-time figure: the mission's time agrees
    assert calm["energy"]["time_s"] == pytest.approx(calm["flight"]["flight_time_s"], abs=0.2)


@pytest.mark.parametrize("vehicle,end", [("multirotor", "land"), ("multirotor", "rtl"),
                                         ("vtol", "land"), ("vtol", "rtl"),
                                         ("fixed_wing", "land"), ("fixed_wing", "rtl")])
def test_in_still_air_the_energy_flies_the_flight_time_s_clock(vehicle, end):
    # one flight: the energy's time is the summary's flight time, a fixed-wing's climb-out
    # and landing pattern included (before, its energy flew a vertical take-off and no
    # pattern: 60 s against a flight time of 140.8 s here)
    m = build_mission(hill_tff().path, hill(), ExportOptions(anchor=ANCHOR, vehicle=vehicle,
                                                              end=end), agl=60.0)
    s = m.summary()
    assert s["energy"]["time_s"] == pytest.approx(s["flight"]["flight_time_s"], abs=0.11)
    assert s["energy"]["time_s"] == pytest.approx(
        float(m.waypoint_times[-1]) + s["flight"]["end_s"], abs=0.11)
    n = len(m.waypoints.points_m)
    assert 0 <= s["energy"]["no_return_waypoint"] <= n - 1  # a waypoint of the whole list


def test_a_fixed_wing_pattern_costs_its_descent_s_power_over_its_time():
    def fly(end):
        m = build_mission(hill_tff().path, hill(), ExportOptions(
            anchor=ANCHOR, vehicle="fixed_wing", end=end), agl=60.0)
        return m, m.summary()

    (land, ls), (rtl, rs) = fly("land"), fly("rtl")
    v = land.options.forward_speed
    assert land.info["flight"]["forward_speed_mps"] == v
    model = POWER_MODELS[DEFAULT_POWER["fixed_wing"]]
    # the same climb-out and route; the ends: the pattern (down from the last waypoint's
    # height above ground over its time) against the line home at the forward speed
    pattern_s, home_s = ls["flight"]["end_s"], rs["flight"]["end_s"]
    assert pattern_s > 30.0  # loiter down, line up, approach
    sink = land.waypoints.agl[-1] / pattern_s
    expected_j = (float(model.power(v, -sink)) * pattern_s - float(model.power(v, 0.0))
                  * home_s)
    got_j = (ls["energy"]["energy_wh"] - rs["energy"]["energy_wh"]) * 3600.0
    assert got_j == pytest.approx(expected_j, abs=0.02 * 3600.0)  # the summary's 0.01 Wh


def test_an_rtl_descends_from_the_last_altitude_to_the_launch_s_ground():
    w = hill()
    g = lambda x, y: float(w.ground_height(x, y))  # noqa: E731
    # from the low corner to the hilltop (ground ~90 m): the way home ends over the low
    # launch, so the descent there is the last altitude above the launch's ground
    path = np.array([[20.0, 20.0, g(20, 20) + 40], [120, 100, g(120, 100) + 40],
                     [200.0, 150.0, g(200, 150) + 40]])
    m = build_mission(path, w, ExportOptions(anchor=ANCHOR, vehicle="multirotor", end="rtl",
                                             tolerance=0.0), agl=40.0)
    s = m.summary()
    p = m.waypoints.points_m
    launch_ground = p[0, 2] - m.waypoints.agl[0]
    descent = p[-1, 2] - launch_ground
    assert descent > m.waypoints.agl[-1] + 50.0  # not the last waypoint's own height
    home_s = np.hypot(*(p[-1, :2] - p[0, :2])) / m.options.forward_speed
    assert s["flight"]["end_s"] == pytest.approx(
        home_s + descent / s["flight"]["descent_rate_mps"], abs=0.11)
    assert s["energy"]["time_s"] == pytest.approx(s["flight"]["flight_time_s"], abs=0.11)
