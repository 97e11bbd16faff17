"""`run_routes` on a 3D map in UTM: every route figure equals an independent measurement of
routes.geojson (pyproj's WGS84 geodesic with the altitude change; the ground under the
written line from the terrain map by scipy's bilinear interpolation)."""

from __future__ import annotations

import json

import numpy as np
import pytest
from pyproj import Geod, Transformer
from scipy import ndimage

from fm2uav import FlightLevel, PlanOptions, Shaping, plan
from fm2uav.io.outdir import OutputDir
from fm2uav.io.starts import Starts
from fm2uav.pipeline.routes import RouteSettings, run_routes

from tests.autopilot.mission_cases import UTM, hill

GEOD = Geod(ellps="WGS84")


def _lowest_agl_of_written_line(world, line, step=0.05):
    """min(alt - ground) along the straight legs of lon/lat/alt positions, every ``step`` m."""
    xy = np.column_stack(Transformer.from_crs("EPSG:4326", UTM, always_xy=True)
                         .transform(line[:, 0], line[:, 1]))
    low = np.inf
    for a, b, za, zb in zip(xy[:-1], xy[1:], line[:-1, 2], line[1:, 2]):
        t = np.linspace(0, 1, max(2, int(np.hypot(*(b - a)) / step) + 1))
        p = a + t[:, None] * (b - a)
        idx = (p - np.asarray(world.origin[:2])) / np.asarray(world.spacing[:2])
        ground = ndimage.map_coordinates(world.terrain, idx.T, order=1, mode="nearest")
        low = min(low, float(np.min(za + t * (zb - za) - ground)))
    return low


@pytest.fixture(scope="module")
def hill_routes(tmp_path_factory):
    w = hill(UTM)
    o = np.asarray(w.origin)
    level = FlightLevel(agl=40.0)
    starts = np.array([o + (30.0, 30.0, 0), o + (60.0, 250.0, 0), o + (350.0, 40.0, 0),
                       o + (-80.0, 40.0, 0)])
    starts[:, 2] = np.asarray(w.ground_height(starts[:, 0], starts[:, 1])) + 40.0
    goal = o + (380.0, 280.0, 0)
    goal[2] = float(w.ground_height(goal[0], goal[1])) + 40.0
    out = tmp_path_factory.mktemp("routes3d") / "r"
    with OutputDir(out) as od:
        run = run_routes(od, w, goal, Starts(ids=("a", "b", "c", "off"), points=starts),
                         shaping=Shaping(), level=level, options=PlanOptions(),
                         settings=RouteSettings(speed=12.0))
    return w, starts, goal, level, run, out


def test_figures_equal_an_independent_check_of_routes_geojson(hill_routes):
    w, starts, goal, level, run, out = hill_routes
    feats = json.loads((out / "routes.geojson").read_text())["features"]
    assert [f["properties"]["id"] for f in feats] == ["a", "b", "c"]
    for ft, start in zip(feats, starts):
        line = np.asarray(ft["geometry"]["coordinates"])
        p = ft["properties"]
        _, _, d = GEOD.inv(line[:-1, 0], line[:-1, 1], line[1:, 0], line[1:, 1])
        measured = float(np.sum(np.hypot(d, np.diff(line[:, 2]))))
        assert p["length_m"] == pytest.approx(measured, abs=6e-4)
        assert p["time_s"] == pytest.approx(measured / 12.0, abs=6e-4)
        # the written line's lowest height above the ground, measured independently
        assert p["lowest_agl_m"] == pytest.approx(_lowest_agl_of_written_line(w, line),
                                                  abs=0.02)
        single = plan(w, start, goal, level=level)
        assert p["planned_length_m"] == round(single.length, 3)
        h = single.height_above_ground()
        assert p["planned_lowest_agl_m"] == pytest.approx(float(h.min()), abs=6e-4)
        # a UTM map: the map's metres are not the ellipsoid's (scale factor ~0.9996 here)
        assert p["length_m"] != pytest.approx(p["planned_length_m"], abs=1e-3)
    off = run.rows[3]
    assert off["reason"] == "outside" and off["message"].startswith(
        f"the start at lon {off['lon']}, lat {off['lat']} lies outside the map (lon 8.")
