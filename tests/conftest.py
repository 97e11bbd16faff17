"""Session-wide fixtures: expensive runs made once and shared by every test that reads them.

``cli_once(args)`` runs ``fm2uav <args> --out <dir>`` once per distinct argument list for the
whole session (the reproductions, the default mission) and hands every caller the same
result and output folder. Tests that read such a run must not write into its folder (a
second run without ``--force`` is fine: it is refused and leaves the folder as it was).

``rough_tif`` (a seeded rough GeoTIFF DEM), ``corridor`` (the formation corridor world) and
``dask_cluster`` (a local Dask cluster of two worker processes, to kill one of) are shared by
test folders that mirror different packages, so they live here too; fixtures used by one
folder only stay in that folder's conftest.py.

The command line's caches between runs (help pages and compiled code: fm2uav._help_cache,
fm2uav._code_cache) live in a folder of the test session's own (``FM2UAV_CACHE_DIR``, set
when pytest starts unless the caller set it; the workers of pytest-xdist inherit it, it is
removed at the end), never in the user's ~/.cache/fm2uav.

Long end-to-end tests are marked ``@pytest.mark.slow``: ``make test`` runs them,
``make test-fast`` (``-m "not slow"``) leaves them out.
"""

from __future__ import annotations

import os
import re
import shutil
import signal
import tempfile
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import pytest
from hypothesis import HealthCheck, settings
from typer.testing import CliRunner, Result

# One hypothesis profile on every machine. Under CI (the CI environment variable) hypothesis
# would load its own "ci" profile, whose derandomize=True every @settings inherits — the
# suite would then run differently there than here, and the scan for unseeded property
# tests (tests/repo/test_property_seeds.py) would see none. Each property test carries its
# own seed; this profile only makes the rest the same everywhere (no deadline, no example
# database written into the checkout).
settings.register_profile("fm2uav", deadline=None, database=None, print_blob=True,
                          derandomize=False,
                          suppress_health_check=[HealthCheck.too_slow])
settings.load_profile("fm2uav")


# ------------------------------------------------------------------ parallel runs (xdist)
#: the session fixtures whose runs are shared across test files (cli_once: one run per
#: distinct CLI argument list; doc_runs: the docs' blocks, made through cli_once)
SHARED_RUNS = ("cli_once", "doc_runs")


def shared_run_files(root: Path) -> frozenset[str]:
    """The test files (as node ids name them) whose tests or fixtures take one of
    :data:`SHARED_RUNS` as an argument: their tests run in one pytest-xdist worker, so that
    each shared run is made once per ``make test``."""
    pat = re.compile(r"\bdef \w+\([^)]*\b(?:" + "|".join(SHARED_RUNS) + r")\b")
    return frozenset(p.relative_to(root).as_posix() for p in (root / "tests").rglob("test_*.py")
                     if pat.search(p.read_text(encoding="utf-8")))


def xdist_scope(nodeid: str, shared: frozenset[str]) -> str:
    """The unit of work ``nodeid`` is handed out in: its file (a module's set-up is made in one
    worker), or ``"shared-runs"`` for every file of ``shared``."""
    path = nodeid.split("::", 1)[0]
    return "shared-runs" if path in shared else path


class XdistScheduling:
    """``make test``'s scheduler (``pytest -n auto --dist loadfile``): pytest-xdist's file
    scheduling with the files of :func:`shared_run_files` as one unit, handed out in
    collection order (the workers put the slow tests first: the long units start early)."""

    @pytest.hookimpl(tryfirst=True)
    def pytest_xdist_make_scheduler(self, config, log):
        if config.getvalue("dist") != "loadfile":
            return None
        from xdist.scheduler import LoadFileScheduling

        shared = shared_run_files(config.rootpath)
        config.option.loadscopereorder = False

        class Scheduling(LoadFileScheduling):
            def _split_scope(self, nodeid: str) -> str:
                return xdist_scope(nodeid, shared)

        return Scheduling(config, log)


def pytest_configure(config):
    if "FM2UAV_CACHE_DIR" not in os.environ:  # this session's own (see the module's notes)
        cache = tempfile.mkdtemp(prefix="fm2uav-test-cache-")
        os.environ["FM2UAV_CACHE_DIR"] = cache
        config.add_cleanup(lambda: shutil.rmtree(cache, ignore_errors=True))
    if config.pluginmanager.hasplugin("xdist"):
        config.pluginmanager.register(XdistScheduling(), "fm2uav-xdist-scheduling")


def pytest_collection_modifyitems(config, items):
    """In a pytest-xdist worker the slow tests come first (a stable sort, the same in every
    worker): the files holding them are handed out first (:class:`XdistScheduling`), so the run
    does not end with one worker alone in a long test."""
    if os.environ.get("PYTEST_XDIST_WORKER"):
        items.sort(key=lambda item: item.get_closest_marker("slow") is None)


