"""fm2uav.app.worker: the jobs' functions, in this process (the same code the worker runs)."""

from __future__ import annotations

import shlex

import pytest
from typer.testing import CliRunner

from fm2uav.app.session import Session
from fm2uav.app.worker import run_job
from fm2uav.cli import app

from .dem import make_dem

AREA = [[10.318, 46.027], [10.328, 46.027], [10.328, 46.031], [10.318, 46.031]]


@pytest.mark.slow
def test_a_cover_job_writes_what_its_command_line_writes(tmp_path, monkeypatch):
    dem = make_dem(tmp_path / "dem.tif")
    s = Session(tmp_path / "session", {}, tmp_path / "m.yaml")
    body = {"mission": {"world": {"dem": str(dem)},
                        "no_fly_zones": [{"circle": {"center": [10.35, 46.03], "radius": 120.0},
                                          "lonlat": True, "name": "mast", "buffer": 10.0}],
                        "airframe": {"firmware": "ardupilot", "hover_speed": 6.0},
                        "outputs": {"thin_tolerance": 3.0}},
            "area": AREA,
            "cover": {"agl": 80.0, "camera": [13.2, 8.8, 8.8, 5472, 3648], "side_overlap": 0.2,
                      "front_overlap": 0.6}}
    payload = s.cover_job("1", body)
    events = []
    state, result = run_job("cover", payload, events.append)
    assert state == "done", result
    kinds = [f["properties"]["kind"] for f in result["map"]["features"]]
    assert kinds.count("area") == 1 and kinds.count("band") == result["map"]["summary"]["bands"]
    assert kinds.count("photo") == result["map"]["summary"]["photos"] > 20
    assert result["map"]["summary"]["gsd_cm_per_px"] == pytest.approx(2.19, abs=0.01)
    assert "report.html" in result["files"] and "coverage.html" in result["files"]
    assert any(e[0] == "progress" and "steering angle" in e[2] for e in events)
    # the command line the page shows writes the same mission, byte for byte
    folder, command = result["command"].split(" && ")
    argv = shlex.split(command)
    assert argv[:2] == ["fm2uav", "cover"] and "--camera" in argv and "--no-fly" in argv
    monkeypatch.chdir(shlex.split(folder)[1])
    res = CliRunner().invoke(app, [*argv[1:-1], "cli", "--quiet"])
    assert res.exit_code == 0, res.output
    job = tmp_path / "session" / "jobs" / "1"
    for name in ("mission.plan", "mission.waypoints", "path.geojson"):
        assert (job / "cli" / name).read_bytes() == (job / "out" / name).read_bytes(), name


def test_a_cover_job_needs_an_area_and_one_of_spacing_or_camera(tmp_path):
    from fm2uav.errors import InputError

    s = Session(tmp_path, {}, tmp_path / "m.yaml")
    with pytest.raises(InputError, match="draw the survey area first"):
        s.cover_job("1", {"mission": {}, "area": [], "cover": {"agl": 80}})
    dem = make_dem(tmp_path / "dem.tif")
    payload = s.cover_job("2", {"mission": {"world": {"dem": str(dem)}}, "area": AREA,
                                "cover": {"agl": 80.0}})
    state, (message, code) = run_job("cover", payload)
    assert (state, code) == ("error", 2)
    assert message == "give exactly one of --spacing (metres) or --camera"


def test_an_internal_error_says_it_is_a_bug(tmp_path):
    state, (message, code) = run_job("plan", {"mission_file": None, "out": str(tmp_path)})
    assert (state, code) == ("error", 70)
    assert message.startswith("internal error: TypeError") and "this is a bug" in message
