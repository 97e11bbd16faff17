"""Acceptance: a truncated GeoTIFF (header fine, pixels missing) is refused with a
one-line error that names the file and the key/flag, exit 2, no output folder."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

rasterio = pytest.importorskip("rasterio")


def _truncated_tif(path):
    from rasterio.transform import from_origin

    full = path.with_name("full.tif")
    z = np.random.default_rng(0).uniform(0, 500, (200, 300)).astype("float32")
    with rasterio.open(full, "w", driver="GTiff", width=300, height=200, count=1,
                       dtype="float32", crs="EPSG:4326",
                       transform=from_origin(10.0, 46.0, 0.001, 0.001)) as dst:
        dst.write(z, 1)
    path.write_bytes(full.read_bytes()[:5000])


def test_truncated_geotiff_is_input_error(tmp_path):
    from fm2uav.errors import InputError
    from fm2uav.world import World

    bad = tmp_path / "corrupt.tif"
    _truncated_tif(bad)
    with pytest.raises(InputError, match=r"corrupt\.tif.*--dem"):
        World.from_dem(str(bad), (100.0, 100.0, 20.0))


def test_truncated_geotiff_cli_one_line_exit_2(tmp_path):
    bad = tmp_path / "corrupt.tif"
    _truncated_tif(bad)
    out = tmp_path / "out"
    exe = str(Path(sys.executable).with_name("fm2uav"))
    r = subprocess.run([exe, "plan", "--dem", str(bad),
                        "--lonlat", "--start", "10.05,45.85", "--goal", "10.25,45.9",
                        "--agl", "120", "--out", str(out)],
                       capture_output=True, text=True, timeout=120)
    assert r.returncode == 2, r.stderr
    lines = [ln for ln in (r.stdout + r.stderr).splitlines() if ln.strip()]
    assert len(lines) == 1 and lines[0].startswith("error:") and "corrupt.tif" in lines[0]
    assert "Traceback" not in r.stderr
    assert not out.exists()
