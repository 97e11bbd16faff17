"""The warm-up groups fill numba's cache with exactly the specialisations later runs use.

The property (``make install`` and a first plan run the groups; a later plan must compile
nothing): every ``(kernel, signature)`` a later run calls is one the groups compiled, and
a later process finds each in the cache. It is tested in parts that each can fail:

* the groups, then the later runs, in one process on the suite's numba cache
  (:mod:`tests.planning.warmup_probe`): the later runs add no signature to any fm2uav
  dispatcher, and every signature there has its entry in the kernel's cache index under
  the key a later process looks up (signature, CPU, bytecode and closure values, for the
  current source stamp and numba version); a second process, after the first, compiles
  nothing; without the groups each later run is for, the same runs add signatures those
  groups compile (the check can fail);
* what else decides a cache hit, over every fm2uav kernel: cached (``cache=True``) unless
  only kernels call it (then its code is in theirs), a cache file of its own (an entry is
  not keyed by the compile flags, e.g. ``parallel=True``), and no module global a group
  lowers read inside a kernel (globals are frozen into the compiled code, not keyed);
* one cold cache (``NUMBA_CACHE_DIR``): ``python -m fm2uav.planning.warmup`` writes, a later
  process loads and compiles nothing.

On the suite's warm cache the probe only loads kernels (seconds); on a fresh checkout its
first process compiles every group, as the rest of the suite would. It shares the cache with
the other workers: numba rewrites a kernel's whole index when it adds an entry, so two
processes compiling two signatures of one kernel at the same moment can drop one entry (a
later process compiles it again); only a cold cache compiles, so only a fresh checkout's
first run can meet this, and the probe's runs are then made again (at most twice).
"""

from __future__ import annotations

import ast
import gc
import importlib
import inspect
import json
import os
import subprocess
import sys
import types
from pathlib import Path

import pytest

from fm2uav.planning import warmup

PROBE = Path(__file__).with_name("warmup_probe.py")

#: Later runs (tests/planning/warmup_probe.py) -> the groups they need beyond the others:
#: each needs a specialisation these groups are the first of GROUPS to compile.
NEEDS = {
    "run3d": ("edt_parallel", "fmm3d_o1_lean", "fmm3d_o2_lean"),
    "par3d": ("fmm3d_parallel",),
    "run2d": ("fmm2d_o1", "fmm2d_o2"),
    "par2d": ("fmm2d_parallel",),
    "level": ("profile",),
}


def _probe(args, env=None):
    # the timeout only guards against a hang: on the suite's warm cache the probe loads;
    # on a fresh checkout it compiles every group (over 600 s of wall time at load 6-8)
    res = subprocess.run([sys.executable, str(PROBE), *args], capture_output=True, text=True,
                         env={**os.environ, **(env or {})}, timeout=3600)
    assert res.returncode == 0, res.stderr
    return res.stdout


def _pairs(rows):
    return {tuple(r) for r in rows}


@pytest.fixture(scope="module")
def later_runs():
    """The probe's runs on the suite's cache, one process each, one after the other: every
    group then every later run; the groups no later run needs beyond the others (``NEEDS``)
    then the same runs; no group, then a uniform 2D march and the 2D runs."""
    needed = {g for gs in NEEDS.values() for g in gs}
    # a fresh checkout's first run: another worker compiling a signature of the same kernel
    # at the same moment may drop an entry the probe wrote (module docstring); the runs are
    # made again then, at most twice — the next run compiles and writes what was dropped,
    # so a missing entry that is not such a race stays missing and fails the tests below
    for _ in range(3):
        full = json.loads(_probe([*warmup.GROUPS, "--", "run3d", "par3d", "uniform2d",
                                  "run2d", "par2d", "level"]))
        short = json.loads(_probe([*(g for g in warmup.GROUPS if g not in needed), "--",
                                   *NEEDS]))
        bare = json.loads(_probe(["--", "uniform2d", "run2d"]))
        if not (full["not_on_disk"] or any(r["compiled"] or r["not_on_disk"]
                                           for r in (short, bare))):
            break
    return full, short, bare


@pytest.mark.slow
def test_a_later_run_needs_no_kernel_signature_the_groups_did_not_compile(later_runs):
    full, _, _ = later_runs
    assert list(full["groups"]) == list(warmup.GROUPS)
    assert all(full["groups"][g] for g in warmup.GROUPS), "a group that adds nothing"
    assert full["later"] == {w: [] for w in full["later"]}
    assert full["unlisted"] == []  # the scan saw every kernel holding a signature
    # each on disk, under the key a later process computes, for the current source stamp
    assert full["not_on_disk"] == []


