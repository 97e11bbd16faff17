"""plan() with a flight level: the height above ground holds, measured independently.

Worlds: the open field, the Jacksboro fault DEM (matplotlib sample data) and
seeded rough GeoTIFF-like terrains; every figure is checked against a bilinear
sampler written here (scipy on the raw elevations), not against fm2uav's own
ground model.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import shapely
from hypothesis import HealthCheck, given, settings, strategies as st
from pyproj import Transformer
from scipy import ndimage

from fm2uav.errors import InputError
from fm2uav.autopilot.legs import refine_legs
from fm2uav.autopilot.thin import thin_indices
from fm2uav.planning import FlightLevel, plan
from fm2uav.scenarios import get_scenario
from fm2uav.world import World
from fm2uav.world.zones import with_zones, zone_from_mapping

from tests.world.rough_terrain import rough_dem

PIXEL = 1.0 / 1200.0  # 3 arc-seconds


def _raw_sampler(z, bounds, world):
    """Bilinear sampler of a north-up lon/lat grid with edge bounds (w, s, e, n)."""
    west, south, east, north = bounds
    rows, cols = z.shape
    tr = Transformer.from_crs(world.crs, "EPSG:4326", always_xy=True)

    def ground(x, y):
        lon, lat = tr.transform(np.asarray(x, float), np.asarray(y, float))
        c = (np.asarray(lon) - west) / (east - west) * cols - 0.5
        r = (north - np.asarray(lat)) / (north - south) * rows - 0.5
        return ndimage.map_coordinates(z, [r, c], order=1, mode="nearest")
    return ground


def _cruise_agl(p, ground):
    pts = p.path[p.phase == "cruise"]
    return pts[:, 2] - ground(pts[:, 0], pts[:, 1])


@pytest.fixture(scope="module")
def jacksboro():
    from fm2uav.scenarios.jacksboro import jacksboro_dem

    sc = get_scenario("jacksboro")
    z, bounds = jacksboro_dem()
    return sc, _raw_sampler(z, bounds, sc.world)


@pytest.mark.parametrize("agl", [100.0, 120.0, 150.0])
def test_jacksboro_cruise_holds_the_request_on_the_source_dem(jacksboro, agl):
    sc, ground = jacksboro
    p = plan(sc.world, sc.start, sc.goal, level=FlightLevel(agl=agl))
    h = _cruise_agl(p, ground)
    assert len(h) > 100
    assert h.min() >= agl - 2.0
    assert abs(np.median(h) - agl) <= 5.0
    # the plan's own figures agree with the independent measurement to 1 m
    fig = p.summary()["height_above_ground"]["cruise"]
    assert fig["min_m"] == pytest.approx(h.min(), abs=1.0)
    assert fig["median_m"] == pytest.approx(np.median(h), abs=1.0)


@pytest.mark.parametrize("agl", [100.0, 120.0, 150.0])
def test_open_field_cruise_holds_the_request(agl):
    sc = get_scenario("open-field")
    w = sc.world
    p = plan(w, sc.start, sc.goal, level=FlightLevel(agl=agl))
    # independent bilinear on the node heights (the open field has no finer DEM)
    def ground(x, y):
        return ndimage.map_coordinates(w.terrain, [np.asarray(x) / 15.0, np.asarray(y) / 15.0],
                                       order=1, mode="nearest")
    h = _cruise_agl(p, ground)
    assert h.min() >= agl - 2.0 and abs(np.median(h) - agl) <= 5.0
    # slope limits of the final profile (45 deg by default)
    d = np.diff(p.path, axis=0)
    horiz = np.hypot(d[:, 0], d[:, 1])
    ok = horiz > 1e-6
    # (slopes are per metre of route; a chord across a corner of the route is a bit shorter)
    assert np.all(np.abs(d[ok, 2]) <= 1.01 * horiz[ok] * math.tan(math.radians(45.0)) + 1e-6)


def _rough_world(seed, agl):
    z = rough_dem(seed, rows=110, cols=140, relief=500.0)
    west, north = -3.80, 40.36
    bounds = (west, north - z.shape[0] * PIXEL, west + z.shape[1] * PIXEL, north)
    w = World.from_dem(z, (200.0, 200.0, 20.0), crs="EPSG:4326", bounds=bounds, agl=agl)
    return w, _raw_sampler(z, bounds, w)


def _endpoints(w, agl_start=40.0):
    b = w.bounds
    pts = []
    for fx, fy in ((0.12, 0.15), (0.88, 0.85)):
        x = b[0, 0] + fx * (b[0, 1] - b[0, 0])
        y = b[1, 0] + fy * (b[1, 1] - b[1, 0])
        i, j = w.to_cell([x, y, w.origin[2]])[:2]  # above the grid's node too
        pts.append(np.array([x, y, max(float(w.ground_height(x, y)), float(w.terrain[i, j]))
                             + agl_start]))
    return pts


@settings(max_examples=8, derandomize=True, deadline=None,
          suppress_health_check=[HealthCheck.too_slow])
@given(seed=st.integers(0, 10_000), agl=st.sampled_from([100.0, 120.0, 150.0]),
       min_agl=st.sampled_from([None, 30.0, 60.0]), buffer=st.sampled_from([0.0, 50.0, 150.0]),
       width=st.floats(300.0, 1500.0))
def test_random_terrains_and_zones(seed, agl, min_agl, buffer, width):
    w, ground = _rough_world(seed, agl)
    start, goal = _endpoints(w)
    mid = 0.5 * (start[:2] + goal[:2])
    d = (goal[:2] - start[:2]) / np.linalg.norm(goal[:2] - start[:2])
    n = np.array([-d[1], d[0]])
    half = 0.5 * float(np.linalg.norm(goal[:2] - start[:2])) * 0.35
    # a wall across the direct route, leaving room around its ends
    corners = [mid - n * half - d * width / 2, mid + n * half - d * width / 2,
               mid + n * half + d * width / 2, mid - n * half + d * width / 2]
    zone = zone_from_mapping({"polygon": [c.tolist() for c in corners], "buffer": buffer,
                              "name": "wall"})
    wz = with_zones(w, [zone])
    level = FlightLevel(agl=agl, min_agl=min_agl)
    p = plan(wz, start, goal, level=level)
    h = p.path[:, 2] - ground(p.path[:, 0], p.path[:, 1])
    if min_agl is not None:
        assert h[1:-1].min() >= min_agl - 0.5
    hc = h[p.phase == "cruise"]
    assert hc.min() >= agl - 2.0 - 0.5 and abs(np.median(hc) - agl) <= 5.0
    keep_out = zone.geometry.buffer(buffer)
    assert not shapely.intersects(shapely.LineString(p.path[:, :2]), keep_out)
    idx = thin_indices(p.path, 5.0)
    idx, _ = refine_legs(idx, p.path, wz, required=p.profile.required)
    assert not shapely.intersects(shapely.LineString(p.path[idx, :2]), keep_out)
    legs = np.concatenate([np.linspace(a, b, 20, endpoint=False)
                           for a, b in zip(p.path[idx][:-1], p.path[idx][1:])])
    hl = legs[:, 2] - ground(legs[:, 0], legs[:, 1])
    # the take-off and landing columns (vertical legs) are exempt from min_agl
    ends = np.minimum(np.hypot(*(legs[:, :2] - start[:2]).T), np.hypot(*(legs[:, :2] - goal[:2]).T))
    if min_agl is not None:
        assert hl[ends > 1e-6].min() >= min_agl - 0.5


@pytest.mark.parametrize("where", ["rough", "jacksboro"])
def test_max_agl_120_over_rough_terrain(where, jacksboro):
    if where == "rough":
        w, ground = _rough_world(11, 100.0)
        start, goal = _endpoints(w)
    else:
        sc, ground = jacksboro
        w = sc.world
        start, goal = (np.array([*q[:2], float(w.ground_height(*q[:2])) + 60.0])
                       for q in (sc.start, sc.goal))
    p = plan(w, start, goal, level=FlightLevel(agl=110.0, max_agl=120.0, tolerance=2.0))
    h = p.path[:, 2] - ground(p.path[:, 0], p.path[:, 1])
    assert h.max() <= 120.0 + 0.5
    assert h[p.phase == "cruise"].min() >= 108.0 - 0.5


def test_agl_above_max_agl_is_refused_in_one_line():
    with pytest.raises(InputError) as e:
        FlightLevel(agl=150.0, max_agl=120.0)
    msg = str(e.value)
    assert "planner.max_agl" in msg and "--max-agl" in msg and "\n" not in msg
    with pytest.raises(InputError) as e:
        FlightLevel(agl=20.0, min_agl=30.0)
    assert "planner.min_agl" in str(e.value) and "--min-agl" in str(e.value)
