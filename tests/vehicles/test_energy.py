"""Energy and time along waypoints in a wind: closed forms of the wind triangle."""

from __future__ import annotations

import math

import numpy as np
import pytest

from fm2uav.errors import InputError
from fm2uav.vehicles.endurance import flight_time
from fm2uav.vehicles.energy import (check_battery, fly_legs, ground_speed_at_airspeed,
                                    no_return_point)
from fm2uav.vehicles.power import POWER_MODELS

QUAD = POWER_MODELS["arducopter"]
DISCO = POWER_MODELS["disco"]
SQUARE = np.array([[0, 0, 50], [1000, 0, 50], [1000, 1000, 80], [0, 1000, 50], [0, 0, 50]],
                  float)


def test_ground_speed_is_the_wind_triangle():
    rng = np.random.default_rng(3)
    heading = rng.uniform(0, 2 * np.pi, 200)
    u = np.column_stack([np.cos(heading), np.sin(heading)])
    w = rng.uniform(-8, 8, (200, 2))
    g = ground_speed_at_airspeed(u, w, 14.0)
    assert np.all(np.isfinite(g))  # |w| < 14 everywhere: always headway
    air = g[:, None] * u - w
    np.testing.assert_allclose(np.hypot(*air.T), 14.0, rtol=1e-12)
    assert np.isnan(ground_speed_at_airspeed([1.0, 0.0], [-15.0, 0.0], 14.0))


def test_still_air_times_equal_the_endurance_module():
    f = fly_legs(SQUARE, QUAD, speed=10.0, climb_rate=2.5, descent_rate=1.5,
                 takeoff_climb=50, final_descent=50)
    ft = flight_time(SQUARE, 10.0, climb_rate=2.5, descent_rate=1.5, takeoff_climb=50,
                     final_descent=50)
    np.testing.assert_allclose(f.leg_time, ft.leg_time, rtol=1e-12)
    assert f.time_s == pytest.approx(ft.time_s, rel=1e-12)
    want = (np.sum(f.power * f.leg_time) + QUAD.power(0.0, 2.5) * 20 + QUAD.power(0.0, -1.5)
            * 50 / 1.5)
    assert f.energy_wh == pytest.approx(want / 3600, rel=1e-12)


def test_fixed_wing_out_and_back_in_wind_takes_2L_Va_over_Va2_minus_w2():
    pts = np.array([[0, 0, 100], [3000, 0, 100], [0, 0, 100]], float)
    va, w = 14.0, 6.0
    f = fly_legs(pts, DISCO, speed=va, climb_rate=3, descent_rate=3, wind=[w, 0.0])
    assert f.time_s == pytest.approx(2 * 3000 * va / (va * va - w * w), rel=1e-12)
    still = fly_legs(pts, DISCO, speed=va, climb_rate=3, descent_rate=3)
    assert f.energy_wh > still.energy_wh  # constant power, longer time
    cross = fly_legs(pts[:2], DISCO, speed=va, climb_rate=3, descent_rate=3, wind=[0.0, w])
    assert cross.groundspeed[0] == pytest.approx(math.sqrt(va * va - w * w), rel=1e-12)


def test_multirotor_holds_ground_speed_until_its_airspeed_runs_out():
    pts = np.array([[0, 0, 50], [2000, 0, 50]], float)
    head = fly_legs(pts, QUAD, speed=10.0, climb_rate=2.5, descent_rate=1.5, wind=[-5.0, 0.0])
    assert head.groundspeed[0] == pytest.approx(10.0) and head.airspeed[0] == pytest.approx(15.0)
    assert head.power[0] == pytest.approx(float(QUAD.power(15.0, 0.0)))
    cap = QUAD.max_airspeed()
    strong = fly_legs(pts, QUAD, speed=10.0, climb_rate=2.5, descent_rate=1.5,
                      wind=[-(cap - 4.0), 0.0])
    assert strong.airspeed[0] == pytest.approx(cap)
    assert strong.groundspeed[0] == pytest.approx(4.0)
    gone = fly_legs(pts, QUAD, speed=10.0, climb_rate=2.5, descent_rate=1.5,
                    wind=[-(cap + 1.0), 0.0])
    assert not gone.flyable[0] and math.isinf(gone.energy_wh) and math.isinf(gone.time_s)
    rep = check_battery(gone, battery_wh=74.0)
    assert not rep.ok and rep.unflyable == [0]
    assert "cannot make headway on 1 leg(s) (0→1" in rep.warning
    assert gone.summary()["energy_wh"] is None


def test_battery_reach_is_where_the_usable_energy_runs_out():
    f = fly_legs(SQUARE, QUAD, speed=10.0, climb_rate=2.5, descent_rate=1.5)
    rep = check_battery(f, battery_wh=f.energy_wh * 2, reserve=0.2)
    assert rep.ok and rep.warning is None and rep.reach_waypoint == 4
    small = 0.6 * f.energy_wh / 0.8
    rep = check_battery(f, battery_wh=small, reserve=0.2)
    assert not rep.ok and rep.usable_wh == pytest.approx(0.6 * f.energy_wh)
    # energy used at the reach point (linear within its leg) equals the usable energy
    used, s = f.used_wh(), np.concatenate([[0], np.cumsum(f.leg_length)])
    k = rep.reach_waypoint
    frac = (rep.reach_m - s[k]) / f.leg_length[k]
    assert used[k] + frac * (used[k + 1] - used[k]) == pytest.approx(rep.usable_wh, rel=1e-9)
    assert f"waypoint {k} of 4" in rep.warning and "Wh" in rep.warning
    with pytest.raises(InputError, match="reserve"):
        check_battery(f, battery_wh=10, reserve=1.0)


def test_the_point_of_no_return_comes_sooner_against_the_wind_home():
    out = np.array([[0, 0, 50], *[[500 * i, 0, 50] for i in range(1, 9)]], float)
    kw = dict(speed=14.0, climb_rate=3.0, descent_rate=3.0, battery_wh=8.0, home=[0, 0, 0])
    still = fly_legs(out, DISCO, speed=14.0, climb_rate=3.0, descent_rate=3.0)
    k_still, m_still = no_return_point(out, still, DISCO, **{**kw, "speed": 14.0})
    tail = fly_legs(out, DISCO, speed=14.0, climb_rate=3.0, descent_rate=3.0, wind=[6.0, 0.0])
    k_wind, m_wind = no_return_point(out, tail, DISCO, wind=[6.0, 0.0], **kw)
    assert 0 <= k_wind < k_still <= 8
    assert m_wind[k_wind] >= 0 > m_wind[k_wind + 1]


def test_holds_cost_hover_power_in_the_wind():
    pts = np.array([[0, 0, 50], [0, 100, 50]], float)
    a = fly_legs(pts, QUAD, speed=5.0, climb_rate=2.5, descent_rate=1.5, wind=[3.0, 0.0])
    b = fly_legs(pts, QUAD, speed=5.0, climb_rate=2.5, descent_rate=1.5, wind=[3.0, 0.0],
                 holds=[0.0, 60.0])
    assert (b.energy_wh - a.energy_wh) * 3600 == pytest.approx(60 * float(QUAD.power(3.0, 0.0)))
    with pytest.raises(InputError, match="wind must be"):
        fly_legs(pts, QUAD, speed=5.0, climb_rate=2.5, descent_rate=1.5, wind=[1, 2, 3])
