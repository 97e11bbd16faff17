"""The warm-up groups fill numba's cache with exactly the specialisations later runs use."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import textwrap

import pytest

from fm2uav.planning import warmup

_LATER_RUN = textwrap.dedent(
    """
    import numpy as np
    from fm2uav import _jit
    compiled = []
    _jit.on_first_compile(lambda: compiled.append(1))
    from fm2uav.eikonal import _edt, _kernels, distance_map, fast_marching
    from fm2uav.planning.geodesic import drop_ties, reaches_any
    _kernels.LEAN_NODES = 0          # a big grid's march, on a small one,
    _edt.EDT_PARALLEL_MIN_NODES = 0  # its distance map and set-up on two threads
    _kernels.SETUP_PARALLEL_MIN_NODES = 0
    rng = np.random.default_rng(0)
    occ = rng.random((30, 20, 10)) < 0.05
    occ[0, 0, 0] = True
    W = distance_map(occ, spacing=(15.0, 15.0, 10.0), threads=2)
    T = fast_marching(W / W.max() + 0.01, [(29, 19, 9)], spacing=(15.0, 15.0, 10.0),
                      stop_at=[(0, 0, 1)], threads=2)
    assert np.isfinite(T[0, 0, 1])
    drop_ties(T, (0, 0, 1))          # the plan's scans of T
    assert not reaches_any(T, occ & ~np.isfinite(T))
    print("compiled" if compiled else "cached")
    """
)


def _run(args, cache):
    # the timeout only guards against a hang: a cold compile of the parallel groups (order 1
    # and 2 drives in every layout) took over 600 s of wall time on the loaded 2-core machine
    # (load 6-8, ~a third of a core)
    env = {**os.environ, "NUMBA_CACHE_DIR": str(cache)}
    return subprocess.run([sys.executable, *args], capture_output=True, text=True, env=env,
                          timeout=1800)


@pytest.mark.slow
def test_big_grid_groups_cache_what_a_big_plan_compiles(tmp_path):
    # the groups a big plan needs beyond the small ones: after them a big-grid
    # march and distance map (forced on a small grid) compile nothing
    small, big = tmp_path / "small", tmp_path / "big"
    res = _run(["-m", "fm2uav.planning.warmup", "edt", "fmm3d_o2", "descent"], small)
    assert res.returncode == 0, res.stderr
    # the small groups' cache, copied, is where the big-grid groups start (numba names a
    # cache folder after the source folder, not after NUMBA_CACHE_DIR: the copy loads)
    shutil.copytree(small, big)
    # without the big-grid groups the later run compiles (the check can fail)
    res = _run(["-c", _LATER_RUN], small)
    assert res.returncode == 0, res.stderr
    assert res.stdout.split() == ["compiled"]
    groups = ["edt", "edt_parallel", "fmm3d_o2", "fmm3d_o2_lean", "descent"]
    res = _run(["-m", "fm2uav.planning.warmup", *groups], big)
    assert res.returncode == 0, res.stderr
    assert [line.split(":")[0] for line in res.stdout.splitlines()] == groups
    res = _run(["-c", _LATER_RUN], big)
    assert res.returncode == 0, res.stderr
    assert res.stdout.split() == ["cached"]


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


_LATER_PARALLEL_RUN = textwrap.dedent(
    """
    import os
    import numpy as np
    from numba.core import event
    from fm2uav.eikonal import _kernels, _parallel, fast_marching

    class FirstCompile(event.Listener):  # the first fm2uav kernel compiled: named, then exit
        def on_start(self, ev):
            disp = ev.data.get("dispatcher") if isinstance(ev.data, dict) else None
            f = getattr(disp, "py_func", None)
            if getattr(f, "__module__", "").startswith("fm2uav"):
                print("compiled", f.__module__, flush=True)
                os._exit(0)

        def on_end(self, ev):
            pass

    event.register("numba:compile", FirstCompile())
    _kernels.LEAN_NODES = 0          # a big grid's two-thread march (lean layout, float32
    _parallel.PARALLEL_MIN_NODES = 0  # speed) and its input scan, on a small one
    _parallel.ORDER2_MIN_NODES_3D = 0
    _kernels.SETUP_PARALLEL_MIN_NODES = 0
    marches, march = [], _parallel.march
    _parallel.march = lambda *a, **k: marches.append(k["order"]) or march(*a, **k)
    v = np.ones((40, 36, 20))
    v[10:14, :30, :] = 0.0
    for order in (1, 2):
        T = fast_marching(v, [(30, 5, 3)], spacing=(15.0, 15.0, 10.0), order=order, threads=2)
        assert np.isfinite(T[0, 0, 1])
    assert marches == [1, 2], marches  # both on the slabs
    print("cached")
    """
)


@pytest.mark.slow
def test_parallel_group_caches_the_lean_layout_of_a_big_two_thread_march(tmp_path):
    # a 1000x1000x40 terrain plan (order 2 by default) marches on both cores in the lean
    # layout (float32 speed): after the install's groups it compiles nothing (it compiled
    # for ~50 s before), order 1 nor 2; its serial pieces in the lean layout (a slab too
    # small to split marches serially, the speed range) are the lean groups', the coarse
    # order-1 march that places the cuts fmm3d_o1's. One cold compile of each group: the
    # serial groups' cache, copied, is where the parallel group starts
    serial, full = tmp_path / "serial", tmp_path / "full"
    res = _run(["-m", "fm2uav.planning.warmup", "fmm3d_o1", "fmm3d_o1_lean", "fmm3d_o2_lean"],
               serial)
    assert res.returncode == 0, res.stderr
    shutil.copytree(serial, full)
    res = _run(["-m", "fm2uav.planning.warmup", "fmm3d_parallel"], full)
    assert res.returncode == 0, res.stderr
    res = _run(["-c", _LATER_PARALLEL_RUN], full)
    assert res.returncode == 0, res.stderr
    assert res.stdout.split() == ["cached"]
    # the check can fail: without the parallel group the same run compiles, first a kernel
    # of the parallel march (the run stops there: no time spent compiling the rest)
    res = _run(["-c", _LATER_PARALLEL_RUN], serial)
    assert res.returncode == 0, res.stderr
    assert res.stdout.split() == ["compiled", "fm2uav.eikonal._parallel"]


_LATER_2D_RUN = textwrap.dedent(
    """
    import numpy as np
    from fm2uav import _jit
    compiled = []
    _jit.on_first_compile(lambda: compiled.append(1))
    from fm2uav.eikonal import distance_map, fast_marching
    occ = np.zeros((40, 36), dtype=bool)
    occ[10:14, :30] = True
    W = np.sqrt(distance_map(occ, spacing=15.0))
    for speed in (W / W.max(), (W > 0) * 1.0):  # an FM² map (interleaved), a uniform one
        for order in ORDERS:
            T = fast_marching(speed, [(30, 5)], spacing=15.0, order=order, stop_at=[(0, 0)])
            assert np.isfinite(T[0, 0])
    print("compiled" if compiled else "cached")
    """
)


@pytest.mark.slow
def test_2d_groups_cache_both_layouts_of_a_2d_plan(tmp_path):
    # a 2D FM² map marches interleaved, a uniform one in separate arrays (their padding
    # compiles per layout): after the 2D groups neither compiles; a march of a uniform
    # speed alone (the groups' run before the interleaved layout) leaves one to compile
    groups = ["edt", "fmm2d_o1", "fmm2d_o2"]
    res = _run(["-m", "fm2uav.planning.warmup", *groups], tmp_path / "groups")
    assert res.returncode == 0, res.stderr
    later = _LATER_2D_RUN.replace("ORDERS", "(1, 2)")
    res = _run(["-c", later], tmp_path / "groups")
    assert res.returncode == 0, res.stderr
    assert res.stdout.split() == ["cached"]
    uniform_only = ("import numpy as np\n"
                    "from fm2uav.eikonal import distance_map, fast_marching\n"
                    "distance_map(np.eye(4, dtype=bool))\n"
                    "fast_marching(np.ones((5, 5)), [(2, 2)], order=1)\n")
    res = _run(["-c", uniform_only], tmp_path / "uniform")
    assert res.returncode == 0, res.stderr
    res = _run(["-c", _LATER_2D_RUN.replace("ORDERS", "(1,)")], tmp_path / "uniform")
    assert res.returncode == 0, res.stderr
    assert res.stdout.split() == ["compiled"]


_LATER_2D_PARALLEL_RUN = textwrap.dedent(
    """
    import numpy as np
    from fm2uav import _jit
    compiled = []
    _jit.on_first_compile(lambda: compiled.append(1))
    from fm2uav.eikonal import _kernels, _parallel, fast_marching
    _parallel.PARALLEL_MIN_NODES = 0  # a big 2D map's two-thread march, on a small one
    v = np.ones((160, 40))
    v[50:54, :30] = 0.0
    for speed in (v * np.linspace(0.5, 1.0, 40), v):  # interleaved slabs; a uniform speed
        T = fast_marching(speed, [(30, 5)], spacing=15.0, order=1, threads=2)
        assert np.isfinite(T[0, 0])
    # the lean layout (float32 speed) on a grid too thin for the cuts' coarse march (a big
    # map's coarse march is small: never lean)
    _kernels.LEAN_NODES = 0
    T = fast_marching(v[:40] * np.linspace(0.5, 1.0, 40), [(30, 5)], order=1, threads=2)
    assert np.isfinite(T[0, 0])
    print("compiled" if compiled else "cached")
    """
)


@pytest.mark.slow
def test_2d_parallel_group_caches_every_layout_of_a_two_thread_2d_march(tmp_path):
    # a 2D map not of one speed marches its slabs interleaved, a uniform one in separate
    # arrays, a big one in the lean layout; the slab cuts run a compiled descent: after the
    # groups none of it compiles; without the parallel group it does (the check can fail)
    res = _run(["-m", "fm2uav.planning.warmup", "fmm2d_o1", "fmm2d_parallel"], tmp_path / "all")
    assert res.returncode == 0, res.stderr
    res = _run(["-c", _LATER_2D_PARALLEL_RUN], tmp_path / "all")
    assert res.returncode == 0, res.stderr
    assert res.stdout.split() == ["cached"]
    res = _run(["-m", "fm2uav.planning.warmup", "fmm2d_o1"], tmp_path / "serial")
    assert res.returncode == 0, res.stderr
    res = _run(["-c", _LATER_2D_PARALLEL_RUN], tmp_path / "serial")
    assert res.returncode == 0, res.stderr
    assert res.stdout.split() == ["compiled"]
