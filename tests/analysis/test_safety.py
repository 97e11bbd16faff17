"""analysis.safety figures against direct computations."""

from __future__ import annotations

import numpy as np
import pytest

from fm2uav.analysis.safety import leg_figures, safety_summary
from fm2uav.planning import FlightLevel
from fm2uav.scenarios import get_scenario
from fm2uav.world.zones import with_zones, zone_from_mapping


@pytest.fixture(scope="module")
def field():
    return get_scenario("open-field").world


def test_figures_on_a_path_at_constant_agl(field):
    x = np.linspace(200, 1500, 400)
    y = np.linspace(300, 1100, 400)
    g = field.ground_height(x, y)
    path = np.column_stack([x, y, g + 120.0])
    path[:20, 2] = g[:20] + np.linspace(20, 120, 20)  # a climb-out
    phase = np.array(["climb-out"] * 20 + ["cruise"] * 380)
    s = safety_summary(field, path, requested=120.0, phase=phase,
                       level=FlightLevel(agl=120.0, min_agl=15.0))
    c = s["height_above_ground"]["cruise"]
    assert c["min_m"] == pytest.approx(120.0) and c["within_band"] == 1.0
    whole = s["height_above_ground"]["path"]
    assert whole["min_m"] == pytest.approx(20.0) and whole["lowest_point_m"][0] == 200.0
    assert s["cruise_points"] == [20, 399]
    assert all(v["ok"] for v in s["checks"].values())
    assert 0 < s["clearance_m"] <= 20.0 + 1e-6


def test_legs_that_cut_a_hill_are_reported(field):
    # two waypoints 150 m above the ends of a leg over the central mountain
    a, b = np.array([300.0, 900.0]), np.array([1700.0, 900.0])
    wps = np.array([[*a, field.ground_height(*a) + 150.0], [*b, field.ground_height(*b) + 150.0]])
    f = leg_figures(field, wps, requested=150.0)
    xs = np.linspace(300, 1700, 2001)
    zs = np.linspace(wps[0, 2], wps[1, 2], 2001)
    truth = (zs - field.ground_height(xs, 900.0))[1:-1].min()
    assert f["min_m"] == pytest.approx(truth, abs=0.5)
    assert f["min_m"] < 100.0


def test_zone_entries_of_legs(field):
    z = zone_from_mapping({"polygon": [[800, 0], [900, 0], [900, 1300], [800, 1300]],
                           "name": "wall"})
    w = with_zones(field, [z])
    wps = np.array([[300.0, 600.0, 500.0], [1500.0, 600.0, 500.0]])
    f = leg_figures(w, wps)
    assert f["zone_entries"] and f["zone_entries"][0]["zone"] == "wall"
