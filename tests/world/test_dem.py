"""World.from_dem: GeoTIFF / array DEMs, CRS handling, nodata rule, and
terrain following on real and geographic DEMs."""

from __future__ import annotations

import numpy as np
import pytest
import rasterio
from rasterio.transform import from_origin

import fm2uav
from fm2uav import World
from fm2uav.analysis import flight_level_deviation
from fm2uav.errors import InputError, WorldError
from fm2uav.world.geo import from_lonlat, to_lonlat, utm_crs

# a 0.03 x 0.025 deg DEM (~2.7 x 2.8 km) near Madrid, 1 arc-second pixels
W0, N0, RES = -3.80, 40.35, 1.0 / 3600.0
ROWS, COLS = 90, 108


def _hills(rows=ROWS, cols=COLS, seed=0):
    rng = np.random.default_rng(seed)
    r, c = np.mgrid[0:rows, 0:cols].astype(float)
    z = 600.0 + 1.2 * c  # rises to the east
    for _ in range(6):
        r0, c0 = rng.uniform(0, rows), rng.uniform(0, cols)
        z += rng.uniform(60, 160) * np.exp(-((r - r0) ** 2 + (c - c0) ** 2) / (2 * rng.uniform(6, 14) ** 2))
    return z


def _write_tif(path, z, crs="EPSG:4326", nodata=None, transform=None):
    t = transform or from_origin(W0, N0, RES, RES)
    with rasterio.open(path, "w", driver="GTiff", height=z.shape[0], width=z.shape[1], count=1,
                       dtype="float32", crs=crs, transform=t, nodata=nodata) as ds:
        ds.write(z.astype("float32"), 1)
    return path


def test_utm_zone():
    assert utm_crs(-3.7, 40.4) == "EPSG:32630"
    assert utm_crs(-84.2, 36.6) == "EPSG:32616"
    assert utm_crs(151.2, -33.9) == "EPSG:32756"


def test_geotiff_geographic_is_resampled_in_utm(tmp_path):
    z = _hills()
    f = _write_tif(tmp_path / "dem.tif", z)
    w = World.from_dem(f, (30.0, 30.0, 15.0))
    assert w.crs == "EPSG:32630"
    # ~ 108 px * 1" * cos(40.35) * 30.9 m = 2.54 km wide; 90 px = 2.78 km tall
    ext = w.bounds[:, 1] - w.bounds[:, 0]
    assert 2400 < ext[0] < 2560 and 2650 < ext[1] < 2790
    # the world's corner nodes map back inside the DEM, and elevations agree
    # with the raster's bilinear value at that lon/lat
    corners = w.to_world(np.array([[0, 0, 0], [w.shape[0] - 1, w.shape[1] - 1, 0]], float))
    ll = to_lonlat(w, corners)
    assert W0 < ll[0, 0] < ll[1, 0] < W0 + COLS * RES
    assert N0 - ROWS * RES < ll[0, 1] < ll[1, 1] < N0
    lon, lat = ll[1, :2]
    col = (lon - W0) / RES - 0.5
    row = (N0 - lat) / RES - 0.5
    r0, c0 = int(row), int(col)
    fr, fc = row - r0, col - c0
    bil = (z[r0, c0] * (1 - fr) * (1 - fc) + z[r0 + 1, c0] * fr * (1 - fc)
           + z[r0, c0 + 1] * (1 - fr) * fc + z[r0 + 1, c0 + 1] * fr * fc)
    assert w.terrain[-1, -1] == pytest.approx(bil, abs=0.05)
    # round trip lon/lat <-> world
    np.testing.assert_allclose(from_lonlat(w, ll), corners, atol=1e-6)
    # the vertical axis: one cell under the lowest ground, default ceiling +20 cells
    assert w.origin[2] <= w.terrain.min() - 15.0
    top = w.bounds[2, 1]
    assert w.terrain.max() + 15 * 19 <= top <= w.terrain.max() + 15 * 21


def test_array_dem_matches_the_geotiff(tmp_path):
    z = _hills()
    f = _write_tif(tmp_path / "dem.tif", z)
    a = World.from_dem(f, 40.0)
    b = World.from_dem(z, 40.0, crs="EPSG:4326",
                       bounds=(W0, N0 - ROWS * RES, W0 + COLS * RES, N0))
    assert a.shape == b.shape and a.crs == b.crs
    np.testing.assert_allclose(a.terrain, b.terrain, atol=1e-3)  # float32 file


def test_projected_dem_keeps_its_crs():
    z = _hills()
    w = World.from_dem(z, 30.0, 1200.0, crs="EPSG:32630",
                       transform=(30.0, 0, 440000.0, 0, -30.0, 4467000.0))
    assert w.crs == "EPSG:32630"
    assert w.origin[0] == pytest.approx(440015.0)  # first pixel centre
    np.testing.assert_allclose(w.terrain, z[::-1].T, atol=1e-9)  # same grid: no resampling
    assert w.bounds[2, 1] <= 1200.0


