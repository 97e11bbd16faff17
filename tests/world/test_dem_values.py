"""What the numbers of a DEM mean (issue 25): plausibility judged by slope, undeclared
sentinels, rasters that are not elevation, pixel sizes on the ground."""

from __future__ import annotations

import numpy as np
import pytest
import rasterio
from scipy import ndimage

from fm2uav.errors import WorldError
from fm2uav.world.dem_values import (
    EARTH_LOWEST,
    MAX_WALL,
    check_plausible,
    find_sentinels,
    length_unit_factor,
    max_step,
    pixel_sizes,
    raster_problem,
)

from . import dem_cases as dc


def _where(r, c):
    return f"row {r}, col {c}"


def test_a_step_is_judged_by_its_slope_not_its_size():
    # issue 25: "a 500 m rise on a 2 km pixel is 14°, not a spike"
    assert max_step(2000.0) > 500.0 and np.degrees(np.arctan2(500, 2000)) < 15
    # the same 500 m over 1 m is a wall, which exists (Mount Thor: 1250 m)
    assert max_step(1.0) > 1250.0
    # 3900 m over 30 m exists nowhere
    assert max_step(30.0) < 3900.0
    assert np.all(np.diff(max_step(np.array([1.0, 10.0, 100.0, 1e3, 1e4]))) > 0)


def _terrain(rng, rows, cols, pixel, *, sea=False):
    """Seeded plausible relief at ``pixel`` metres: smooth hills whose slopes stay below
    55°, sometimes a vertical wall up to 1400 m, sometimes a sea floor down to -4000 m."""
    noise = ndimage.gaussian_filter(rng.standard_normal((rows, cols)), rng.uniform(1.5, 6))
    g = np.hypot(*np.gradient(noise))
    slope = np.tan(np.radians(rng.uniform(1, 55)))
    z = noise / max(g.max(), 1e-12) * slope * pixel + rng.uniform(-300, 3000)
    if rng.random() < 0.3:  # a wall
        c0 = int(rng.integers(1, cols - 1))
        z[:, c0:] += rng.uniform(0, min(1400.0, MAX_WALL - 100))
    if sea:
        z = np.minimum(z, 0) - rng.uniform(0, 4000) * (z < 0)
    return z


@pytest.mark.parametrize("seed", range(24))
def test_plausible_relief_is_never_refused(seed):
    """Seeded: relief of any pixel size from 0.5 m to 2 km, walls, sea floors — all
    accepted, and no sentinel is found in them."""
    rng = np.random.default_rng(seed)
    pixel = float(10 ** rng.uniform(np.log10(0.5), np.log10(2000)))
    z = _terrain(rng, 40, 50, pixel, sea=bool(seed % 3 == 0))
    assert z.min() >= EARTH_LOWEST
    check_plausible(z, pixel, pixel, "the DEM", _where)
    mask, found = find_sentinels(z, "float64", lambda v: v, pixel, pixel)
    assert not mask.any() and not found


@pytest.mark.parametrize("seed", range(24))
def test_an_impossible_pixel_is_found_where_it_is(seed):
    """Seeded: the same relief with one pixel moved further from its neighbours than any
    terrain steps is refused, naming that pixel."""
    rng = np.random.default_rng(1000 + seed)
    pixel = float(10 ** rng.uniform(np.log10(0.5), np.log10(2000)))
    z = _terrain(rng, 40, 50, pixel)
    r, c = int(rng.integers(1, 39)), int(rng.integers(1, 49))
    nb = z[r - 1:r + 2, c - 1:c + 2]
    jump = float(max_step(pixel * np.sqrt(2))) * rng.uniform(1.1, 3.0)
    z[r, c] = (nb.max() + jump) if rng.random() < 0.5 else (nb.min() - jump)
    with pytest.raises(WorldError, match=rf"pixel \(row {r}, col {c}\) at row {r}, col {c}.*no "
                                         r"terrain on Earth steps like that"):
        check_plausible(z, pixel, pixel, "the DEM", _where)


def test_elevations_no_ground_has_are_refused_as_another_unit_or_nodata():
    z = np.full((10, 10), 9500.0) + np.arange(10)  # Everest in feet is 29032
    with pytest.raises(WorldError, match=r"above 9000 m .*feet: gdal_edit.py -units ft"):
        check_plausible(z, 30.0, 30.0, "the DEM", _where)
    z = np.full((10, 10), 100.0)
    z[2:4, 2:4] = -20000.0
    with pytest.raises(WorldError, match=r"4 of them exactly -20000.*world.nodata_value: -20000 "
                                         r"\(CLI --nodata-value -20000\)"):
        check_plausible(z, 30.0, 30.0, "the DEM", _where)


