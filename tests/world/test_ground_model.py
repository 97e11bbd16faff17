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


def _brute_bulge(w, a, b, n=40001):
    t = np.linspace(0.0, 1.0, n)
    out = []
    for p, q in zip(a, b):
        xy = p[None, :] + t[:, None] * (q - p)[None, :]
        g = w.ground_height(xy[:, 0], xy[:, 1])
        lin = g[0] + t * (g[-1] - g[0])
        out.append((max((g - lin).max(), 0.0), max((lin - g).max(), 0.0)))
    return np.array(out)


@pytest.mark.parametrize("kind", ["nodes", "dem in lon/lat", "two dems"])
def test_ground_bulge_is_the_exact_rise_and_drop_along_a_chord(kind):
    """The bilinear ground along a chord is quadratic between grid lines: the bulge is found
    at the crossings and the pieces' vertices, to the dense brute force's accuracy."""
    from fm2uav.world.ground_model import ground_bulge

    from tests.world.rough_terrain import rough_dem

    z = rough_dem(4, rows=40, cols=50, relief=300.0)
    if kind == "nodes":
        w = World.from_heightmap(z.T, 30.0, 40)
    else:
        pix = 1.0 / 1200.0
        w = World.from_dem(z, (50.0, 50.0, 20.0), crs="EPSG:4326",
                           bounds=(8.5, 47.4 - 40 * pix, 8.5 + 50 * pix, 47.4))
        assert w.ground is not None
        if kind == "two dems":  # a hole in the DEM filled by a coarser one on its own grid
            from fm2uav.world.ground_model import GroundLayer, GroundModel

            top = w.ground.layers[0]
            valid = np.ones(z.shape, bool)
            valid[10:25, 15:35] = False
            a_, b_, c_, d_, e_, f_ = top.transform
            fill = GroundLayer(z=rough_dem(7, rows=30, cols=36, relief=300.0), valid=np.ones(
                (30, 36), bool), transform=(a_ * 1.4, b_, c_ - 0.3 * a_, d_, e_ * 1.4,
                                            f_ - 0.3 * e_), crs=top.crs,
                world_crs=top.world_crs, pixel_m=top.pixel_m * 1.4, name="fill")
            w = w.with_fields(ground=GroundModel((GroundLayer(
                z=top.z, valid=valid, transform=top.transform, crs=top.crs,
                world_crs=top.world_crs, pixel_m=top.pixel_m, name="dem"), fill)))
            assert w.ground_filled(*w.bounds[:2].mean(axis=1)) == False  # noqa: E712
    rng = np.random.default_rng(5)
    b = w.bounds
    a = rng.uniform(b[:2, 0] + 50, b[:2, 1] - 50, size=(60, 2))
    d = rng.normal(0.0, 1.0, size=(60, 2))
    d = d / np.linalg.norm(d, axis=1)[:, None] * rng.uniform(5.0, 120.0, size=(60, 1))
    if kind == "two dems":  # half of the chords cross from one DEM to the other
        a = rng.uniform(b[:2, 0] + 50, b[:2, 1] - 50, size=(3000, 2))
        d = rng.normal(0.0, 1.0, size=(3000, 2))
        d = d / np.linalg.norm(d, axis=1)[:, None] * rng.uniform(5.0, 120.0, size=(3000, 1))
        t = np.linspace(0.0, 1.0, 101)
        xy = a[:, None, :] + t[None, :, None] * d[:, None, :]
        src = w.ground_source(xy[..., 0].ravel(), xy[..., 1].ravel()).reshape(3000, -1)
        switch = src.min(axis=1) != src.max(axis=1)
        pick = np.r_[np.flatnonzero(switch)[:30], np.flatnonzero(~switch)[:30]]
        assert switch.sum() >= 30
        a, d = a[pick], d[pick]
    rise, drop = ground_bulge(w, a, a + d)
    ref = _brute_bulge(w, a, a + d)
    # never below the dense brute force (every 3 mm at most; a DEM in another CRS bends the
    # chord by a fraction of a millimetre), above it by no more than 3 mm sampling can miss
    assert np.all(rise >= ref[:, 0] - 1e-3) and np.all(drop >= ref[:, 1] - 1e-3)
    # (beside a step between two DEMs the brute force's last sample before the step is up
    # to 3 mm x the face's slope short of the one-sided limit ground_bulge reads)
    tol = 1e-2 if kind == "two dems" else 2e-3
    assert np.all(rise - ref[:, 0] < tol) and np.all(drop - ref[:, 1] < tol)
    assert rise.max() > 0.05 and drop.max() > 0.05  # real kinks were crossed


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
