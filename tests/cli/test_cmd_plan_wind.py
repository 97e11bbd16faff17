"""fm2uav plan / run in a wind: --wind-file and the mission file's wind: {file}."""

from __future__ import annotations

import json

import pytest
from typer.testing import CliRunner

from fm2uav.cli import app

runner = CliRunner()


@pytest.mark.slow
def test_plan_in_a_wind_file_and_a_mission_wind(tmp_path):
    import numpy as np
    import xarray as xr

    lons, lats = np.linspace(-3.80, -3.70, 11), np.linspace(40.30, 40.36, 7)
    ds = xr.Dataset({"u": (("lat", "lon"), np.full((7, 11), 2.0)),
                     "v": (("lat", "lon"), np.full((7, 11), 1.0))},
                    coords={"lat": lats, "lon": lons})
    ds.to_netcdf(tmp_path / "wind.nc")
    res = runner.invoke(app, ["plan", "--export", "plan", "--wind-file", str(tmp_path / "wind.nc"),
                              "--saturation-distance", "100", "--out", str(tmp_path / "p"),
                              "--json"])
    assert res.exit_code == 0, res.output
    s = json.loads((tmp_path / "p" / "summary.json").read_text())
    assert s["params"]["wind"]["kind"] == "grid" and s["params"]["wind"]["refused_nodes"] >= 0
    assert s["autopilot"]["energy"]["wind"]["max_speed_mps"] == pytest.approx(5 ** 0.5, abs=1e-3)
    ex = runner.invoke(app, ["export", str(tmp_path / "p" / "path.csv"), "--scenario",
                             "open-field", "--wind-file", str(tmp_path / "wind.nc"), "--out",
                             str(tmp_path / "e"), "--json"])
    assert ex.exit_code == 0, ex.output
    e = json.loads((tmp_path / "e" / "summary.json").read_text())["autopilot"]["energy"]
    assert e["wind"]["kind"] == "grid" and e["wind"]["source"] == "wind.nc: u/v"
    both = runner.invoke(app, ["plan", "--wind", "3@90", "--wind-file", str(tmp_path / "wind.nc"),
                               "--out", str(tmp_path / "q")])
    assert both.exit_code == 2 and "not both" in both.output
    (tmp_path / "m.yaml").write_text(
        "world: {scenario: open-field}\nplanner: {saturation_distance: 100}\n"
        "wind: {file: wind.nc}\noutputs: {formats: [plan, json]}\n")
    run = runner.invoke(app, ["run", str(tmp_path / "m.yaml"), "--out", str(tmp_path / "r"),
                              "--json"])
    assert run.exit_code == 0, run.output
    r = json.loads((tmp_path / "r" / "summary.json").read_text())
    assert r["params"]["wind"]["source"].startswith("wind.nc: u/v")
