"""One-off numba compilation: is it coming, and a hook to say so.

The kernels are compiled by numba on first use and cached on disk
(``cache=True``); every later process loads them in milliseconds. A cold
cache (fresh install, new numba, edited kernel source) costs seconds of
compilation before the first result, so the command line says so at once.
Library code never prints: this module only *detects* and *calls back*.

* :func:`likely_cold` answers "will the first plan compile?" in a few
  milliseconds **without importing numba** (~0.5 s): it reads the cache index
  files of a few kernels the way numba's own cache locators find them.
* :func:`on_first_compile` registers a callback run once per process, right
  before numba compiles the first fm2uav function (a cache miss): the reliable
  fallback for every other path (other commands, stale or foreign caches). It
  does not import numba either: the listener is installed when numba is first
  imported.
* :func:`cache_fault` tells a damaged cache file (truncated, overwritten, a
  foreign format: numba fails to load it, every run, until it is deleted) from
  other errors, and :func:`clear_cache` deletes fm2uav's cache files so that the
  kernels are compiled again (the command line does both, see
  :func:`fm2uav.cli._common.handle_errors`).

Bottom layer (fm2uav imports only ``_kernel_stamp``: a kernel cache's stamp is its file and
the modules it imports, as ``fm2uav._numba`` stamps it): the kernels are named by file and
function.
"""

from __future__ import annotations

import os
import sys
from collections.abc import Callable, Iterable
from pathlib import Path
from typing import Any

from ._kernel_stamp import kernel_stamp

__all__ = [
    "FIRST_PLAN_KERNELS",
    "ROUTES_KERNELS",
    "COLD_FIRST_PLAN_CPU_S",
    "NOTICE",

    "cache_fault",
    "clear_cache",
    "clear_kernel_cache",
    "cold_estimate_s",
    "likely_cold",
    "announced",
    "mark_announced",

    "on_first_compile",
]

_PKG = Path(__file__).resolve().parent

#: Kernels a first ``fm2uav plan`` (built-in 3D scenario, order 2) compiles:
#: ``(file relative to the package, function name)``. If any has no valid cache
#: index, the plan will compile.
FIRST_PLAN_KERNELS: tuple[tuple[str, str], ...] = (
    ("eikonal/_edt.py", "_edt_serial"),
    ("eikonal/_sources.py", "init_sources"),
    ("eikonal/_kernels.py", "march3d_o2"),
    ("planning/_geodesic_kernels.py", "descend_kernel"),
    ("world/_clearance_kernels.py", "surface_distance"),
)

#: Kernels a first ``fm2uav routes`` compiles: a first plan's and the batch descent's
#: (``descend_sweep``) and clearance (``min_box_clearances``) of ``plan_many``.
ROUTES_KERNELS: tuple[tuple[str, str], ...] = FIRST_PLAN_KERNELS + (
    ("planning/_geodesic_kernels.py", "descend_sweep"),
    ("world/_clearance_kernels.py", "min_box_clearances"),
)

#: What the command line says before the first compilation (``seconds``: :func:`cold_estimate_s`).
NOTICE = "compiling kernels, first use only, ~{seconds} s"

#: CPU time [s] of a first ``fm2uav plan`` with an empty numba cache, both
#: processes together (compilation, imports, the plan): measured 17-18 s on the
#: 2-core machine (``/usr/bin/time fm2uav plan`` after ``pip install .``; the
#: ``coldstart`` rows of docs/performance.md give the wall times).
COLD_FIRST_PLAN_CPU_S = 18.0


def cold_estimate_s() -> int:
    """Seconds a cold first plan will take here: its CPU time over the idle cores.

    The compilation runs in two processes, so it uses up to two cores; the idle
    ones are the CPU count minus the 1-minute load average (at least one).
    """
    try:
        idle = (os.cpu_count() or 1) - os.getloadavg()[0]
    except OSError:  # no load average on this platform
        idle = float(os.cpu_count() or 1)
    return int(round(COLD_FIRST_PLAN_CPU_S / max(1.0, min(2.0, idle))))


