"""FM² in a wind: time-optimal routes, the tracking check, refused nodes."""

from __future__ import annotations

import numpy as np
import pytest

from fm2uav import World, plan
from fm2uav.eikonal.wind import zermelo_time
from fm2uav.errors import InputError, PlanningError, UnreachableError
from fm2uav.planning import FlightLevel, PlanOptions, Shaping
from fm2uav.planning.wind import WindOptions, path_timing
from fm2uav.vehicles.wind_flight import fly_in_wind
from fm2uav.world.wind import WindField

H = 25.0
OPEN = World(np.zeros((61, 41), bool), spacing=H)
V = 12.0


def _jet(speed: float = 9.0, frm: float = 90.0) -> WindField:
    """A wind jet along y = 500 m, Gaussian across (120 m), calm 300 m either side."""
    x, y = np.arange(61) * H, np.arange(41) * H
    s = speed * np.exp(-((y[None, :] - 500.0) / 120.0) ** 2) * np.ones((61, 1))
    th = np.radians(frm)
    return WindField.grid(x, y, -s * np.sin(th), -s * np.cos(th), source="jet")


def test_calm_wind_is_the_still_air_plan_in_seconds():
    a, b = (100.0, 300.0), (1400.0, 700.0)
    calm = plan(OPEN, a, b, wind=WindOptions(WindField.constant(0.0, 0.0), V))
    still = plan(OPEN, a, b)
    assert calm.length == pytest.approx(still.length, rel=0.01)
    start = OPEN.to_cell(np.array(a))
    assert calm.T[start] == pytest.approx(still.T[start] / V, rel=0.01)
    assert calm.wind_timing.total_s == pytest.approx(calm.T[start], rel=0.01)
    assert calm.params["wind"]["refused_nodes"] == 0


@pytest.mark.parametrize("frm", [0.0, 90.0, 200.0, 315.0])
def test_constant_wind_flies_straight_in_the_closed_form_time(frm):
    a, b = np.array([100.0, 300.0]), np.array([1400.0, 700.0])
    f = WindField.constant(5.0, frm)
    p = plan(OPEN, a, b, wind=WindOptions(f, V))
    d = b - a
    u = d / np.linalg.norm(d)
    off = np.abs(u[0] * (p.path[:, 1] - a[1]) - u[1] * (p.path[:, 0] - a[0]))
    assert off.max() < H  # within a cell of the straight line
    want = float(zermelo_time(d, V, f.at([[0.0, 0.0]])[0]))
    assert p.wind_timing.total_s == pytest.approx(want, rel=0.01)
    assert p.T[OPEN.to_cell(a)] == pytest.approx(want, rel=0.01)


@pytest.mark.parametrize("frm", [90.0, 60.0])   # headwind jet, and one from the north-east
def test_wind_route_arrives_sooner_when_flown_in_the_same_wind(frm):
    jet = _jet(9.0, frm)
    a, b = (100.0, 500.0), (1400.0, 500.0)
    windy = plan(OPEN, a, b, wind=WindOptions(jet, V))
    still = plan(OPEN, a, b)
    flown_w = fly_in_wind(windy.path, windy.w * V, jet, dt=0.05)
    flown_s = fly_in_wind(still.path, still.w * V, jet, dt=0.05)
    assert flown_w.reached and flown_s.reached
    assert flown_w.time_s < 0.8 * flown_s.time_s          # the detour out of the jet pays
    predicted = windy.wind_timing.total_s
    assert abs(flown_w.time_s - predicted) < 0.05 * flown_w.time_s
    still_pred = path_timing(OPEN, still.path, still.w, WindOptions(jet, V)).total_s
    assert abs(flown_s.time_s - still_pred) < 0.05 * flown_s.time_s
    assert windy.length > still.length                    # longer, yet sooner


def test_obstacles_keep_shaping_the_airspeed_and_refuse_where_the_wind_wins():
    occ = np.zeros((61, 41), bool)
    occ[28:33, 0:30] = True                               # a wall with a gap in the north
    w = World(occ, spacing=H)
    p = plan(w, (100.0, 200.0), (1400.0, 200.0), wind=WindOptions(WindField.constant(3.0, 0.0),
                                                                      V))
    refused = p.params["wind"]["refused_nodes"]
    assert refused > 0                                     # next to the wall, W x V < 3 m/s
    air = p.wind_timing.airspeed
    assert np.all(air > 3.0 - 1e-9)                        # never through a refused node
    assert np.all(p.W[tuple(np.rint(w.to_index(p.path)).astype(int).T)] * V >= 3.0 - 0.5)
    assert p.path[:, 1].max() > 30 * H                     # through the gap


def test_refusals_are_errors_that_say_why():
    occ = np.zeros((61, 41), bool)
    occ[30, :] = False
    with pytest.raises(PlanningError, match="wind at the start .* not below the safe airspeed"):
        plan(OPEN, (100.0, 500.0), (1400.0, 500.0), wind=WindOptions(WindField.constant(
            13.0, 90.0), V))
    # a band of 15 m/s across the whole map closes every way
    x, y = np.arange(61) * H, np.arange(41) * H
    band = np.where((x[:, None] > 600) & (x[:, None] < 800), 15.0, 0.0) * np.ones((1, 41))
    gale = WindField.grid(x, y, band, np.zeros_like(band))
    with pytest.raises(UnreachableError, match="in this wind .* refused"):
        plan(OPEN, (100.0, 500.0), (1400.0, 500.0), wind=WindOptions(gale, V))
    with pytest.raises(InputError, match="WindOptions"):
        plan(OPEN, (100.0, 500.0), (1400.0, 500.0), wind=WindField.constant(1.0, 0.0))
    with pytest.raises(InputError, match="airspeed must be"):
        WindOptions(gale, 0.0)


def test_a_flight_level_plan_in_a_wind_profile():
    z = 50.0 + 30.0 * np.sin(np.linspace(0, 3, 41))[None, :] * np.ones((31, 1))
    world = World.from_heightmap(z, 20.0, 16)
    f = WindField.profile(6.0, 270.0, ref_height=10.0, exponent=0.2)
    p = plan(world, (60.0, 60.0, 130.0), (540.0, 740.0, 140.0), level=FlightLevel(agl=60.0),
             shaping=Shaping(saturation_distance=40.0), wind=WindOptions(f, 15.0),
             options=PlanOptions(storage="full"))
    t = p.wind_timing
    assert len(t.time) == len(p.path) and np.all(np.isfinite(t.time))
    agl = p.height_above_ground()
    mid = 0.5 * (agl[1:] + agl[:-1])
    speeds = np.hypot(*t.wind.T)
    np.testing.assert_allclose(speeds, 6.0 * (np.maximum(mid, 1.0) / 10.0) ** 0.2, rtol=1e-4)
    assert p.params["wind"]["kind"] == "profile"
