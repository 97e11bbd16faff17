"""Acceptance (issue 25): every file ``fm2uav formation`` writes for a vehicle tells the flight
its mission will fly. Re-measured from the files only — ``*_path.geojson``,
``*_mission.plan``, ``trajectories.csv`` — against the GeoTIFF sampled bilinearly with
rasterio + scipy here; the summary's figures must agree to 1 m (the trajectory files sat
10–20 m below the missions: median 105–110 m against 120 m)."""

from __future__ import annotations

import csv
import json

import numpy as np
import pytest
from pyproj import Transformer
from typer.testing import CliRunner

from fm2uav.cli import app

from tests.e2e.conftest import write_dem
from tests.e2e.remeasure import dem_ground

X0, Y0, PX, CRS = 465000.0, 5248200.0, 10.0, "EPSG:32632"
AGL = 120.0


def _ground_ll(tif, lon, lat):
    """The GeoTIFF's bilinear ground at lon/lat, measured as every acceptance test does."""
    return dem_ground(tif)(np.asarray(lon), np.asarray(lat))


@pytest.fixture(scope="module")
def flight(tmp_path_factory):
    d = tmp_path_factory.mktemp("formation")
    r, c = np.mgrid[0:70, 0:150].astype(float)
    tif = write_dem(d / "hills.tif", 400.0 + 30 * np.sin(c / 11.0) + 20 * np.cos(r / 8.0),
                    x0=X0, y0=Y0, px=PX, crs=CRS)
    to_ll = Transformer.from_crs(CRS, "EPSG:4326", always_xy=True)
    s = to_ll.transform(X0 + 200, Y0 - 350)
    g = to_ll.transform(X0 + 1300, Y0 - 350)
    out = d / "out"
    res = CliRunner().invoke(app, [
        "formation", "--dem", str(tif), "--lonlat", "--start", f"{s[0]},{s[1]}",
        "--goal", f"{g[0]},{g[1]}", "--agl", str(AGL), "--no-gif", "--firmware", "px4",
        "--out", str(out), "--quiet"])
    assert res.exit_code == 0, res.output
    return out, tif, json.loads((out / "summary.json").read_text())


def _line(path, name="path"):
    gj = json.loads(path.read_text())
    return np.array(next(f for f in gj["features"] if f["properties"].get("name") == name)
                    ["geometry"]["coordinates"])


@pytest.mark.slow
def test_formation_files_tell_one_flight(flight):
    out, tif, summary = flight
    names = summary["missions"].keys()
    assert set(names) == {"leader", "follower 1", "follower 2"}
    traj = {}
    with open(out / "trajectories.csv") as fh:
        table = list(csv.DictReader(fh))
    for name in names:
        prefix = name.replace(" ", "")
        path = _line(out / f"{prefix}_path.geojson")
        agl = path[:, 2] - _ground_ll(tif, path[:, 0], path[:, 1])
        fig = summary["safety"][name]["height_above_ground"]
        # the summary's figures are those of the file (to 1 m; here to centimetres)
        assert fig["path"]["min_m"] == pytest.approx(agl.min(), abs=0.05)
        assert fig["path"]["median_m"] == pytest.approx(np.median(agl), abs=0.05)
        cruise = fig["cruise"]
        assert cruise["median_m"] == pytest.approx(AGL, abs=1.0)
        assert cruise["min_m"] >= AGL - 2.0 - 0.05
        # the mission flies the same heights: its waypoints lie on the file's path
        plan = json.loads((out / f"{prefix}_mission.plan").read_text())
        items = [it for it in plan["mission"]["items"] if it["command"] == 16]
        assert all(it["frame"] == 0 for it in items)  # PX4: altitudes above sea level
        wp = np.array([[it["params"][5], it["params"][4], it["params"][6]] for it in items])
        wagl = wp[:, 2] - _ground_ll(tif, wp[:, 0], wp[:, 1])
        to_m = Transformer.from_crs("EPSG:4326", CRS, always_xy=True)
        pm = np.column_stack(to_m.transform(path[:, 0], path[:, 1]))
        for q, h in zip(np.column_stack(to_m.transform(wp[:, 0], wp[:, 1])), wagl):
            k = int(np.argmin(np.hypot(*(pm - q).T)))
            assert np.hypot(*(pm[k] - q)) < 0.01 and abs(agl[k] - h) < 0.05
        assert np.median(wagl) == pytest.approx(AGL, abs=1.0)
        # trajectories.csv (the common sample times) lies on the same path, same heights
        xyz = np.array([[float(r["x_m"]), float(r["y_m"]), float(r["z_m"])] for r in table
                        if r["uav"] == name])
        lon, lat = Transformer.from_crs(CRS, "EPSG:4326", always_xy=True).transform(
            xyz[:, 0], xyz[:, 1])
        t_agl = xyz[:, 2] - _ground_ll(tif, np.asarray(lon), np.asarray(lat))
        for q, h in zip(xyz[:, :2], t_agl):
            k = int(np.argmin(np.hypot(*(pm - q).T)))
            assert np.hypot(*(pm[k] - q)) < 0.01 and abs(agl[k] - h) < 0.01
        traj[name] = agl
    assert len(traj) == 3
