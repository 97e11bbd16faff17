"""`make bench` writes its table into docs/performance.md and its summary into README.md."""

from __future__ import annotations

import shutil
import sys
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))
from benchmarks import run as bench  # noqa: E402

PAGES = {"table": ROOT / "docs" / "performance.md", "summary": ROOT / "README.md"}

ROWS = [
    {"benchmark": "fmm", "case": "2048x2048 order 1", "ours_s": 0.2, "peer": "scikit-fmm",
     "peer_s": 0.8, "ratio": 4.0, "peak_mb": 100.0, "peer_peak_mb": 140.0, "bar": ">= 3x",
     "notes": "a | b"},
    {"benchmark": "fmm", "case": "160x160x160 order 2", "ours_s": 1.0, "peer": "scikit-fmm",
     "peer_s": 3.5, "ratio": 3.5},
    {"benchmark": "fmm", "case": "2048x2048 FM²-shaped order 1", "ours_s": 0.25,
     "peer": "scikit-fmm", "peer_s": 0.75, "ratio": 3.0},
    {"benchmark": "coldstart", "case": "first `fm2uav plan`, empty numba cache", "ours_s": 11.0,
     "first_output_s": 0.2},
    {"benchmark": "coldstart", "case": "first `fm2uav plan`, numba cache filled", "ours_s": 1.5,
     "first_output_s": 1.2},
    {"benchmark": "cli", "case": "`fm2uav --help`", "ours_s": 0.21, "cpu_s": 0.19,
     "peer": "one-command typer app (framework floor)", "peer_s": 0.18, "ratio": 0.86},
    {"benchmark": "cli", "case": "`fm2uav plan --bogus` (a bad flag)", "ours_s": 0.26,
     "cpu_s": 0.24},
]
REPORT = {"machine": {"python": "3.11", "cpus": 2, "date": "2026-12-01", "load_before": 0.3,
                      "load_after": 0.9}}


@pytest.mark.parametrize("name", sorted(PAGES))
def test_each_page_has_its_bench_block_once(name):
    text = PAGES[name].read_text()
    start, end = bench.marker(name)
    assert text.count(start) == 1 and text.count(end) == 1
    assert text.index(start) < text.index(end)


def test_write_docs_replaces_the_blocks_only(tmp_path):
    (tmp_path / "docs").mkdir()
    for name, page in PAGES.items():
        shutil.copy(page, tmp_path / page.relative_to(ROOT))
    bench.write_docs(ROWS, REPORT, root=tmp_path)
    table = (tmp_path / "docs" / "performance.md").read_text()
    readme = (tmp_path / "README.md").read_text()
    assert "| fmm | 2048x2048 order 1 | 0.2 s | scikit-fmm | 0.8 s | 4.00× | 100 / 140 |" in table
    assert "a \\| b" in table and "machine otherwise idle" in table
    assert "FMM 3.50–4.00× faster than scikit-fmm (160x160x160, 2048x2048, order 1 and 2)" in readme
    assert "3.00× on FM²-shaped maps" in readme  # apart: not mixed into the smooth field's span
    assert "takes 11 s" in readme and "every later one 1.5 s" in readme
    assert ("`fm2uav --help` answers in 0.21 s, `fm2uav plan --bogus` in 0.26 s (warm, CPU "
            "0.19/0.24 s)") in readme
    assert "2 CPUs, load average" in table and "2-core machine (load" in readme  # no model
    assert "| cli | `fm2uav --help` | 0.21 s | one-command typer app (framework floor) |" in table

    # the prose around the blocks is kept, and a second run gives the same pages
    for name, page in PAGES.items():
        before = page.read_text().split(bench.marker(name)[0])[0]
        assert (tmp_path / page.relative_to(ROOT)).read_text().startswith(before)
    bench.write_docs(ROWS, REPORT, root=tmp_path)
    assert (tmp_path / "README.md").read_text() == readme


def test_fill_needs_the_markers():
    with pytest.raises(ValueError):
        bench.fill("no block here", "table", "x")


def test_fm2_shaped_field_is_an_fm2_map():
    from benchmarks import fields

    W, src = fields.fm2_shaped((120, 90))
    again, src2 = fields.fm2_shaped((120, 90))
    np.testing.assert_array_equal(W, again)  # seeded
    assert src == src2 and W[src] >= 0.5
    walls = W == 0
    assert 0.24 < walls.mean() < 0.3  # a quarter of the nodes are obstacles
    assert W.max() == 1.0 and 0 < W[~walls].min() < 0.3  # sqrt(1 / d_max) next to a wall
    assert abs(src[0] / 120 - 0.3) < 0.15 and abs(src[1] / 90 - 0.6) < 0.15  # off-centre
    phi, v = fields.skfmm_point_source(W, src)
    assert phi.mask.sum() == walls.sum() and (v > 0).all()


def test_the_run_names_the_cpu_model(tmp_path):
    """The header and the README's sentence name the processor: the peers' ratios move with
    it. The model read here is the machine's own (``/proc/cpuinfo`` on Linux)."""
    (tmp_path / "docs").mkdir()
    for page in PAGES.values():
        shutil.copy(page, tmp_path / page.relative_to(ROOT))
    model = bench.cpu_model()
    assert isinstance(model, str)
    if Path("/proc/cpuinfo").exists():
        assert model and model in Path("/proc/cpuinfo").read_text()
    report = {"machine": dict(REPORT["machine"], cpu="Test CPU 9000")}
    bench.write_docs(ROWS, report, root=tmp_path)
    table = (tmp_path / "docs" / "performance.md").read_text()
    assert "2 CPUs (Test CPU 9000), load average" in table
    assert "2-core machine (Test CPU 9000) (load" in (tmp_path / "README.md").read_text()
