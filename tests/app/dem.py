"""Small GeoTIFFs for the app's tests (made by the tests, in their tmp folders)."""

from __future__ import annotations

from pathlib import Path

import numpy as np


def make_dem(path: Path, *, nx: int = 180, ny: int = 120, cell: float = 30.0,
             west: float = 600000.0, north: float = 5100000.0, crs: str = "EPSG:32632") -> Path:
    """A GeoTIFF in UTM 32N (default 5.4 x 3.6 km of 30 m pixels): a hill in the west,
    gentle waves east; ``z = 300 + 150 exp(-r^2 / (2 * 700^2)) + 20 sin(x / 500)`` [m]
    with ``r`` the distance from (1500, 1500) m of the raster's north-west corner
    (x east, y south)."""
    import rasterio
    from rasterio.transform import from_origin

    x, y = np.meshgrid(np.arange(nx) * cell, np.arange(ny) * cell)
    z = 300 + 150 * np.exp(-((x - 1500) ** 2 + (y - 1500) ** 2) / (2 * 700.0 ** 2)) \
        + 20 * np.sin(x / 500.0)
    with rasterio.open(path, "w", driver="GTiff", height=ny, width=nx, count=1,
                       dtype="float32", crs=crs,
                       transform=from_origin(west, north, cell, cell)) as ds:
        ds.write(z.astype("float32"), 1)
    return path


def mission_yaml(path: Path, dem: Path, **more: str) -> Path:
    """A mission file over ``dem`` (made by :func:`make_dem` with its defaults): start in
    the west, goal in the east, 60 m above ground, plan + waypoints + summary only."""
    extra = "".join(f"{k}: {v}\n" for k, v in more.items())
    path.write_text(
        f"version: 1\nname: app test\nworld: {{dem: {dem}}}\n"
        "start: {lon: 10.3000, lat: 46.0300, agl: 60}\n"
        "goal: {lon: 10.3550, lat: 46.0300, agl: 60}\n"
        "planner: {agl: 60}\n"
        "outputs: {formats: [plan, wpl, geojson, json]}\n" + extra)
    return path
