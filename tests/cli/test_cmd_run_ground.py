"""`fm2uav run` on DEMs as they come (issue 25): a NaN-nodata DEM with every default output
(path.geojson was an exit-70 crash), and a WKT-only southern CRS run as a real process: no
library warning, no WKT dumped into the summary."""

from __future__ import annotations

import json
import os
import subprocess
import sys

import numpy as np
import pytest
from pyproj import Transformer
from typer.testing import CliRunner

from fm2uav.cli import app

from tests.world import dem_cases as dc


def _lonlat(crs, x, y):
    lon, lat = Transformer.from_crs(crs, "EPSG:4326", always_xy=True).transform(x, y)
    return float(lon), float(lat)


def test_nan_nodata_dem_with_every_default_output(tmp_path):
    tif = dc.nan_hole(tmp_path / "us_dem.tif")
    s = _lonlat("EPSG:26913", 480500.0, 4396500.0)
    g = _lonlat("EPSG:26913", 484500.0, 4399500.0)
    (tmp_path / "m.yaml").write_text(
        "world: {dem: us_dem.tif, nodata: fill, cell_size: 40}\n"
        f"start: {{lon: {s[0]}, lat: {s[1]}, agl: 60}}\n"
        f"goal: {{lon: {g[0]}, lat: {g[1]}, agl: 60}}\n"
        "planner: {agl: 60}\n")
    out = tmp_path / "out"
    res = CliRunner().invoke(app, ["run", str(tmp_path / "m.yaml"), "--out", str(out)])
    assert res.exit_code == 0, res.output
    for name in ("path.geojson", "summary.json", "mission.plan"):
        json.loads((out / name).read_text())  # strict JSON: no NaN anywhere
    summary = json.loads((out / "summary.json").read_text())
    src = summary["world"]["georef"]["sources"][0]["details"]
    assert src["nodata"] == "nan" and src["nodata_rule"] == "fill"
    g_ = summary["safety"]["ground"]
    assert g_["measured"]["length_m"] + g_["filled"]["length_m"] == pytest.approx(
        g_["length_m"], abs=1e-3)


@pytest.mark.slow
def test_a_wkt_only_crs_runs_quietly_as_a_process(tmp_path):
    tif = dc.wkt_south(tmp_path / "andes.tif")
    s = _lonlat(dc.WKT_SOUTH, 331000.0, 6285000.0)
    g = _lonlat(dc.WKT_SOUTH, 335500.0, 6288500.0)
    env = {**os.environ, "COLUMNS": "200", "FM2UAV_DEBUG": ""}
    env.pop("FM2UAV_DEBUG")
    res = subprocess.run(
        [sys.executable, "-m", "fm2uav", "plan", "--dem", str(tif), "--lonlat",
         "--start", f"{s[0]},{s[1]}", "--goal", f"{g[0]},{g[1]}", "--agl", "80",
         "--cell-size", "60", "--export", "plan", "--out", str(tmp_path / "o")],
        capture_output=True, text=True, env=env, timeout=600)
    assert res.returncode == 0, res.stderr
    both = res.stdout + res.stderr
    for noise in ("UserWarning", "Warning:", "warnings.warn", "PROJCRS", "BOUNDCRS", "PROJCS",
                  "+proj="):
        assert noise not in both, noise
    assert '"Custom UTM 19 South (PSAD56-like)"' in both
    header = (tmp_path / "o" / "path.csv").read_text().splitlines()[0]
    assert header.startswith("# crs=wkt-sha256:") and len(header) < 400
    # fm2uav export recognises the path as planned on this world (the CRS has no EPSG code)
    res2 = subprocess.run(
        [sys.executable, "-m", "fm2uav", "export", str(tmp_path / "o" / "path.csv"),
         "--mission", str(_mission(tmp_path, tif, s, g)), "--format", "wpl",
         "--out", str(tmp_path / "e")], capture_output=True, text=True, env=env, timeout=600)
    assert res2.returncode == 0, res2.stderr
    assert "says crs=" not in res2.stdout + res2.stderr


def _mission(tmp_path, tif, s, g):
    p = tmp_path / "andes.yaml"
    p.write_text(f"world: {{dem: {tif.name}, cell_size: 60}}\n"
                 f"start: {{lon: {s[0]}, lat: {s[1]}, agl: 80}}\n"
                 f"goal: {{lon: {g[0]}, lat: {g[1]}, agl: 80}}\nplanner: {{agl: 80}}\n")
    return p
