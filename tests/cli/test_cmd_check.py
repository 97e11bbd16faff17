"""CLI: fm2uav check (any path file) and fm2uav reproduce city."""

from __future__ import annotations

import json

import numpy as np
import pytest
from typer.testing import CliRunner

from fm2uav.cli import app

runner = CliRunner()


def _write(path, pts, header="x_m,y_m,z_m"):
    path.write_text(header + "\n" + "\n".join(",".join(f"{v:.6f}" for v in p) for p in pts) + "\n")


def test_check_straight_path_is_feasible(tmp_path):
    s = np.linspace(0, 300, 61)
    f = tmp_path / "p.csv"
    _write(f, np.column_stack([s, 0.5 * s, 100 + 0.1 * s]))
    res = runner.invoke(app, ["check", str(f), "--airframe", "disco", "--out", str(tmp_path / "o"),
                              "--json"])
    assert res.exit_code == 0, res.output
    rep = json.loads(res.stdout)
    assert rep["feasible"] is True
    assert rep["tracking"]["max_separation_m"] < 1e-6
    for name in ("report.json", "flown.csv", "check.png"):
        assert (tmp_path / "o" / name).exists()
    # no overwrite without --force
    again = runner.invoke(app, ["check", str(f), "--out", str(tmp_path / "o")])
    assert again.exit_code == 2 and "--force" in again.output


def test_check_tight_circle_infeasible_with_fail_flag(tmp_path):
    th = np.linspace(0, 1.5 * np.pi, 300)
    f = tmp_path / "c.csv"
    _write(f, np.column_stack([5 * np.cos(th), 5 * np.sin(th)]), header="x,y")
    res = runner.invoke(app, ["check", str(f), "--airframe", "disco", "--out", str(tmp_path / "o"),
                              "--fail-infeasible", "--quiet"])
    assert res.exit_code == 1
    rep = json.loads((tmp_path / "o" / "report.json").read_text())
    assert rep["feasible"] is False and rep["geometric"]["feasible"] is False


def test_check_bad_input_exit_2(tmp_path):
    good = tmp_path / "g.csv"
    _write(good, [[0, 0, 0], [10, 0, 0]])
    one = tmp_path / "one.csv"
    _write(one, [[0, 0, 0]])
    nan = tmp_path / "nan.csv"
    nan.write_text("x_m,y_m,z_m\n0,0,0\nnan,1,1\n")
    cases = [
        ([str(good), "--airframe", "concorde"], "unknown airframe"),
        ([str(one)], "at least 2 points"),
        ([str(nan)], "non-finite"),
        ([str(good), "--speed", "-4"], "speed"),
        ([str(tmp_path / "missing.csv")], "does not exist"),
    ]
    for i, (args, msg) in enumerate(cases):
        res = runner.invoke(app, ["check", *args, "--out", str(tmp_path / f"o{i}")])
        assert res.exit_code == 2, (args, res.output)
        assert msg in res.output, (args, res.output)
        assert "Traceback" not in res.output


@pytest.mark.slow
def test_reproduce_city(tmp_path, cli_once):
    # the same run as tests/cli_reports (one run per session, tests/conftest.py)
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