def _usable(path: Path) -> bool:
    """Can numba keep its cache in ``path`` (created if missing, writable)? As its locators."""
    try:
        import tempfile

        os.makedirs(path, exist_ok=True)
        with tempfile.TemporaryFile(dir=path):
            pass
    except OSError:
        return False
    return True


def _cache_candidates(py_file: Path) -> list[Path]:
    """Where numba may keep ``py_file``'s cache, in the order its locators try them:
    ``$NUMBA_CACHE_DIR/<dir>_<sha1(dir)>`` when set, the source's ``__pycache__``,
    the user-wide cache directory (``$XDG_CACHE_HOME/numba/<dir>_<sha1(dir)>``)."""
    import hashlib

    parent = py_file.parent
    sub = f"{parent.name}_{hashlib.sha1(str(parent).encode()).hexdigest()}"
    candidates = []
    user_dir = os.environ.get("NUMBA_CACHE_DIR")
    if user_dir:
        candidates.append(Path(os.path.abspath(user_dir)) / sub)
    xdg = os.environ.get("XDG_CACHE_HOME") or os.path.expanduser("~/.cache")
    candidates += [parent / "__pycache__", Path(xdg) / "numba" / sub]
    return candidates


def _cache_dir(py_file: Path) -> Path | None:
    """The directory where numba keeps ``py_file``'s cache (first usable candidate of
    :func:`_cache_candidates`, as ``numba.core.caching``'s locators), None if none is."""
    return next((c for c in _cache_candidates(py_file) if _usable(c)), None)


class _Stub:
    """Stands in for every numba object while unpickling an index (no numba import)."""

    def __init__(self, *args, **kwargs):
        pass

    def __setstate__(self, state):
        pass

    def __call__(self, *args, **kwargs):
        return _Stub()


_UNPICKLER: list[type] = []


def _index_unpickler() -> type:
    """The unpickler of numba's cache indexes: :class:`_Stub` for every numba object
    (a class made on first use: :mod:`pickle`, :mod:`hashlib` and :mod:`tempfile` load
    only when a cache is read, not with every command line that imports this module)."""
    if not _UNPICKLER:
        import pickle

        class _IndexUnpickler(pickle.Unpickler):
            def find_class(self, module: str, name: str) -> Any:
                if module.split(".")[0] in ("numba", "llvmlite", "numpy"):
                    return _Stub
                return super().find_class(module, name)

        _UNPICKLER.append(_IndexUnpickler)
    return _UNPICKLER[0]


def _numba_version() -> str | None:
    """numba's version as its distribution records it, or None if it cannot tell.

    Read from the name of the ``numba-<version>.dist-info`` folder beside the ``numba``
    package that imports first on ``sys.path`` (a directory listing: importlib.metadata
    costs ~50 ms of a bad flag's answer, the email package included); importlib.metadata
    where there is no such folder.
    """
    for entry in sys.path:
        try:
            names = os.listdir(entry or os.curdir)
        except OSError:
            continue
        if "numba" not in names:
            continue
        for name in names:
            if name.startswith("numba-") and name.endswith(".dist-info"):
                return name[len("numba-"):-len(".dist-info")]
        break
    try:
        from importlib.metadata import version

        return version("numba")
    except Exception:  # not installed as a distribution: cannot tell
        return None


def _fresh_index(index: Path, source_hash: bytes, numba_version: str | None) -> bool:
    """True if ``index`` is a numba cache index of this source with an entry."""
    import pickle

    try:
        with open(index, "rb") as fh:
            version = pickle.load(fh)
            # numba: pickle of (stamp, overloads)
            stamp, overloads = _index_unpickler()(fh).load()
    except Exception:  # unreadable, truncated, another format: not usable
        return False
    if numba_version is not None and version != numba_version:
        return False
    return stamp == source_hash and len(overloads) > 0


def _cached(rel_file: str, func: str, numba_version: str | None) -> bool:
    py_file = _PKG / rel_file
    try:
        source_hash = kernel_stamp(py_file)
    except OSError:
        return False
    tag = f"py{sys.version_info[0]}{sys.version_info[1]}{getattr(sys, 'abiflags', '')}"
    d = _cache_dir(py_file)
    if d is None:
        return False
    return any(_fresh_index(d / name, source_hash, numba_version)
               for name in _names(d, f"{py_file.stem}.{func}-", f".{tag}.nbi"))


