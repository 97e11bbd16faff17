"""A .plan names its sources by file name: the same mission gives the same bytes from any folder."""

from __future__ import annotations

import json
import shutil

from typer.testing import CliRunner

from fm2uav.cli import app
from tests.app.dem import make_dem, mission_yaml


def test_the_plan_does_not_depend_on_where_the_mission_was_run_from(tmp_path, monkeypatch):
    a = tmp_path / "a"
    a.mkdir()
    make_dem(a / "dem.tif")
    mission_yaml(a / "m.yaml", "dem.tif")
    b = tmp_path / "deeper" / "b"
    shutil.copytree(a, b)
    runner = CliRunner()
    monkeypatch.chdir(tmp_path)
    assert runner.invoke(app, ["run", "a/m.yaml", "--out", "oa", "--quiet"]).exit_code == 0
    monkeypatch.chdir(b)
    assert runner.invoke(app, ["run", str(b / "m.yaml"), "--out", str(tmp_path / "ob"),
                               "--quiet"]).exit_code == 0
    pa, pb = (tmp_path / "oa" / "mission.plan"), (tmp_path / "ob" / "mission.plan")
    assert pa.read_bytes() == pb.read_bytes()
    src = json.loads(pa.read_text())["fm2uav"]["georef"]["sources"][0]
    assert src["path"] == "dem.tif" and len(src["sha256"]) == 64
    summary = json.loads((tmp_path / "ob" / "summary.json").read_text())
    assert summary["world"]["georef"]["sources"][0]["path"] == str(b / "dem.tif")  # full there
