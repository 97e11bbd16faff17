"""DEMs as they come (issue 25), written here with rasterio for the tests: a topo-bathymetric
grid of ~2 km pixels with a sea floor to -4000 m and real islands, float32 with a NaN hole,
float16, int16 with undeclared -32768 voids, a WKT-only southern-hemisphere CRS, a DEM at
78°N, a country-shaped DEM (nodata outside a border) with a coarser DEM of the neighbour in
another CRS, rotated geotransforms, and rasters that are not elevation (RGB, palette,
complex, a temperature band) — plus an independent reader of which ground is measured.

Every terrain is a function of lon/lat, so each file samples the same ground at its own
pixel centres and a test can say what the ground truly is anywhere.
"""

from __future__ import annotations

import numpy as np
import rasterio
from affine import Affine
from pyproj import Transformer
from rasterio.crs import CRS
from rasterio.transform import from_origin

# --------------------------------------------------------------------------- writing


def write(path, z, crs, transform, *, nodata=None, dtype="float32", **profile):
    """A single-band GeoTIFF of ``z`` (rows north -> south); returns the path."""
    z = np.asarray(z)
    with rasterio.open(path, "w", driver="GTiff", height=z.shape[0], width=z.shape[1], count=1,
                       dtype=dtype, crs=None if crs is None else CRS.from_user_input(crs),
                       transform=transform, nodata=nodata, **profile) as ds:
        ds.write(z.astype(dtype), 1)
    return path


def lonlat_grid(west, north, res, rows, cols):
    """(transform, lon, lat of pixel centres) of a lon/lat grid."""
    t = from_origin(west, north, res, res)
    c, r = np.meshgrid(np.arange(cols) + 0.5, np.arange(rows) + 0.5)
    return t, west + c * res, north - r * res


# --------------------------------------------------------------------- topo-bathymetry

#: The archipelago: lon/lat box, three islands (lon, lat, height [m], radius [km]).
BATHY_WEST, BATHY_NORTH, BATHY_RES = 24.0, 39.5, 1.0 / 55.0   # ~2 km pixels at 39°N
ISLANDS = ((24.90, 38.77, 1500.0, 6.0), (24.55, 39.13, 900.0, 4.0), (25.35, 38.42, 1200.0, 5.0))


def bathy_ground(lon, lat):
    """Topo-bathymetry [m]: a basin to ~-4000 m, islands with mountains up to 1500 m."""
    lon, lat = np.asarray(lon, float), np.asarray(lat, float)
    km_x = (lon - 24.9) * 86.5
    km_y = (lat - 38.77) * 111.1
    z = -4000.0 + 2600.0 * (1 - np.exp(-(km_x ** 2 + km_y ** 2) / (2 * 70.0 ** 2)))
    for lo, la, h, rad in ISLANDS:
        d2 = ((lon - lo) * 86.5) ** 2 + ((lat - la) * 111.1) ** 2
        z = np.maximum(z, h - (h + 1800.0) * (np.sqrt(d2) / (3 * rad)) ** 1.5)
    return z


def topo_bathy(path, rows=80, cols=100):
    """EPSG:4326, 1/55° (~1.7 x 2.0 km) pixels, sea floor to ~-4000 m, islands to ~1900 m."""
    t, lon, lat = lonlat_grid(BATHY_WEST, BATHY_NORTH, BATHY_RES, rows, cols)
    return write(path, bathy_ground(lon, lat), "EPSG:4326", t)


# --------------------------------------------------------------- a generic rough terrain

def hills(x_km, y_km, seed=0, base=400.0):
    """Smooth hills [m] in a local km frame, seeded."""
    rng = np.random.default_rng(seed)
    z = base + 8.0 * x_km
    for _ in range(8):
        cx, cy = rng.uniform(-5, 5, 2)
        z = z + rng.uniform(50, 250) * np.exp(-((x_km - cx) ** 2 + (y_km - cy) ** 2)
                                               / (2 * rng.uniform(0.6, 2.0) ** 2))
    return z


