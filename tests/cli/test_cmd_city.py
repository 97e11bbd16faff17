"""`fm2uav reproduce city` (cli/cmd_city.py): its outputs, read back by `fm2uav check`."""

from __future__ import annotations

import json

import pytest
from typer.testing import CliRunner

from fm2uav.cli import app

runner = CliRunner()


@pytest.mark.slow
def test_reproduce_city(tmp_path, cli_once):
    # the same run as tests/e2e/test_reports.py (one run per session, tests/conftest.py)
    run = cli_once(["reproduce", "city", "--rrt-time", "0.5", "--rrtstar-time", "0.3",
                    "--report", "--json"])
    res, out = run.result, run.out
    assert res.exit_code == 0, res.output
    summary = json.loads(res.stdout)
    assert len(summary["table"]) == 6
    assert [r["planner"] for r in summary["rrt"]][0].startswith("FM2")
    for name in ("table.md", "table.csv", "rrt.csv", "low_paths.png", "high_paths.png",
                 "speed_profiles.png", "rrt.png", "low_W0.25.csv"):
        assert (out / name).exists(), name
    # a path written by reproduce city is a valid input of fm2uav check in its world
    res2 = runner.invoke(app, ["check", str(out / "low_W1.csv"), "--scenario", "city",
                               "--out", str(tmp_path / "chk"), "--json"])
    assert res2.exit_code == 0, res2.output
    assert json.loads(res2.stdout)["collision"]["inside_obstacle"] == 0