@pytest.fixture(autouse=True)
def _each_test_a_fresh_process_for_stops():
    """A stop signal a test raises and catches itself (``pytest.raises(Interrupted)``) stays
    recorded as not reported (:mod:`fm2uav.io._stops`: the command line raises it again at its
    next checkpoint); each test is a process of its own for that record, as each command is."""
    yield
    import sys

    stops = sys.modules.get("fm2uav.io._stops")
    if stops is not None:
        stops.stop_reported()


@dataclass(frozen=True)
class CliRun:
    """One shared CLI run: its result, its output folder and its arguments (without --out)."""

    result: Result
    out: Path
    args: tuple[str, ...]


@pytest.fixture(scope="session")
def cli_once(tmp_path_factory):
    """``cli_once(args) -> CliRun``: ``fm2uav <args> --out <dir>``, run once per session.

    Identical argument lists share one run (the cache key is the argument tuple), so give
    the same arguments wherever the same run is wanted.
    """
    from fm2uav.cli import app

    runner = CliRunner()
    done: dict[tuple[str, ...], CliRun] = {}
    root = tmp_path_factory.mktemp("cli_once")

    def run(args) -> CliRun:
        key = tuple(str(a) for a in args)
        if key not in done:
            slug = re.sub(r"[^A-Za-z0-9]+", "-", "-".join(Path(a).name for a in key[:2]))
            out = root / f"{len(done):02d}-{slug.strip('-')}"
            done[key] = CliRun(runner.invoke(app, [*key, "--out", str(out)]), out, key)
        return done[key]

    return run


@pytest.fixture(scope="session")
def rough_tif(tmp_path_factory):
    """A seeded rough GeoTIFF DEM in lon/lat (tests/world/rough_terrain.py), written once;
    read by the world, io and planning flight-safety tests."""
    from tests.world.rough_terrain import rough_dem, write_geotiff

    path = tmp_path_factory.mktemp("dem") / "rough.tif"
    return write_geotiff(path, rough_dem(5))


def corridor_world(width_cells: int = 8, length: tuple[int, int] = (20, 40)):
    """60 x 40 x 14 nodes of 10 m: flat ground, two walls up to 125 m (just below the
    130 m ceiling, so the clearance band closes them) leaving a corridor along y = 20."""
    import numpy as np

    from fm2uav import World

    h = np.zeros((60, 40))
    lo = 20 - width_cells // 2
    hi = 20 + width_cells // 2
    h[length[0]:length[1], :lo] = 125.0
    h[length[0]:length[1], hi + 1:] = 125.0
    return World.from_heightmap(h, 10.0, 14, name="corridor")


@pytest.fixture(scope="session")
def corridor():
    """The corridor world (``corridor_world()``), shared by the formation and viz tests."""
    return corridor_world()


@pytest.fixture(scope="session")
def returns_mission():
    """An ArduPilot mission over a ridge with its safe returns (tests/autopilot/return_cases.py):
    one rally point, an RTL end but no return altitude under the ceiling (so the mission carries
    its planned return home instead), 10 min endurance; read by the autopilot and io tests."""
    from fm2uav.autopilot.safe_return import ReturnOptions
    from tests.autopilot.return_cases import build, ridge_plan

    return build(ridge_plan(), ReturnOptions(rally=((1100.0, 700.0),)), end="rtl")


@dataclass
class DaskCluster:
    """A running two-worker Dask cluster (:func:`dask_cluster`): its client, each worker's
    process id by address, and the worker :meth:`kill_a_busy_worker` killed."""

    client: Any
    pids: dict[str, int]
    killed: dict[str, list] = field(default_factory=dict)

    def kill_a_busy_worker(self) -> bool:
        """SIGKILL the first worker that holds a task, once per cluster; True when this call
        killed one (its address → the keys it held: :attr:`killed`)."""
        if self.killed:
            return False
        for addr, keys in self.client.processing().items():
            if keys:
                os.kill(self.pids[addr], signal.SIGKILL)
                self.killed[addr] = list(keys)
                return True
        return False


@pytest.fixture
def dask_cluster():
    """A local Dask cluster of two single-thread worker processes and its client (skipped
    without dask.distributed). The scheduler retries a task once (as the local pool) and gives
    each worker one task at a time, so a worker's death counts only against the task it was
    running (Dask counts it against every task assigned to that worker)."""
    dask = pytest.importorskip("dask")
    distributed = pytest.importorskip("dask.distributed")
    settings = {"distributed.scheduler.allowed-failures": 1,
                "distributed.scheduler.worker-saturation": 1.0}
    with dask.config.set(settings), \
            distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                     dashboard_address=None) as cluster, \
            distributed.Client(cluster) as client:
        yield DaskCluster(client, client.run(os.getpid))
