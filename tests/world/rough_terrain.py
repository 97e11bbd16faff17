"""Real-ish terrain for the flight-safety tests (world, planning, io, cli): seeded rough relief,
GeoTIFFs written from it, and an independent bilinear sampler of such a file.

The session fixture ``rough_tif`` (tests/conftest.py) is ``write_geotiff(..., rough_dem(5))``.
"""

from __future__ import annotations

import numpy as np


def rough_dem(seed: int, rows: int = 160, cols: int = 200, relief: float = 400.0) -> np.ndarray:
    """Seeded rough relief [m]: a few ridges plus pixel-scale noise, 200-1000 m."""
    rng = np.random.default_rng(seed)
    r, c = np.mgrid[0:rows, 0:cols] / max(rows, cols)
    z = np.zeros((rows, cols))
    for _ in range(6):
        kx, ky = rng.uniform(2, 9, 2)
        z += rng.uniform(0.3, 1.0) * np.sin(2 * np.pi * (kx * c + ky * r) + rng.uniform(0, 6))
    z += 0.03 * rng.standard_normal((rows, cols))
    z = (z - z.min()) / (z.max() - z.min())
    return 200.0 + relief * z


def write_geotiff(path, z, *, west=-3.80, north=40.36, pixel_deg=1.0 / 1200.0,
                  crs="EPSG:4326"):
    """Write a north-up single-band GeoTIFF; returns its path."""
    import rasterio
    from rasterio.transform import from_origin

    with rasterio.open(path, "w", driver="GTiff", height=z.shape[0], width=z.shape[1], count=1,
                       dtype="float32", crs=crs,
                       transform=from_origin(west, north, pixel_deg, pixel_deg)) as ds:
        ds.write(z.astype("float32"), 1)
    return path


def source_ground(tif, world, x, y):
    """Independent bilinear sampling of a GeoTIFF at world points (rasterio + scipy)."""
    import rasterio
    from pyproj import Transformer
    from scipy import ndimage

    with rasterio.open(tif) as ds:
        z = ds.read(1).astype(float)
        inv = ~ds.transform
        crs = ds.crs.to_string()
    lon, lat = Transformer.from_crs(world.crs, crs, always_xy=True).transform(
        np.asarray(x, dtype=float), np.asarray(y, dtype=float))
    col, row = inv * (np.asarray(lon), np.asarray(lat))
    return ndimage.map_coordinates(z, [np.asarray(row) - 0.5, np.asarray(col) - 0.5], order=1,
                                   mode="nearest")