def test_nodata_is_refused_or_filled(tmp_path):
    z = _hills()
    z[40:44, 50:53] = -9999.0
    f = _write_tif(tmp_path / "hole.tif", z, nodata=-9999.0)
    with pytest.raises(WorldError, match=r"nodata/NaN under \d+ of .* lon -3\.\d+, lat 40\.\d+"):
        World.from_dem(f, 30.0)
    w = World.from_dem(f, 30.0, nodata="fill")
    assert np.all(np.isfinite(w.terrain)) and w.terrain.min() > 500
    # the heights written: on a UTM DEM at its own pixel size (nodes on the pixel centres)
    # the measured nodes are the file's pixels and each filled node takes the height of a
    # nearest measured node (brute force here, every tie allowed), marked in World.filled
    z[20:27, 30:33] = -9999.0  # a second hole, 7 x 3 pixels: most nodes have no GDAL value
    f = _write_tif(tmp_path / "hole_utm.tif", z, crs="EPSG:32630", nodata=-9999.0,
                   transform=from_origin(440000.0, 4467000.0, 30.0, 30.0))
    w = World.from_dem(f, 30.0, nodata="fill")
    assert w.crs == "EPSG:32630"
    src = z.astype(np.float32)[::-1].T.astype(float)  # [ix, iy], rows north -> south
    hole = src == -9999.0
    np.testing.assert_array_equal(w.filled, hole)
    np.testing.assert_allclose(w.terrain[~hole], src[~hole], atol=1e-6)
    measured = np.argwhere(~hole)
    for node in np.argwhere(hole):
        d = np.hypot(*(measured - node).T)
        nearest = measured[d <= d.min() + 1e-9]
        assert any(abs(w.terrain[tuple(node)] - src[tuple(m)]) < 1e-6 for m in nearest), node
    zn = _hills()
    zn[0:60, :] = np.nan
    with pytest.raises(WorldError, match="more than half"):
        World.from_dem(zn, 30.0, crs="EPSG:4326", bounds=(W0, N0 - ROWS * RES, W0 + COLS * RES, N0),
                       nodata="fill")


def test_wrong_or_missing_crs(tmp_path):
    z = _hills()
    # metres declared as degrees
    with pytest.raises(WorldError, match="not degrees.*world.crs"):
        World.from_dem(z, 30.0, crs="EPSG:4326", transform=(30.0, 0, 440000.0, 0, -30.0, 4467000.0))
    with pytest.raises(WorldError, match="no coordinate reference system"):
        World.from_dem(z, 30.0, bounds=(0, 0, 1, 1))
    f = _write_tif(tmp_path / "nocrs.tif", z, crs=None)
    with pytest.raises(WorldError, match="no coordinate reference system"):
        World.from_dem(f, 30.0)
    with pytest.raises(WorldError, match="unknown coordinate reference system"):
        World.from_dem(z, 30.0, crs="EPSG:999999", bounds=(0, 0, 1, 1))
    # US survey feet: not metres, so reprojected to the local UTM zone
    w = World.from_dem(z, 30.0, crs="EPSG:2228", transform=(100.0, 0, 6e6, 0, -100.0, 2e6))
    assert w.crs == "EPSG:32610" and "feet" in w.georef.reprojection.replace("foot", "feet")
    # 107 pixel-centre steps of 100 US ft = 3261 m across; the inner box of the (rotated)
    # footprint in UTM is a little narrower
    assert 3000 < w.bounds[0, 1] - w.bounds[0, 0] < 3262


def test_bad_arguments(tmp_path):
    z = _hills()
    b = (W0, N0 - ROWS * RES, W0 + COLS * RES, N0)
    with pytest.raises(InputError, match="cell_size"):
        World.from_dem(z, -5.0, crs="EPSG:4326", bounds=b)
    with pytest.raises(WorldError, match="ceiling"):
        World.from_dem(z, 30.0, 500.0, crs="EPSG:4326", bounds=b)
    with pytest.raises(InputError, match="transform= or bounds="):
        World.from_dem(z, 30.0, crs="EPSG:4326")
    with pytest.raises(InputError, match="cannot read"):
        World.from_dem(tmp_path / "missing.tif", 30.0)


def _plan_and_check(w, agl, start_ij, goal_ij, p1=0.5, p2=1.3, above=None):
    above = agl + 2 * w.spacing[2] if above is None else above

    def pt(i, j):
        return np.array([w.origin[0] + i * w.spacing[0], w.origin[1] + j * w.spacing[1],
                         w.terrain[i, j] + above])

    p = fm2uav.plan(w, pt(*start_ij), pt(*goal_ij), level=fm2uav.FlightLevel(agl=agl, p1=p1, p2=p2))
    r = flight_level_deviation(w, p.path, agl)
    assert r.inside_terrain == 0
    assert r.within >= 0.8, r.summary()
    return p, r


def test_geotiff_terrain_following(tmp_path):
    f = _write_tif(tmp_path / "dem.tif", _hills(seed=3))
    w = World.from_dem(f, (30.0, 30.0, 15.0))
    p, r = _plan_and_check(w, 150.0, (5, 5), (w.shape[0] - 6, w.shape[1] - 6))
    ll = p.lonlat()
    assert ll.shape == p.path.shape and np.all(np.abs(ll[:, 0] + 3.78) < 0.03)


def test_jacksboro_scenario_follows_the_terrain():
    sc = fm2uav.scenarios.get_scenario("jacksboro")
    w = sc.world
    assert w.crs == "EPSG:32616" and w.shape == (194, 206, 49)
    assert 236 <= w.terrain.min() and w.terrain.max() <= 1076
    ll = to_lonlat(w, np.stack([sc.start, sc.goal]))
    assert np.all((-84.414 < ll[:, 0]) & (ll[:, 0] < -84.078))
    assert np.all((36.446 < ll[:, 1]) & (ll[:, 1] < 36.733))
    for agl, p2 in ((300.0, 1.3), (150.0, 1.5)):
        p = fm2uav.plan(w, sc.start, sc.goal, level=fm2uav.FlightLevel(agl=agl, p1=0.5, p2=p2))
        r = flight_level_deviation(w, p.path, agl)
        assert r.inside_terrain == 0 and r.within >= 0.8, r.summary()
