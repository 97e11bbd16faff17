"""Sweep fault tests (issue 17 item 4): dead workers, killed or interrupted main process,
torn and damaged files, concurrent sweeps, Dask worker deaths. Every test asserts exact
row counts: each case of the grid exactly once in the summary and in the log."""

from __future__ import annotations

import json
import os
import shutil
import signal
import subprocess
import sys
import time
import zlib
from pathlib import Path

import numpy as np
import pytest
import yaml
from typer.testing import CliRunner

from fm2uav.errors import InputError
from fm2uav.experiments._executors import Job, LocalPool
from fm2uav.experiments.runner import LOG_NAME, make_config, run_sweep, sweep_lock
from fm2uav.scenarios.city2d import city2d_pairs

psutil = pytest.importorskip("psutil")

_S, _G = city2d_pairs(3, 0)
PAIRS = [[float(v) for v in (*_S[i], *_G[i])] for i in range(3)]
BETA = {"start": 0.05, "stop": 0.6, "step": 0.05}  # 12 β: a job is one (pair, α) row of 12 cases
SMALL = {"pairs": PAIRS[:2], "alpha": {"start": 0.5, "stop": 1.0, "step": 0.5}, "beta": BETA,
         "models": ["dubins"], "results": "results.csv"}  # 2 x 2 x 12 = 48 cases
LONG = {**SMALL, "alpha": {"start": 0.1, "stop": 1.0, "step": 0.1}}  # 2 x 10 x 12 = 240 cases
N_SMALL, N_LONG = 48, 240
CLI = [sys.executable, "-c", "from fm2uav.cli import main; main()"]
runner = CliRunner()


def _log_rows(out: Path) -> list[dict]:
    """Case rows of the log (checksums verified), header excluded."""
    rows = []
    for line in (out / LOG_NAME).read_bytes().split(b"\n")[1:]:
        if line and zlib.crc32(line[9:]) == int(line[:8], 16):
            rows.append(json.loads(line[9:]))
    return rows


def _keys(rows) -> list[tuple]:
    return [(int(r["pair"]), round(float(r["alpha"]), 10), round(float(r["beta"]), 10)) for r in rows]


def _assert_each_case_once(res, out: Path, n: int) -> None:
    """n cases, all ok, once each in the summary, the results file and the log."""
    cols = res.columns
    assert len(cols["pair"]) == n and set(cols["status"]) == {"ok"}
    assert np.all(np.isfinite(cols["frechet_dubins"])) and np.all(np.isfinite(cols["area_dubins"]))
    keys = _keys([dict(pair=p, alpha=a, beta=b) for p, a, b in zip(cols["pair"], cols["alpha"], cols["beta"])])
    assert len(set(keys)) == n
    log = _log_rows(out)
    assert len(log) == n and len(set(_keys(log))) == n  # no duplicate was appended
    assert len((out / res.config.results).read_text().splitlines()) == 1 + n


def _by_key(cols) -> dict:
    return {k: v for k, v in zip(_keys([dict(pair=p, alpha=a, beta=b) for p, a, b in
                                        zip(cols["pair"], cols["alpha"], cols["beta"])]),
                                 cols["frechet_dubins"])}


@pytest.fixture(scope="module")
def baseline(tmp_path_factory):
    """The LONG sweep run in this process: references and ground-truth metrics."""
    out = tmp_path_factory.mktemp("baseline")
    res = run_sweep(make_config(LONG), out, workers=1)
    _assert_each_case_once(res, out, N_LONG)
    return out, _by_key(res.columns)


def _seed(out: Path, baseline, cfg: dict = LONG) -> Path:
    """A folder of the sweep ``cfg`` that already holds its references (skips that phase)."""
    out.mkdir(parents=True, exist_ok=True)
    shutil.copy(baseline[0] / "references.npz", out / "references.npz")
    (out / "config.json").write_text(json.dumps(make_config(cfg).identity()))
    return out


def _same_values(res, baseline) -> None:
    truth = baseline[1]
    for k, v in _by_key(res.columns).items():
        assert v == pytest.approx(truth[k], rel=1e-9), k


