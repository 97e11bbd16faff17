"""fm2uav.pipeline.batch: many mission files on the sweep's executors (issue 27, deliverable 5).

Every mission of a batch is written once, whole, equal to ``fm2uav run FILE`` (byte for byte
but summary.json's timings), by the main process; a worker killed mid-mission costs its
mission one attempt on another worker, and nothing is lost, duplicated or left half-written.
"""

from __future__ import annotations

import json
import os
import signal
import time
from pathlib import Path

import pytest
import yaml
from typer.testing import CliRunner

from fm2uav.cli import app
from fm2uav.errors import InputError
from fm2uav.experiments._executors import InlinePool, LocalPool, make_pool
from fm2uav.pipeline.batch import (
    BATCH_FILE,
    mission_files,
    plan_mission_files,
    prepare_batch,
    run_batch,
)

from .batch_missions import same_as_single_run, write_missions

runner = CliRunner()


@pytest.fixture(scope="module")
def missions(tmp_path_factory):
    """The tiny missions, and each ok one run alone with ``fm2uav run FILE``."""
    root = tmp_path_factory.mktemp("batch")
    files = write_missions(root / "m")
    single = {}
    for name in ("east", "north", "far", "big"):
        single[name] = root / "single" / name
        res = runner.invoke(app, ["run", str(files[name]), "--out", str(single[name]),
                                  "--quiet"])
        assert res.exit_code == 0, res.output
    return files, single


def _leftovers(folder: Path) -> list[str]:
    """Temporary, old or lock entries of output sets anywhere under ``folder``."""
    return [str(p) for p in folder.rglob(".*")]


def test_a_worker_removes_the_private_folders_of_dead_workers_only(tmp_path):
    import subprocess
    import sys

    from fm2uav.pipeline.batch import _remove_stale_work

    dead = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"],
                          capture_output=True, text=True, check=True).stdout.strip()
    alive = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(60)"])
    try:
        folders = {name: tmp_path / f"fm2uav-batch-{name}-abc" for name in
                   (dead, str(alive.pid), str(os.getpid()), "x1")}
        for d in folders.values():
            (d / "set").mkdir(parents=True)
        (tmp_path / "fm2uav-batch-other").mkdir()  # not a worker folder: no pid
        assert _remove_stale_work(tmp_path) == [folders[dead]]
        assert sorted(p.name for p in tmp_path.iterdir()) == sorted(
            [f"fm2uav-batch-{alive.pid}-abc", f"fm2uav-batch-{os.getpid()}-abc",
             "fm2uav-batch-x1-abc", "fm2uav-batch-other"])
    finally:
        alive.kill()
        alive.wait()


# ----------------------------------------------------------------- before any work
def test_mission_files_reads_folders_in_name_order_and_keeps_each_file_once(tmp_path):
    files = write_missions(tmp_path / "m", names=("north", "east"))
    (tmp_path / "m" / "notes.txt").write_text("not a mission")
    (tmp_path / "m" / "c.YML").write_text("version: 1\n")
    got = mission_files([files["north"], tmp_path / "m", str(files["east"])])
    assert got == [files["north"], tmp_path / "m" / "c.YML", files["east"]]
    with pytest.raises(InputError, match=r"mission file .*nope.yaml does not exist"):
        mission_files([files["east"], tmp_path / "nope.yaml"])
    (tmp_path / "empty").mkdir()
    with pytest.raises(InputError, match=r"folder .*empty holds no mission file"):
        mission_files([tmp_path / "empty"])
    with pytest.raises(InputError, match="no mission file given"):
        mission_files([])


def test_prepare_batch_places_each_mission_and_refuses_clashes_before_any_work(tmp_path):
    files = write_missions(tmp_path / "m", names=("east", "north"))
    own = yaml.safe_load(files["north"].read_text())
    own["outputs"]["dir"] = "mine"  # relative to the mission file, like fm2uav run
    files["north"].write_text(yaml.safe_dump(own))
    broken = tmp_path / "m" / "broken.yaml"
    broken.write_text("version: 1\nname: x\nworld: {scenario: open-field}\nstart: [1, 2]\n")
    out = tmp_path / "out"
    todo, results = prepare_batch([tmp_path / "m"], out, report=True)
    assert [r.file for r in results] == [str(broken), str(files["east"]), str(files["north"])]
    assert [r.status for r in results] == ["failed", "not run", "not run"]
    assert results[0].exit_code == 2 and "start" in results[0].error
    assert [(m.index, m.out) for m in todo] == [(1, str(out / "east")),
                                                (2, str(tmp_path / "m" / "mine"))]
    assert todo[0].formats[-1] == "html" and todo[0].path == os.path.abspath(files["east"])
    assert not out.exists() and _leftovers(tmp_path) == []  # checked, nothing written

    # two files of one name in two folders would write one folder
    other = write_missions(tmp_path / "other", names=("east",))
    with pytest.raises(InputError, match=r"east.yaml and .*other/east.yaml would both write"):
        prepare_batch([files["east"], other["east"]], out)
    # an existing folder (or an earlier batch.json) needs --force
    (out / "east").mkdir(parents=True)
    (out / "east" / "path.csv").write_text("old")
    with pytest.raises(InputError, match=r"east/path.csv already exists.*--force"):
        prepare_batch([files["east"]], out)
    (out / BATCH_FILE).write_text("{}")
    with pytest.raises(InputError, match=r"batch.json already exists.*--force"):
        prepare_batch([files["east"]], out)
    assert len(prepare_batch([files["east"]], out, force=True)[0]) == 1
    assert (out / "east" / "path.csv").read_text() == "old"


