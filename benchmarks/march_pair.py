"""How this machine runs two serial marches at once: the ceiling of a two-thread ratio (issue 27).

Two processes, each with the same grid, march on one thread (``threads=1``): first one
alone while the other waits, then both at the same moment (a barrier), in turn, medians::

    python -m benchmarks.march_pair [--case 2048x2048:fm2] [--order 1] [--repeats 5]

Prints the wall time of a march alone, of each of the two at once and their ratio (1.00x:
the machine gives two full cores to this work; 1.30x: each march is 30 % slower beside
the other, and no two-thread march can pass 2 / 1.30 = 1.54x). Unlike the loops of
:mod:`benchmarks.machine_scaling` this is the march's own mix of cache misses and
arithmetic: on 5 December 2026 two marches at once took 0.97-1.03x the time of one
(2048², constant and FM²-shaped, order 1 and 2) while ``machine_scaling``'s memory-bound
``lines`` loop doubled only 1.06-1.09x; the two-thread march's own losses are in the code
(docs/performance.md, "Where two threads lose").

A case is ``SHAPE:FIELD``, the field ``constant`` (centre source), ``smooth`` or ``fm2``
(:mod:`benchmarks.fields`).
"""

from __future__ import annotations

import argparse
import multiprocessing as mp
import statistics
import time

import numpy as np


def problem(case: str) -> tuple[np.ndarray, tuple[int, ...]]:
    """The speed field [m/s] and source node of ``SHAPE:FIELD``."""
    from benchmarks import fields

    shape_s, field = case.split(":")
    shape = tuple(int(n) for n in shape_s.split("x"))
    if field == "constant":
        return np.ones(shape), tuple(n // 2 for n in shape)
    return fields.smooth(shape) if field == "smooth" else fields.fm2_shaped(shape)


def _worker(case, order, repeats, index, barrier, queue):
    """March ``repeats`` rounds: alone (process 0 only), then both at once."""
    from fm2uav import fast_marching

    v, src = problem(case)
    fast_marching(v, [src], order=order, threads=1)  # compiled kernels loaded, pages touched
    out = []
    for _ in range(repeats):
        for together in (False, True):
            barrier.wait()
            if together or index == 0:
                t = time.perf_counter()
                fast_marching(v, [src], order=order, threads=1)
                out.append((together, time.perf_counter() - t))
            if not together:
                barrier.wait()  # the other one starts no march before this one ends
    queue.put(out)


def measure(case: str = "2048x2048:fm2", order: int = 1, repeats: int = 5) -> dict:
    """Median wall times [s] of a serial march alone and of each of two at once.

    Must run before the calling process starts a thread pool (the two marchers are
    forked); the marches are serial, so they start none either.
    """
    ctx = mp.get_context("fork")
    barrier, queue = ctx.Barrier(2), ctx.Queue()
    procs = [ctx.Process(target=_worker, args=(case, order, repeats, i, barrier, queue))
             for i in range(2)]
    for p in procs:
        p.start()
    runs = [r for _ in procs for r in queue.get(timeout=600)]
    for p in procs:
        p.join(timeout=60)
    alone = statistics.median(w for together, w in runs if not together)
    pair = statistics.median(w for together, w in runs if together)
    return {"case": case, "order": order, "alone_s": alone, "pair_s": pair,
            "ratio": pair / alone}


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--case", default="2048x2048:fm2")
    ap.add_argument("--order", type=int, default=1, choices=(1, 2))
    ap.add_argument("--repeats", type=int, default=5)
    args = ap.parse_args(argv)
    r = measure(args.case, args.order, args.repeats)
    print(f"{r['case']} order {r['order']}, medians of {args.repeats}: alone "
          f"{1e3 * r['alone_s']:.1f} ms, each of two at once {1e3 * r['pair_s']:.1f} ms "
          f"({r['ratio']:.2f}x; a two-thread march's ceiling {2 / r['ratio']:.2f}x)")


if __name__ == "__main__":
    main()
