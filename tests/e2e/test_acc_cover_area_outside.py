"""Acceptance: a lon/lat survey area (KML) outside the DEM's map is refused with a
one-line error that names the fix (--bbox / the area's CRS), exit 2, no outputs."""

from __future__ import annotations

from pathlib import Path
import subprocess
import sys

import numpy as np
import pytest

rasterio = pytest.importorskip("rasterio")

KML = """<kml xmlns="http://www.opengis.net/kml/2.2"><Document><Placemark><Polygon>
<outerBoundaryIs><LinearRing><coordinates>20,50 20.01,50 20.01,50.01 20,50.01 20,50
</coordinates></LinearRing></outerBoundaryIs></Polygon></Placemark></Document></kml>"""


def test_area_outside_dem_names_bbox(tmp_path):
    from rasterio.transform import from_origin

    tif = tmp_path / "dem.tif"
    z = np.random.default_rng(0).uniform(100, 200, (40, 40)).astype("float32")
    with rasterio.open(tif, "w", driver="GTiff", width=40, height=40, count=1,
                       dtype="float32", crs="EPSG:4326",
                       transform=from_origin(10.0, 45.04, 0.001, 0.001)) as dst:
        dst.write(z, 1)
    area = tmp_path / "area.kml"
    area.write_text(KML)
    out = tmp_path / "out"
    exe = str(Path(sys.executable).with_name("fm2uav"))
    r = subprocess.run([exe, "cover", "--dem", str(tif), "--area", str(area), "--spacing", "20",
                        "--agl", "60", "--out", str(out)],
                       capture_output=True, text=True, timeout=120)
    assert r.returncode == 2, r.stdout + r.stderr
    lines = [ln for ln in (r.stdout + r.stderr).splitlines() if ln.strip()]
    assert len(lines) == 1 and "outside the map" in lines[0] and "--bbox" in lines[0], lines
    assert "map's metres" not in lines[0]
    assert not out.exists()
