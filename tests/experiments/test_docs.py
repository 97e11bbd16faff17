"""The generated blocks of docs/ match a fresh run (fm2uav.experiments.docs)."""

from __future__ import annotations

import re

import numpy as np
import pytest

from fm2uav.experiments import docs
from fm2uav.experiments.sweep import near_best


def test_every_block_has_its_markers_and_every_marker_a_block():
    found = {}
    for page in docs.DOCS.glob("*.md"):
        for name in docs.blocks_in(page.read_text()):
            found[name] = page.name
        # a marker whose closing half is missing or misspelt would be left out silently
        text = page.read_text()
        assert len(re.findall(r"<!-- generated:", text)) == len(re.findall(r"<!-- /generated:", text)), page
    assert set(found) == set(docs.BLOCKS)
    for name, block in docs.BLOCKS.items():
        assert found[name] == block.page
        assert "PLACEHOLDER" not in docs.blocks_in((docs.DOCS / block.page).read_text())[name]


def test_fill_replaces_only_the_named_block():
    start, end = docs.marker("a")
    s2, e2 = docs.marker("b")
    text = f"x\n{start}\nold\n{end}\ny\n{s2}\nkeep\n{e2}\n"
    out = docs.fill(text, {"a": "new\nlines"})
    assert docs.blocks_in(out) == {"a": "new\nlines", "b": "keep"}
    assert out.startswith("x\n") and "\ny\n" in out


def test_normalise_blanks_time_columns_only():
    body = "| case | length [m] | plan, warm [s] |\n|---|---|---|\n| a | 12 | 0.25 |"
    other = body.replace("0.25", "0.31")
    assert docs.normalise(body) == docs.normalise(other)
    assert docs.normalise(body) != docs.normalise(body.replace("| 12 |", "| 13 |"))
    rows = body + "\n| b | 7 | 1.0 |"
    assert "| b |" not in docs.normalise(rows, exact_rows=("a",))


def test_inexact_blocks_compare_wording_not_numbers():
    b = docs.Block("x.md", lambda: "", exact=False)
    assert docs._key("keeps 3.7 m, 1 of 3", b) == docs._key("keeps 6.9 m, 2 of 3", b)
    assert docs._key("keeps 3.7 m", b) != docs._key("stays 3.7 m", b)


def test_fast_blocks_match_a_fresh_run():
    names = [n for n, b in docs.BLOCKS.items() if not b.slow]
    assert names
    assert docs.check(names) == []


#: the slow blocks by the run they share (``docs._city()``, ``docs._curvature()``, ...): one
#: test case per run, so that pytest-xdist's workers make them side by side
SLOW_RUNS = {
    "tff-jacksboro": ["tff-jacksboro"],
    "tff-readings-jacksboro": ["tff-readings-jacksboro"],
    "urban": ["urban-table"],
    "city": ["city-table", "city-rrt", "city-claims", "city-rrt-claims"],
    "formation": ["formation-table"],
    "curvature": ["curvature-results", "curvature-timing", "tracking"],
}


def test_the_slow_runs_hold_every_slow_block_once():
    listed = [n for names in SLOW_RUNS.values() for n in names]
    assert sorted(listed) == sorted(n for n, b in docs.BLOCKS.items() if b.slow)


@pytest.mark.slow
@pytest.mark.parametrize("run", SLOW_RUNS)
def test_slow_blocks_match_a_fresh_run(run):
    assert docs.check(SLOW_RUNS[run]) == []


def test_near_best_reports_the_flat_valley():
    a = np.array([0.1, 0.2, 0.3])
    b = np.array([0.5, 0.6, 0.7])
    m = np.array([[2.0, 1.004, 1.0], [1.009, 1.5, np.inf], [1.02, np.nan, 3.0]])
    r = near_best(m, a, b)
    assert r["count"] == 3
    assert r["points"][0] == (0.1, 0.7)           # the argmin first
    assert (r["alpha_min"], r["alpha_max"], r["beta_min"], r["beta_max"]) == (0.1, 0.2, 0.5, 0.7)
    assert r["share"] == pytest.approx(3 / 7)
    assert near_best(m, a, b, tolerance=0.0)["count"] == 1
    assert near_best(m, a, b, tolerance=0.05)["count"] == 4
