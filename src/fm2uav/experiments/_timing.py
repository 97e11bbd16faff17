"""Warm timings for the reproduction tables.

The numba kernels are compiled (or loaded from the on-disk cache) the first time a
process calls them: the first ``plan()`` of a fresh process took 44 s in the city table
and 0.22 s on a rerun. A table's timing must measure the algorithm, not the compiler,
so every timed stage runs once untimed first (:func:`warm`). The worlds' caches (the
distance transform, the surface index, ...) are emptied between the two calls, so the
timed call still pays for everything a first plan on that map computes; only the
compilation is excluded.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Iterable
from typing import Any, TypeVar

__all__ = ["WARM_NOTE", "warm", "clear_caches"]

T = TypeVar("T")

#: One sentence for table captions.
WARM_NOTE = ("timings are warm: each timed stage ran once untimed first (numba compilation "
             "excluded), with the map's cached distance transform cleared before the timed run")


def clear_caches(worlds: Iterable[Any]) -> None:
    """Empty the per-world caches (distance transform, surface index, ...) of ``worlds``."""
    for w in worlds:
        cache = getattr(w, "_cache", None)
        if cache is not None:
            cache.clear()


def warm(stage: Callable[[], T], worlds: Iterable[Any] = ()) -> tuple[T, float]:
    """Run ``stage`` once untimed, clear the caches of ``worlds``, run and time it again.

    Parameters
    ----------
    stage : callable
        The timed stage, without arguments (deterministic: both calls give the same result).
    worlds : iterable of World
        Worlds whose caches the stage fills; emptied before the timed call.

    Returns
    -------
    result, seconds
        The second call's result and its wall time [s].
    """
    worlds = list(worlds)
    stage()
    clear_caches(worlds)
    t0 = time.perf_counter()
    out = stage()
    return out, time.perf_counter() - t0
