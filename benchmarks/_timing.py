"""Timing helper shared by the benchmark modules."""

from __future__ import annotations

import statistics
import time
from collections.abc import Callable
from typing import Any


def median_time(fn: Callable[[], Any], repeats: int, *, warmup: bool = False) -> tuple[float, Any]:
    """Median wall time of ``repeats`` calls of ``fn`` [s] and the last call's result.

    ``warmup=True`` makes one untimed call first (JIT compilation, caches).
    """
    if warmup:
        fn()
    out = None
    times = []
    for _ in range(max(1, repeats)):
        t = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t)
    return statistics.median(times), out