def _wait_for(pred, timeout=90.0, what="condition"):
    t0 = time.monotonic()
    while not pred():
        if time.monotonic() - t0 > timeout:
            raise AssertionError(f"timed out waiting for {what}")
        time.sleep(0.01)


def _n_rows(out: Path) -> int:
    p = out / LOG_NAME
    return max(0, p.read_bytes().count(b"\n") - 1) if p.exists() else 0


def _workers_of(pid: int) -> list:
    try:
        return [c for c in psutil.Process(pid).children(recursive=True)
                if "_worker_main" in " ".join(c.cmdline())]
    except psutil.Error:
        return []


def _cli(cfg: dict, out: Path, *extra: str) -> subprocess.Popen:
    path = out.parent / f"{out.name}.yaml"
    path.write_text(yaml.safe_dump(cfg))
    return subprocess.Popen([*CLI, "sweep", str(path), "--out", str(out), "--workers", "2",
                             "--quiet", *extra], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True)


# ----------------------------------------------------------------- local workers
def _explode(ctx, unit):
    """Test job function: 'boom' kills its own worker, 'bad' raises, others sleep ctx s."""
    if unit == "boom":
        os.kill(os.getpid(), signal.SIGKILL)
    if unit == "bad":
        raise ValueError("bad unit")
    time.sleep(ctx)
    return unit.upper()


@pytest.mark.slow
def test_pool_retries_a_deadly_case_once_then_records_it():
    pool = LocalPool(2)
    try:
        outs = list(pool.run(_explode, [Job(0.01, ["a", "boom", "c", "d"], tag=0),
                                        Job(0.01, ["e", "bad", "f"], tag=1)]))
    finally:
        pool.close()
    by = {o.unit: o for o in outs}
    assert sorted(by) == ["a", "bad", "boom", "c", "d", "e", "f"] and len(outs) == 7
    assert all(by[u].ok and by[u].value == u.upper() and by[u].attempt == 1 for u in "acdef")
    assert not by["bad"].ok and by["bad"].value == "ValueError: bad unit" and by["bad"].attempt == 1
    boom = by["boom"]
    assert not boom.ok and boom.attempt == 2
    assert "died 2 times" in boom.value and "SIGKILL" in boom.value
    assert pool.deaths == 2 and pool.retried == 1 and pool.pids() == []


