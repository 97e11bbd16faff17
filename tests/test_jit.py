"""First use without the wait: the compile notice, the cache check, a light import."""

from __future__ import annotations

import os
import selectors
import subprocess
import sys
import time
from pathlib import Path

import pytest

from fm2uav import _jit

ROOT = Path(__file__).resolve().parents[1]
NOTICE = "compiling kernels, first use only"


def _env(cache: Path) -> dict:
    src = str(ROOT / "src")
    path = os.environ.get("PYTHONPATH")
    return {**os.environ, "NUMBA_CACHE_DIR": str(cache),
            "PYTHONPATH": src if not path else f"{src}{os.pathsep}{path}"}


def _python(code: str, cache: Path) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          timeout=300, env=_env(cache))


def test_import_fm2uav_loads_no_numba_scipy_or_matplotlib(tmp_path):
    res = _python("import sys, fm2uav; print(sorted(m for m in ('numba', 'scipy', "
                  "'matplotlib') if m in sys.modules)); fm2uav.World; print('numba' in sys.modules); "
                  "fm2uav.plan; print('numba' in sys.modules)",
                  tmp_path)
    assert res.returncode == 0, res.stderr
    # lazy, the World light (its builders load on first call), the planner loads the kernels
    assert res.stdout.split("\n")[:3] == ["[]", "False", "True"]


def test_likely_cold_follows_numba_cache_index(tmp_path, monkeypatch):
    kernel = [("eikonal/_kernels.py", "scan_speed")]
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path))
    assert _jit.likely_cold(kernel)
    res = _python("import numpy as np; from fm2uav.eikonal import _kernels as k; "
                  "k.scan_speed(k._readonly(np.ones(3)), 1e-9)", tmp_path)
    assert res.returncode == 0, res.stderr
    assert not _jit.likely_cold(kernel)
    assert _jit.likely_cold(kernel + [("eikonal/_kernels.py", "unpad_grid")])
    monkeypatch.setenv("NUMBA_DISABLE_JIT", "1")
    assert not _jit.likely_cold(kernel + [("eikonal/_kernels.py", "unpad_grid")])


def test_first_compile_callback_fires_once_and_only_on_a_cache_miss(tmp_path):
    code = (
        "import numpy as np\n"
        "from fm2uav import _jit\n"
        "_jit.on_first_compile(lambda: print('FIRED', flush=True))\n"
        "from fm2uav.eikonal import _kernels as k\n"
        "k.scan_speed(k._readonly(np.ones(3)), 1e-9)\n"
        "k.unpad_grid(np.zeros(27), 1, 1, 1, np.zeros(1))\n"
        "print('DONE')\n"
    )
    cold = _python(code, tmp_path)
    assert cold.returncode == 0, cold.stderr
    assert cold.stdout.split() == ["FIRED", "DONE"]
    warm = _python(code, tmp_path)  # both kernels load from the cache now
    assert warm.returncode == 0, warm.stderr
    assert warm.stdout.split() == ["DONE"]


def _first_plan(cache: Path, out: Path) -> tuple[float, str, str, float]:
    """Run ``python -m fm2uav plan``: (seconds to the first output, first line, stderr, wall)."""
    t0 = time.perf_counter()
    proc = subprocess.Popen([sys.executable, "-m", "fm2uav", "plan", "--out", str(out),
                             "--force"], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            env=_env(cache))
    sel = selectors.DefaultSelector()
    sel.register(proc.stdout, selectors.EVENT_READ)
    sel.register(proc.stderr, selectors.EVENT_READ)
    first_t, first, err, streams = None, b"", b"", 2
    while streams:
        for key, _ in sel.select(timeout=600):
            chunk = os.read(key.fileobj.fileno(), 65536)
            if not chunk:
                sel.unregister(key.fileobj)
                streams -= 1
                continue
            if first_t is None:
                first_t, first = time.perf_counter() - t0, chunk
            if key.fileobj is proc.stderr:
                err += chunk
    assert proc.wait(timeout=600) == 0, err.decode()[-3000:]
    return first_t, first.decode().splitlines()[0], err.decode(), time.perf_counter() - t0


@pytest.mark.slow
def test_cold_first_plan_says_so_within_a_second_and_a_warm_one_does_not(tmp_path):
    cache, out = tmp_path / "numba", tmp_path / "plan"
    cache.mkdir()
    first_t, first_line, err, _ = _first_plan(cache, out)
    assert first_line.startswith(NOTICE)
    assert first_t < 1.0, f"first output after {first_t:.2f} s"
    assert err.count(NOTICE) == 1
    assert (out / "path.csv").is_file()
    # the cold run cached every kernel the plan needs: a second process compiles
    # nothing (the numba-event fallback would print the notice on any compilation)
    _, first_line, err, _ = _first_plan(cache, out)
    assert NOTICE not in err and not first_line.startswith(NOTICE)


def test_cold_estimate_spreads_the_cpu_time_over_up_to_two_idle_cores(monkeypatch):
    monkeypatch.setattr(os, "cpu_count", lambda: 2)
    monkeypatch.setattr(os, "getloadavg", lambda: (0.0, 0.0, 0.0))
    idle = _jit.cold_estimate_s()
    assert idle == round(_jit.COLD_FIRST_PLAN_CPU_S / 2)
    monkeypatch.setattr(os, "getloadavg", lambda: (3.0, 3.0, 3.0))
    assert _jit.cold_estimate_s() == round(_jit.COLD_FIRST_PLAN_CPU_S) > idle
    monkeypatch.setattr(os, "cpu_count", lambda: 16)
    monkeypatch.setattr(os, "getloadavg", lambda: (0.0, 0.0, 0.0))
    assert _jit.cold_estimate_s() == idle  # two processes use at most two cores


