"""`make test` runs the suite in parallel (pytest-xdist) with the scheduling of tests/conftest.py:
one file's tests in one worker, the files sharing ``cli_once``'s runs together."""

from __future__ import annotations

import re
import tomllib
from pathlib import Path

import pytest

from tests.conftest import XdistScheduling, shared_run_files, xdist_scope

ROOT = Path(__file__).resolve().parents[2]


def test_make_test_runs_in_parallel_with_the_file_scheduling():
    make = (ROOT / "Makefile").read_text()
    recipe = make.split("\ntest: ", 1)[1].split("\n\n", 1)[0]
    assert "$(XDIST)" in recipe
    assert re.search(r"^XDIST\s*:?=\s*-n \$\(WORKERS\) --dist loadfile$", make, re.M)
    extra = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"][
        "optional-dependencies"]["test"]
    assert any(dep.startswith("pytest-xdist") for dep in extra)


def test_the_files_sharing_runs_are_found_and_only_they():
    shared = shared_run_files(ROOT)
    assert {"tests/repo/test_docs_run.py", "tests/cli/test_cmd_city.py",
            "tests/io/test_mission.py"} <= shared
    assert "tests/test_layout.py" not in shared
    assert "tests/repo/test_parallel_suite.py" not in shared  # names no shared run


def test_files_are_units_and_the_shared_files_one_unit():
    shared = frozenset({"tests/a/test_x.py", "tests/b/test_y.py"})
    assert xdist_scope("tests/a/test_x.py::test_one[1]", shared) == \
        xdist_scope("tests/b/test_y.py::T::test_two", shared) == "shared-runs"
    assert xdist_scope("tests/c/test_z.py::test_three[a::b]", shared) == "tests/c/test_z.py"
    assert xdist_scope("src/fm2uav/geometry.py::fm2uav.geometry.f", shared) == \
        "src/fm2uav/geometry.py"


def test_the_scheduler_is_made_for_loadfile_only(pytestconfig, monkeypatch):
    pytest.importorskip("xdist", reason="pytest-xdist (the test extra) is not installed")
    plugin = XdistScheduling()
    monkeypatch.setattr(pytestconfig.option, "dist", "load", raising=False)
    assert plugin.pytest_xdist_make_scheduler(pytestconfig, None) is None
    monkeypatch.setattr(pytestconfig.option, "dist", "loadfile")
    monkeypatch.setattr(pytestconfig.option, "loadscopereorder", True, raising=False)
    monkeypatch.setattr(pytestconfig.option, "numprocesses", 2, raising=False)
    monkeypatch.setattr(pytestconfig.option, "tx", ["popen", "popen"], raising=False)
    sched = plugin.pytest_xdist_make_scheduler(pytestconfig, None)
    assert sched._split_scope("tests/repo/test_docs_run.py::test_x[README.md:12]") == \
        sched._split_scope("tests/cli/test_cmd_city.py::test_reproduce_city") == "shared-runs"
    assert sched._split_scope("tests/test_layout.py::test_y") == "tests/test_layout.py"
    assert pytestconfig.option.loadscopereorder is False  # collection order: slow files first