def test_pool_job_that_cannot_load_fails_its_units(tmp_path, monkeypatch):
    mod = tmp_path / "vanishing_job.py"
    mod.write_text("def double(ctx, unit):\n    return 2 * unit\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    import vanishing_job

    pool = LocalPool(1)
    try:
        assert [o.value for o in pool.run(vanishing_job.double, [Job(None, [1, 2])])] == [2, 4]
        pool.close()  # a fresh worker must import the module again: it is gone now
        mod.unlink()
        outs = list(pool.run(vanishing_job.double, [Job(None, [1, 2, 3])]))
    finally:
        pool.close()
        sys.modules.pop("vanishing_job", None)
    assert len(outs) == 3 and not any(o.ok for o in outs)
    assert all(o.value.startswith("cannot load the job in the worker: ModuleNotFoundError")
               for o in outs)
    assert pool.deaths == 0


@pytest.mark.slow
def test_killed_worker_costs_its_case_only(tmp_path, baseline):
    cfg = make_config(SMALL)
    out = _seed(tmp_path / "s", baseline, SMALL)
    killed: dict = {}

    def on_progress(stage, done, total, failed):
        if stage == "fm2" and done == 1 and not killed:
            last = _log_rows(out)[-1]  # the first case of a job: 11 more to go on that worker
            assert last["beta"] == BETA["start"]
            os.kill(last["worker"], signal.SIGKILL)
            killed.update(last)

    res = run_sweep(cfg, out, workers=2, on_progress=on_progress)
    assert killed
    _assert_each_case_once(res, out, N_SMALL)
    assert res.worker_deaths == 1 and res.cases_retried == 1 and res.cases_run == N_SMALL
    log = _log_rows(out)
    retried = [r for r in log if r["attempts"] == 2]
    assert len(retried) == 1 and sum(r["attempts"] == 1 for r in log) == N_SMALL - 1
    r = retried[0]  # the case the killed worker was running: same job, later β
    assert (r["pair"], r["alpha"]) == (killed["pair"], killed["alpha"]) and r["beta"] > killed["beta"]
    assert r["worker"] != killed["worker"]
    _same_values(res, baseline)


@pytest.mark.slow
def test_worker_killed_in_references_phase(tmp_path):
    cfg = make_config({**SMALL, "pairs": PAIRS})  # 3 references on 2 workers
    out = tmp_path / "r"
    killed = []

    def on_progress(stage, done, total, failed):
        if stage == "references" and done == 1 and not killed:
            # one worker just finished its reference, the other is still searching: kill both
            killed.extend(_workers_of(os.getpid()))
            for p in killed:
                p.kill()

    res = run_sweep(cfg, out, workers=2, on_progress=on_progress)
    assert len(killed) == 2
    refs = res.references
    assert len(refs) == 3 and all(not r["error"] for r in refs.values())
    attempts = sorted(r["attempts"] for r in refs.values())
    # the busy one runs again (a second attempt, its worker's death charged) — unless, on a
    # loaded machine, it finished its reference in the moment between the other's result
    # and the kill: then its result is in the pipe, read before its end, and nobody is charged
    assert attempts in ([1, 1, 2], [1, 1, 1])
    assert res.worker_deaths == attempts.count(2)
    _assert_each_case_once(res, out, 3 * 2 * 12)


# ----------------------------------------------------------------- the main process
@pytest.mark.slow
@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGKILL])
def test_killed_main_process_leaves_no_workers_and_resumes(tmp_path, baseline, sig):
    out = _seed(tmp_path / "m", baseline)
    proc = _cli(LONG, out)
    _wait_for(lambda: _n_rows(out) >= 10 or proc.poll() is not None, what="10 cases")
    workers = _workers_of(proc.pid)
    assert proc.poll() is None, proc.communicate()
    assert len(workers) == 2
    proc.send_signal(sig)
    _, err = proc.communicate(timeout=20)
    gone, alive = psutil.wait_procs(workers, timeout=5)
    assert alive == []
    if sig == signal.SIGTERM:
        assert proc.returncode == 130  # the CLI's "interrupted" code
        assert "interrupted: sweep interrupted by SIGTERM: workers stopped" in err
        assert "resume" in err and err.count("\n") == 1
        assert "Traceback" not in err
    else:
        assert proc.returncode == -signal.SIGKILL
    before = len(set(_keys(_log_rows(out))))
    assert 10 <= before < N_LONG
    res = run_sweep(make_config(LONG), out, workers=1)
    assert res.cases_skipped == before and res.cases_run == N_LONG - before
    _assert_each_case_once(res, out, N_LONG)
    _same_values(res, baseline)


@pytest.mark.slow
def test_main_process_killed_in_references_phase(tmp_path):
    from fm2uav.experiments._store import load_references

    out = tmp_path / "k"
    cfg = {**SMALL, "pairs": PAIRS}  # 3 references on 2 workers, each saved as it is found
    proc = _cli(cfg, out)
    _wait_for(lambda: (out / "references.npz").exists() or proc.poll() is not None,
              what="the first reference")
    workers = _workers_of(proc.pid)
    proc.kill()
    proc.communicate(timeout=20)
    _, alive = psutil.wait_procs(workers, timeout=5)
    assert workers and alive == []
    kept = load_references(out / "references.npz")
    assert 1 <= len(kept) < 3 and _n_rows(out) == 0  # killed in the references phase
    res = run_sweep(make_config(cfg), out, workers=1)
    assert len(res.references) == 3 and all(not r["error"] for r in res.references.values())
    _assert_each_case_once(res, out, 3 * 2 * 12)  # no NaN reported as ok
    for k, r in kept.items():  # the kept references were not searched again
        assert r["time_s"] == res.references[k]["time_s"]


