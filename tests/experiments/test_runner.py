"""Sweep runner: streaming results, resume, recorded failures, Dask, CLI."""

import json

import numpy as np
import pytest
from typer.testing import CliRunner

from fm2uav.experiments.runner import load_config, make_config, run_sweep
from fm2uav.errors import InputError
from fm2uav.scenarios.city2d import city2d_pairs

BAD = [200.0, 150.0]  # inside the Centre Pompidou


def _config(results="r.csv", bad=True):
    s, g = city2d_pairs(2, 0)
    pairs = [[*s[0], *g[0]], [*s[1], *g[1]]]
    if bad:
        pairs[1] = [*BAD, *g[1]]
    return make_config({
        "pairs": pairs,
        "alpha": {"start": 0.5, "stop": 1.0, "step": 0.5},
        "beta": {"start": 0.4, "stop": 0.8, "step": 0.4},
        "models": ["dubins"],
        "results": results,
    })


def test_run_resume_and_failures(tmp_path):
    cfg = _config()
    seen = []
    res = run_sweep(cfg, tmp_path, workers=1, on_progress=lambda *a: seen.append(a))
    cols = res.columns
    assert res.cases_run == 8 and res.cases_skipped == 0
    assert len(cols["pair"]) == 8
    ok = cols["status"] == "ok"
    assert np.all(ok[cols["pair"] == 0]) and not np.any(ok[cols["pair"] == 1])
    assert all("PointError" in e for e in cols["error"][cols["pair"] == 1])
    assert res.references[(1, "dubins")]["error"].startswith("PointError")
    assert np.all(cols["frechet_dubins"][ok] > 0)
    assert seen[-1] == ("fm2", 8, 8, 4)
    assert all(e.startswith("no dubins reference: PointError") for e in cols["error"][~ok])
    text = (tmp_path / "r.csv").read_text().splitlines()
    assert len(text) == 9  # summary: header + one line per case
    assert len((tmp_path / "cases.jsonl").read_text().splitlines()) == 9  # log: header + 8 cases

    # a resume re-runs the failed cases (and their failed reference) by default; failures that
    # repeat word for word are not appended to the log again
    again = run_sweep(cfg, tmp_path, workers=1)
    assert again.cases_run == 4 and again.cases_skipped == 4 and again.cases_failed == 4
    np.testing.assert_allclose(np.sort(again.columns["frechet_dubins"][again.columns["status"] == "ok"]),
                               np.sort(cols["frechet_dubins"][ok]), rtol=1e-12)
    assert len((tmp_path / "r.csv").read_text().splitlines()) == 9
    assert len((tmp_path / "cases.jsonl").read_text().splitlines()) == 9

    keep = run_sweep(cfg, tmp_path, workers=1, retry_failed=False)
    assert keep.cases_run == 0 and keep.cases_skipped == 8 and keep.cases_failed == 4

    other = _config(bad=False)
    with pytest.raises(InputError, match="different configuration"):
        run_sweep(other, tmp_path, workers=1)
    fresh = run_sweep(other, tmp_path, workers=1, fresh=True)
    assert fresh.cases_run == 8 and fresh.cases_failed == 0


def test_resume_after_partial_run(tmp_path):
    cfg = _config(bad=False)
    full = run_sweep(cfg, tmp_path / "a", workers=1)
    # simulate an interrupted run: the log's header and first 3 cases, no summary yet
    (tmp_path / "b").mkdir()
    for name in ("config.json", "references.npz"):
        (tmp_path / "b" / name).write_bytes((tmp_path / "a" / name).read_bytes())
    lines = (tmp_path / "a" / "cases.jsonl").read_text().splitlines()
    (tmp_path / "b" / "cases.jsonl").write_text("\n".join(lines[:4]) + "\n")
    part = run_sweep(cfg, tmp_path / "b", workers=1)
    assert part.cases_skipped == 3 and part.cases_run == 5
    assert len((tmp_path / "b" / "cases.jsonl").read_text().splitlines()) == 1 + 8

    def key(c):
        order = np.lexsort((c["beta"], c["alpha"], c["pair"]))
        return c["frechet_dubins"][order]

    np.testing.assert_allclose(key(part.columns), key(full.columns), rtol=1e-12)


def test_dask_local_cluster_and_parquet(tmp_path):
    distributed = pytest.importorskip("dask.distributed")
    pytest.importorskip("pyarrow")
    cfg_local = _config(bad=False)
    local = run_sweep(cfg_local, tmp_path / "local", workers=1)
    cfg = _config(results="r.parquet", bad=False)
    with distributed.LocalCluster(n_workers=1, threads_per_worker=2, processes=False,
                                  dashboard_address=None) as cluster, \
            distributed.Client(cluster) as client:
        res = run_sweep(cfg, tmp_path / "dask", client=client)
    assert res.cases_run == 8
    import pyarrow.parquet as pq

    table = pq.read_table(tmp_path / "dask" / "r.parquet")  # one file, written at the end
    assert table.num_rows == 8 and set(table.column("status").to_pylist()) == {"ok"}

    def key(c):
        order = np.lexsort((c["beta"], c["alpha"], c["pair"]))
        return c["area_dubins"][order]

    np.testing.assert_allclose(key(res.columns), key(local.columns), rtol=1e-12)
    again = run_sweep(cfg, tmp_path / "dask", workers=1)
    assert again.cases_run == 0 and again.cases_skipped == 8