def _names(folder: Path, prefix: str, suffix: str) -> list[str]:
    """The files ``folder/<prefix>*<suffix>`` (what ``glob`` matches, without its regular
    expressions: the check runs before a plan's arguments are parsed)."""
    try:
        names = os.listdir(folder)
    except OSError:
        return []
    return sorted(n for n in names if n.startswith(prefix) and n.endswith(suffix)
                  and len(n) >= len(prefix) + len(suffix))


def likely_cold(kernels: Iterable[tuple[str, str]] = FIRST_PLAN_KERNELS) -> bool:
    """Will calling these kernels compile them (no valid numba cache entry)?

    Cheap (a few ms, numba not imported). It checks that each kernel has a
    cache index for the current source text and numba version with at least
    one entry; it does not check the entry's CPU or argument types, so a
    cache made on another machine reads as warm (numba then recompiles, and
    :func:`on_first_compile` still fires). Always False when numba's JIT is
    disabled (``NUMBA_DISABLE_JIT=1``).

    Parameters
    ----------
    kernels : iterable of (str, str)
        ``(file relative to the fm2uav package, function name)``.
    """
    if os.environ.get("NUMBA_DISABLE_JIT", "0") not in ("", "0"):
        return False
    version = _numba_version()
    return not all(_cached(f, name, version) for f, name in kernels)


def _fm2uav_sources() -> list[Path]:
    return sorted(p for p in _PKG.rglob("*.py") if "__pycache__" not in p.parts)


def clear_cache() -> list[Path]:
    """Delete the numba cache files of fm2uav's kernels (index ``.nbi`` and data ``.nbc``)
    where this process keeps them (:func:`_cache_dir`: ``$NUMBA_CACHE_DIR`` when set, else
    the package's ``__pycache__`` folders or the user-wide cache, as numba chooses).

    The next call of each kernel compiles it again and writes a fresh cache.
    Files that cannot be deleted are left (and not returned). Caches of other
    locations (another ``$NUMBA_CACHE_DIR``) are not touched.

    Returns
    -------
    list of Path
        The files deleted.
    """
    removed = []
    for py_file in _fm2uav_sources():
        d = _cache_dir(py_file)
        if d is not None and d.is_dir():
            removed += _unlink_cache_files(d, py_file.stem)
    return removed


def _unlink_cache_files(folder: Path, prefix: str) -> list[Path]:
    """Delete ``folder/<prefix>.*.nbi`` and ``.nbc``; the files deleted (others left)."""
    import glob

    removed = []
    for f in glob.glob(str(glob.escape(str(folder)) + "/" + glob.escape(prefix) + ".*.nb[ic]")):
        try:
            os.unlink(f)
        except OSError:
            continue
        removed.append(Path(f))
    return removed


def clear_kernel_cache(path: str) -> list[Path]:
    """Delete the numba cache files of the one kernel whose file ``path`` failed to load.

    ``path`` is what :func:`cache_fault` returns: an index (``<module>.<kernel>-<line>.<tag>
    .nbi``) or data file (``....<n>.nbc``) of a kernel; every file of that kernel in that
    folder goes (its index and all its data files), the other kernels' caches stay — another
    process may be using them, and they load. A ``path`` that names no kernel's cache file
    (``"numba cache"``: the file was not known) falls back to :func:`clear_cache`.

    Returns
    -------
    list of Path
        The files deleted.
    """
    import re

    p = Path(path)
    m = re.match(r"^(.+?-\d+)\.py\d", p.name)
    if m is None or p.suffix not in (".nbi", ".nbc"):
        return clear_cache()
    return _unlink_cache_files(p.parent, m.group(1))


def _chain(exc: BaseException) -> Iterable[BaseException]:
    seen: set[int] = set()
    while exc is not None and id(exc) not in seen:
        seen.add(id(exc))
        yield exc
        exc = exc.__cause__ or exc.__context__


