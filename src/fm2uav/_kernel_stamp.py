"""The freshness stamp of a kernel file's numba cache: the file and the modules it imports.

numba stamps a function's cache with its own source file (the SHA-256 of its bytes): the
code it compiled in from other files — an ``@njit`` callee inlined or linked into the
caller, a constant read as a global — is not part of the stamp. Editing
``eikonal/_heap.py`` alone therefore left the cached machine code of the marches that call
its queue as it was, in every later process (numba's documented limitation, "Cache
invalidation fails to recognize changes in symbols defined in a different file";
numba/numba#1833), and an upgrade that changed only a helper module would run the old
helper from a cache kept outside the package.

:func:`kernel_stamp` is the stamp fm2uav's kernels use instead (``fm2uav._numba``
registers it with numba; ``fm2uav._jit`` reads it to tell a warm cache): the file's own
SHA-256 when it imports no other module of the package — numba's own stamp, so such
caches stay valid — else a SHA-256 over the file and every package module it imports,
followed through the imported modules that use numba (a callee's own callees and
constants). Found by reading the import lines (``from .x import``, ``from ..a.b import``,
``from fm2uav.x import``, ``import fm2uav.x``; a name imported from a package that is a
module of it counts as that module), not by importing anything. Bottom layer: no numba,
no fm2uav imports.
"""

from __future__ import annotations

import os
from pathlib import Path

__all__ = ["CALL_TIME_ONLY", "PACKAGE", "kernel_stamp", "kernel_sources"]

#: The fm2uav package folder (absolute imports ``fm2uav.x`` resolve against it).
PACKAGE = Path(__file__).resolve().parent

#: Package modules (paths relative to the package) that a kernel file imports but no kernel
#: compiles in: numbers its Python code reads at call time, never a kernel (a test of
#: ``tests/planning/test_warmup.py`` checks that no compiled function names one). They are
#: left out of the stamps, so that changing one (e.g. a tuned window size of the parallel
#: march, ``eikonal/_tuning.py``) keeps every cached kernel instead of recompiling them all.
CALL_TIME_ONLY = frozenset({"eikonal/_tuning.py"})

_PATTERNS: list = []


def _patterns() -> tuple:
    """The import-line patterns, compiled on first use (the command line imports this
    module with ``fm2uav._jit`` and reads no cache on its error paths: no ``re`` work, no
    ``hashlib`` there)."""
    if not _PATTERNS:
        import re

        _PATTERNS.extend([
            re.compile(r"^[ \t]*from[ \t]+(\.+[\w.]*|fm2uav(?:\.[\w.]+)?)[ \t]+import[ \t]+(.*)$",
                       re.MULTILINE),
            re.compile(r"^[ \t]*import[ \t]+fm2uav\.([\w.]+)", re.MULTILINE),
            re.compile(r"\w+"),
        ])
    return tuple(_PATTERNS)


def _module_file(folder: Path) -> Path | None:
    """The source of the module at ``folder`` (``folder.py`` or ``folder/__init__.py``)."""
    for cand in (folder.with_suffix(".py"), folder / "__init__.py"):
        if cand.is_file():
            return cand
    return None


def _imports(py_file: Path, package: Path) -> set[Path]:
    """The package modules ``py_file`` imports (its import lines, see the module docstring)."""
    try:
        text = py_file.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError):
        return set()
    from_, import_, name_ = _patterns()
    found: set[Path] = set()
    targets: list[tuple[Path, str]] = []
    for m in from_.finditer(text):
        mod, names = m.group(1), m.group(2)
        if mod.startswith("."):
            dots = len(mod) - len(mod.lstrip("."))
            base = py_file.parent
            for _ in range(dots - 1):
                base = base.parent
            rest = mod.lstrip(".")
        else:
            base, rest = package, mod[len("fm2uav"):].lstrip(".")
        folder = base.joinpath(*rest.split(".")) if rest else base
        targets.append((folder, names.split("#", 1)[0]))
    for m in import_.finditer(text):
        targets.append((package.joinpath(*m.group(1).split(".")), ""))
    for folder, names in targets:
        target = _module_file(folder)
        if target is None:
            continue
        found.add(target)
        if target.name == "__init__.py":  # `from . import _heap`: the submodule
            for name in name_.findall(names.replace(" as ", " ")):
                sub = _module_file(folder / name)
                if sub is not None:
                    found.add(sub)
    found.discard(py_file)
    try:
        return {p for p in found if p.resolve().is_relative_to(package.resolve())}
    except OSError:
        return set()


def kernel_sources(py_file: str | os.PathLike, package: Path = PACKAGE) -> list[Path]:
    """The package modules whose source goes into ``py_file``'s stamp, sorted (the file
    itself excluded): the ones it imports, and theirs for each that uses numba."""
    start = Path(py_file).resolve()
    package = package.resolve()
    seen: set[Path] = set()
    todo = [start]
    while todo:
        f = todo.pop()
        for dep in _imports(f, package):
            if dep in seen or dep == start or _call_time_only(dep, package):
                continue
            seen.add(dep)
            try:
                if "numba" in dep.read_text(encoding="utf-8"):
                    todo.append(dep)
            except (OSError, UnicodeDecodeError):
                continue
    return sorted(seen)


def _call_time_only(path: Path, package: Path) -> bool:
    """Whether ``path`` is one of :data:`CALL_TIME_ONLY` of ``package``."""
    try:
        rel = path.resolve().relative_to(package).as_posix()
    except (OSError, ValueError):
        return False
    return rel in CALL_TIME_ONLY


_STAMPS: dict[tuple, bytes] = {}
_SOURCES: dict[tuple[Path, Path], list[Path]] = {}


def kernel_stamp(py_file: str | os.PathLike, package: Path = PACKAGE) -> bytes:
    """The stamp of ``py_file``'s numba cache (module docstring): 32 bytes of SHA-256.

    Equal to numba's own stamp (the SHA-256 of the file's bytes) when the file imports no
    package module. Kept per process while no file involved changes its modification time
    or size (as numba keeps its own)."""
    import hashlib

    path = py_file if isinstance(py_file, Path) and py_file.is_absolute() else \
        Path(py_file).resolve()
    key0 = (path, package)
    deps = _SOURCES.get(key0)
    if deps is None:
        deps = _SOURCES[key0] = kernel_sources(path, package)
    files = [path, *deps]
    stats = []
    for f in files:
        try:
            st = os.stat(f)
        except OSError:
            stats.append(None)
            continue
        stats.append((st.st_mtime_ns, st.st_size))
    key = (path, package, tuple(stats))
    stamp = _STAMPS.get(key)
    if stamp is None:
        own = path.read_bytes()
        if not deps:
            stamp = hashlib.sha256(own).digest()
        else:
            h = hashlib.sha256(own)
            for f in deps:
                try:
                    data = f.read_bytes()
                except OSError:
                    data = b""
                rel = os.path.relpath(f, package.resolve()).replace(os.sep, "/")
                h.update(b"\0" + rel.encode() + b"\0" + hashlib.sha256(data).digest())
            stamp = h.digest()
        _STAMPS[key] = stamp
    return stamp
