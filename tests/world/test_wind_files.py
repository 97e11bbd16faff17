"""Gridded wind files onto a world: NetCDF through xarray, two-band GeoTIFFs through rasterio."""

from __future__ import annotations

import numpy as np
import pytest
import rasterio
import xarray as xr
from pyproj import Transformer
from rasterio.transform import from_origin

from fm2uav.errors import InputError
from fm2uav.world import World
from fm2uav.world.geo import to_lonlat
from fm2uav.world.wind import WindField
from fm2uav.world.wind_files import check_wind_file, read_wind_file, resolve_wind

WORLD = World(np.zeros((21, 11), bool), spacing=50.0)   # at the default anchor, no CRS


def _netcdf(path, *, lon360=False, names=("u10", "v10")):
    ll = to_lonlat(WORLD, np.array([[0.0, 0.0], [1000.0, 500.0]]))
    lons = np.linspace(ll[0, 0] - 0.01, ll[1, 0] + 0.01, 30)
    lats = np.linspace(ll[1, 1] + 0.01, ll[0, 1] - 0.01, 25)        # descending, as ERA5
    L, A = np.meshgrid(lons, lats, indexing="ij")
    u = 3.0 + 100.0 * (L - lons[0])                                   # linear: exact
    v = -2.0 + 50.0 * (A - lats[-1])
    coords_lon = lons + 360.0 if lon360 else lons
    ds = xr.Dataset({names[0]: (("time", "latitude", "longitude"), np.stack([u.T, 2 * u.T])),
                     names[1]: (("time", "latitude", "longitude"), np.stack([v.T, v.T]))},
                    coords={"time": np.array(["2026-12-02T10:00", "2026-12-02T11:00"],
                                             dtype="datetime64[ns]"),
                            "latitude": lats, "longitude": coords_lon})
    ds.to_netcdf(path)
    return lambda lon, lat: (3.0 + 100.0 * (lon - lons[0]), -2.0 + 50.0 * (lat - lats[-1]))


@pytest.mark.parametrize("lon360", [False, True])
def test_netcdf_wind_is_sampled_exactly_at_the_first_time(tmp_path, lon360):
    truth = _netcdf(tmp_path / "w.nc", lon360=lon360)
    f = read_wind_file(tmp_path / "w.nc", WORLD)
    assert f.kind == "grid" and f.u.shape == (21, 11)
    assert "u10/v10 at time=2026-12-02T10:00" in f.source
    q = np.array([[500.0, 250.0], [123.0, 456.0]])
    ll = to_lonlat(WORLD, q)
    u, v = truth(ll[:, 0], ll[:, 1])
    np.testing.assert_allclose(f.at(q), np.column_stack([u, v]), atol=1e-6)


def test_geotiff_wind_in_another_crs(tmp_path):
    ll = to_lonlat(WORLD, np.array([[0.0, 500.0]]))[0]
    x0, y0 = Transformer.from_crs("EPSG:4326", "EPSG:32630", always_xy=True).transform(
        ll[0] - 0.005, ll[1] + 0.005)
    arr = np.stack([np.full((40, 40), 4.0), np.full((40, 40), -1.0)]).astype("float32")
    with rasterio.open(tmp_path / "w.tif", "w", driver="GTiff", width=40, height=40, count=2,
                       dtype="float32", crs="EPSG:32630",
                       transform=from_origin(x0, y0, 50, 50)) as dst:
        dst.write(arr)
    f = read_wind_file(tmp_path / "w.tif", WORLD)
    np.testing.assert_allclose(f.at([[500.0, 250.0]]), [[4.0, -1.0]], atol=1e-6)
    assert resolve_wind(WindField.from_file(tmp_path / "w.tif"), WORLD).kind == "grid"


def test_wind_files_that_cannot_serve_are_refused(tmp_path):
    with pytest.raises(InputError, match="not found"):
        check_wind_file(tmp_path / "none.nc")
    (tmp_path / "w.grib2").write_bytes(b"GRIB")
    with pytest.raises(InputError, match="unknown kind '.grib2'"):
        check_wind_file(tmp_path / "w.grib2")
    _netcdf(tmp_path / "t.nc", names=("temp", "rh"))
    with pytest.raises(InputError, match="no wind variables.*it has temp, rh"):
        check_wind_file(tmp_path / "t.nc")
    far = World(np.zeros((21, 11), bool), spacing=5000.0)             # 100 km: not covered
    _netcdf(tmp_path / "w.nc")
    with pytest.raises(InputError, match="does not cover the map"):
        read_wind_file(tmp_path / "w.nc", far)
    with rasterio.open(tmp_path / "one.tif", "w", driver="GTiff", width=4, height=4, count=1,
                       dtype="float32", crs="EPSG:32630",
                       transform=from_origin(500000, 4000000, 1, 1)) as dst:
        dst.write(np.zeros((1, 4, 4), "float32"))
    with pytest.raises(InputError, match="two bands"):
        check_wind_file(tmp_path / "one.tif")
    with pytest.raises(InputError, match="not on a map yet"):
        WindField.from_file(tmp_path / "w.nc").at([[0.0, 0.0]])