@pytest.mark.parametrize("value, dtype", [(-32768, "int16"), (32767, "int16"),
                                          (65535, "uint16"), (-2147483648, "int32"),
                                          (float(np.finfo(np.float32).min), "float32"),
                                          (-3.4e38, "float32"), (-99999.0, "float32")])
def test_sentinels_outside_the_earth_are_always_nodata(value, dtype):
    raw = np.full((20, 20), 500.0)
    raw[3:5, 7] = float(np.asarray(value, dtype=dtype))
    raw[15, 15] = float(np.asarray(value, dtype=dtype))
    mask, found = find_sentinels(raw, dtype, lambda v: v, 30.0, 30.0)
    assert int(mask.sum()) == 3 and mask[15, 15] and mask[3, 7]
    assert len(found) == 1 and found[0].pixels == 3 and "outside the Earth" in found[0].reason


def test_minus_9999_is_nodata_on_land_and_a_trench_floor_at_sea():
    land = np.full((30, 30), 600.0) + np.arange(30)
    land[10:14, 10:12] = -9999.0
    mask, found = find_sentinels(land, "float32", lambda v: v, 30.0, 30.0)
    assert int(mask.sum()) == 8 and found[0].value == -9999.0
    # a Kermadec-like trench on 2 km pixels: -9999 m next to -9800 m is the sea floor
    trench = -9000.0 - 800.0 * np.exp(-((np.arange(30)[:, None] - 15) / 4.0) ** 2) \
        + np.zeros((30, 30))
    trench[15, 15] = -9999.0
    mask, found = find_sentinels(trench, "float32", lambda v: v, 2000.0, 2000.0)
    assert not mask.any() and not found
    # scale/offset apply: stored -32768 with scale 0.1 is -3276.8 m, which is real sea floor
    # but steps 4000 m from 800 m land over 30 m: nodata
    raw = np.full((10, 10), 8000.0)
    raw[4, 4] = -32768.0
    mask, found = find_sentinels(raw, "int16", lambda v: v * 0.1, 30.0, 30.0)
    assert mask[4, 4] and mask.sum() == 1


@pytest.mark.parametrize("make, says", [
    (dc.rgb, "is an RGB colour image (3 bands of uint8)"),
    (dc.palette, "colour-indexed (palette) image"),
    (dc.complex_raster, "complex complex64 pixels"),
    (dc.temperature, "band unit 'degC', which is not a length"),
])
def test_rasters_that_are_not_elevation_are_named(tmp_path, make, says):
    p = make(tmp_path / "x.tif")
    with rasterio.open(p) as ds:
        msg = raster_problem(ds, p)
    assert says in msg and "world.dem / --dem" in msg


def test_elevation_rasters_pass_and_units_become_metres(tmp_path):
    p = dc.nan_hole(tmp_path / "dem.tif")
    with rasterio.open(p) as ds:
        assert raster_problem(ds, p) is None
    assert length_unit_factor("") == 1.0 and length_unit_factor("metre") == 1.0
    assert length_unit_factor("US survey foot") == pytest.approx(1200 / 3937)
    assert length_unit_factor("ft") == 0.3048 and length_unit_factor("cm") == 0.01
    assert length_unit_factor("degC") is None and length_unit_factor("K") is None
    # unit texts as files write them
    assert length_unit_factor("m above mean sea level") == 1.0
    assert length_unit_factor("Meters (EGM2008)") == 1.0
    assert length_unit_factor("elevation (m)") == 1.0
    assert length_unit_factor("height [ft]") == 0.3048
    assert length_unit_factor("temperature (K)") is None


def test_pixel_sizes_on_the_ground():
    # 3 arc-second pixels at 78.2°N: ~19 m east-west, ~93 m north-south
    ex, ey = pixel_sizes((1 / 1200, 0, 15.4, 0, -1 / 1200, 78.25), "EPSG:4326", (72, 360))
    assert 18.5 < ex[36] < 19.5 and 92 < ey[36] < 93.5 and ex[0] < ex[-1]
    # a rotated geotransform: its own axes
    from affine import Affine
    t = Affine.translation(5e5, 4.5e6) * Affine.rotation(20) * Affine.scale(30, -30)
    ex, ey = pixel_sizes(tuple(t)[:6], "EPSG:32630", (10, 10))
    assert np.allclose(ex, 30 / 0.9996, rtol=2e-3) and np.allclose(ey, 30 / 0.9996, rtol=2e-3)
    # Web Mercator at 60°N stores 2 projected metres per ground metre
    from pyproj import Transformer
    x, y = Transformer.from_crs(4326, 3857, always_xy=True).transform(10.0, 60.0)
    ex, _ = pixel_sizes((100, 0, x, 0, -100, y), "EPSG:3857", (2, 2))
    assert 49 < ex[0] < 51
