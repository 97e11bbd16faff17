"""Acceptance: AGL is measured on the source DEM even when its pixels are coarser
than the planning grid (a 0.01 deg DEM planned on its default, rounded-down cell)."""

from __future__ import annotations

import numpy as np
import pytest

rasterio = pytest.importorskip("rasterio")


def _write_rough_dem(path, seed=3):
    from rasterio.transform import from_origin
    from scipy.ndimage import gaussian_filter

    rng = np.random.default_rng(seed)
    z = gaussian_filter(rng.standard_normal((30, 40)), 1.5)
    z = (z - z.min()) / (z.max() - z.min()) * 1200.0
    with rasterio.open(path, "w", driver="GTiff", width=40, height=30, count=1,
                       dtype="float32", crs="EPSG:4326",
                       transform=from_origin(10.0, 45.3, 0.01, 0.01)) as dst:
        dst.write(z.astype("float32"), 1)


def _source_bilinear(path, lon, lat):
    with rasterio.open(path) as src:
        z = src.read(1).astype(float)
        col, row = ~src.transform * (lon, lat)
    from scipy import ndimage
    return ndimage.map_coordinates(z, [np.asarray(row) - 0.5, np.asarray(col) - 0.5], order=1)


def test_ground_height_is_the_source_dem_when_the_dem_is_coarser(tmp_path):
    from pyproj import Transformer

    from fm2uav.world import World

    tif = tmp_path / "coarse.tif"
    _write_rough_dem(tif)
    w = World.from_dem(str(tif), (500.0, 500.0, 20.0))  # pixels ~787 x 1111 m
    assert w.ground is not None and w.ground.pixel_m > 500.0
    rng = np.random.default_rng(1)
    lon = rng.uniform(10.05, 10.35, 3000)
    lat = rng.uniform(45.05, 45.25, 3000)
    x, y = Transformer.from_crs("EPSG:4326", w.crs, always_xy=True).transform(lon, lat)
    ours = np.asarray(w.ground_height(np.asarray(x), np.asarray(y)))
    theirs = _source_bilinear(tif, lon, lat) - 0.0
    # world z is metres above the datum the DEM uses (no offset for this file)
    assert np.max(np.abs(ours - theirs)) < 0.05
