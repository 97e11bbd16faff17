"""`fm2uav reproduce tff` and `fm2uav tune` (cli/cmd_tff.py): outputs, trends, bad input."""

from __future__ import annotations

import json

import pytest
from typer.testing import CliRunner


def _cli(args):
    from fm2uav.cli import app

    return CliRunner().invoke(app, args)


@pytest.mark.slow
def test_reproduce_tff_cli(cli_once):
    # the same run as tests/e2e/test_reports.py (one run per session, tests/conftest.py)
    run = cli_once(["reproduce", "tff", "--report", "--json"])
    r, out = run.result, run.out
    assert r.exit_code == 0, r.output
    table = (out / "tff_table.md").read_text()
    assert table.count("\n| ") >= 7
    data = json.loads((out / "tff_summary.json").read_text())
    cases = {c["case"]: c for c in data["cases"]}
    lvl10 = cases["level 10"]
    assert lvl10["within"] >= 0.8 and lvl10["inside_terrain"] == 0
    # the seeds' trends at level 10: bigger p2 - p1 -> sharper turns and climbs,
    # closer to the layer
    s10, s08 = cases["smooth p2=1.0"], cases["smooth p2=0.8"]
    assert lvl10["turn_max_deg"] > s10["turn_max_deg"] > s08["turn_max_deg"]
    assert lvl10["climb_max_deg"] > s10["climb_max_deg"] > s08["climb_max_deg"]
    assert lvl10["mean_dev_layer_m"] < s08["mean_dev_layer_m"]
    for name in ("tff_3d_levels.png", "tff_kinematics.png", "tff_profile_smoothness.png"):
        assert (out / name).stat().st_size > 10_000
    # no overwrite without --force, and nothing written before the check
    r = _cli(["reproduce", "tff", "--out", str(out), "--quiet"])
    assert r.exit_code == 2 and "already exists" in r.output


def test_cli_bad_input_leaves_no_output(tmp_path):
    out = tmp_path / "bad"
    r = _cli(["tune", "--agl", "900", "--out", str(out), "--quiet"])
    assert r.exit_code in (1, 2) and "leaves the map" in r.output
    assert not out.exists() or not any(out.iterdir())
    r = _cli(["tune", "--p1", "0", "--out", str(out), "--quiet"])
    assert r.exit_code == 2
    r = _cli(["reproduce", "tff", "--mode", "nope", "--out", str(out), "--quiet"])
    assert r.exit_code == 2
    assert not out.exists() or not any(out.iterdir())


def test_tune_cli(tmp_path):
    out = tmp_path / "tune"
    r = _cli(["tune", "--p1", "0.5", "--p2", "0.8,1.3", "--max-climb", "60",
              "--min-turn-radius", "50", "--out", str(out), "--json"])
    assert r.exit_code == 0, r.output
    data = json.loads(r.output[r.output.index("{"):])
    assert data["best"]["p2"] == 0.8
    assert (out / "tune_table.md").exists() and (out / "tune_best_path.csv").exists()
