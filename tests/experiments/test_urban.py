"""fm2uav reproduce urban (thesis §4.4): the levels are kept, smoothness follows p2 − p1."""

from __future__ import annotations

import json

import numpy as np
from typer.testing import CliRunner

from fm2uav.cli import app
from fm2uav.experiments.urban import URBAN_MARGIN, urban_seed, urban_world, _points
from fm2uav.world.clearance import clearance_profile


def test_seed_keeps_the_margin_and_the_layers_fit():
    seed = urban_seed()
    w = urban_world(seed)
    s, g = _points(w)
    assert clearance_profile(w, np.array([s, g])).min() >= URBAN_MARGIN
    assert seed == 1  # seed 0 has a building on the thesis' start
    assert not w.occupancy[w.to_cell(s)] and not w.occupancy[w.to_cell(g)]


def test_reproduce_urban_cli_writes_the_table_and_the_thesis_story_holds(tmp_path):
    out = tmp_path / "urban"
    res = CliRunner().invoke(app, ["reproduce", "urban", "--out", str(out), "--quiet",
                                   "--report"])
    assert res.exit_code == 0, res.output
    html = (out / "report.html").read_text(encoding="utf-8")  # --report: six paths, the table
    assert '"case 6: level 30 (p1=0.5, p2=1.5)"' in html
    assert "Flight levels (thesis §4.4)" in html
    rows = json.loads((out / "summary.json").read_text())["cases"]
    assert len(rows) == 6 and (out / "case6.csv").exists()
    assert "plan, warm [s]" in (out / "table.md").read_text()
    levels, smooth = rows[:3], rows[3:]
    # §4.4.1: every level is kept between the transitions, with abrupt climbs
    assert all(r["within"] >= 0.95 and r["within_all"] >= 0.7 for r in levels)
    assert all(r["climb_max_deg"] > 60 for r in levels)
    # §4.4.2: a larger p2 − p1 keeps more of the path on the level, with steeper climbs
    share = [r["within_all"] for r in smooth]
    climb = [r["climb_max_deg"] for r in smooth]
    assert share == sorted(share) and share[-1] - share[0] > 0.15
    assert climb == sorted(climb) and climb[0] < 35 and climb[-1] > 60
    assert all(r["clearance_m"] > 5 for r in rows)
