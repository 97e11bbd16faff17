"""fm2uav reproduce tracking (seed 004 §3.5) on a tiny grid: every path flown by both vehicles."""

from __future__ import annotations

import json

from typer.testing import CliRunner

from fm2uav.cli import app


def test_reproduce_tracking_cli_tiny_grid(tmp_path):
    out = tmp_path / "tracking"
    res = CliRunner().invoke(app, ["reproduce", "tracking", "--step", "0.5", "--pairs", "2",
                                   "--out", str(out), "--sweep-dir", str(tmp_path / "sw"),
                                   "--quiet", "--report"])
    assert res.exit_code == 0, res.output
    html = (out / "report.html").read_text(encoding="utf-8")  # --report: paths and table
    assert 'pair 1"' in html and '"Dubins references"' in html
    assert "Tracking error per pair, vehicle and look-ahead" in html
    s = json.loads((out / "summary.json").read_text())
    assert s["alpha"] in (0.5, 1.0) and s["beta"] in (0.5, 1.0)
    assert s["paths"] == 2 and len(s["rows"]) == 2 * 2 * 2  # pairs x vehicles x look-aheads
    assert s["bound_per_m"] == 0.1
    assert 0 <= s["above_bound"] <= 2
    for g in s["vehicles"].values():
        assert g["reached"] == g["paths"] == 2
        assert 0 <= g["max_error_median_m"] <= g["max_error_max_m"] < 50
    # the seed's 40 m look-ahead cuts corners more than the fixed-wing's own turn radius
    fw40 = s["vehicles"]["fixed-wing, look-ahead 40 m (seed)"]
    fw = s["vehicles"]["fixed-wing, look-ahead default"]
    assert fw40["lookahead_m"] == 40 and fw["lookahead_m"] < 40
    assert fw40["max_error_max_m"] >= fw["max_error_max_m"]
    assert "peak κ raw" in (out / "table.md").read_text()
    # a rerun resumes the sweep (nothing recomputed) and gives the same table
    res2 = CliRunner().invoke(app, ["reproduce", "tracking", "--step", "0.5", "--pairs", "2",
                                    "--out", str(out), "--sweep-dir", str(tmp_path / "sw"),
                                    "--quiet", "--force"])
    assert res2.exit_code == 0, res2.output
    assert json.loads((out / "summary.json").read_text())["rows"] == s["rows"]
