"""Shared pieces of the reliability catalogue (issue 17).

Hypothesis runs derandomized (fixed seed) with 25 examples per property by default; set
``FM2UAV_FUZZ=slow`` for the slow profile (400 examples each).
"""

from __future__ import annotations

import os

import numpy as np
import pytest
from hypothesis import HealthCheck, settings

# Applied per test (``@FUZZ``), not loaded as the session's profile: other suites keep theirs.
FUZZ = settings(derandomize=True, database=None, deadline=None,
                max_examples=400 if os.environ.get("FM2UAV_FUZZ") == "slow" else 25,
                suppress_health_check=[HealthCheck.too_slow])


def write_dem(path, z, *, x0=500000.0, y0=4500000.0, px=30.0, crs="EPSG:32630", nodata=None,
              dtype="float32"):
    """A small GeoTIFF DEM (rows north -> south) for the file cases."""
    import rasterio
    from rasterio.transform import from_origin

    z = np.asarray(z, dtype=dtype)
    with rasterio.open(path, "w", driver="GTiff", height=z.shape[0], width=z.shape[1], count=1,
                       dtype=dtype, crs=crs, transform=from_origin(x0, y0, px, px),
                       nodata=nodata) as ds:
        ds.write(z, 1)
    return path


def relief(n=40, seed=0):
    rng = np.random.default_rng(seed)
    return 100.0 + rng.normal(0.0, 1.0, (n, n)).cumsum(0)


@pytest.fixture
def fifo(tmp_path):
    p = tmp_path / "pipe.geojson"
    os.mkfifo(p)
    return p
