"""The stamp of a kernel file's numba cache: its own bytes and the modules it imports."""

from __future__ import annotations

import hashlib
from pathlib import Path

import pytest

from fm2uav import _kernel_stamp
from fm2uav._kernel_stamp import PACKAGE, kernel_sources, kernel_stamp


def _package(root: Path) -> Path:
    """A package ``pkgx`` whose kernel ``a`` calls ``b`` (numba), which reads a constant of
    ``c`` (no numba), which imports ``d``; ``sub/e`` imports ``a`` two ways; ``lone`` nothing."""
    pkg = root / "pkgx"
    (pkg / "sub").mkdir(parents=True)
    files = {
        "__init__.py": "",
        "a.py": "from numba import njit\nfrom .b import g  # the callee\n\n@njit(cache=True)\n"
                "def f():\n    return g()\n",
        "b.py": "from numba import njit\nfrom .c import K\n\n@njit(cache=True)\n"
                "def g():\n    return K\n",
        "c.py": "from .d import nothing\nK = 1\n",
        "d.py": "nothing = None\n",
        "lone.py": "import numpy as np\nfrom numba import njit\n",
        "sub/__init__.py": "",
        "sub/e.py": "from .. import a, lone as L\nfrom ..b import (\n    g,\n)\n",
    }
    for name, text in files.items():
        (pkg / name).write_text(text)
    return pkg


def test_a_file_importing_nothing_of_the_package_has_numbas_own_stamp(tmp_path):
    pkg = _package(tmp_path)
    lone = pkg / "lone.py"
    assert kernel_sources(lone, pkg) == []
    assert kernel_stamp(lone, pkg) == hashlib.sha256(lone.read_bytes()).digest()


def test_the_sources_follow_imports_through_the_modules_that_use_numba(tmp_path):
    pkg = _package(tmp_path)
    assert [p.name for p in kernel_sources(pkg / "a.py", pkg)] == ["b.py", "c.py"]
    # `from .. import a, lone as L`: the submodules; `from ..b import (`: the module
    e = [p.relative_to(pkg).as_posix() for p in kernel_sources(pkg / "sub/e.py", pkg)]
    assert e == ["__init__.py", "a.py", "b.py", "c.py", "lone.py"]


@pytest.mark.parametrize("edited, changes", [("a.py", True), ("b.py", True), ("c.py", True),
                                             ("d.py", False), ("lone.py", False)])
def test_the_stamp_changes_with_the_file_and_what_it_compiles_in(tmp_path, edited, changes):
    pkg = _package(tmp_path)
    before = kernel_stamp(pkg / "a.py", pkg)
    assert kernel_stamp(pkg / "a.py", pkg) == before  # kept: the same bytes
    target = pkg / edited
    target.write_text(target.read_text() + "# edited, one byte more or less\n")
    assert (kernel_stamp(pkg / "a.py", pkg) != before) is changes


def test_the_package_kernels_stamps_include_their_helpers():
    parallel = PACKAGE / "eikonal" / "_parallel.py"
    deps = {p.relative_to(PACKAGE).as_posix() for p in kernel_sources(parallel)}
    assert {"eikonal/_heap.py", "eikonal/_kernels.py", "_numba.py"} <= deps
    assert kernel_stamp(parallel) != hashlib.sha256(parallel.read_bytes()).digest()
    # the reference baselines inline the interleaved heap from another package
    ref = PACKAGE / "baselines" / "reference" / "_kernels.py"
    assert "eikonal/_heap.py" in {p.relative_to(PACKAGE).as_posix() for p in kernel_sources(ref)}


def test_the_parallel_marchs_tuned_numbers_are_not_in_its_stamp():
    """``eikonal/_tuning.py`` is read at call time only (no kernel names it: test_warmup.py):
    a tuned number changes no stamp, so no kernel of ``_parallel.py`` recompiles for it."""
    parallel = PACKAGE / "eikonal" / "_parallel.py"
    assert "from . import _kernels, _tuning" in parallel.read_text(encoding="utf-8")
    deps = {p.relative_to(PACKAGE).as_posix() for p in kernel_sources(parallel)}
    assert "eikonal/_tuning.py" not in deps and "eikonal/_kernels.py" in deps
    assert _kernel_stamp.CALL_TIME_ONLY == {"eikonal/_tuning.py"}  # a new one is a choice


def test_a_call_time_only_module_is_left_out_of_the_stamp(tmp_path, monkeypatch):
    pkg = _package(tmp_path)
    monkeypatch.setattr(_kernel_stamp, "CALL_TIME_ONLY", frozenset({"c.py"}))
    _kernel_stamp._SOURCES.clear()
    assert [p.name for p in kernel_sources(pkg / "a.py", pkg)] == ["b.py"]
    before = kernel_stamp(pkg / "a.py", pkg)
    (pkg / "c.py").write_text((pkg / "c.py").read_text() + "K = 2\n")
    assert kernel_stamp(pkg / "a.py", pkg) == before
    _kernel_stamp._SOURCES.clear()


def test_an_unreadable_import_is_skipped_not_fatal(tmp_path):
    pkg = _package(tmp_path)
    (pkg / "c.py").unlink()  # imported by b, gone: b's stamp is its own bytes and nothing
    assert [p.name for p in kernel_sources(pkg / "b.py", pkg)] == []
    assert len(kernel_stamp(pkg / "b.py", pkg)) == 32
    _kernel_stamp._SOURCES.clear()
