"""Session-wide fixtures: expensive runs made once and shared by every test that reads them.

``cli_once(args)`` runs ``fm2uav <args> --out <dir>`` once per distinct argument list for the
whole session (the reproductions, the default mission) and hands every caller the same
result and output folder. Tests that read such a run must not write into its folder (a
second run without ``--force`` is fine: it is refused and leaves the folder as it was).

``rough_tif`` (a seeded rough GeoTIFF DEM) and ``corridor`` (the formation corridor world) are
shared by test folders that mirror different packages, so they live here too; fixtures used by
one folder only stay in that folder's conftest.py.

Long end-to-end tests are marked ``@pytest.mark.slow``: ``make test`` runs them,
``make test-fast`` (``-m "not slow"``) leaves them out.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

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


#: session fixtures whose runs are worth sharing across test files: their users run in one
#: pytest-xdist worker (the docs' blocks and the CLI tests giving the same arguments share runs)
SHARED_RUNS = frozenset({"cli_once", "doc_runs"})


def xdist_group_of(item) -> str | None:
    """The pytest-xdist group ``item`` runs in under ``make test`` (``-n auto --dist
    loadgroup``): ``"cli_once"`` for the users of :data:`SHARED_RUNS`, its file for a test
    that uses a module-scoped fixture (each module's set-up made once, in one worker), None
    (any worker) for the rest."""
    names = set(getattr(item, "fixturenames", ()))
    if names & SHARED_RUNS:
        return "cli_once"
    info = getattr(item, "_fixtureinfo", None)
    defs = info.name2fixturedefs.values() if info is not None else ()
    if any(d and d[-1].scope in ("module", "package", "class") for d in defs):
        return item.nodeid.split("::", 1)[0]
    return None


def pytest_collection_modifyitems(config, items):
    """Mark each test with its :func:`xdist_group_of` (``xdist_group``; without ``--dist
    loadgroup``, or without pytest-xdist, the marks change nothing)."""
    for item in items:
        group = xdist_group_of(item)
        if group is not None:
            item.add_marker(pytest.mark.xdist_group(group))


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
