"""Write the Jacksboro fault DEM (matplotlib's sample data) as a GeoTIFF.

A real DEM to try `fm2uav run` on a GeoTIFF, as with your own data:

    .venv/bin/python examples/make_jacksboro_geotiff.py            # → examples/jacksboro.tif
    .venv/bin/fm2uav run examples/jacksboro_geotiff.yaml

344 x 403 elevations [m] at 3 arc-seconds around 84.08-84.41° W, 36.45-36.73° N
(Tennessee), in geographic WGS84 (EPSG:4326); fm2uav reprojects it to UTM 16N.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import rasterio
from rasterio.transform import from_bounds

from fm2uav.scenarios.jacksboro import jacksboro_dem


def write_geotiff(target: Path) -> Path:
    """Write the DEM to ``target`` (GeoTIFF, float32, EPSG:4326); returns the path."""
    z, (west, south, east, north) = jacksboro_dem()
    rows, cols = z.shape
    profile = {
        "driver": "GTiff", "height": rows, "width": cols, "count": 1, "dtype": "float32",
        "crs": "EPSG:4326", "transform": from_bounds(west, south, east, north, cols, rows),
        "compress": "deflate", "nodata": -9999.0,
    }
    with rasterio.open(target, "w", **profile) as ds:
        ds.write(z.astype(np.float32), 1)
    return target


if __name__ == "__main__":
    out = Path(sys.argv[1]) if len(sys.argv) > 1 else Path(__file__).with_name("jacksboro.tif")
    print(write_geotiff(out))
