"""Test data made here for the geodata tests: one analytic terrain written as GeoTIFFs in
several CRSs (EPSG:4326 with nodata outside a "border", Web Mercator, UTM), a
topo-bathymetric grid, and helpers. The terrain is a function of lon/lat, so every file
samples the same ground at its own pixel centres."""

from __future__ import annotations

import numpy as np
import rasterio
from pyproj import Transformer
from rasterio.crs import CRS
from rasterio.transform import from_origin

#: The area (lon/lat degrees): ~19.5 km x 22 km in the Po plain / Alps foothills, UTM 32N.
W, S, E, N = 10.00, 45.50, 10.25, 45.70
LON_C, LAT_C = 0.5 * (W + E), 0.5 * (S + N)
NODATA = -9999.0
#: start and goal of the test missions (lon, lat) inside the border
START = (10.06, 45.55)
GOAL = (10.19, 45.65)


def terrain(lon, lat):
    """Ground height [m] at lon/lat [deg]: a ridge across the START -> GOAL line, hills."""
    lon, lat = np.asarray(lon, float), np.asarray(lat, float)
    x = (lon - LON_C) * 111320.0 * np.cos(np.radians(LAT_C))  # metres east of the centre
    y = (lat - LAT_C) * 111132.0
    ridge = 700.0 * np.exp(-0.5 * (((x + y) / 2.0) / 1800.0) ** 2) * (
        1.0 - 0.6 * np.exp(-0.5 * ((x - y) / 3000.0) ** 2))
    hills = (250.0 * np.exp(-((x - 5000) ** 2 + (y + 4000) ** 2) / (2 * 2500.0 ** 2))
             + 180.0 * np.exp(-((x + 6000) ** 2 + (y - 5000) ** 2) / (2 * 2000.0 ** 2)))
    return 300.0 + 0.01 * x + ridge + hills


def inside_border(lon, lat):
    """The 'country': an ellipse a little inside the area."""
    u = (np.asarray(lon) - LON_C) / (0.47 * (E - W))
    v = (np.asarray(lat) - LAT_C) / (0.47 * (N - S))
    return u * u + v * v <= 1.0


def _write(path, z, crs, transform, nodata=None, dtype="float32", **profile):
    with rasterio.open(path, "w", driver="GTiff", height=z.shape[0], width=z.shape[1], count=1,
                       dtype=dtype, crs=CRS.from_user_input(crs), transform=transform,
                       nodata=nodata, **profile) as ds:
        ds.write(z.astype(dtype), 1)
    return path


def grid_in(crs, res, bounds_ll=(W, S, E, N), pad=0.0):
    """(transform, lon, lat of pixel centres) of a north-up grid in ``crs`` covering the area."""
    fwd = Transformer.from_crs("EPSG:4326", crs, always_xy=True)
    inv = Transformer.from_crs(crs, "EPSG:4326", always_xy=True)
    w, s, e, n = bounds_ll
    t = np.linspace(0, 1, 41)
    lon = np.concatenate([w + (e - w) * t, np.full(41, e), w + (e - w) * t, np.full(41, w)])
    lat = np.concatenate([np.full(41, s), s + (n - s) * t, np.full(41, n), s + (n - s) * t])
    x, y = fwd.transform(lon, lat)
    x0, x1 = np.min(x) - pad, np.max(x) + pad
    y0, y1 = np.min(y) - pad, np.max(y) + pad
    cols, rows = int(np.ceil((x1 - x0) / res)), int(np.ceil((y1 - y0) / res))
    tr = from_origin(x0, y1, res, res)
    cc, rr = np.meshgrid(np.arange(cols) + 0.5, np.arange(rows) + 0.5)
    px, py = tr * (cc, rr)
    plon, plat = inv.transform(px, py)
    return tr, np.asarray(plon), np.asarray(plat)


def dem_4326(path, *, border=True, res=1 / 1200):
    """EPSG:4326 GeoTIFF (3 arc-s) with nodata -9999 outside the border ellipse."""
    tr, lon, lat = grid_in("EPSG:4326", res)
    z = terrain(lon, lat)
    if border:
        z = np.where(inside_border(lon, lat), z, NODATA)
    return _write(path, z, "EPSG:4326", tr, nodata=NODATA)


def dem_3857(path, res=100.0):
    """The same terrain in Web Mercator (100 m pixels, ~70 m on the ground here)."""
    tr, lon, lat = grid_in("EPSG:3857", res)
    return _write(path, terrain(lon, lat), "EPSG:3857", tr)


def dem_utm(path, res=75.0):
    """The same terrain in UTM 32N (75 m pixels)."""
    tr, lon, lat = grid_in("EPSG:32632", res)
    return _write(path, terrain(lon, lat), "EPSG:32632", tr)


def topo_bathy(path, res=1 / 1200):
    """A coast: sea floor down to -120 m in the south-west, land rising to the north-east."""
    tr, lon, lat = grid_in("EPSG:4326", res)
    x = (lon - LON_C) * 111320.0 * np.cos(np.radians(LAT_C))
    y = (lat - LAT_C) * 111132.0
    z = 0.012 * (x + y) + 60.0 * np.sin(x / 1500.0) * np.cos(y / 1700.0)
    return _write(path, np.maximum(z, -120.0), "EPSG:4326", tr)
