"""``fm2uav plan`` on a DEM with ``--storage regional`` (planning/regional.py through the CLI):
the summary's safety figures equal a measurement of the written files against the GeoTIFF."""

from __future__ import annotations

import json

import numpy as np
import rasterio
from pyproj import Transformer
from rasterio.transform import from_origin
from typer.testing import CliRunner

from fm2uav.cli import app

from tests.e2e.remeasure import check_run, dem_ground

CELL = 30.0


def test_cli_plans_a_dem_regionally(tmp_path):
    n = 200
    x = np.linspace(0.0, 3.0 * np.pi, n)
    h = (600.0 + 200.0 * np.sin(x)[:, None] * np.cos(0.7 * x)[None, :]).astype(np.float32)
    dem = tmp_path / "dem.tif"
    with rasterio.open(dem, "w", driver="GTiff", width=n, height=n, count=1, dtype="float32",
                       crs="EPSG:32630", transform=from_origin(400000.0, 4500000.0, CELL, CELL)
                       ) as ds:
        ds.write(h, 1)
    to_ll = Transformer.from_crs("EPSG:32630", "EPSG:4326", always_xy=True)
    (lo0, la0), (lo1, la1) = (to_ll.transform(400300, 4494300), to_ll.transform(405600, 4499700))
    out = tmp_path / "out"
    res = CliRunner().invoke(app, [
        "plan", "--dem", str(dem), "--cell-size", "30", "--agl", "120", "--storage", "regional",
        "--lonlat", f"--start={lo0:.6f},{la0:.6f},120", f"--goal={lo1:.6f},{la1:.6f},120",
        "--export", "geojson,plan", "--out", str(out), "--quiet"])
    assert res.exit_code == 0, res.output
    summary = json.loads((out / "summary.json").read_text())
    assert summary["params"]["storage"] == "regional"
    assert all(c["ok"] for c in summary["safety"]["checks"].values())
    # the figures are what the written files show over the GeoTIFF (rasterio + pyproj here)
    measured = check_run(out, dem_ground(dem))
    i0, i1 = summary["safety"]["cruise_points"]
    cruise = measured["path"][i0:i1 + 1]
    assert cruise.min() >= 118.0 and abs(np.median(cruise) - 120.0) <= 2.0
    assert measured["legs"].min() >= 118.0 - 30.0  # the climb-out / descent legs included
    # the path runs from the start to the goal asked for
    doc = json.loads((out / "path.geojson").read_text())
    line = np.array(doc["features"][0]["geometry"]["coordinates"])
    np.testing.assert_allclose(line[[0, -1], :2], [[lo0, la0], [lo1, la1]], atol=1e-5)
