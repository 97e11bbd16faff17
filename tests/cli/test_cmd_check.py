"""`fm2uav check` (cli/cmd_check.py): any path file, its outputs and exit codes."""

from __future__ import annotations

import json

import numpy as np
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
        ([str(nan)], "not a finite number"),
        ([str(good), "--speed", "-4"], "speed"),
        ([str(tmp_path / "missing.csv")], "not found"),
    ]
    for i, (args, msg) in enumerate(cases):
        res = runner.invoke(app, ["check", *args, "--out", str(tmp_path / f"o{i}")])
        assert res.exit_code == 2, (args, res.output)
        assert msg in res.output, (args, res.output)
        assert "Traceback" not in res.output
