"""DEMs as they come (issue 25 deliverable 1): topo-bathymetry on 2 km pixels, NaN holes,
float16, undeclared -32768 voids, a WKT-only southern CRS, 78°N, rotated geotransforms,
DEMs without CRS and rasters that are not elevation — each planned or refused in one line,
every ground height checked against an independent reading of the file."""

from __future__ import annotations

import json
import warnings

import numpy as np
import pytest
import rasterio
from pyproj import Geod, Transformer
from scipy import ndimage

import fm2uav
from fm2uav import World
from fm2uav.errors import InputError, WorldError
from fm2uav.planning import FlightLevel
from fm2uav.world.dem import GeodataWarning
from fm2uav.world.geo import crs_label, from_lonlat, to_lonlat

from . import dem_cases as dc


@pytest.fixture(scope="module")
def d(tmp_path_factory):
    root = tmp_path_factory.mktemp("as_they_come")
    names = ("topo_bathy", "nan_hole", "half_float", "srtm_voids", "wkt_south", "svalbard",
             "rgb", "palette", "complex_raster", "temperature")
    return {n: getattr(dc, n)(root / f"{n}.tif") for n in names} | {"dir": root}


def _sampled(tif, world, x, y, *, sea_level=None):
    """Independent bilinear reading of a GeoTIFF at world points (rasterio + pyproj)."""
    with rasterio.open(tif) as ds:
        z = ds.read(1, masked=True).astype(float).filled(np.nan)
        inv = ~ds.transform
        crs = ds.crs.to_wkt()
    if sea_level is not None:
        z = np.maximum(z, sea_level)
    px, py = Transformer.from_crs(world.crs, crs, always_xy=True).transform(x, y)
    col, row = inv * (np.asarray(px), np.asarray(py))
    return ndimage.map_coordinates(z, [np.asarray(row) - 0.5, np.asarray(col) - 0.5], order=1,
                                   mode="nearest")


def _inside(world, n=400, seed=0):
    rng = np.random.default_rng(seed)
    b = world.bounds
    return rng.uniform(b[0, 0], b[0, 1], n), rng.uniform(b[1, 0], b[1, 1], n)


# ------------------------------------------------------------------- topo-bathymetry

def test_topo_bathymetry_on_2km_pixels_plans_over_the_water(d):
    """The sea floor to -4000 m and islands rising 1000+ m over one 2 km pixel are terrain:
    with sea_level 0 the archipelago plans; the ground is the file clamped at 0."""
    with warnings.catch_warnings():
        warnings.simplefilter("error", GeodataWarning)
        w = World.from_dem(d["topo_bathy"], (2000.0, 2000.0, 20.0), sea_level=0.0, agl=120.0)
    assert w.terrain.min() == 0.0 and w.terrain.max() > 1000.0
    assert w.georef.sources[0].details["sea_nodes"] > 0.8 * w.terrain.size
    x, y = _inside(w)
    np.testing.assert_allclose(w.ground_height(x, y), _sampled(d["topo_bathy"], w, x, y,
                                                               sea_level=0.0), atol=1e-3)
    start = from_lonlat(w, [24.45, 38.95])
    goal = from_lonlat(w, [25.60, 38.30])
    p = fm2uav.plan(w, [*start, 120.0], [*goal, 120.0], level=FlightLevel(agl=120.0))
    agl = p.path[:, 2] - _sampled(d["topo_bathy"], w, p.path[:, 0], p.path[:, 1], sea_level=0)
    assert agl.min() > 100.0


def test_the_sea_floor_without_sea_level_is_kept_and_named(d):
    with pytest.warns(GeodataWarning, match=r"lowest -3\d\d\d\.\d m.*deeper than any dry land.*"
                                            r"world.sea_level: 0 \(CLI --sea-level 0\)"):
        w = World.from_dem(d["topo_bathy"], (4000.0, 4000.0, 200.0))
    assert w.terrain.min() < -3000.0  # nothing erased


def test_crop_comes_before_plausibility(tmp_path):
    """A data error outside world.bbox does not refuse the DEM; inside it does."""
    t, lon, lat = dc.lonlat_grid(dc.BATHY_WEST, dc.BATHY_NORTH, dc.BATHY_RES, 80, 100)
    z = dc.bathy_ground(lon, lat)
    z[5, 90] = 9800.0 + z[5, 90] * 0  # far north-east: above any mountain
    p = dc.write(tmp_path / "glitch.tif", z, "EPSG:4326", t)
    with pytest.raises(WorldError, match=r"above 9000 m"):
        World.from_dem(p, 4000.0, sea_level=0.0)
    w = World.from_dem(p, 2000.0, sea_level=0.0, bbox=(24.2, 38.3, 25.2, 39.0))
    assert w.terrain.max() < 2000.0


