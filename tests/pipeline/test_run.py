"""fm2uav.pipeline.run: the run of a mission file, shared by `fm2uav run` and the app."""

from __future__ import annotations

import json

import pytest
from typer.testing import CliRunner

from fm2uav.cli import app
from fm2uav.io.mission import load_mission
from fm2uav.io.outdir import OutputDir
from fm2uav.pipeline.run import run_mission
from fm2uav.progress import reporting
from tests.app.dem import make_dem, mission_yaml


@pytest.fixture(scope="module")
def mission_file(tmp_path_factory):
    root = tmp_path_factory.mktemp("pipeline")
    return mission_yaml(root / "m.yaml", make_dem(root / "dem.tif"))


def test_run_mission_writes_the_set_reports_progress_and_equals_fm2uav_run(mission_file,
                                                                            tmp_path):
    m = load_mission(mission_file)
    events = []
    with OutputDir(tmp_path / "lib") as outdir, reporting(events.append):
        run = run_mission(m, outdir, mission_file=mission_file)
    names = sorted(p.name for p in (tmp_path / "lib").iterdir())
    assert names == ["mission.plan", "mission.waypoints", "path.geojson", "summary.json"]
    assert run.info["safety"]["height_above_ground"]["cruise"]["median_m"] == \
        pytest.approx(60, abs=1)
    assert run.built.waypoints.frame == 0 and run.world_name == "dem.tif"
    msgs = [e.message for e in events]
    assert msgs[0] == "building the world" and "planning (FM²)" in msgs
    assert "planning (FM²): arrival times T (Fast Marching)" in msgs
    assert "writing the mission files: writing the exports: writing mission.plan" in msgs
    assert events[-1].fraction == 1.0
    assert [e.fraction for e in events] == sorted(e.fraction for e in events)
    summary = json.loads((tmp_path / "lib" / "summary.json").read_text())
    assert summary["mission_file"] == str(mission_file)

    res = CliRunner().invoke(app, ["run", str(mission_file), "--out", str(tmp_path / "cli"),
                                   "--quiet"])
    assert res.exit_code == 0, res.output
    for name in ("mission.plan", "mission.waypoints", "path.geojson"):
        assert (tmp_path / "cli" / name).read_bytes() == (tmp_path / "lib" / name).read_bytes()


def test_run_mission_adds_zone_files_and_planner_overrides(mission_file, tmp_path):
    zone = tmp_path / "zone.geojson"
    zone.write_text(json.dumps({"type": "FeatureCollection", "features": [{
        "type": "Feature", "properties": {"name": "range"}, "geometry": {
            "type": "Polygon", "coordinates": [[[10.325, 46.02], [10.33, 46.02],
                                                [10.33, 46.045], [10.325, 46.045],
                                                [10.325, 46.02]]]}}]}))
    m = load_mission(mission_file)
    with OutputDir(tmp_path / "z") as outdir:
        run = run_mission(m, outdir, no_fly=[zone], planner={"max_agl": 120})
    assert [z.name for z in run.resolved.world.zones] == ["range"]
    assert run.info["safety"]["zones"]["path_entries"] == []
    assert run.plan.level.max_agl == 120
