"""What the first touch of fresh memory costs here, in huge pages and in 4 KiB pages (issue 27).

The big marches (the lean layout of ``fm2uav.eikonal._kernels``, the slabs of
``fm2uav.eikonal._parallel``) map their buffers fresh for every march and advise them for
transparent huge pages; their padding is mostly the page faults of that first touch
(``benchmarks/terrain_stages.py``'s system time). On a virtual machine whose guest hands free
memory back to the host, a fresh huge page may cost far more than the 512 small pages it
replaces. This probe maps ``--mb`` MB in a fresh child process, advised for huge pages or not,
touches one byte a page, then gathers 5 M random bytes from it (the TLB's share: a kernel
reading scattered rows), the two kinds interleaved, with ``--pause`` seconds between children
(memory freed by the last child may still be backed by the host)::

    python -m benchmarks.first_touch [--mb 700] [--repeats 3] [--pause 6]

Prints per kind the medians of the touch's wall and system time [s], its minor page faults,
the time per MB [ms] and the gather's wall time [s]. Not part of ``make bench`` (the pauses);
docs/performance.md quotes it.
"""

from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import sys
import textwrap
import time

_CHILD = textwrap.dedent(
    """
    import json, mmap, resource, sys, time
    import numpy as np
    huge, nbytes = sys.argv[1] == "huge", int(sys.argv[2])
    r0 = resource.getrusage(resource.RUSAGE_SELF)
    t0 = time.perf_counter()
    mm = mmap.mmap(-1, nbytes, flags=mmap.MAP_PRIVATE | mmap.MAP_ANONYMOUS)
    if huge:
        mm.madvise(mmap.MADV_HUGEPAGE)
    a = np.frombuffer(mm, dtype=np.uint8)
    a[::4096] = 1
    t1 = time.perf_counter()
    r1 = resource.getrusage(resource.RUSAGE_SELF)
    idx = np.random.default_rng(0).integers(0, nbytes, 5_000_000)
    t2 = time.perf_counter()
    int(a[idx].sum())
    t3 = time.perf_counter()
    print(json.dumps({"touch": t1 - t0, "sys": r1.ru_stime - r0.ru_stime,
                      "faults": r1.ru_minflt - r0.ru_minflt, "gather": t3 - t2}))
    """
)

KINDS = ("huge", "small")


def measure(mb: int, repeats: int, pause: float) -> dict[str, list[dict]]:
    """``repeats`` rounds of one child per kind (huge pages, 4 KiB pages), in turn."""
    runs: dict[str, list[dict]] = {k: [] for k in KINDS}
    nbytes = mb * 2**20
    for _ in range(repeats):
        for kind in KINDS:
            time.sleep(pause)
            out = subprocess.run([sys.executable, "-c", _CHILD, kind, str(nbytes)],
                                 capture_output=True, text=True, check=True).stdout
            runs[kind].append(json.loads(out.splitlines()[-1]))
    return runs


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--mb", type=int, default=700, help="MB mapped and touched per child")
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--pause", type=float, default=6.0, help="seconds before each child")
    args = ap.parse_args(argv)
    runs = measure(args.mb, args.repeats, args.pause)
    print(f"{args.mb} MB, medians of {args.repeats} fresh children per kind")
    print("| pages | touch [s] | system [s] | minor faults | ms per MB | gather 5 M [s] |")
    print("|---|---|---|---|---|---|")
    for kind in KINDS:
        med = {k: statistics.median(r[k] for r in runs[kind]) for k in runs[kind][0]}
        label = "huge (MADV_HUGEPAGE)" if kind == "huge" else "4 KiB (no advice)"
        print(f"| {label} | {med['touch']:.3f} | {med['sys']:.3f} | {med['faults']:.0f} | "
              f"{1e3 * med['touch'] / args.mb:.2f} | {med['gather']:.3f} |")


if __name__ == "__main__":
    main()