def nan_hole(path):
    """A US DEM (NAD83 / UTM 13N, 10 m pixels, float32) whose nodata is NaN, with a hole."""
    rows, cols = 400, 500
    t = from_origin(480000.0, 4400000.0, 10.0, 10.0)
    c, r = np.meshgrid(np.arange(cols) + 0.5, np.arange(rows) + 0.5)
    z = hills((c - cols / 2) / 100.0, (rows / 2 - r) / 100.0, seed=3, base=1600.0)
    z[150:260, 200:320] = np.nan
    return write(path, z, "EPSG:26913", t, nodata=np.nan)


def half_float(path):
    """The same kind of terrain stored as float16 (GeoTIFF NBITS=16), NaN nodata, 30 m."""
    rows, cols = 200, 240
    t = from_origin(500000.0, 4200000.0, 30.0, 30.0)
    c, r = np.meshgrid(np.arange(cols) + 0.5, np.arange(rows) + 0.5)
    z = hills((c - cols / 2) * 0.03, (rows / 2 - r) * 0.03, seed=4, base=2400.0)
    return write(path, z, "EPSG:32633", t, nodata=np.nan, NBITS=16)


def srtm_voids(path):
    """int16 lon/lat DEM (3″) with voids of -32768 the file does not declare (SRTM v1 style)."""
    t, lon, lat = lonlat_grid(7.0, 46.2, 1.0 / 1200.0, 150, 180)
    km_x, km_y = (lon - 7.075) * 77.0, (lat - 46.1375) * 111.1
    z = np.round(hills(km_x, km_y, seed=5, base=1200.0)).astype(np.int16)
    z[60:75, 90:110] = -32768
    z[10:12, 10:13] = -32768
    return write(path, z, "EPSG:4326", t, dtype="int16")


#: A UTM zone 19 south written as plain WKT with a datum shift and no authority anywhere
#: (pyproj finds no EPSG code for it): Chilean Andes near 33.5°S.
WKT_SOUTH = (
    'PROJCS["Custom UTM 19 South (PSAD56-like)",GEOGCS["Custom PSAD56",'
    'DATUM["D_Custom_PSAD56",SPHEROID["International 1924",6378388,297],'
    'TOWGS84[-288,175,-376,0,0,0,0]],PRIMEM["Greenwich",0],'
    'UNIT["degree",0.0174532925199433]],PROJECTION["Transverse_Mercator"],'
    'PARAMETER["latitude_of_origin",0],PARAMETER["central_meridian",-69],'
    'PARAMETER["scale_factor",0.9996],PARAMETER["false_easting",500000],'
    'PARAMETER["false_northing",10000000],UNIT["metre",1]]')


def wkt_south(path):
    """30 m DEM in :data:`WKT_SOUTH` (no EPSG code), Andes foothills."""
    rows, cols = 200, 220
    t = from_origin(330000.0, 6290000.0, 30.0, 30.0)
    c, r = np.meshgrid(np.arange(cols) + 0.5, np.arange(rows) + 0.5)
    z = hills((c - cols / 2) * 0.03, (rows / 2 - r) * 0.03, seed=6, base=900.0)
    return write(path, z, WKT_SOUTH, t)


def svalbard(path):
    """A lon/lat DEM at 78°N (Adventdalen-like): 1/1200° pixels, ~19 m x 93 m on the ground."""
    t, lon, lat = lonlat_grid(15.40, 78.25, 1.0 / 1200.0, 72, 360)
    km_x, km_y = (lon - 15.55) * 22.9, (lat - 78.22) * 111.6
    z = hills(km_x, km_y, seed=7, base=40.0) - 400.0 * np.exp(-(km_y / 0.8) ** 2)
    return write(path, np.maximum(z, 0.0), "EPSG:4326", t)


