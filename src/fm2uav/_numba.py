"""numba as fm2uav's kernels use it: ``njit``, ``prange`` and ``types``, with caches that go
stale when a module a kernel's file imports changes, not only the file itself.

Importing this module registers, ahead of numba's own, cache locators for the files of the
fm2uav package (``KERNEL_ROOTS``): the same folders as numba's (``$NUMBA_CACHE_DIR``, the
source's ``__pycache__``, the user-wide cache, in numba's order), stamped with
:func:`fm2uav._kernel_stamp.kernel_stamp` instead of the file's own SHA-256. A kernel whose
callee or constant in another module changed then misses its cache and compiles again, as
an edited kernel does. Files outside the package keep numba's locators. Every kernel module
takes its ``njit`` from here (``from .._numba import njit``), so the locators are in place
before the first kernel is decorated.

It also puts OpenMP first among numba's threading layers (:data:`THREADING_LAYERS`), unless
the user chose one (``NUMBA_THREADING_LAYER`` or ``NUMBA_THREADING_LAYER_PRIORITY``): numba
prefers TBB whenever a TBB library is on the machine (Debian's ``libtbb12`` comes with
OpenCV, VTK and other packages), and the parallel march starts a parallel region in every
time window (hundreds a march), where TBB's second thread joined each region ~130 µs late
and OpenMP's ~1 µs (docs/performance.md, "Where two threads lose").
"""

from __future__ import annotations

import os
from pathlib import Path

import numba
from numba import njit, prange, types
from numba.core import caching

from ._kernel_stamp import PACKAGE, kernel_stamp

__all__ = ["KERNEL_ROOTS", "LOCATORS", "THREADING_LAYERS", "njit", "prange", "types"]

#: numba's threading layers in the order fm2uav tries them (numba's own: TBB first). Measured
#: on the 2-core machine (5 December 2026, medians of 5, two threads): 2048^2 constant speed
#: order 1 137.2 ms with TBB, 124.9 ms with OpenMP (the serial march 208 ms); the FM²-shaped
#: map order 2 216.2 / 193.4 ms. Read by numba when it starts its first parallel region.
THREADING_LAYERS = ["omp", "tbb", "workqueue"]
if not ({"NUMBA_THREADING_LAYER", "NUMBA_THREADING_LAYER_PRIORITY"} & set(os.environ)):
    numba.config.THREADING_LAYER_PRIORITY = list(THREADING_LAYERS)

#: Folders whose Python files are stamped with their imports (each is its own package root
#: for ``fm2uav.x`` imports only when it is the fm2uav package).
KERNEL_ROOTS: list[Path] = [PACKAGE]


_RESOLVED: dict[str, Path | None] = {}


def _root(py_file: str) -> Path | None:
    """The entry of KERNEL_ROOTS holding ``py_file``, None if none does (numba asks for each
    cached function: the file's real path is resolved once)."""
    path = _RESOLVED.get(py_file)
    if path is None:
        try:
            path = _RESOLVED[py_file] = Path(py_file).resolve()
        except (OSError, TypeError, ValueError):
            return None
    return next((r for r in KERNEL_ROOTS if path.is_relative_to(r)), None)


def _stamped(base: type) -> type:
    """``base`` (a numba locator backed by a source file), for KERNEL_ROOTS' files only,
    stamped with the file and its imports."""

    class Locator(base):
        @classmethod
        def from_function(cls, py_func, py_file):
            if _root(py_file) is None:
                return None
            return super().from_function(py_func, py_file)

        def get_source_stamp(self):
            return kernel_stamp(_RESOLVED.get(self._py_file) or self._py_file,
                                _root(self._py_file) or PACKAGE)

    Locator.__name__ = Locator.__qualname__ = f"Fm2uav{base.__name__}"
    return Locator


#: The locators registered, in numba's order for source files.
LOCATORS: tuple[type, ...] = tuple(
    _stamped(b) for b in (caching.UserProvidedCacheLocator, caching.InTreeCacheLocator,
                          caching.UserWideCacheLocator))

if not any(c.__name__.startswith("Fm2uav") for c in caching.CacheImpl._locator_classes):
    caching.CacheImpl._locator_classes[0:0] = list(LOCATORS)