def test_a_bad_flag_on_a_cold_cache_compiles_nothing(tmp_path):
    cache = tmp_path / "numba"
    cache.mkdir()
    res = subprocess.run([sys.executable, "-m", "fm2uav", "plan", "--bogus"],
                         capture_output=True, text=True, timeout=300, env=_env(cache))
    assert res.returncode == 2 and "No such option" in res.stderr
    assert not list(cache.rglob("*.nbi"))  # neither this process nor a warm-up child compiled


def test_on_first_compile_waits_for_numba_without_importing_it(tmp_path):
    code = (
        "import sys\n"
        "from fm2uav import _jit\n"
        "_jit.on_first_compile(lambda: print('FIRED', flush=True))\n"
        "print('numba' in sys.modules, flush=True)\n"
        "import numpy as np\n"
        "from fm2uav.eikonal import _kernels as k\n"  # imports numba: the listener is installed
        "k.scan_speed(k._readonly(np.ones(3)), 1e-9)\n"
        "print('DONE')\n"
    )
    res = _python(code, tmp_path)
    assert res.returncode == 0, res.stderr
    assert res.stdout.split() == ["False", "FIRED", "DONE"]


def test_cache_fault_finds_numba_s_cache_loader_and_clear_cache_deletes_its_files(tmp_path):
    code = ("import numpy as np; from fm2uav.eikonal import _kernels as k; "
            "k.scan_speed(k._readonly(np.ones(3)), 1e-9)")
    assert _python(code, tmp_path).returncode == 0
    files = sorted(tmp_path.rglob("_kernels.scan_speed-*.nb[ic]"))
    assert len(files) >= 2
    index = next(f for f in files if f.suffix == ".nbi")
    index.write_bytes(b"\x80\x04")  # truncated
    in_tree = ROOT / "src" / "fm2uav" / "eikonal" / "__pycache__"
    others = sorted(in_tree.glob("_kernels.*.nb[ic]"))  # another location's cache
    probe = (
        "import numpy as np\n"
        "from fm2uav import _jit\n"
        "from fm2uav.eikonal import _kernels as k\n"
        "try:\n"
        "    k.scan_speed(k._readonly(np.ones(3)), 1e-9)\n"
        "except Exception as exc:\n"
        "    print('FAULT', _jit.cache_fault(exc))\n"
        "    print('OTHER', _jit.cache_fault(ValueError('x')))\n"
        "    print('REMOVED', len(_jit.clear_cache()))\n"
    )
    res = _python(probe, tmp_path)
    assert res.returncode == 0, res.stderr
    lines = dict(line.split(" ", 1) for line in res.stdout.splitlines())
    assert lines["FAULT"] == str(index)
    assert lines["OTHER"] == "None"
    assert int(lines["REMOVED"]) >= 2
    assert not list(tmp_path.rglob("_kernels.scan_speed-*.nb[ic]"))
    assert sorted(in_tree.glob("_kernels.*.nb[ic]")) == others  # only where this process caches

    assert _python(code, tmp_path).returncode == 0  # compiles and caches again


def test_numba_version_is_the_distribution_s_without_importlib_metadata(tmp_path, monkeypatch):
    """The version the cache check compares with numba's index (its dist-info folder's name:
    what importlib.metadata reads, without loading it); where there is no such folder, the
    fallback still answers."""
    import importlib.metadata

    import numba

    assert _jit._numba_version() == importlib.metadata.version("numba") == numba.__version__
    res = subprocess.run([sys.executable, "-c", "import sys; from fm2uav import _jit; "
                          "_jit._numba_version(); print('importlib.metadata' in sys.modules)"],
                         capture_output=True, text=True, timeout=120)
    assert res.stdout.split() == ["False"], res.stderr
    # a numba package without a dist-info folder beside it: importlib.metadata's answer
    (tmp_path / "numba").mkdir()
    monkeypatch.setattr(sys, "path", [str(tmp_path), *sys.path])
    assert _jit._numba_version() == importlib.metadata.version("numba")


def test_clear_kernel_cache_deletes_the_damaged_kernel_s_files_only(tmp_path, monkeypatch):
    """One kernel's index or data file failed to load: its index and every data file go, the
    other kernels' (same module, same line, other names) stay; an unknown file: all of them."""
    names = ["_kernels.march2d_o1-643.py311.nbi", "_kernels.march2d_o1-643.py311.1.nbc",
             "_kernels.march2d_o1-643.py311.2.nbc", "_kernels.march2d_o2-643.py311.nbi",
             "_kernels.march2d_o2-643.py311.1.nbc", "_kernels.scan_speed-1416.py311.nbi",
             "_kernels.cpython-311.pyc"]
    for n in names:
        (tmp_path / n).write_bytes(b"x")
    removed = _jit.clear_kernel_cache(str(tmp_path / names[1]))
    assert sorted(p.name for p in removed) == sorted(names[:3])
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(names[3:])
    assert _jit.clear_kernel_cache(str(tmp_path / names[3])) and \
        sorted(p.name for p in tmp_path.iterdir()) == sorted(names[5:])
    # not a kernel's cache file: every fm2uav cache file (where this process keeps them)
    calls = []
    monkeypatch.setattr(_jit, "clear_cache", lambda: calls.append(1) or [])
    assert _jit.clear_kernel_cache("numba cache") == [] and calls == [1]
