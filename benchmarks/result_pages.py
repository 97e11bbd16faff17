"""A march after the machine sat idle: its result in pooled pages or in a fresh array (issue 27).

``fast_marching`` writes its times into a mapping of ``fm2uav.eikonal._kernels``' result pool
when an earlier result (and every view of it) is gone; a fresh ``np.empty`` maps new pages,
whose first touch, after a few seconds idle, is slow on a virtual machine that hands its free
memory back to the host. In one process, the two alternating march by march (the fresh
array by replacing ``_kernels.result_array`` with ``np.empty``), a pause before each::

    python -m benchmarks.result_pages --case constant --shape 2048x2048 --threads 1 \\
        --pause 8 --repeats 5

Prints the medians of the wall time, the process' system CPU time and its minor page faults
(``getrusage``) per mode, and whether both modes gave the same times. Not part of
``make bench`` (the pauses); docs/performance.md quotes it.
"""

from __future__ import annotations

import argparse
import gc
import resource
import statistics
import time

import numpy as np

from benchmarks import fields


def _field(case: str, shape: tuple[int, ...]):
    if case == "fm2":
        return fields.fm2_shaped(shape, seed=0)
    if case == "smooth":
        return fields.smooth(shape)
    return np.ones(shape), tuple(n // 2 for n in shape)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--case", choices=["constant", "smooth", "fm2"], default="constant")
    ap.add_argument("--shape", default="2048x2048")
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--order", type=int, default=1)
    ap.add_argument("--pause", type=float, default=8.0, help="seconds idle before each march")
    ap.add_argument("--repeats", type=int, default=5)
    args = ap.parse_args()
    from fm2uav import fast_marching
    from fm2uav.eikonal import _kernels

    shape = tuple(int(n) for n in args.shape.split("x"))
    v, src = _field(args.case, shape)
    modes = {"pool": _kernels.result_array, "fresh": lambda n: np.empty(n)}
    ref = {}
    try:
        for name, make in modes.items():  # warm-up: kernels loaded, the pool's mapping made
            _kernels.result_array = make
            ref[name] = fast_marching(v, [src], order=args.order, threads=args.threads).copy()
        runs: dict[str, list[tuple[float, float, int]]] = {m: [] for m in modes}
        for r in range(args.repeats):
            for name in (list(modes) if r % 2 == 0 else list(modes)[::-1]):
                _kernels.result_array = modes[name]
                gc.collect()
                time.sleep(args.pause)
                r0 = resource.getrusage(resource.RUSAGE_SELF)
                t0 = time.perf_counter()
                T = fast_marching(v, [src], order=args.order, threads=args.threads)
                wall = time.perf_counter() - t0
                r1 = resource.getrusage(resource.RUSAGE_SELF)
                del T
                runs[name].append((wall, r1.ru_stime - r0.ru_stime, r1.ru_minflt - r0.ru_minflt))
    finally:
        _kernels.result_array = modes["pool"]
    print(f"{args.case} {args.shape} order {args.order}, {args.threads} thread(s), "
          f"{args.pause:g} s idle before each march, medians of {args.repeats}; same times: "
          f"{np.array_equal(ref['pool'], ref['fresh'])}")
    print("| result | wall [ms] | system CPU [ms] | minor page faults |")
    print("|---|---|---|---|")
    for name, rs in runs.items():
        wall, sys_, faults = (statistics.median(x) for x in zip(*rs))
        print(f"| {name} | {wall * 1e3:.1f} | {sys_ * 1e3:.1f} | {faults:.0f} |")


if __name__ == "__main__":
    main()