def test_sentinels_are_nodata_before_the_sea_level_clamp(d):
    """-32768 voids on land stay nodata with sea_level 0: never turned into sea."""
    with pytest.warns(GeodataWarning, match=r"pixel\(s\) of -32768"):
        with pytest.raises(WorldError, match=r"nodata/NaN under \d+ .*of -32768"):
            World.from_dem(d["srtm_voids"], 100.0, sea_level=0.0)
    with pytest.warns(GeodataWarning, match=r"-32768"):
        w = World.from_dem(d["srtm_voids"], 100.0, sea_level=0.0, nodata="fill")
    assert w.filled.any() and w.terrain[w.filled].min() > 1000.0  # filled from the land
    assert w.georef.sources[0].details["undeclared_nodata"][0]["value"] == -32768.0


# --------------------------------------------------------------------- NaN, float16

def test_nan_nodata_is_refused_or_filled_and_serialises(d):
    with pytest.raises(WorldError, match=r"nodata/NaN under \d+ of \d+ world nodes, first at node"
                                         r" .* = lon -105\.\d+, lat 39\.\d+"):
        World.from_dem(d["nan_hole"], 20.0)
    w = World.from_dem(d["nan_hole"], 20.0, nodata="fill")
    assert w.filled.sum() > 0
    doc = json.dumps(w.georef.as_dict(), allow_nan=False)  # the old exit-70 crash
    assert '"nodata": "nan"' in doc
    x, y = _inside(w, seed=3)
    known = ~w.ground_filled(x, y)
    np.testing.assert_allclose(w.ground_height(x[known], y[known]),
                               _sampled(d["nan_hole"], w, x[known], y[known]), atol=1e-3)


def test_float16_elevations_are_read_as_stored_and_their_rounding_said(d):
    with pytest.warns(GeodataWarning, match=r"half-precision floats \(float16\): elevations near "
                                            r"\d+ m are rounded to steps of 2 m"):
        w = World.from_dem(d["half_float"], 30.0)
    assert w.georef.sources[0].details["dtype"] == "float16"
    with rasterio.open(d["half_float"]) as ds:
        z = ds.read(1)
    assert np.all(z == z.astype(np.float16))  # the file holds float16 values
    x, y = _inside(w, seed=4)
    np.testing.assert_allclose(w.ground_height(x, y), _sampled(d["half_float"], w, x, y),
                               atol=1e-3)


# ------------------------------------------------------------------ CRSs and places

def test_a_wkt_only_southern_crs_is_used_quietly_and_named_short(d):
    with warnings.catch_warnings(record=True) as seen:
        warnings.simplefilter("always")
        w = World.from_dem(d["wkt_south"], 30.0)
    assert not seen, [str(s.message) for s in seen]  # no pyproj/rasterio warning at all
    assert w.georef.epsg is None
    assert any(k in w.crs for k in ("PROJCRS", "PROJCS", "BOUNDCRS"))  # the file's own WKT
    name = crs_label(w.crs)
    assert name.startswith('"Custom UTM 19 South') and "WKT without an EPSG code" in name
    assert len(name) < 100 and "BOUNDCRS" not in w.georef.comment()
    assert w.georef.comment().startswith("crs=wkt-sha256:")
    # lon/lat through the file's own WKT (its datum shift included), independently
    c = w.to_world(np.array([10.0, 20.0, 0.0]))
    ll = to_lonlat(w, c)
    with rasterio.open(d["wkt_south"]) as ds:
        lon, lat = Transformer.from_crs(ds.crs.to_wkt(), "EPSG:4326",
                                        always_xy=True).transform(c[0], c[1])
    assert abs(ll[0] - lon) < 1e-9 and abs(ll[1] - lat) < 1e-9 and -34 < lat < -33


def test_78_degrees_north(d):
    w = World.from_dem(d["svalbard"], 50.0)
    assert w.crs == "EPSG:32633"
    b = w.bounds
    ll = to_lonlat(w, [[b[0, 0], b[1, 0], 0], [b[0, 1], b[1, 0], 0], [b[0, 0], b[1, 1], 0]])
    geod = Geod(ellps="WGS84")
    assert geod.inv(*ll[0, :2], *ll[1, :2])[2] == pytest.approx(b[0, 1] - b[0, 0], rel=0.005)
    assert geod.inv(*ll[0, :2], *ll[2, :2])[2] == pytest.approx(b[1, 1] - b[1, 0], rel=0.005)
    x, y = _inside(w, seed=5)
    np.testing.assert_allclose(w.ground_height(x, y), _sampled(d["svalbard"], w, x, y),
                               atol=1e-3)


