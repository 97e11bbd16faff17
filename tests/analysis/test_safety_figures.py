"""analysis.safety: each figure and check on a case built so that one wrong line changes it
(the mutation pass of issue 25 deliverable 9 found these lines unguarded)."""

from __future__ import annotations

import numpy as np
import pytest

from fm2uav import World
from fm2uav.analysis.safety import height_above_ground, leg_figures, safety_summary
from fm2uav.planning import FlightLevel
from fm2uav.scenarios import get_scenario
from fm2uav.world.ground_model import sampling_step
from fm2uav.world.zones import with_zones, zone_from_mapping


@pytest.fixture(scope="module")
def field():
    return get_scenario("open-field").world


def _on_ground(world, xy, agl):
    xy = np.asarray(xy, float)
    return np.column_stack([xy, world.ground_height(xy[:, 0], xy[:, 1]) + agl])


def test_height_above_ground_and_above_the_roofs_differ_over_a_building():
    city = get_scenario("city").world
    over_roof = np.array([[400.0, 375.0, 450.0], [100.0, 100.0, 450.0]])
    assert city.surface_height(400.0, 375.0) == pytest.approx(385.0)  # a roof
    assert height_above_ground(city, over_roof) == pytest.approx([450.0, 450.0])
    assert height_above_ground(city, over_roof, surface=True)[0] == pytest.approx(65.0)


def test_a_one_node_spike_under_a_leg_is_seen():
    """Legs are sampled at a quarter of sampling_step: a spike between waypoints is seen
    to within its slope times half a sample step."""
    h = np.zeros((40, 11))
    h[20, 5] = 100.0
    w = World.from_heightmap(h, 15.0, 20)
    peak = float(w.ground_height(300.0, 75.0))
    assert peak == pytest.approx(100.0)
    f = leg_figures(w, [[7.0, 75.0, 200.0], [583.0, 75.0, 200.0]])
    assert f["step_m"] <= 0.25 * sampling_step(w) + 1e-3
    slope = peak / 15.0
    assert f["min_m"] == pytest.approx(200.0 - peak, abs=slope * f["step_m"] / 2 + 1e-6)


def test_terrain_frame_legs_interpolate_the_waypoints_agl(field):
    wps = _on_ground(field, [[300.0, 600.0], [1500.0, 600.0]], 0.0)
    f = leg_figures(field, wps, terrain_frame=True, waypoint_agl=[100.0, 200.0])
    assert f["min_m"] == pytest.approx(100.0) and f["max_m"] == pytest.approx(200.0)
    assert f["median_m"] == pytest.approx(150.0, abs=1.0)


def test_the_takeoff_and_landing_columns_are_apart_from_min_agl(field):
    a, b = [300.0, 300.0], [360.0, 300.0]
    wps = np.vstack([_on_ground(field, [a], 0.0), _on_ground(field, [a, b], 100.0),
                     _on_ground(field, [b], 0.0)])
    f = leg_figures(field, wps)
    assert f["min_m"] == pytest.approx(0.0, abs=1e-9)
    assert f["min_off_takeoff_landing_m"] > 50.0


def _cruise_path(world, dip):
    x = np.linspace(200, 1500, 261)
    path = _on_ground(world, np.column_stack([x, np.linspace(300, 1100, 261)]), 120.0)
    path[130, 2] -= dip
    return path, np.array(["cruise"] * len(path))


def test_min_agl_check_fails_half_a_metre_below_the_limit(field):
    path, phase = _cruise_path(field, 120.0 - 14.5)  # 14.5 m above ground at one point
    s = safety_summary(field, path, requested=120.0, phase=phase,
                       level=FlightLevel(agl=120.0, min_agl=15.0, tolerance=200.0))
    assert s["checks"]["min_agl"]["lowest_m"] == pytest.approx(14.5)
    assert s["checks"]["min_agl"]["ok"] is False


def test_cruise_floor_is_agl_minus_tolerance(field):
    path, phase = _cruise_path(field, 2.5)  # 0.5 m below the floor 120 - 2
    s = safety_summary(field, path, requested=120.0, phase=phase,
                       level=FlightLevel(agl=120.0))
    assert s["checks"]["cruise_floor"]["limit_m"] == pytest.approx(118.0)
    assert s["checks"]["cruise_floor"]["ok"] is False
    ok = safety_summary(field, _cruise_path(field, 1.5)[0], requested=120.0, phase=phase,
                        level=FlightLevel(agl=120.0))
    assert ok["checks"]["cruise_floor"]["ok"] is True


def test_cruise_legs_floor_takes_min_agl_when_it_is_higher(field):
    path, phase = _cruise_path(field, 0.0)
    idx = np.arange(0, len(path), 20)
    idx[-1] = len(path) - 1
    wps = path[idx].copy()
    wps[3, 2] -= 25.0  # one waypoint 95 m above ground: below min_agl, above agl - tol
    lvl = FlightLevel(agl=120.0, tolerance=30.0, min_agl=100.0)
    s = safety_summary(field, path, requested=120.0, phase=phase, waypoints=wps,
                       waypoint_indices=idx, level=lvl)
    c = s["checks"]["cruise_legs_floor"]
    assert c["limit_m"] == pytest.approx(100.0)
    assert 90.0 < c["lowest_m"] <= 95.0 and c["ok"] is False


def test_a_leg_through_a_zone_fails_the_zone_check_though_the_path_goes_round(field):
    wall = zone_from_mapping({"polygon": [[800, 550], [900, 550], [900, 650], [800, 650]],
                              "name": "block"})
    w = with_zones(field, [wall])
    xy = np.array([[300.0, 600.0], [850.0, 800.0], [1500.0, 600.0]])
    dense = np.vstack([np.linspace(xy[k], xy[k + 1], 100)[:-1] for k in range(2)] + [xy[-1:]])
    path = _on_ground(w, dense, 150.0)
    s = safety_summary(w, path, requested=150.0, waypoints=path[[0, -1]],
                       level=FlightLevel(agl=150.0))
    assert s["zones"]["path_entries"] == []
    assert s["legs"]["zone_entries"] and s["checks"]["zones"]["ok"] is False


def test_the_clearance_point_is_the_closest_one(field):
    path, phase = _cruise_path(field, 100.0)  # 20 m above ground at point 130
    s = safety_summary(field, path, requested=120.0, phase=phase)
    assert s["clearance_m"] <= 20.0 + 1e-6
    assert s["clearance_point_m"] == pytest.approx(path[130], abs=1e-3)


def test_legs_over_filled_ground_are_counted_apart():
    """A leg flying lower over filled (invented) ground than over measured ground: the
    measured minimum is taken over the measured samples only."""
    h = np.zeros((40, 11))
    filled = np.zeros((40, 11), bool)
    filled[25:, :] = True  # x >= 375 m is invented ground
    w = World.from_heightmap(h, 15.0, 20).with_fields(filled=filled)
    wps = np.array([[30.0, 75.0, 120.0], [300.0, 75.0, 120.0], [560.0, 75.0, 60.0]])
    f = leg_figures(w, wps)
    g = f["ground"]
    assert g["filled_samples"] > 0 and g["filled_min_m"] == pytest.approx(60.0)
    xs = np.linspace(300.0, 560.0, 10001)
    zs = np.interp(xs, [300.0, 560.0], [120.0, 60.0])
    measured_low = zs[xs <= 360.0 + 1e-9].min()  # the last x whose stencil is all measured
    assert g["measured_min_m"] == pytest.approx(measured_low, abs=0.5)
    assert g["measured_min_m"] > 100.0
