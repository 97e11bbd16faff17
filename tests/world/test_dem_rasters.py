"""Rasters (issue 12 part 2): any GDAL raster (GeoTIFF in several CRSs, VRT, HGT, tiles),
masks, scale/offset, reprojection to UTM with true lengths, bbox crop, sea level,
filled nodata, undeclared nodata, lon/lat grids (xarray layout), the Jacksboro npz."""

from __future__ import annotations

import warnings

import numpy as np
import pytest
import rasterio
from pyproj import Geod, Transformer
from rasterio.transform import from_origin

import fm2uav
from fm2uav import World
from fm2uav.errors import InputError, WorldError
from fm2uav.planning import FlightLevel
from fm2uav.world.dem import GeodataWarning, from_lonlat_grid
from fm2uav.world.geo import from_lonlat, to_lonlat

from . import geodata_data as gd

BBOX = (10.05, 45.54, 10.20, 45.66)  # inside the border ellipse
CELL = (250.0, 250.0, 25.0)


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    d = tmp_path_factory.mktemp("dem")
    return {"4326": gd.dem_4326(d / "country_4326.tif"),
            "4326_full": gd.dem_4326(d / "full_4326.tif", border=False),
            "3857": gd.dem_3857(d / "country_3857.tif"),
            "utm": gd.dem_utm(d / "country_32632.tif"),
            "dir": d}


def _point(world, lonlat, agl):
    x, y = from_lonlat(world, [lonlat[0], lonlat[1], 0.0])[:2]
    return np.array([x, y, world.ground_height(x, y) + agl])


def _plan(world, agl=100.0):
    return fm2uav.plan(world, _point(world, gd.START, agl), _point(world, gd.GOAL, agl),
                       level=FlightLevel(agl=agl))


@pytest.fixture(scope="module")
def worlds(files):
    with warnings.catch_warnings():
        warnings.simplefilter("error", GeodataWarning)
        return {k: World.from_dem(files[k], CELL, bbox=BBOX, agl=100.0)
                for k in ("4326", "3857", "utm")}


def test_every_crs_ends_in_utm_with_true_lengths(worlds):
    geod = Geod(ellps="WGS84")
    true = geod.inv(*gd.START, *gd.GOAL)[2]
    for k, w in worlds.items():
        assert w.crs == "EPSG:32632", k
        assert w.georef.epsg == 32632 and w.georef.scale_error < 0.005
        a = from_lonlat(w, [*gd.START, 0.0])
        b = from_lonlat(w, [*gd.GOAL, 0.0])
        assert np.hypot(*(b - a)[:2]) == pytest.approx(true, rel=0.005), k
    assert "distorts lengths" in worlds["3857"].georef.reprojection
    assert "geographic" in worlds["4326"].georef.reprojection
    assert "kept" in worlds["utm"].georef.reprojection


def test_same_terrain_from_every_crs(worlds):
    ref = worlds["4326"]
    for k in ("3857", "utm"):
        w = worlds[k]
        assert w.shape[:2] == ref.shape[:2] and w.origin[:2] == pytest.approx(ref.origin[:2])
        # different rasters of one terrain (3 arc-s / 100 m / 75 m pixels): a few metres apart
        assert np.abs(w.terrain - ref.terrain).max() < 12.0, k
        assert np.abs(w.terrain - ref.terrain).mean() < 1.5, k


def test_web_mercator_and_lonlat_path_lengths_agree(worlds):
    lengths = {k: _plan(w).length for k, w in worlds.items()}
    for k in ("3857", "utm"):
        assert lengths[k] == pytest.approx(lengths["4326"], rel=0.01), lengths