def test_config_errors(tmp_path):
    p = tmp_path / "c.yaml"
    p.write_text("models: [bicycle]\n")
    with pytest.raises(InputError, match="models"):
        load_config(p)
    p.write_text("alpha: {start: 0.1, stop: 1.0, step: 0.1}\nbogus: 1\n")
    with pytest.raises(InputError, match="bogus"):
        load_config(p)
    with pytest.raises(InputError, match="not found"):
        load_config(tmp_path / "missing.yaml")


@pytest.mark.slow
def test_cli_sweep_and_resume(tmp_path):
    from fm2uav.cli import app

    s, g = city2d_pairs(1, 3)
    cfg = tmp_path / "sweep.yaml"
    cfg.write_text(
        "pairs: [[%f, %f, %f, %f]]\n" % (*s[0], *g[0])
        + "alpha: {start: 0.5, stop: 1.0, step: 0.5}\n"
        + "beta: {start: 0.5, stop: 1.0, step: 0.5}\n"
        + "models: [dubins]\nresults: results.csv\n"
    )
    out = tmp_path / "out"
    runner = CliRunner()
    r = runner.invoke(app, ["sweep", str(cfg), "--out", str(out), "--workers", "1", "--json",
                            "--report"])
    assert r.exit_code == 0, r.output
    summary = json.loads(r.output)
    assert summary["cases"] == {"run": 4, "resumed": 0, "failed": 0}
    for name in ("tables.md", "heatmap_frechet.png", "heatmap_area.png", "curvature_area.png",
                 "best_paths_area.png", "results.csv", "report.html"):
        assert (out / name).exists()
    html = (out / "report.html").read_text(encoding="utf-8")  # --report (README: every command)
    assert "best area vs Dubins, pair 1" in html and "Dubins references" in html
    assert "Best (α, β) per metric and model" in html
    assert "Table 3" in (out / "tables.md").read_text()
    kept = {n: (out / n).read_bytes() for n in ("cases.jsonl", "references.npz", "results.csv")}
    r = runner.invoke(app, ["sweep", str(cfg), "--out", str(out), "--workers", "1", "--json"])
    assert r.exit_code == 0, r.output
    assert json.loads(r.output)["cases"] == {"run": 0, "resumed": 4, "failed": 0}
    # the report is rewritten, the sweep's own files stay (the report set is merged in)
    assert {n: (out / n).read_bytes() for n in kept} == kept
    assert (out / "tables.md").exists() and not [p for p in out.parent.iterdir() if ".tmp-" in p.name]
    bad = tmp_path / "bad.yaml"
    bad.write_text("xi: -1\n")
    r = runner.invoke(app, ["sweep", str(bad), "--out", str(tmp_path / "o2")])
    assert r.exit_code == 2


def test_size_limits_refused_up_front_as_the_doc_says(tmp_path):
    """docs/sweeps.md's limits are the code's, and its example message is the one printed."""
    import re
    from pathlib import Path

    from fm2uav.experiments.runner import MAX_SWEEP_CASES, MAX_SWEEP_PAIRS

    doc = (Path(__file__).resolve().parents[2] / "docs" / "sweeps.md").read_text()
    flat = " ".join(doc.split())
    assert f"more than {MAX_SWEEP_CASES:,} cases" in flat
    assert f"more than {MAX_SWEEP_PAIRS} pairs" in flat
    shown = re.search(r"error: huge.yaml: (the sweep would have .*)", doc).group(1)
    cfg = tmp_path / "huge.yaml"
    cfg.write_text("pairs: 1000\nalpha: {start: 1e-7, stop: 1, step: 1e-7}\n"
                   "beta: {start: 1e-7, stop: 1, step: 1e-7}\n")
    with pytest.raises(InputError) as err:
        load_config(cfg)  # counted, never made: 1e7 values a side would be 80 MB each
    assert str(err.value) == f"{cfg}: {shown}"
    with pytest.raises(InputError, match="1001 pairs would need"):
        make_config({"pairs": 1001})
    for bad in ({"pairs": True}, {"cell": "2"}, {"xi": float("nan")}, {"order": 2.5},
                {"alpha": {"start": 0.5, "stop": 0.1}}):
        with pytest.raises(InputError):
            make_config(bad)