@pytest.mark.slow
def test_sigint_stops_workers_and_keeps_the_cases(tmp_path, baseline):
    from fm2uav.experiments.runner import SweepInterrupted

    out = _seed(tmp_path / "i", baseline)
    workers = []

    def on_progress(stage, done, total, failed):
        if stage == "fm2" and done == 10 and not workers:
            workers.extend(_workers_of(os.getpid()))
            os.kill(os.getpid(), signal.SIGINT)

    with pytest.raises(SweepInterrupted) as info:
        run_sweep(make_config(LONG), out, workers=2, on_progress=on_progress)
    assert info.value.signum == signal.SIGINT and len(workers) == 2
    assert f"of {N_LONG} cases recorded in {out / LOG_NAME}" in str(info.value)
    _, alive = psutil.wait_procs(workers, timeout=5)
    assert alive == [] and _workers_of(os.getpid()) == []
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler  # handlers restored
    before = len(_log_rows(out))
    assert before >= 10
    res = run_sweep(make_config(LONG), out, workers=1)
    assert res.cases_skipped == before and res.cases_run == N_LONG - before
    _assert_each_case_once(res, out, N_LONG)


@pytest.mark.slow
def test_two_sweeps_into_one_folder_are_serialised(tmp_path, baseline):
    out = _seed(tmp_path / "c", baseline)
    code = ("import sys, yaml; from fm2uav.experiments.runner import make_config, run_sweep; "
            "run_sweep(make_config(yaml.safe_load(sys.argv[1])), sys.argv[2], workers=2)")
    first = subprocess.Popen([sys.executable, "-c", code, yaml.safe_dump(LONG), str(out)],
                             stderr=subprocess.PIPE, text=True)  # a sweep from the library
    _wait_for(lambda: _n_rows(out) >= 1 or first.poll() is not None, what="the first sweep")
    with pytest.raises(InputError, match=r"in use by another sweep \(pid \d+"):
        run_sweep(make_config(LONG), out, workers=1)
    from fm2uav.cli import app

    cfg = tmp_path / "c.yaml"
    cfg.write_text(yaml.safe_dump(LONG))
    second = runner.invoke(app, ["sweep", str(cfg), "--out", str(out), "--workers", "1"])
    assert second.exit_code == 2 and "in use by another sweep (pid" in second.output, second.output
    assert "Traceback" not in second.output
    _, err = first.communicate(timeout=120)
    assert first.returncode == 0, err
    rows = _log_rows(out)
    assert len(rows) == N_LONG and len(set(_keys(rows))) == N_LONG
    # the lock died with its holder: a later sweep gets the folder
    with sweep_lock(out):
        pass


# ----------------------------------------------------------------- torn and damaged files
def _finished(tmp_path, baseline, name="t") -> Path:
    out = tmp_path / name
    shutil.copytree(baseline[0], out)
    return out


def test_torn_last_line_loses_only_that_case(tmp_path, baseline):
    out = _finished(tmp_path, baseline)
    log = out / LOG_NAME
    data = log.read_bytes()
    last_start = data.rstrip(b"\n").rfind(b"\n") + 1
    lost = json.loads(data[last_start + 9:].rstrip(b"\n"))
    log.write_bytes(data[: last_start + 40])  # cut mid-line, as a crash mid-write would
    seen = []
    res = run_sweep(make_config(LONG), out, workers=1, on_warning=seen.append)
    assert len(seen) == 1 and "last line is incomplete" in seen[0] and str(log) in seen[0]
    assert res.cases_run == 1 and res.cases_skipped == N_LONG - 1
    _assert_each_case_once(res, out, N_LONG)
    assert _keys(_log_rows(out))[-1] == _keys([lost])[0]  # the lost case, run again, last
    assert log.read_bytes().endswith(b"\n")
    _same_values(res, baseline)