@pytest.mark.slow
def test_a_later_process_compiles_nothing(later_runs):
    # the second process loads everything it calls from the cache (no numba:compile):
    # the slab march's parallel drives and the closures of the march kernels included
    _, short, bare = later_runs
    for run in (short, bare):
        assert run["compiled"] == []
        assert run["not_on_disk"] == [] and run["unlisted"] == []


@pytest.mark.slow
def test_without_its_groups_each_later_run_needs_what_they_compile(later_runs):
    # the check can fail: without the groups of NEEDS the later runs add signatures, among
    # them one that each of these groups is the first of GROUPS to compile
    full, short, bare = later_runs
    first = {g: _pairs(rows) for g, rows in full["groups"].items()}
    for run, groups in NEEDS.items():
        new = _pairs(short["later"][run])
        for g in groups:
            assert new & first[g], (run, g, sorted(new))
    # the 2D FM² map (interleaved) needs other specialisations of kernels a uniform march
    # (separate arrays) uses: the 2D run covers both layouts (so do the 2D groups, above)
    uniform, fm2 = _pairs(bare["later"]["uniform2d"]), _pairs(bare["later"]["run2d"])
    assert {k for k, _ in uniform} & {k for k, _ in fm2 & first["fmm2d_o1"]}, (uniform, fm2)


@pytest.mark.slow
def test_a_later_process_loads_what_the_warm_up_command_wrote(tmp_path):
    # the one cold cache: the cheapest group. Empty, the probe would compile (it stops at
    # the first compile); after `python -m fm2uav.planning.warmup GROUP`, a later process
    # loads the group's kernels from NUMBA_CACHE_DIR and compiles nothing
    group = "surface"
    env = {"NUMBA_CACHE_DIR": str(tmp_path / "cache")}
    assert _probe(["--stop-at-first-compile", group], env).split()[0] == "compiled"
    res = subprocess.run([sys.executable, "-m", "fm2uav.planning.warmup", group],
                         capture_output=True, text=True, env={**os.environ, **env},
                         timeout=3600)
    assert res.returncode == 0, res.stderr
    assert res.stdout.split(":")[0] == group  # the command ran the group, and said so
    later = json.loads(_probe([group], env))
    assert later["groups"][group] and later["compiled"] == []
    assert list((tmp_path / "cache").rglob("*.nbi"))


# ------------------------------------------------------------ what else decides a cache hit
def _kernel_modules():
    """Every fm2uav module that defines numba kernels, imported."""
    src = Path(warmup.__file__).resolve().parents[1]
    names = sorted("fm2uav." + ".".join(p.relative_to(src).with_suffix("").parts)
                   for p in src.rglob("*.py")
                   if "__pycache__" not in p.parts and "njit" in p.read_text(encoding="utf-8"))
    return [importlib.import_module(n.removesuffix(".__init__")) for n in names]


def _dispatchers():
    from tests.planning.warmup_probe import dispatchers

    _kernel_modules()
    return dispatchers()


def _codes(code, skip=frozenset()):
    yield code
    for c in code.co_consts:
        if isinstance(c, types.CodeType) and id(c) not in skip:
            yield from _codes(c, skip)


def _names(code, skip=frozenset()):
    """The global and attribute names ``code`` and the functions it defines use (but not
    those whose code is in ``skip``: the kernels a factory makes)."""
    return {n for c in _codes(code, skip) for n in c.co_names}


def _python_callers(kernels):
    """``module.function -> name`` for each plain Python function of fm2uav (not a kernel)
    whose code names one of ``kernels`` (a global of its module)."""
    py_funcs = {id(d.py_func) for d in _dispatchers().values()}
    kernel_codes = frozenset(id(d.py_func.__code__) for d in _dispatchers().values())
    out = []
    for f in gc.get_objects():
        if (not isinstance(f, types.FunctionType) or id(f) in py_funcs
                or not (getattr(f, "__module__", "") or "").startswith("fm2uav")):
            continue
        for n in _names(f.__code__, kernel_codes):
            if any(f.__globals__.get(n) is d for d in kernels):
                out.append(f"{f.__module__}.{f.__qualname__} -> {n}")
    return sorted(out)


def test_every_kernel_is_cached_or_only_called_by_kernels():
    # a kernel without cache=True that Python code calls would compile in every process;
    # one only kernels call is compiled into their cached code (the EDT's line transforms)
    from numba.core.caching import NullCache

    kernels = _dispatchers()
    assert len(kernels) > 100
    uncached = [d for d in kernels.values() if isinstance(d._cache, NullCache)]
    assert _python_callers(uncached) == []
    assert len(uncached) < 5, sorted(d.py_func.__qualname__ for d in uncached)
    # the scan sees Python calling kernels (it can fail)
    assert "fm2uav.eikonal._edt.edt -> _edt_serial" in _python_callers(
        kernels.values())


