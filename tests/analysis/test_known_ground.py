"""Known and unknown ground (issue 25 deliverable 2) and the DEM-resolution figure: every
split figure of a border route checked against an independent reading of the source
GeoTIFF (rasterio + pyproj), the physics of the resolution rule against an analytic terrain."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import fm2uav
from fm2uav import World
from fm2uav.analysis.known_ground import (
    RESOLUTION_MARGIN,
    check_ground,
    dem_resolution,
    ground_split,
)
from fm2uav.analysis.safety import safety_summary
from fm2uav.errors import PlanningError
from fm2uav.planning import FlightLevel
from fm2uav.world.dem import GeodataWarning
from fm2uav.world.geo import from_lonlat

from tests.world import dem_cases as dc


@pytest.fixture(scope="module")
def border(tmp_path_factory):
    """The country DEM (nodata beyond a bent border), filled, and a 100 m AGL plan across
    the neighbour's bay."""
    d = tmp_path_factory.mktemp("border")
    tif = dc.country(d / "country.tif")
    w = World.from_dem(tif, (150.0, 150.0, 15.0), nodata="fill", agl=100.0)
    s = from_lonlat(w, list(dc.BORDER_START))
    g = from_lonlat(w, list(dc.BORDER_GOAL))
    p = fm2uav.plan(w, [*s, w.ground_height(*s) + 100], [*g, w.ground_height(*g) + 100],
                    level=FlightLevel(agl=100.0))
    return tif, w, p


def test_the_split_equals_an_independent_reading_of_the_dem(border):
    tif, w, p = border
    sf = safety_summary(w, p.path, requested=100.0, phase=p.phase, level=p.level)
    g = sf["ground"]
    unknown = lambda pts: ~dc.measured_mask(tif, w, pts)  # noqa: E731
    over, total = dc.length_over(p.path, unknown, step=0.5)
    assert total == pytest.approx(p.length, abs=1e-6)
    assert g["length_m"] == pytest.approx(total, abs=1e-3)
    assert over > 2000.0  # the route does cross the bay
    assert g["filled"]["length_m"] == pytest.approx(over, abs=1.0)
    assert g["measured"]["length_m"] == pytest.approx(total - over, abs=1.0)
    assert g["filled"]["share"] == pytest.approx(over / total, abs=1e-4)
    # the points: classified independently, their figures from the independent reading
    pts_unknown = unknown(p.path)
    assert g["filled"]["points"] == int(pts_unknown.sum())
    assert g["measured"]["points"] == int((~pts_unknown).sum())
    from tests.world.rough_terrain import source_ground
    agl = p.path[:, 2] - source_ground(tif, w, p.path[:, 0], p.path[:, 1])
    m = g["measured"]["height_above_ground"]
    assert m["min_m"] == pytest.approx(agl[~pts_unknown].min(), abs=1e-3)
    assert m["median_m"] == pytest.approx(np.median(agl[~pts_unknown]), abs=1e-3)
    assert m["within_band"] == pytest.approx(np.mean(np.abs(agl[~pts_unknown] - 100) <= 5),
                                             abs=1e-4)
    # the filled stretches lie where no measured pixel is
    for st in g["filled"]["stretches"]:
        for ll in (st["from_lonlat"], st["to_lonlat"]):
            xy = from_lonlat(w, [ll])
            assert unknown(np.column_stack([xy, [0.0]]))[0]
    assert g["filled"]["stretch_count"] >= 1
    # the whole-path figures are still there, and the split adds up
    assert sf["height_above_ground"]["path"]["n"] == g["filled"]["points"] + g["measured"]["points"]
    assert sf["clearance_m"] == pytest.approx(min(g["filled"]["clearance_m"],
                                                  g["measured"]["clearance_m"]), abs=1e-9)


def test_fill_warns_with_the_length_and_error_on_route_refuses_naming_where(border):
    tif, w, p = border
    sf = safety_summary(w, p.path, requested=100.0, phase=p.phase, level=p.level)
    km = sf["ground"]["filled"]["length_m"] / 1000
    with pytest.warns(GeodataWarning, match=rf"flies {km:.2f} km of .* over filled DEM nodata, "
                                            r"unknown ground .*lon 10\.\d+, lat 45\.\d+.*"
                                            r"world.dem_fill, CLI --dem-fill FILE"):
        check_ground(w, sf)
    w2 = World.from_dem(tif, (150.0, 150.0, 15.0), nodata="error_on_route", agl=100.0)
    assert w2.georef.sources[0].details["nodata_rule"] == "error_on_route"
    sf2 = safety_summary(w2, p.path, requested=100.0)
    with pytest.raises(PlanningError, match=r"km of .* over filled DEM nodata.*lon 10\.\d+.*"
                                            r"world.nodata: error_on_route \(CLI --nodata "
                                            r"error_on_route\) refuses such plans"):
        check_ground(w2, sf2)


