"""``fm2uav app``: the starting mission from the flags, the flags' errors, --help."""

from __future__ import annotations

from pathlib import Path

import pytest
from typer.testing import CliRunner

from fm2uav.cli import app
from fm2uav.cli.cmd_app import initial_mission
from fm2uav.cli.options import WorldFlags
from tests.app.dem import make_dem, mission_yaml

runner = CliRunner()


def test_help_names_the_options():
    res = runner.invoke(app, ["app", "--help"], env={"COLUMNS": "200"})
    assert res.exit_code == 0
    for flag in ("--port", "--no-browser", "--mission", "--dem", "--buildings", "--bbox",
                 "--dir"):
        assert flag in res.output


def test_the_world_flags_become_the_starting_mission(tmp_path, monkeypatch):
    dem = make_dem(tmp_path / "dem.tif")
    monkeypatch.chdir(tmp_path)
    doc = initial_mission(WorldFlags(dem=[Path("dem.tif")], cell_size=60.0), None, 80.0)
    assert doc == {"version": 1, "name": "mission",
                   "world": {"dem": str(dem), "cell_size": 60.0}, "planner": {"agl": 80.0}}


def test_a_mission_file_starts_the_page_with_absolute_paths(tmp_path, monkeypatch):
    dem = make_dem(tmp_path / "dem.tif")
    mission_yaml(tmp_path / "m.yaml", Path("dem.tif"))
    monkeypatch.chdir(tmp_path.parent)
    doc = initial_mission(WorldFlags(), Path(tmp_path.name) / "m.yaml", 60.0)
    assert doc["world"]["dem"] == str(dem)
    assert doc["start"] == {"lon": 10.3, "lat": 46.03, "agl": 60.0}
    assert doc["outputs"]["formats"] == ["plan", "wpl", "geojson", "json"]


@pytest.mark.parametrize("args, words", [
    (["--dem", "missing.tif"], "--dem = 'missing.tif': file not found"),
    (["--bbox", "1,2,3,4"], "--bbox needs real data"),
    (["--mission", "missing.yaml"], "missing.yaml"),
])
def test_bad_flags_exit_2_before_serving(tmp_path, monkeypatch, args, words):
    monkeypatch.chdir(tmp_path)
    res = runner.invoke(app, ["app", "--no-browser", "--port", "0", *args])
    assert res.exit_code == 2, res.output
    assert words in " ".join(res.output.split())


def test_a_busy_port_is_named(tmp_path, monkeypatch):
    from fm2uav.app import bind

    sock = bind(0)
    port = sock.getsockname()[1]
    monkeypatch.chdir(tmp_path)
    dem = make_dem(tmp_path / "dem.tif")
    try:
        res = runner.invoke(app, ["app", "--no-browser", "--port", str(port), "--dem", str(dem)])
    finally:
        sock.close()
    assert res.exit_code == 2
    assert f"--port {port}: cannot listen on 127.0.0.1:{port}" in " ".join(res.output.split())
