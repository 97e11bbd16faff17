"""World.ground_height reads the source DEM, not the coarser planning grid."""

from __future__ import annotations

import numpy as np
import pytest

from fm2uav.world import World

from .rough_terrain import source_ground


def test_ground_height_is_the_source_dem_bilinear(rough_tif):
    w = World.from_dem(str(rough_tif), (250.0, 250.0, 25.0))  # pixels are ~70 x 93 m
    assert w.ground is not None and w.ground.pixel_m < 100
    rng = np.random.default_rng(1)
    b = w.bounds
    x = rng.uniform(b[0, 0], b[0, 1], 5000)
    y = rng.uniform(b[1, 0], b[1, 1], 5000)
    ours = w.ground_height(x, y)
    theirs = source_ground(rough_tif, w, x, y)
    assert np.max(np.abs(ours - theirs)) < 0.01
    # the planning grid alone would be far off between its nodes
    from scipy import ndimage
    grid = ndimage.map_coordinates(w.terrain, [(x - w.origin[0]) / 250.0,
                                               (y - w.origin[1]) / 250.0], order=1)
    assert np.max(np.abs(grid - theirs)) > 5.0


def test_ground_model_kept_when_the_dem_is_coarser(rough_tif):
    # the bilinear surface of a finer reprojected grid is not the DEM's own:
    # the model is kept at any cell size (acceptance, tests/e2e/test_acc_ground_coarse_dem.py)
    w = World.from_dem(str(rough_tif), (40.0, 40.0, 20.0))
    assert w.ground is not None and w.ground.pixel_m > 40.0
    rng = np.random.default_rng(2)
    b = w.bounds
    x = rng.uniform(b[0, 0], b[0, 1], 2000)
    y = rng.uniform(b[1, 0], b[1, 1], 2000)
    assert np.max(np.abs(w.ground_height(x, y) - source_ground(rough_tif, w, x, y))) < 0.01


def test_filled_ground_is_the_nearest_measured_pixel(tmp_path):
    """Deep in a nodata gap (the neighbour's bay of the country DEM, ``nodata="fill"``) the
    ground is the elevation of the nearest measured pixel, found here by brute force."""
    import rasterio

    from fm2uav.world.geo import from_lonlat

    from tests.world import dem_cases as dc

    tif = dc.country(tmp_path / "country.tif")
    w = World.from_dem(tif, (150.0, 150.0, 15.0), nodata="fill", agl=100.0)
    lonlat = np.array([[10.2, 45.66], [10.19, 45.64]])
    xy = from_lonlat(w, lonlat)
    assert w.ground_filled(xy[:, 0], xy[:, 1]).all()
    got = w.ground_height(xy[:, 0], xy[:, 1])
    with rasterio.open(tif) as ds:
        z = ds.read(1, masked=True)
        rows, cols = np.nonzero(~z.mask)
        for (lon, lat), g in zip(lonlat, got):
            r, c = ds.index(lon, lat)
            k = np.argmin((rows - r) ** 2 + (cols - c) ** 2)
            assert np.hypot(rows[k] - r, cols[k] - c) > 20  # far inside the gap
            assert g == pytest.approx(float(z[rows[k], cols[k]]), abs=0.5)
