"""fm2uav.app.terrain: the DEM as shaded-relief tiles, contours and point heights (rio-tiler)."""

from __future__ import annotations

import io

import morecantile
import numpy as np
import pytest
from PIL import Image

from fm2uav.app.terrain import Terrain

from .dem import make_dem

TMS = morecantile.tms.get("WebMercatorQuad")


@pytest.fixture(scope="module")
def dems(tmp_path_factory):
    root = tmp_path_factory.mktemp("terrain")
    west = make_dem(root / "west.tif")
    east = make_dem(root / "east.tif", west=605400.0)   # the next 5.4 km east
    return west, east


def test_info_gives_the_bounds_in_lonlat_and_the_elevation_range(dems):
    import rasterio
    from rasterio.warp import transform_bounds

    t = Terrain([str(dems[0])])
    with rasterio.open(dems[0]) as ds:
        expect = transform_bounds(ds.crs, "EPSG:4326", *ds.bounds)
        z = ds.read(1)
    info = t.info()
    assert info["bounds"] == pytest.approx(expect, abs=1e-4)
    lo, hi = info["elevation"]
    assert lo == pytest.approx(z.min(), abs=1.0) and hi == pytest.approx(z.max(), abs=2.0)


def test_a_tile_is_shaded_relief_inside_and_none_outside(dems):
    t = Terrain([str(dems[0])])
    w, s, e, n = t.bounds
    tile = TMS.tile((w + e) / 2, (s + n) / 2, 14)
    img = np.asarray(Image.open(io.BytesIO(t.tile_png(tile.x, tile.y, tile.z))))
    assert img.shape == (256, 256, 4)
    assert (img[..., 3] == 255).mean() > 0.5           # mostly inside the DEM
    assert img[..., :3].std() > 3                       # relief, not one flat colour
    far = TMS.tile(w - 1.0, s, 14)
    assert t.tile_png(far.x, far.y, far.z) is None


def test_two_files_make_one_mosaic(dems):
    both = Terrain([str(d) for d in dems])
    one = Terrain([str(dems[0])])
    assert both.bounds[2] > one.bounds[2] + 0.05
    tile = TMS.tile(one.bounds[2], (one.bounds[1] + one.bounds[3]) / 2, 13)  # on the seam
    img = np.asarray(Image.open(io.BytesIO(both.tile_png(tile.x, tile.y, tile.z))))
    cols = np.where((img[..., 3] == 255).any(axis=0))[0]
    half = np.asarray(Image.open(io.BytesIO(one.tile_png(tile.x, tile.y, tile.z))))
    assert (img[..., 3] == 255).sum() > (half[..., 3] == 255).sum()
    assert len(cols) > 0


def test_height_is_the_dem_value_and_none_off_the_map(dems):
    import rasterio

    t = Terrain([str(dems[0])])
    with rasterio.open(dems[0]) as ds:
        x, y = ds.xy(40, 70)                           # centre of row 40, column 70
        z = float(ds.read(1)[40, 70])
        from pyproj import Transformer

        lon, lat = Transformer.from_crs(ds.crs, "EPSG:4326", always_xy=True).transform(x, y)
    assert t.height(lon, lat) == pytest.approx(z, abs=0.01)
    assert t.height(lon + 1.0, lat) is None


def test_contours_follow_the_interval(dems):
    t = Terrain([str(dems[0])])
    c = t.contours()
    assert c["interval"] == 20.0                       # ~190 m of relief: 10 to 20 lines
    levels = [f["properties"]["elevation"] for f in c["features"]]
    assert levels == sorted(levels) and all(v % 20 == 0 for v in levels)
    assert 8 <= len(levels) <= 20
    assert any(f["properties"]["index"] for f in c["features"])
    w, s, e, n = t.bounds
    for f in c["features"]:
        pts = np.array([p for line in f["geometry"]["coordinates"] for p in line])
        assert (pts[:, 0] >= w - 1e-3).all() and (pts[:, 0] <= e + 1e-3).all()
        assert (pts[:, 1] >= s - 1e-3).all() and (pts[:, 1] <= n + 1e-3).all()


def test_tiles_are_cached(dems, monkeypatch):
    t = Terrain([str(dems[0])])
    w, s, e, n = t.bounds
    tile = TMS.tile((w + e) / 2, (s + n) / 2, 13)
    first = t.tile_png(tile.x, tile.y, tile.z)
    monkeypatch.setattr(t, "_render", lambda *a: pytest.fail("rendered twice"))
    assert t.tile_png(tile.x, tile.y, tile.z) == first
