"""The two-thread march under libgomp spin counts, march by march (issue 27).

The parallel march's windows end at a parallel region's barrier twice per window; how long
the thread that arrives first spins before it sleeps is libgomp's ``GOMP_SPINCOUNT``
(``fm2uav.eikonal._tuning.SPIN_COUNT`` unless the user sets it). One child per spin count
(``benchmarks/threads_march.py``'s child: the same code, kernels loaded once), the children's
marches alternating one by one, each case on 1 and 2 threads::

    python -m benchmarks.wait_policy --cases 2048x2048:fm2 160x160x160:fm2 \\
        --spins 0 2000 --repeats 9

``0`` is passive (sleep at once). Cases as ``threads_march``'s. Prints per case and spin count
the medians of the wall time on 1 and 2 threads, the two threads' process CPU, the quartiles of
the two-thread wall and the ratio one thread / two threads. Not part of ``make bench`` (the
children's warm-ups); docs/performance.md quotes it.
"""

from __future__ import annotations

import argparse
import os
import statistics

from benchmarks.threads_march import ROOT, _Child


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--cases", nargs="+", default=["2048x2048:fm2", "160x160x160:fm2"])
    ap.add_argument("--spins", nargs="+", type=int, default=[0, 2000])
    ap.add_argument("--repeats", type=int, default=9)
    args = ap.parse_args()
    src = str(ROOT / "src")
    kids = {n: _Child(src, {**os.environ, "OMP_WAIT_POLICY": "PASSIVE",
                            "GOMP_SPINCOUNT": str(n)}) for n in args.spins}
    res: dict = {(n, c, th): [] for n in kids for c in args.cases for th in (1, 2)}
    loads = []
    try:
        for _ in range(args.repeats):
            for c in args.cases:
                for th in (1, 2):
                    for n, child in kids.items():
                        r = child.run(c, th)
                        res[(n, c, th)].append(r)
                        loads.append(r["load"])
    finally:
        for child in kids.values():
            child.close()
    print(f"medians of {args.repeats}, load {min(loads):.1f}-{max(loads):.1f}")
    print("| case | spins | 1 thread [ms] | 2 threads [ms] | 2 threads' CPU [ms] "
          "| 2 threads q25-q75 [ms] | 1 / 2 threads | digest |")
    print("|---|---|---|---|---|---|---|---|")
    for c in args.cases:
        for n in kids:
            one = statistics.median(r["wall"] for r in res[(n, c, 1)])
            w2 = sorted(r["wall"] for r in res[(n, c, 2)])
            two = statistics.median(w2)
            cpu = statistics.median(r["cpu"] for r in res[(n, c, 2)])
            q = len(w2) // 4
            digests = {r["digest"] for th in (1, 2) for r in res[(n, c, th)]}
            print(f"| {c} | {n} | {one * 1e3:.1f} | {two * 1e3:.1f} | {cpu * 1e3:.1f} "
                  f"| {w2[q] * 1e3:.1f}-{w2[-1 - q] * 1e3:.1f} | {one / two:.2f}x "
                  f"| {'/'.join(sorted(digests))} |")


if __name__ == "__main__":
    main()