def test_a_failing_mission_is_a_result_not_an_exception(missions, tmp_path):
    files, _ = missions
    todo, _ = prepare_batch([files["outside"]], files["outside"].parent / "o")
    value = plan_mission_files({"cwd": os.getcwd()}, todo[0])
    assert value["ok"] is False and value["exit_code"] == 2
    assert "goal" in value["error"] and "outside the map" in value["error"]
    assert "files" not in value and value["time_s"] > 0


# ----------------------------------------------------------------- the batch
def test_batch_in_this_process_writes_each_mission_as_fm2uav_run(missions, tmp_path):
    files, single = missions
    out = tmp_path / "out"
    todo, results = prepare_batch([files["north"], files["outside"], files["east"]], out)
    seen = []
    run_batch(todo, results, make_pool(1), on_result=lambda r: seen.append(r.file))
    assert sorted(seen) == sorted(str(files[n]) for n in ("north", "outside", "east"))
    assert [r.status for r in results] == ["ok", "failed", "ok"]
    assert results[1].exit_code == 2 and "outside the map" in results[1].error
    assert results[1].files == [] and not (out / "outside").exists()
    for name in ("north", "east"):
        same_as_single_run(out / name, single[name])
    assert results[0].files == [str(out / "north" / n) for n in sorted(
        p.name for p in (out / "north").iterdir())]
    assert results[0].length_m > 0 and results[0].waypoints >= 2 and results[0].attempt == 1
    assert _leftovers(out) == []


def _workers_of(pid: int) -> list:
    psutil = pytest.importorskip("psutil")
    return [c for c in psutil.Process(pid).children(recursive=True)
            if "_worker_main" in " ".join(c.cmdline())]


def _wait_for(pred, timeout=120.0, what="condition"):
    t0 = time.monotonic()
    while not pred():
        if time.monotonic() - t0 > timeout:
            raise AssertionError(f"timed out waiting for {what}")
        time.sleep(0.01)


@pytest.mark.slow  # four missions on two worker processes, one of them killed
def test_a_worker_killed_mid_mission_costs_one_attempt_and_nothing_else(missions, tmp_path,
                                                                       monkeypatch):
    pytest.importorskip("psutil")
    files, single = missions
    work_tmp = tmp_path / "worker-tmp"  # where the workers plan (their private folders)
    work_tmp.mkdir()
    monkeypatch.setenv("TMPDIR", str(work_tmp))
    out = tmp_path / "out"
    # the failing mission first: its result comes back while the other worker plans `big`
    order = ["outside", "big", "east", "north", "far"]
    todo, results = prepare_batch([files[n] for n in order], out)
    pool = LocalPool(2)
    killed: dict = {}

    def on_result(res):
        if killed:
            return
        assert res.file == str(files["outside"]) and res.status == "failed"
        _wait_for(lambda: any(work_tmp.glob("fm2uav-batch-*")), what="a mission under way")
        victim = next(p for p in _workers_of(os.getpid()) if p.pid != res.worker)
        os.kill(victim.pid, signal.SIGKILL)
        killed["pid"] = victim.pid

    run_batch(todo, results, pool, on_result=on_result)
    assert killed
    by = {Path(r.file).stem: r for r in results}
    assert [r.status for r in results] == ["failed", "ok", "ok", "ok", "ok"]
    assert pool.deaths == 1 and pool.retried == 1
    retried = [n for n, r in by.items() if r.attempt == 2]
    assert len(retried) == 1 and by[retried[0]].worker != killed["pid"]
    for name in ("big", "east", "north", "far"):  # each written once, whole, as run alone
        same_as_single_run(out / name, single[name])
    assert sorted(p.name for p in out.iterdir()) == ["big", "east", "far", "north"]
    assert _leftovers(out) == [] and pool.pids() == []
    # the killed worker's private folder was swept by the mission that ran after it
    assert not list(work_tmp.glob(f"fm2uav-batch-{killed['pid']}-*"))


@pytest.mark.slow  # a Dask cluster of two worker processes
def test_dask_worker_killed_mid_batch_reruns_its_mission(missions, tmp_path, dask_cluster):
    files, single = missions
    out = tmp_path / "out"
    order = ["outside", "big", "east", "north", "far"]
    todo, results = prepare_batch([files[n] for n in order], out)
    run_batch(todo, results, make_pool(None, client=dask_cluster.client),
              on_result=lambda res: dask_cluster.kill_a_busy_worker())
    killed = dask_cluster.killed
    assert killed, "no worker was busy"
    assert [r.status for r in results] == ["failed", "ok", "ok", "ok", "ok"]
    for name in ("big", "east", "north", "far"):
        same_as_single_run(out / name, single[name])
    assert sorted(p.name for p in out.iterdir()) == ["big", "east", "far", "north"]
    assert _leftovers(out) == []


def test_an_interrupted_batch_keeps_the_missions_written_and_stops_the_pool(missions,
                                                                           tmp_path):
    files, single = missions
    out = tmp_path / "out"
    todo, results = prepare_batch([files["east"], files["north"]], out)

    class Pool(InlinePool):
        closed = None

        def close(self, *, now=False):
            Pool.closed = now

    def stop(res):
        raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        run_batch(todo, results, Pool(), on_result=stop)
    assert Pool.closed is True
    assert [r.status for r in results] == ["ok", "not run"]
    same_as_single_run(out / "east", single["east"])
    assert not (out / "north").exists() and _leftovers(out) == []
    assert json.dumps([r.status for r in results])  # plain data, for batch.json