def test_damaged_line_and_nan_row_are_run_again(tmp_path, baseline):
    out = _finished(tmp_path, baseline)
    log = out / LOG_NAME
    lines = log.read_bytes().split(b"\n")
    # flip one digit inside line 7 of the file (checksum mismatch) ...
    i = lines[6].index(b'"length_m":') + 12
    lines[6] = lines[6][:i] + (b"1" if lines[6][i:i + 1] != b"1" else b"2") + lines[6][i + 1:]
    # ... and make line 10 an "ok" row without metrics, with a valid checksum
    row = json.loads(lines[9][9:])
    for k in ("frechet_dubins", "area_dubins"):
        row.pop(k)
    payload = json.dumps(row, sort_keys=True, separators=(",", ":")).encode()
    lines[9] = b"%08x %s" % (zlib.crc32(payload), payload)
    log.write_bytes(b"\n".join(lines))
    seen = []
    res = run_sweep(make_config(LONG), out, workers=1, on_warning=seen.append)
    assert len(seen) == 1 and "1 damaged line(s) (line 7" in seen[0]
    assert res.cases_run == 2 and res.cases_skipped == N_LONG - 2
    assert set(res.columns["status"]) == {"ok"} and len(res.columns["pair"]) == N_LONG
    rows = _log_rows(out)
    assert len(rows) == N_LONG + 1  # 238 good, the NaN row (superseded), 2 re-runs; damaged: skipped
    _same_values(res, baseline)


def test_torn_summary_is_rewritten_from_the_log(tmp_path, baseline):
    out = _finished(tmp_path, baseline)
    csv = out / "results.csv"
    csv.write_bytes(csv.read_bytes()[:5000])
    res = run_sweep(make_config(LONG), out, workers=1)
    assert res.cases_run == 0
    _assert_each_case_once(res, out, N_LONG)


def test_old_streamed_csv_without_log_is_imported(tmp_path, baseline):
    """A folder of the previous fm2uav (streamed results.csv, no log): ok rows are kept,
    a torn last row is dropped with a warning, error rows are run again."""
    out = _finished(tmp_path, baseline)
    (out / LOG_NAME).unlink()
    lines = (out / "results.csv").read_text().splitlines()
    lines[3] = lines[3].replace(",ok,", ",error,")
    (out / "results.csv").write_text("\n".join(lines)[:-7])  # torn last row
    seen = []
    res = run_sweep(make_config(LONG), out, workers=1, on_warning=seen.append)
    assert any("last row is incomplete" in w for w in seen)
    assert res.cases_run == 2 and res.cases_skipped == N_LONG - 2
    _assert_each_case_once(res, out, N_LONG)



@pytest.mark.parametrize("name, damage, fragment", [
    ("config.json", b"{not json", "config.json is damaged (not valid JSON"),
    ("references.npz", b"PK\x03\x04garbage", "references.npz is damaged (BadZipFile"),
    (LOG_NAME, b"garbage\n", "cases.jsonl does not start with a sweep log header"),
])
def test_damaged_sweep_file_is_one_line_error(tmp_path, baseline, name, damage, fragment):
    from fm2uav.cli import app

    out = _finished(tmp_path, baseline)
    (out / name).write_bytes(damage)
    cfg = tmp_path / "c.yaml"
    cfg.write_text(yaml.safe_dump(LONG))
    args = ["sweep", str(cfg), "--out", str(out), "--workers", "1", "--json"]
    r = runner.invoke(app, args)
    assert r.exit_code == 2, r.output
    assert fragment in r.output and "delete it" in r.output
    assert "Traceback" not in r.output and r.output.count("error:") == 1
    (out / name).unlink()  # the fix the message gives: no case is lost
    r = runner.invoke(app, args)
    assert r.exit_code == 0, r.output
    assert json.loads(r.output)["cases"] == {"run": 0, "resumed": N_LONG, "failed": 0}
    assert len((out / "results.csv").read_text().splitlines()) == 1 + N_LONG