def rotated(path, degrees=20.0):
    """A UTM 30N DEM whose geotransform is rotated by ``degrees`` (30 m pixels)."""
    rows, cols = 120, 120
    t = Affine.translation(500000.0, 4500000.0) * Affine.rotation(degrees) * \
        Affine.scale(30.0, -30.0)
    c, r = np.meshgrid(np.arange(cols) + 0.5, np.arange(rows) + 0.5)
    x, y = t * (c, r)
    z = hills((x - 501800.0) / 1000.0, (y - 4498200.0) / 1000.0, seed=8, base=700.0)
    return write(path, z, "EPSG:32630", t)


# ---------------------------------------------------------- the country and its neighbour

COUNTRY_WEST, COUNTRY_NORTH, COUNTRY_RES = 10.00, 45.70, 1.0 / 1200.0
COUNTRY_ROWS, COUNTRY_COLS = 240, 300


def country_ground(lon, lat):
    """The ground [m] on both sides of the border (one terrain, two DEMs sample it): gentle
    hills, so that FM² flies the direct line across the bay."""
    lon, lat = np.asarray(lon, float), np.asarray(lat, float)
    km_x, km_y = (lon - 10.125) * 78.0, (lat - 45.60) * 111.1
    return 300.0 + 0.4 * (hills(km_x, km_y, seed=9, base=0.0) - 8.0 * km_x) + 3.0 * km_x


def _uv(lon, lat):
    return (np.asarray(lon, float) - 10.0) / 0.25, (np.asarray(lat, float) - 45.5) / 0.2


def inside_country(lon, lat):
    """The country: the whole area but a bay of the neighbour, a wedge along the diagonal
    from the north-east corner to the middle."""
    u, v = _uv(lon, lat)
    bay = (u + v > 0.9) & (np.abs(u - v) < 0.1 + 0.3 * (u + v - 0.9))
    return ~bay


#: A route along the bay, from one side of it to the other: start and goal inside the
#: country, the direct line across the bay (over the neighbour's ground).
BORDER_START = (10.0875, 45.67)   # u 0.35, v 0.85
BORDER_GOAL = (10.2125, 45.57)    # u 0.85, v 0.35


def country(path, nodata=-9999.0):
    """EPSG:4326 3″ DEM of the country, ``nodata`` outside its border."""
    t, lon, lat = lonlat_grid(COUNTRY_WEST, COUNTRY_NORTH, COUNTRY_RES, COUNTRY_ROWS,
                              COUNTRY_COLS)
    z = np.where(inside_country(lon, lat), country_ground(lon, lat), nodata)
    return write(path, z, "EPSG:4326", t, nodata=nodata)


def neighbour(path, res=90.0):
    """The neighbour's coarser model: UTM 32N, 90 m pixels, both sides of the border."""
    fwd = Transformer.from_crs("EPSG:4326", "EPSG:32632", always_xy=True)
    inv = Transformer.from_crs("EPSG:32632", "EPSG:4326", always_xy=True)
    x0, y1 = fwd.transform(COUNTRY_WEST - 0.01, COUNTRY_NORTH + 0.01)
    x1, y0 = fwd.transform(COUNTRY_WEST + COUNTRY_COLS * COUNTRY_RES + 0.01,
                           COUNTRY_NORTH - COUNTRY_ROWS * COUNTRY_RES - 0.01)
    x0, y0 = min(x0, x1) - 2000, min(y0, y1) - 2000
    x1, y1 = x0 + 30000, y0 + 30000
    cols, rows = int((x1 - x0) / res), int((y1 - y0) / res)
    t = from_origin(x0, y1, res, res)
    c, r = np.meshgrid(np.arange(cols) + 0.5, np.arange(rows) + 0.5)
    lon, lat = inv.transform(*(t * (c, r)))
    return write(path, country_ground(lon, lat), "EPSG:32632", t, nodata=-9999.0)


# --------------------------------------------------------------- not elevation at all

def rgb(path):
    """A 3-band uint8 RGB image with a CRS (a map screenshot)."""
    data = np.random.default_rng(0).integers(0, 255, (3, 50, 60), dtype=np.uint8)
    with rasterio.open(path, "w", driver="GTiff", height=50, width=60, count=3, dtype="uint8",
                       crs="EPSG:32630", transform=from_origin(500000, 4500000, 30, 30),
                       photometric="RGB") as ds:
        ds.write(data)
    return path