def cache_fault(exc: BaseException) -> str | None:
    """The cache file numba failed to load if ``exc`` comes from loading its cache, else None.

    A numba cache file that cannot be read back (truncated by a full disk or a
    killed writer, overwritten, from another numba build) makes numba raise
    from ``numba.core.caching`` (``UnpicklingError``, ``EOFError``, ...) at
    the first call of the kernel, in every process, until the file is deleted.
    This looks for a frame of ``numba/core/caching.py`` in the traceback of
    ``exc`` or of the errors it was raised from.

    Returns
    -------
    str or None
        The file being read when known, else ``"numba cache"``; None if ``exc`` did
        not come from numba's cache.
    """
    for e in _chain(exc):
        tb, found = e.__traceback__, None
        while tb is not None:
            code = tb.tb_frame.f_code
            if code.co_filename.replace(os.sep, "/").endswith("numba/core/caching.py"):
                loc = tb.tb_frame.f_locals
                path = loc.get("path") or getattr(loc.get("self"), "_index_path", None)
                found = str(path) if path else (found or "numba cache")
            tb = tb.tb_next
        if found is not None:
            return found
    return None


_callbacks: list[Callable[[], None]] = []
_fired = False
_listener = None
_hook = None


def _fire() -> None:
    global _fired
    if _fired:
        return
    _fired = True
    for cb in list(_callbacks):
        cb()


def mark_announced() -> None:
    """Record that the caller has already told the user (no second callback)."""
    global _fired
    _fired = True


def announced() -> bool:
    """Whether the compile notice was given in this process (:func:`mark_announced`, or a
    callback of :func:`on_first_compile` fired)."""
    return _fired


def on_first_compile(callback: Callable[[], None]) -> None:
    """Call ``callback()`` once, right before numba compiles the first fm2uav function.

    Fires on a real compilation only (numba's ``numba:compile`` event follows
    a cache miss; loading from the cache does not fire it), at most once per
    process over all callbacks, and not at all after :func:`mark_announced`.
    Does not import numba: if it is not imported yet, the listener is
    installed right after its first import (an import hook that watches for
    ``numba`` only), so a command that never needs a kernel never loads it.
    """
    global _hook
    _callbacks.append(callback)
    if _listener is not None or _hook is not None:
        return
    if "numba" in sys.modules:
        _listen()
        return
    _hook = _AfterImport("numba", _listen)
    sys.meta_path.insert(0, _hook)


class _AfterImport:
    """A meta-path finder that runs ``then()`` once, right after module ``name`` is imported
    (it finds the module as the other finders do and wraps its loader's ``exec_module``)."""

    def __init__(self, name: str, then: Callable[[], None]) -> None:
        self.name, self.then = name, then

    def find_spec(self, name: str, path: Any = None, target: Any = None) -> Any:
        if name != self.name:
            return None
        import importlib.util

        _remove_hook()
        spec = importlib.util.find_spec(name)
        loader = getattr(spec, "loader", None)
        if loader is None or not hasattr(loader, "exec_module"):
            return spec
        exec_module, then = loader.exec_module, self.then

        def exec_then(module: Any) -> None:
            exec_module(module)
            then()

        loader.exec_module = exec_then
        return spec


def _remove_hook() -> None:
    global _hook
    if _hook is not None:
        try:
            sys.meta_path.remove(_hook)
        except ValueError:
            pass
        _hook = None


def _listen() -> None:
    """Register the ``numba:compile`` listener of :func:`on_first_compile` (imports numba)."""
    global _listener
    if _listener is not None:
        return
    from numba.core import event

    class _FirstCompile(event.Listener):
        def on_start(self, ev):
            disp = ev.data.get("dispatcher") if isinstance(ev.data, dict) else None
            mod = getattr(getattr(disp, "py_func", None), "__module__", "") or ""
            if mod == "fm2uav" or mod.startswith("fm2uav."):
                _fire()

        def on_end(self, ev):
            pass

    _listener = _FirstCompile()
    event.register("numba:compile", _listener)