def test_damaged_old_csv_is_one_line_error(tmp_path, baseline):
    out = _finished(tmp_path, baseline)
    (out / LOG_NAME).unlink()
    lines = (out / "results.csv").read_text().splitlines()
    lines[5] = lines[5].replace(",ok,", ",ok,oops,")
    (out / "results.csv").write_text("\n".join(lines) + "\n")
    with pytest.raises(InputError, match=r"results.csv is damaged \(line 6: .*delete it"):
        run_sweep(make_config(LONG), out, workers=1)


def test_failed_cases_exit_3_and_retry(tmp_path, baseline):
    from fm2uav.cli import app

    bad = {**SMALL, "pairs": [PAIRS[0], [200.0, 150.0, *PAIRS[1][2:]]]}  # start in a building
    cfg = tmp_path / "bad.yaml"
    cfg.write_text(yaml.safe_dump(bad))
    out = tmp_path / "o"
    args = ["sweep", str(cfg), "--out", str(out), "--workers", "1", "--json"]
    r = runner.invoke(app, args)
    assert r.exit_code == 3, r.output
    assert "24 of 48 cases failed (first: no dubins reference: PointError" in r.output
    summary = json.loads((out / "summary.json").read_text())
    assert summary["cases"] == {"run": 48, "resumed": 0, "failed": 24}
    r = runner.invoke(app, args + ["--keep-failed"])
    assert r.exit_code == 3 and json.loads((out / "summary.json").read_text())["cases"]["run"] == 0
    assert len(_log_rows(out)) == 48
    assert "3 the sweep finished but some cases failed" in " ".join(
        runner.invoke(app, ["sweep", "--help"]).output.split())


# ----------------------------------------------------------------- Dask
@pytest.mark.slow
def test_dask_killed_worker_tasks_rerun(tmp_path, baseline, dask_cluster):
    from fm2uav.experiments._executors import DaskPool

    out = _seed(tmp_path / "d", baseline)
    client = dask_cluster.client

    def on_progress(stage, done, total, failed):
        if stage == "fm2" and done >= 1:
            dask_cluster.kill_a_busy_worker()

    res = run_sweep(make_config(LONG), out, client=client, on_progress=on_progress)
    assert dask_cluster.killed, "no worker was busy"
    _assert_each_case_once(res, out, N_LONG)  # the scheduler ran its tasks again
    _same_values(res, baseline)

    # a case that kills every worker it runs on: its job is split, only it fails
    pool = DaskPool(None, client)
    outs = list(pool.run(_explode, [Job(0.01, ["a", "boom", "c"])]))
    by = {o.unit: o for o in outs}
    assert len(outs) == 3 and by["a"].ok and by["c"].ok
    assert not by["boom"].ok and "KilledWorker" in by["boom"].value


def test_a_signal_deferred_while_closing_is_raised_when_the_block_ends():
    """A Ctrl-C that arrives while the sweep closes its workers is never swallowed."""
    from fm2uav.experiments.runner import SweepInterrupted, raise_on_signals

    with pytest.raises(SweepInterrupted) as exc:
        with raise_on_signals() as signals:
            signals.closing = True  # cleaning up: a signal waits
            os.kill(os.getpid(), signal.SIGINT)
            time.sleep(0.05)  # the handler ran (and deferred it)
            assert signals.pending == signal.SIGINT
    assert exc.value.signum == signal.SIGINT


def test_a_signal_the_parent_ignores_stays_ignored_during_a_sweep():
    """A background job of a shell without job control ignores SIGINT (the terminal's Ctrl-C
    is the foreground's): the sweep must not take it back; SIGTERM still stops it."""
    from fm2uav.experiments.runner import SweepInterrupted, raise_on_signals

    before = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        with pytest.raises(SweepInterrupted) as exc:
            with raise_on_signals():
                assert signal.getsignal(signal.SIGINT) is signal.SIG_IGN
                os.kill(os.getpid(), signal.SIGINT)  # ignored
                time.sleep(0.05)
                os.kill(os.getpid(), signal.SIGTERM)
                time.sleep(5)  # the handler raises here
        assert exc.value.signum == signal.SIGTERM
        assert signal.getsignal(signal.SIGINT) is signal.SIG_IGN
    finally:
        signal.signal(signal.SIGINT, before)