def test_every_kernel_has_a_cache_file_of_its_own():
    # numba names a kernel's cache files after its module, name and line, and keys an entry
    # by signature, CPU, bytecode and closure values, never by the compile flags
    # (parallel=True, nogil, error_model): two kernels sharing a file could load each other's
    from numba.core.caching import NullCache

    paths = {}
    for name, d in _dispatchers().items():
        if not isinstance(d._cache, NullCache):
            paths.setdefault(d._cache._cache_file._index_path, []).append(name)
    shared = {p: names for p, names in paths.items() if len(names) > 1}
    assert shared == {}
    assert len(paths) > 100


def _lowered():
    """Module attributes the warm-up groups set while they compile (``_kernels.LEAN_NODES =
    0``, ...), and those the probe's later runs lower (``_patched(_edt, ...=0)``)."""
    out = set()
    for source in (inspect.getsource(warmup), PROBE.read_text(encoding="utf-8")):
        for node in ast.walk(ast.parse(source)):
            if isinstance(node, ast.Call) and getattr(node.func, "id", "") == "_patched":
                out |= {k.arg for k in node.keywords}
            targets = (node.targets if isinstance(node, ast.Assign)
                       else [node.target] if isinstance(node, ast.AugAssign) else [])
            for t in targets:
                for e in (t.elts if isinstance(t, ast.Tuple) else [t]):
                    if isinstance(e, ast.Attribute) and isinstance(e.value, ast.Name):
                        out.add(e.attr)
    return out


def test_no_kernel_reads_a_global_the_groups_lower():
    # numba freezes a global's value into the compiled code and does not key the cache
    # entry by it: a kernel reading a size floor a group lowers while it compiles would
    # keep the lowered value in every later process
    lowered = _lowered()
    assert {"LEAN_NODES", "PARALLEL_MIN_NODES", "SETUP_PARALLEL_MIN_NODES",
            "ORDER2_MIN_NODES_3D", "EDT_PARALLEL_MIN_NODES"} <= lowered
    kernels = _dispatchers()
    readers = sorted(f"{name} reads {sorted(_names(d.py_func.__code__) & lowered)}"
                     for name, d in kernels.items() if _names(d.py_func.__code__) & lowered)
    assert readers == []
    # the scan reads the kernels' globals, the closures of the slab drives' factory included
    assert "_C_NEXT" in _names(kernels["fm2uav.eikonal._parallel:drive3d_o2"].py_func.__code__)


def test_no_kernel_reads_the_tuning_numbers():
    # eikonal/_tuning.py holds the parallel march's measured numbers so that they can be
    # changed without recompiling: a kernel reading one would freeze it into its cache entry
    from fm2uav.eikonal import _tuning

    tunables = {n for n in vars(_tuning) if n.isupper()}
    assert {"ORDER2_MIN_NODES_2D", "WINDOW_NODES", "SLABS_PER_THREAD"} <= tunables
    read = tunables | {"_tuning"}
    readers = sorted(f"{name} reads {sorted(_names(d.py_func.__code__) & read)}"
                     for name, d in _dispatchers().items() if _names(d.py_func.__code__) & read)
    assert readers == []
    # and the module itself is numbers only: it imports nothing (no kernel to compile)
    tree = ast.parse(inspect.getsource(_tuning))
    imports = {n.module if isinstance(n, ast.ImportFrom) else n.names[0].name
               for n in ast.walk(tree) if isinstance(n, (ast.Import, ast.ImportFrom))}
    assert imports == {"__future__"}


def test_unknown_group_is_refused_with_the_known_names(capsys):
    assert warmup.main(["fmm9d"]) == 2
    err = capsys.readouterr().err
    assert "fmm9d" in err and "fmm3d_o2_lean" in err and "edt_parallel" in err


def test_the_command_line_child_compiles_the_first_plan_child_groups():
    # the command line names the child's group of a default `fm2uav plan` (3D, order 2)
    from fm2uav.cli._first_use import fmm_group

    assert (fmm_group(order=2, ndim=3),) == warmup.FIRST_PLAN_CHILD

    assert not set(warmup.FIRST_PLAN_CHILD) & set(warmup.FIRST_PLAN_MAIN)
    assert set(warmup.FIRST_PLAN_CHILD + warmup.FIRST_PLAN_MAIN) <= set(warmup.GROUPS)