@pytest.mark.parametrize("degrees", [20.0, 90.0, 45.0])
def test_rotated_geotransforms(tmp_path, degrees):
    p = dc.rotated(tmp_path / "rot.tif", degrees)
    w = World.from_dem(p, 30.0)
    assert w.georef.sources[0].details["rotation_deg"] == pytest.approx(degrees, abs=1e-6)
    x, y = _inside(w, seed=6)
    np.testing.assert_allclose(w.ground_height(x, y), _sampled(p, w, x, y), atol=1e-3)
    assert not w.filled.any()  # the map lies inside the rotated footprint
    ext = w.bounds[:2, 1] - w.bounds[:2, 0]
    assert ext.min() > 1500.0  # 3.6 km square: a real box, not a sliver
    # a bbox reads the window of a rotated raster too (rasterio's from_bounds refuses it)
    b = w.bounds
    ll = to_lonlat(w, [[b[0, 0], b[1, 0], 0], [b[0, 1], b[1, 1], 0]])
    box = (ll[0, 0] + 0.003, ll[0, 1] + 0.003, ll[1, 0] - 0.003, ll[1, 1] - 0.003)
    w2 = World.from_dem(p, 30.0, bbox=box)
    assert w2.terrain.size < w.terrain.size
    x, y = _inside(w2, seed=7)
    np.testing.assert_allclose(w2.ground_height(x, y), _sampled(p, w2, x, y), atol=1e-3)


def test_world_crs_is_honoured_for_a_dem_without_one(tmp_path):
    from fm2uav.world.load import WorldSpec, load_world

    z = dc.hills(np.zeros((60, 80)), np.zeros((60, 80))) + np.arange(80) * 0.5
    p = dc.write(tmp_path / "nocrs.tif", z, None, rasterio.transform.from_origin(5e5, 4.5e6,
                                                                                 30, 30))
    with pytest.raises(ValueError, match=r"no coordinate reference system.*world.crs \(CLI --crs"):
        WorldSpec(dem=str(p))
    w = load_world(WorldSpec(dem=str(p), crs="EPSG:32630", cell_size=30.0))
    assert w.crs == "EPSG:32630"
    assert w.georef.sources[0].crs_rule == "given (world.crs / --crs)"


@pytest.mark.parametrize("name, says", [("rgb", "RGB colour image"),
                                        ("palette", "colour-indexed"),
                                        ("complex_raster", "complex complex64"),
                                        ("temperature", "unit 'degC'")])
def test_rasters_that_are_not_elevation_are_refused(d, name, says):
    from fm2uav.world.load import WorldSpec

    with pytest.raises(InputError, match=says):
        World.from_dem(d[name], 30.0)
    with pytest.raises(ValueError, match=says):
        WorldSpec(dem=str(d[name]))


def test_a_hole_smaller_than_a_cell_is_unknown_ground_too(tmp_path):
    """A 2 x 2-pixel NaN hole between the world's 60 m nodes: nodata: error refuses it (the
    ground model would fill it silently otherwise), fill reports it where the path crosses."""
    from fm2uav.analysis.known_ground import ground_split
    from fm2uav.world.ground import has_unknown_ground

    rows, cols = 120, 150
    t = rasterio.transform.from_origin(500000.0, 4500000.0, 10.0, 10.0)
    c, r = np.meshgrid(np.arange(cols) + 0.5, np.arange(rows) + 0.5)
    z = dc.hills((c - 75) / 100, (60 - r) / 100, seed=2)
    z[62:64, 74:76] = np.nan  # pixel centres 745..755 m east, 615..625 m south of the top
    p = dc.write(tmp_path / "lidar.tif", z, "EPSG:32630", t, nodata=np.nan)
    with pytest.raises(WorldError, match=r"4 nodata/NaN pixel\(s\) inside the map.*between the "
                                         r"world's nodes.*world.nodata: fill"):
        World.from_dem(p, 60.0)
    w = World.from_dem(p, 60.0, nodata="fill")
    assert not w.filled.any() and has_unknown_ground(w)
    assert w.georef.sources[0].details["filled_pixels_between_nodes"] == 4
    y = 4500000.0 - 620.0
    path = np.column_stack([np.linspace(500100, 501400, 60), np.full(60, y), np.full(60, 900.0)])
    g = ground_split(w, path, path[:, 2] - w.ground_height(path[:, 0], path[:, 1]))
    over, _ = dc.length_over(path, lambda q: ~dc.measured_mask(p, w, q), step=0.05)
    assert over > 10.0 and g["filled"]["length_m"] == pytest.approx(over, abs=0.2)