def palette(path):
    """A colour-indexed uint8 image (a classified land-cover map)."""
    data = np.random.default_rng(1).integers(0, 4, (50, 60), dtype=np.uint8)
    with rasterio.open(path, "w", driver="GTiff", height=50, width=60, count=1, dtype="uint8",
                       crs="EPSG:32630", transform=from_origin(500000, 4500000, 30, 30)) as ds:
        ds.write(data, 1)
        ds.write_colormap(1, {0: (0, 0, 255), 1: (0, 255, 0), 2: (255, 0, 0), 3: (9, 9, 9)})
    return path


def complex_raster(path):
    """A complex64 band (an interferogram)."""
    z = (np.ones((40, 40)) + 1j * np.ones((40, 40))).astype(np.complex64)
    return write(path, z, "EPSG:32630", from_origin(500000, 4500000, 30, 30), dtype="complex64")


def temperature(path):
    """A float band in degrees Celsius (band unit 'degC')."""
    p = write(path, np.full((40, 40), 21.5), "EPSG:32630", from_origin(500000, 4500000, 30, 30))
    with rasterio.open(p, "r+") as ds:
        ds.units = ("degC",)
    return p


# ---------------------------------------------------------------- independent reading

def measured_mask(tif, world, points):
    """Independently of fm2uav: whether the ground under each point (x, y) is measured by
    the GeoTIFF ``tif``, i.e. every pixel of its bilinear stencil (non-zero weight) is valid
    and the point is within the pixel-centre footprint (rasterio + pyproj). ``world`` is a
    World (points in its CRS) or a CRS (e.g. ``"EPSG:4326"`` for lon/lat points)."""
    p = np.asarray(points, dtype=float)
    src_crs = getattr(world, "crs", world)
    with rasterio.open(tif) as ds:
        valid = ~np.ma.getmaskarray(ds.read(1, masked=True))
        valid &= np.isfinite(ds.read(1).astype(float))
        inv = ~ds.transform
        crs = ds.crs.to_wkt()
    x, y = Transformer.from_crs(src_crs, crs, always_xy=True).transform(p[:, 0], p[:, 1])
    col, row = inv * (np.asarray(x), np.asarray(y))
    col, row = np.asarray(col) - 0.5, np.asarray(row) - 0.5
    rows, cols = valid.shape
    ok = (row >= -1e-6) & (row <= rows - 1 + 1e-6) & (col >= -1e-6) & (col <= cols - 1 + 1e-6)
    r = np.clip(row, 0, rows - 1)
    c = np.clip(col, 0, cols - 1)
    r0 = np.minimum(np.floor(r).astype(int), rows - 2)
    c0 = np.minimum(np.floor(c).astype(int), cols - 2)
    fr, fc = r - r0, c - c0
    for dr, dc, w in ((0, 0, (1 - fr) * (1 - fc)), (0, 1, (1 - fr) * fc), (1, 0, fr * (1 - fc)),
                      (1, 1, fr * fc)):
        ok &= (w <= 1e-12) | valid[r0 + dr, c0 + dc]
    return ok


def length_over(points, unknown_at, step=0.5):
    """3D length [m] of the polyline ``points`` over ground where ``unknown_at(pts)`` is True,
    each sub-segment of at most ``step`` metres classified at its middle; and the total."""
    p = np.asarray(points, dtype=float)
    seg = np.linalg.norm(np.diff(p, axis=0), axis=1)
    n = np.maximum(np.ceil(seg / step).astype(int), 1)
    i = np.repeat(np.arange(len(seg)), n)
    k = np.concatenate([np.arange(m) for m in n])
    mid = p[i] + ((k + 0.5) / n[i])[:, None] * (p[i + 1] - p[i])
    over = float(np.sum((seg[i] / n[i])[np.asarray(unknown_at(mid), dtype=bool)]))
    return over, float(seg.sum())
