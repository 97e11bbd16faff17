"""How the machine itself scales from one thread to two, loop by loop (issue 27).

The two-thread ratios of the march (``benchmarks/threads_march.py``, ``bench_core``'s threads
rows) depend on the machine as much as on the code: a virtual machine's two vCPUs may share
the host's memory system so that work bound by cache misses does not double. This probe
times five loops with the same total work on one thread and on two (each thread its own half
of the data, no sharing, no synchronisation inside), interleaved, medians::

    python -m benchmarks.machine_scaling [--mb 256] [--repeats 5]

* ``compute``: a dependent multiply-add chain in registers (no memory);
* ``l2``: sums over 1 MiB per thread, again and again (the data in each core's L2);
* ``stream``: sums over each half of a ``--mb`` array (contiguous, prefetched);
* ``lines``: one read per 64-byte cache line of each half (the memory's line rate);
* ``gather``: reads at random indices of the whole array (latency-bound misses).

Prints per loop the wall times on one and two threads and their ratio (2.0: the loop
doubles). The march itself is not bound by ``lines``: two serial marches at once ran at
1.01-1.03x the time of one while ``lines`` doubled 1.06-1.09x (:mod:`benchmarks.march_pair`,
the probe to read beside a two-thread ratio of the march).
"""

from __future__ import annotations

import argparse
import statistics
import time

import numba
import numpy as np
from numba import njit, prange

#: Doubles per thread of the ``l2`` loop (1 MiB).
L2_DOUBLES = 131072


@njit(parallel=True, cache=False)
def _compute(n, reps):
    out = np.zeros(2)
    for t in prange(2):
        acc = 0.0
        for i in range(n // 2):
            x = 1.0 + i * 1e-9
            for _ in range(reps):
                x = x * 1.0000001 + 1e-7
            acc += x
        out[t] = acc
    return out


@njit(parallel=True, cache=False)
def _sums(a, reps, stride, lo_hi):
    """Thread ``t`` sums ``a[lo_hi[t, 0]:lo_hi[t, 1]:stride]``, ``reps`` times."""
    out = np.zeros(2)
    for t in prange(2):
        acc = 0.0
        for _ in range(reps):
            for i in range(lo_hi[t, 0], lo_hi[t, 1], stride):
                acc += a[i]
        out[t] = acc
    return out


@njit(parallel=True, cache=False)
def _gather(a, idx):
    out = np.zeros(2)
    half = idx.size // 2
    for t in prange(2):
        acc = 0.0
        for i in range(t * half, (t + 1) * half):
            acc += a[idx[i]]
        out[t] = acc
    return out


def loops(mb: float, seed: int = 0) -> dict:
    """The five loops as calls without arguments, on an array of ``mb`` MiB (seeded)."""
    n = max(int(mb * 2**20 / 8), 4 * L2_DOUBLES)
    a = np.ones(n)
    halves = np.array([[0, n // 2], [n // 2, n]], dtype=np.int64)
    l2 = np.array([[0, L2_DOUBLES], [L2_DOUBLES, 2 * L2_DOUBLES]], dtype=np.int64)
    idx = np.random.default_rng(seed).integers(0, n, n // 8)
    reps_l2 = max(1, n // (2 * L2_DOUBLES)) * 4
    return {
        "compute": lambda: _compute(2000, max(1, n // 8000)),
        "l2": lambda: _sums(a, reps_l2, 1, l2),
        "stream": lambda: _sums(a, 2, 1, halves),
        "lines": lambda: _sums(a, 8, 8, halves),
        "gather": lambda: _gather(a, idx),
    }


def measure(mb: float, repeats: int) -> dict[str, tuple[float, float]]:
    """Median wall times [s] of each loop on one and on two threads, interleaved."""
    prev = numba.get_num_threads()
    runs = loops(mb)
    times: dict[str, dict[int, list[float]]] = {k: {1: [], 2: []} for k in runs}
    try:
        for th in (1, 2):  # compile and fault in first
            numba.set_num_threads(min(th, numba.config.NUMBA_NUM_THREADS))
            for fn in runs.values():
                fn()
        for _ in range(max(1, repeats)):
            for name, fn in runs.items():
                for th in (1, 2):
                    numba.set_num_threads(min(th, numba.config.NUMBA_NUM_THREADS))
                    t = time.perf_counter()
                    fn()
                    times[name][th].append(time.perf_counter() - t)
    finally:
        numba.set_num_threads(prev)
    return {k: (statistics.median(v[1]), statistics.median(v[2])) for k, v in times.items()}


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--mb", type=float, default=256.0, help="the array of the memory loops [MiB]")
    ap.add_argument("--repeats", type=int, default=5)
    args = ap.parse_args(argv)
    res = measure(args.mb, args.repeats)
    cores = numba.config.NUMBA_NUM_THREADS
    print(f"{args.mb:g} MiB, medians of {args.repeats}, {cores} threads in numba's pool")
    print("| loop | 1 thread [s] | 2 threads [s] | ratio |")
    print("|---|---|---|---|")
    for name, (one, two) in res.items():
        print(f"| {name} | {one:.4g} | {two:.4g} | {one / two:.2f}x |")


if __name__ == "__main__":
    main()