def test_a_path_over_measured_ground_only_says_nothing(border):
    tif, w, p = border
    s = from_lonlat(w, [10.02, 45.52])
    g = from_lonlat(w, [10.08, 45.56])
    path = np.column_stack([np.linspace(s[0], g[0], 50), np.linspace(s[1], g[1], 50),
                            np.full(50, 800.0)])
    sf = safety_summary(w, path)
    assert sf["ground"]["filled"]["length_m"] == 0 and sf["ground"]["filled"]["stretches"] == []
    with warnings.catch_warnings():
        warnings.simplefilter("error", GeodataWarning)
        check_ground(w, sf)


def test_synthetic_worlds_have_no_split():
    sc = fm2uav.scenarios.get_scenario("open-field")
    p = fm2uav.plan(sc.world, sc.start, sc.goal)
    assert ground_split(sc.world, p.path, p.path[:, 2]) is None
    assert "ground" not in safety_summary(sc.world, p.path)


# -------------------------------------------------------------------- DEM resolution

A, WAVE = 300.0, 4000.0   # a sine terrain: max slope atan(2 pi A / WAVE) = 25 deg


def _sine_world(pixel):
    n = int(24000 / pixel)
    x = (np.arange(n) + 0.5) * pixel
    z = 500.0 + A * np.sin(2 * np.pi * x / WAVE)[None, :] + np.zeros((max(n // 8, 4), 1))
    return World.from_dem(z, (max(pixel, 60.0),) * 2 + (20.0,), crs="EPSG:32630",
                          transform=(pixel, 0, 500000.0, 0, -pixel, 4500000.0 + 0 * n))


@pytest.mark.parametrize("pixel, ok", [(30.0, True), (100.0, True), (600.0, False)])
def test_the_dem_resolution_rule_is_the_hidden_relief_against_the_flight_height(pixel, ok):
    w = _sine_world(pixel)
    b = w.bounds
    x = np.linspace(b[0, 0] + WAVE, b[0, 0] + 4 * WAVE, 3000)
    y = np.full_like(x, 0.5 * (b[1, 0] + b[1, 1]))
    path = np.column_stack([x, y, w.ground_height(x, y) + 120.0])
    r = dem_resolution(w, path, 120.0)
    tan_max = 2 * np.pi * A / WAVE
    # the 95th percentile of |cos| over whole periods is cos(0.05 pi / 2)
    tan95 = tan_max * np.cos(0.05 * np.pi / 2)
    kp = 2 * np.pi * pixel / WAVE   # a central difference over +-1 pixel sees sin(kp)/kp of it
    assert np.tan(np.radians(r["slope_p95_deg"])) == pytest.approx(
        tan95 * np.sin(kp) / kp, rel=0.06)
    assert r["pixel_m"] == pytest.approx(pixel, rel=1e-3)
    assert r["hidden_relief_m"] == pytest.approx(np.tan(np.radians(r["slope_p95_deg"])) * pixel,
                                                 rel=0.02)
    assert r["ok"] is ok and r["limit_m"] == RESOLUTION_MARGIN * 120.0
    if pixel == 30.0:  # what resolution is needed: half of 120 m over the true slope
        assert r["needed_pixel_m"] == pytest.approx(60.0 / tan95, rel=0.06)
    if not ok:
        sf = {"dem_resolution": r}
        with pytest.warns(GeodataWarning, match=rf"the DEM's {pixel:.0f} m pixels cannot resolve "
                                                r"the relief.*pixels of at most ~1\d\d m"):
            check_ground(w, sf)


@pytest.mark.parametrize("seed", range(12))
def test_random_routes_split_as_the_dem_says(border, seed):
    """Seeded: random polylines across the country and the bay; the split always equals
    the independent reading of the GeoTIFF, and measured + filled is the whole length."""
    tif, w, _ = border
    rng = np.random.default_rng(seed)
    b = w.bounds
    n = int(rng.integers(2, 7))
    path = np.column_stack([rng.uniform(b[0, 0], b[0, 1], n), rng.uniform(b[1, 0], b[1, 1], n),
                            rng.uniform(300, 1500, n)])
    agl = path[:, 2] - w.ground_height(path[:, 0], path[:, 1])
    g = ground_split(w, path, agl)
    over, total = dc.length_over(path, lambda pts: ~dc.measured_mask(tif, w, pts), step=0.5)
    assert g["filled"]["length_m"] == pytest.approx(over, abs=1.0)
    assert g["measured"]["length_m"] + g["filled"]["length_m"] == pytest.approx(total, abs=1e-3)
    assert g["filled"]["points"] == int((~dc.measured_mask(tif, w, path)).sum())
