"""fm2uav.app.jobs: jobs in a worker process, progress, errors in the CLI's words, cancel."""

from __future__ import annotations

import os
import signal
import time

import pytest

from fm2uav.app.jobs import JobManager

from .dem import make_dem, mission_yaml


@pytest.fixture(scope="module")
def jobs():
    m = JobManager()
    yield m
    m.close()


@pytest.fixture(scope="module")
def dem(tmp_path_factory):
    return make_dem(tmp_path_factory.mktemp("jobs") / "dem.tif")


def wait(jobs, job, timeout=120.0, until=lambda j: j.final):
    """Follow the job's versions until ``until(job)``; returns the stages seen."""
    seen, version, t0 = [], -1, time.time()
    while time.time() - t0 < timeout:
        j = jobs.wait(job.id, version, 2.0)
        if j.version != version:
            version = j.version
            seen.append((j.fraction, j.stage))
        if until(j):
            return seen
    raise AssertionError(f"job {job.id} still {jobs.get(job.id).state} after {timeout} s")


def test_a_world_job_returns_the_world_with_progress(jobs, dem):
    job = jobs.submit("world", {"world": {"dem": str(dem)}, "agl": 60})
    seen = wait(jobs, job)
    j = jobs.get(job.id)
    assert j.state == "done", j.error
    r = j.public()["result"]
    w, s, e, n = r["bounds"]
    assert 10.29 < w < e < 10.37 and 46.01 < s < n < 46.05
    assert r["summary"]["crs"] == "EPSG:32632" and r["ground"][0] > 280
    assert "building the world" in [st for _, st in seen]
    assert j.public()["fraction"] == 1.0


def test_a_plan_job_writes_the_outputs_and_the_map(jobs, dem, tmp_path):
    mf = mission_yaml(tmp_path / "m.yaml", dem)
    job = jobs.submit("plan", {"mission_file": str(mf), "out": str(tmp_path / "out")})
    seen = wait(jobs, job)
    j = jobs.get(job.id)
    assert j.state == "done", j.error
    # the mission files and, with the safe returns (on by default), their two files
    assert j.result["files"] == ["mission.param", "mission.plan", "mission.waypoints",
                                 "path.geojson", "returns.geojson", "summary.json"]
    kinds = {f["properties"]["kind"] for f in j.result["map"]["features"]}
    assert {"route", "item", "start", "goal", "return"} <= kinds
    rows = j.result["map"]["rows"]
    assert rows["mission"] == "app test"
    assert "longest way back" in rows
    assert any(k.startswith("point of no return") for k in rows), rows  # "(battery binds; …)"
    stages = [st for _, st in seen]
    assert "planning (FM²): arrival times T (Fast Marching)" in stages
    fractions = [f for f, _ in seen]
    assert fractions == sorted(fractions)


def test_errors_come_back_in_the_command_lines_words(jobs, tmp_path):
    bad = tmp_path / "bad.tif"
    bad.write_text("not a raster")
    job = jobs.submit("world", {"world": {"dem": str(bad)}, "source": "mission"})
    wait(jobs, job)
    j = jobs.get(job.id)
    assert j.state == "error" and j.exit_code == 2
    assert j.error.startswith("mission: world.dem = '/") and "/bad.tif'" in j.error
    assert j.error.endswith("' cannot be read as a raster (RasterioIOError); allowed: a raster "
                            "file GDAL reads (GeoTIFF, VRT, .hgt)")
    job = jobs.submit("plan", {"mission_file": str(tmp_path / "missing.yaml"),
                               "out": str(tmp_path / "o")})
    wait(jobs, job)
    assert "missing.yaml" in jobs.get(job.id).error and jobs.get(job.id).exit_code == 2


def test_cancel_a_running_and_a_queued_job_then_go_on(jobs, tmp_path):
    big = make_dem(tmp_path / "big.tif", nx=700, ny=700, cell=10.0)
    mf = mission_yaml(tmp_path / "big.yaml", big)
    running = jobs.submit("plan", {"mission_file": str(mf), "out": str(tmp_path / "o1")})
    queued = jobs.submit("world", {"world": {"dem": str(big)}})
    wait(jobs, running, until=lambda j: j.state == "running" and j.fraction >= 0.15)
    pid = jobs._proc.pid
    assert jobs.cancel(queued.id).state == "cancelled"
    assert jobs.cancel(running.id).state == "cancelled"
    assert not _alive(pid)                     # the worker was stopped at once
    assert not (tmp_path / "o1").exists()      # no half-written output set
    again = jobs.submit("world", {"world": {"dem": str(big)}})
    wait(jobs, again)
    assert jobs.get(again.id).state == "done"  # a fresh worker took the next job
    assert jobs.get(queued.id).state == "cancelled"


def test_a_worker_that_dies_fails_its_job_and_is_replaced(jobs, dem, tmp_path):
    big = make_dem(tmp_path / "big.tif", nx=700, ny=700, cell=10.0)
    job = jobs.submit("plan", {"mission_file": str(mission_yaml(tmp_path / "m.yaml", big)),
                               "out": str(tmp_path / "o")})
    wait(jobs, job, until=lambda j: j.state == "running")
    os.kill(jobs._proc.pid, signal.SIGKILL)
    wait(jobs, job)
    j = jobs.get(job.id)
    assert j.state == "error" and j.exit_code == 70 and "worker stopped" in j.error
    nxt = jobs.submit("world", {"world": {"dem": str(dem)}})
    wait(jobs, nxt)
    assert jobs.get(nxt.id).state == "done"


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    try:  # a zombie not yet reaped counts as stopped
        with open(f"/proc/{pid}/stat") as fh:
            return fh.read().split()[2] != "Z"
    except FileNotFoundError:
        return False
