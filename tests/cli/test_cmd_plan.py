"""`fm2uav plan`: outputs, summary, exit codes, no overwrite without --force."""

import json

import numpy as np
from typer.testing import CliRunner

from fm2uav.cli import app
from fm2uav.io import read_path_csv

runner = CliRunner()


def test_plan_writes_outputs_and_refuses_overwrite(tmp_path):
    out = tmp_path / "plan"
    res = runner.invoke(app, ["plan", "--out", str(out)])
    assert res.exit_code == 0, res.output
    for name in ("path.csv", "plan.png", "summary.json"):
        assert (out / name).stat().st_size > 0
    path = read_path_csv(out / "path.csv")
    np.testing.assert_allclose(path[0], [300, 300, 300])
    np.testing.assert_allclose(path[-1], [1500, 1200, 450])
    summary = json.loads((out / "summary.json").read_text())
    assert summary["length_m"] > 1500
    assert (out / "plan.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    before = (out / "path.csv").read_bytes()
    res = runner.invoke(app, ["plan", "--out", str(out), "--exponent", "2"])
    assert res.exit_code == 2
    assert "--force" in res.output
    assert (out / "path.csv").read_bytes() == before
    res = runner.invoke(app, ["plan", "--out", str(out), "--exponent", "2", "--force", "--quiet"])
    assert res.exit_code == 0
    assert res.output.strip() == ""


def test_json_summary_and_cells(tmp_path):
    res = runner.invoke(
        app,
        ["plan", "--out", str(tmp_path), "--start", "20,20,20", "--goal", "100,80,30", "--cells",
         "--json", "--saturation", "0.5"],
    )
    assert res.exit_code == 0, res.output
    data = json.loads(res.output)
    assert data["start_m"] == [300.0, 300.0, 300.0]
    assert data["params"]["saturation"] == 0.5
    assert len(data["files"]) == 3


def test_bad_inputs_exit_2_with_one_line(tmp_path):
    cases = [
        ["--scenario", "moon"],
        ["--start", "20,20,2", "--cells"],
        ["--start", "1,2"],
        ["--exponent", "-1"],
        ["--order", "3"],
        ["--threads", "0"],
        ["--start", "99999,0,0"],
    ]
    for i, extra in enumerate(cases):
        res = runner.invoke(app, ["plan", "--out", str(tmp_path / str(i)), *extra])
        assert res.exit_code == 2, (extra, res.output)
        assert "error:" in res.output and "Traceback" not in res.output
        assert not (tmp_path / str(i) / "path.csv").exists()


def test_help_shows_example():
    res = runner.invoke(app, ["plan", "--help"])
    assert res.exit_code == 0
    assert "fm2uav plan --scenario open-field" in res.output


def test_flight_level_options_reach_the_planner_and_exports(tmp_path):
    res = runner.invoke(app, ["plan", "--agl", "150", "--p1", "0.5", "--p2", "1.3", "--export", "plan",
                              "--out", str(tmp_path), "--json"])
    assert res.exit_code == 0, res.output
    data = json.loads(res.output)
    assert data["params"]["agl"] == 150.0 and data["params"]["p2"] == 1.3
    # terrain-following plans: PX4 (the default) gets AMSL from the DEM, ArduPilot the terrain frame
    assert data["mavlink_frame"] == 0 and data["autopilot"]["frame"]["name"] == "amsl"
    res = runner.invoke(app, ["plan", "--agl", "900", "--out", str(tmp_path / "high")])
    assert res.exit_code == 1 and "leaves the map" in res.output