def test_web_mercator_kept_as_is_would_be_wrong(files):
    # the pre-geodata reading (metres of EPSG:3857 taken as ground metres) is 40 % off here
    with rasterio.open(files["3857"]) as ds:
        k = (ds.bounds.right - ds.bounds.left)
    fwd = Transformer.from_crs("EPSG:4326", "EPSG:3857", always_xy=True)
    (x0, x1), _ = fwd.transform([gd.W, gd.E], [gd.LAT_C, gd.LAT_C])
    ground = Geod(ellps="WGS84").inv(gd.W, gd.LAT_C, gd.E, gd.LAT_C)[2]
    assert (x1 - x0) / ground > 1.39 and k > 0


def test_nodata_outside_the_border(files):
    with pytest.raises(WorldError, match=r"nodata/NaN under \d+ .*world.bbox \(CLI --bbox "
                                         r"W,S,E,N\).*world.nodata: fill \(CLI --nodata fill\)"):
        World.from_dem(files["4326"], 400.0)
    w = World.from_dem(files["4326"], 400.0, nodata="fill")
    assert w.filled is not None and 0 < w.filled.sum() < w.filled.size / 2
    assert w.georef.sources[0].details["filled_nodes"] == int(w.filled.sum())
    # corners are outside the ellipse, the centre inside
    assert w.filled[0, 0] and w.filled[-1, -1] and not w.filled[w.shape[0] // 2, w.shape[1] // 2]
    # a bbox inside the border needs no fill
    assert not World.from_dem(files["4326"], 400.0, bbox=BBOX).filled.any()


def test_bbox_crops_and_reads_a_window(files):
    full = World.from_dem(files["4326_full"], 500.0)
    small = World.from_dem(files["4326_full"], 500.0, bbox=(10.1, 45.55, 10.15, 45.6))
    ext = small.bounds[:2, 1] - small.bounds[:2, 0]
    assert 3300 < ext[0] < 4400 and 5000 < ext[1] < 6000
    ll = to_lonlat(small, small.to_world(np.array([[0, 0, 0], [small.shape[0] - 1,
                                                               small.shape[1] - 1, 0]], float)))
    assert 10.095 < ll[0, 0] and ll[1, 0] < 10.155 and 45.545 < ll[0, 1] and ll[1, 1] < 45.605
    # same ground as the full world at the same place
    x, y = small.to_world(np.array([3.0, 4.0, 0.0]))[:2]
    assert small.ground_height(x, y) == pytest.approx(full.ground_height(x, y), abs=2.0)
    with pytest.raises(InputError, match=r"does not overlap the DEM.*world.bbox \(CLI --bbox"):
        World.from_dem(files["4326_full"], 500.0, bbox=(12.0, 45.0, 12.1, 45.1))
    with pytest.raises(InputError, match="W,S,E,N"):
        World.from_dem(files["4326_full"], 500.0, bbox=(10.2, 45.5, 10.1, 45.6))


def test_tiles_vrt_and_hgt(files, tmp_path):
    src = files["4326_full"]
    with rasterio.open(src) as ds:
        z = ds.read(1)
        t = ds.transform
        prof = ds.profile
    h = z.shape[1] // 2
    parts = []
    for k, (c0, c1) in enumerate(((0, h), (h, z.shape[1]))):
        p = tmp_path / f"tile{k}.tif"
        with rasterio.open(p, "w", **{**prof, "width": c1 - c0,
                                      "transform": t * rasterio.Affine.translation(c0, 0)}) as o:
            o.write(z[:, c0:c1], 1)
        parts.append(p)
    whole = World.from_dem(src, 500.0)
    tiled = World.from_dem(parts, 500.0)
    assert tiled.shape == whole.shape
    np.testing.assert_allclose(tiled.terrain, whole.terrain, atol=1e-6)
    assert [s.role for s in tiled.georef.sources] == ["dem", "dem"]
    # a VRT over the two tiles
    vrt = tmp_path / "mosaic.vrt"
    bands = "".join(
        f"<SimpleSource><SourceFilename relativeToVRT='1'>{p.name}</SourceFilename>"
        f"<SourceBand>1</SourceBand><SrcRect xOff='0' yOff='0' xSize='{c1 - c0}' "
        f"ySize='{z.shape[0]}'/><DstRect xOff='{c0}' yOff='0' xSize='{c1 - c0}' "
        f"ySize='{z.shape[0]}'/></SimpleSource>"
        for p, (c0, c1) in zip(parts, ((0, h), (h, z.shape[1]))))
    vrt.write_text(
        f"<VRTDataset rasterXSize='{z.shape[1]}' rasterYSize='{z.shape[0]}'>"
        f"<SRS>EPSG:4326</SRS><GeoTransform>{t.c}, {t.a}, 0, {t.f}, 0, {t.e}</GeoTransform>"
        f"<VRTRasterBand dataType='Float32' band='1'>{bands}</VRTRasterBand></VRTDataset>")
    np.testing.assert_allclose(World.from_dem(vrt, 500.0).terrain, whole.terrain, atol=1e-6)
    # an SRTM .hgt tile (1201 x 1201 big-endian int16, -32768 = void)
    hgt = tmp_path / "N45E010.hgt"
    lon = 10.0 + np.arange(1201) / 1200.0
    lat = 46.0 - np.arange(1201) / 1200.0
    q = gd.terrain(*np.meshgrid(lon, lat)).round().astype(">i2")
    q[600:603, 100:104] = -32768
    q.tofile(hgt)
    w = World.from_dem(hgt, 500.0, bbox=BBOX, nodata="fill")
    assert "SRTM" in w.georef.vertical and w.georef.vertical_assumed
    assert w.georef.sources[0].details["driver"] == "SRTMHGT"
    ref = World.from_dem(files["4326_full"], 500.0, bbox=BBOX)
    assert w.shape == ref.shape and np.abs(w.terrain - ref.terrain).max() < 3.0


def test_masks_alpha_scale_offset_and_vertical_crs(tmp_path):
    tr = from_origin(10.0, 45.7, 1 / 1200, 1 / 1200)
    rows, cols = 200, 240
    lon = 10.0 + (np.arange(cols) + 0.5) / 1200
    lat = 45.7 - (np.arange(rows) + 0.5) / 1200
    z = gd.terrain(*np.meshgrid(lon, lat))
    hole = (slice(90, 110), slice(100, 130))
    # 1) internal mask band
    p = tmp_path / "mask.tif"
    with rasterio.open(p, "w", driver="GTiff", height=rows, width=cols, count=1,
                       dtype="float32", crs="EPSG:4326", transform=tr) as ds:
        ds.write(z.astype("float32"), 1)
        m = np.full((rows, cols), 255, np.uint8)
        m[hole] = 0
        ds.write_mask(m)
    # 2) alpha band: GDAL masks UInt16 alpha itself, float alpha is read by us
    files = [p]
    for dtype in ("uint16", "float32"):
        pa = tmp_path / f"alpha_{dtype}.tif"
        with rasterio.open(pa, "w", driver="GTiff", height=rows, width=cols, count=2,
                           dtype=dtype, crs="EPSG:4326", transform=tr, photometric="MINISBLACK",
                           alpha="YES") as ds:
            ds.write(z.astype(dtype), 1)
            a = np.full((rows, cols), 255, dtype)
            a[hole] = 0
            ds.write(a, 2)
        files.append(pa)
    for f in files:
        with pytest.raises(WorldError, match="nodata/NaN under"):
            World.from_dem(f, 200.0)
        assert World.from_dem(f, 200.0, nodata="fill").filled.any()
    # 3) int16 decimetres with scale/offset, and a compound CRS with EGM96 heights
    ps = tmp_path / "scaled.tif"
    from pyproj import CRS

    with rasterio.open(ps, "w", driver="GTiff", height=rows, width=cols, count=1,
                       dtype="int16", transform=tr,
                       crs=rasterio.crs.CRS.from_wkt(CRS("EPSG:4326+5773").to_wkt())) as ds:
        ds.scales, ds.offsets = (0.1,), (100.0,)
        ds.write(np.round((z - 100.0) / 0.1).astype("int16"), 1)
    ref = World.from_dem(z, 200.0, crs="EPSG:4326", transform=tuple(tr)[:6])
    w = World.from_dem(ps, 200.0)
    np.testing.assert_allclose(w.terrain, ref.terrain, atol=0.06)
    assert w.georef.vertical_crs == "EGM96 height" and not w.georef.vertical_assumed
    assert "EGM96" in w.georef.vertical and w.crs == "EPSG:32632"


@pytest.mark.parametrize("value", [-9999.0, -32768.0, 32767.0])
def test_undeclared_nodata_is_found_said_and_left_to_the_nodata_rule(tmp_path, value):
    """Sentinels the file does not declare are nodata (issue 25): said once in a warning that
    names the value and how to declare it; world.nodata then decides (error names them too)."""
    z = gd.terrain(*np.meshgrid(10.0 + np.arange(120) / 1200, 45.6 - np.arange(100) / 1200))
    z[40:45, 50:60] = value
    p = gd._write(tmp_path / "undeclared.tif", z, "EPSG:4326", from_origin(10, 45.6, 1 / 1200,
                                                                           1 / 1200))
    with pytest.warns(GeodataWarning, match=rf"50 pixel\(s\) of {value:g} .*nodata the file does "
                                            rf"not declare.*world.nodata_value: {value:g}, CLI "
                                            rf"--nodata-value {value:g}"):
        with pytest.raises(WorldError, match=rf"nodata/NaN under \d+ .*among the gaps: 50 "
                                             rf"pixel\(s\) of {value:g}"):
            World.from_dem(p, 100.0)
    with pytest.warns(GeodataWarning, match="nodata the file does not declare"):
        w = World.from_dem(p, 100.0, nodata="fill")
    assert w.filled.any() and w.terrain.max() < 2000
    assert w.georef.sources[0].details["undeclared_nodata"] == [{"value": value, "pixels": 50}]
    # declared by the user: no warning, the same world
    with warnings.catch_warnings():
        warnings.simplefilter("error", GeodataWarning)
        w2 = World.from_dem(p, 100.0, nodata_value=value, nodata="fill")
    np.testing.assert_array_equal(w2.terrain, w.terrain)
    # the heights written into the filled columns come from the measured ground around them
    # (GDAL's bilinear value from the valid pixels, else the nearest measured node): never
    # outside the range of the measured nodes within four cells
    f = w.filled
    for i, j in np.argwhere(f):
        nb = (slice(max(i - 4, 0), i + 5), slice(max(j - 4, 0), j + 5))
        around = w.terrain[nb][~f[nb]]
        assert around.size and around.min() - 1e-6 <= w.terrain[i, j] <= around.max() + 1e-6


def test_sea_level_and_the_below_zero_warning(tmp_path):
    f = gd.topo_bathy(tmp_path / "coast.tif")
    with pytest.warns(GeodataWarning, match=r"below 0 m.*world.sea_level: 0 \(CLI --sea-level 0\)"):
        raw = World.from_dem(f, CELL, bbox=BBOX, agl=100.0)
    assert raw.terrain.min() < -50
    with warnings.catch_warnings():
        warnings.simplefilter("error", GeodataWarning)
        w = World.from_dem(f, CELL, bbox=BBOX, sea_level=0.0, agl=100.0)
    assert w.terrain.min() == 0.0 and "sea_level = 0" in w.georef.vertical
    assert w.georef.sources[0].details["sea_nodes"] > 0
    p = _plan(w, agl=100.0)
    assert p.path[:, 2].min() >= 0.0 + 50.0  # flown over the water surface, never below it
    ground = w.ground_height(p.path[:, 0], p.path[:, 1])
    assert ground.min() == 0.0  # the route does cross the sea


def test_ceiling_follows_the_requested_height(files):
    w = World.from_dem(files["4326"], CELL, bbox=BBOX, agl=300.0)
    assert w.bounds[2, 1] >= w.terrain.max() + 300.0 + 10 * CELL[2] - 1e-6
    hmax = w.terrain.max()
    with pytest.raises(WorldError, match=r"world.ceiling \(--ceiling\) = 1350 m leaves no room "
                                         r"to fly 120 m"):
        assert hmax + 25 < 1350 < hmax + 120
        World.from_dem(files["4326"], CELL, 1350.0, bbox=BBOX, agl=120.0)


def test_lonlat_grid_0_360_south_up_and_mercator_rows(files):
    ref = World.from_dem(files["4326_full"], 400.0, bbox=BBOX)
    # longitudes in 0..360 (a grid east of the antimeridian would be > 180), rows south-up
    lon = np.arange(9.9, 10.35, 1 / 600)
    lat = np.arange(45.45, 45.75, 1 / 600)
    z = gd.terrain(*np.meshgrid(lon, lat))  # z[i_lat, i_lon], lat increasing (south-up)
    w = from_lonlat_grid(z, lon, lat, 400.0, bbox=BBOX)
    assert w.crs == ref.crs and w.shape == ref.shape
    assert np.abs(w.terrain - ref.terrain).max() < 6.0
    # a grid across lon 0 given in 0..360 (359.9 .. 360, 0 .. 0.5): wrapped to -0.1 .. 0.5
    lon2 = np.arange(-0.1, 0.5, 1 / 600) % 360.0
    lat2 = lat[::-1]  # north-up this time
    z2 = gd.terrain(*np.meshgrid(np.where(lon2 > 180, lon2 - 360, lon2) + 10.2, lat2))
    w2 = World.from_lonlat_grid(z2, lon2, lat2, 400.0)
    assert w2.crs == "EPSG:32631"  # centred on lon 0
    # rows regular in Web Mercator y (irregular in latitude)
    merc = Transformer.from_crs("EPSG:4326", "EPSG:3857", always_xy=True)
    inv = Transformer.from_crs("EPSG:3857", "EPSG:4326", always_xy=True)
    y0, y1 = merc.transform([10, 10], [45.45, 45.75])[1]
    latm = np.asarray(inv.transform(np.full(200, 10.0), np.linspace(y0, y1, 200))[1])
    zm = gd.terrain(*np.meshgrid(lon, latm))
    wm = from_lonlat_grid(zm, lon, latm, 400.0, bbox=BBOX)
    assert wm.shape == ref.shape and np.abs(wm.terrain - ref.terrain).max() < 8.0
    with pytest.raises(InputError, match=r"z\.T"):
        from_lonlat_grid(z.T, lon, lat, 400.0)


def test_jacksboro_npz_through_the_lonlat_grid():
    from matplotlib import cbook

    from fm2uav.scenarios.jacksboro import jacksboro_world

    d = cbook.get_sample_data("jacksboro_fault_dem.npz")
    z = np.asarray(d["elevation"], float)
    rows, cols = z.shape
    # ymin is the north edge in this file (see fm2uav.scenarios.jacksboro)
    rx = (float(d["xmax"]) - float(d["xmin"])) / cols
    ry = (float(d["ymin"]) - float(d["ymax"])) / rows
    lon = float(d["xmin"]) + (np.arange(cols) + 0.5) * rx
    lat = float(d["ymin"]) - (np.arange(rows) + 0.5) * ry  # north -> south
    w = World.from_lonlat_grid(z, lon, lat, (150.0, 150.0, 30.0))
    ref = jacksboro_world()
    assert w.crs == ref.crs == "EPSG:32616" and w.shape[:2] == ref.shape[:2]
    np.testing.assert_allclose(w.terrain, ref.terrain, atol=1e-6)
