"""Timing helper shared by the benchmark modules."""

from __future__ import annotations

import argparse
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


def interleaved_runs(repeats: int, threads: list[int], peer_src: str | None, own_src: str,
                     run: Callable[[str, int], dict]) -> dict[tuple[str, int], list[dict]]:
    """Each ``run(src, threads)`` of our checkout and an optional peer's, interleaved.

    Rounds of every thread count and every code in turn (a change of the machine's load hits
    both alike); keys ``("ours" | "peer", threads)``, each with ``repeats`` results.
    """
    codes = {"ours": own_src}
    if peer_src:
        codes["peer"] = peer_src
    runs: dict[tuple[str, int], list[dict]] = {}
    for _ in range(repeats):
        for th in threads:
            for name, src in codes.items():
                runs.setdefault((name, th), []).append(run(src, th))
    return runs


def ab_parser(description: str) -> argparse.ArgumentParser:
    """The options of an A/B script run by :func:`interleaved_runs`: ``--threads``,
    ``--repeats`` and ``--peer-src`` (another checkout's ``src/`` to interleave)."""
    ap = argparse.ArgumentParser(description=description)
    ap.add_argument("--threads", type=int, nargs="+", default=[1, 2])
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--peer-src", default=None, help="another checkout's src/ to interleave")
    return ap
