"""Where the 1000 x 1000 x 40 terrain plan spends its time, stage by stage (issue 27).

The world and start/goal of ``benchmarks/bench_core.py``'s terrain row; each run is a fresh
child process (the bench's conditions: first plan after the JIT warm-up), the thread counts
(``FM2UAV_THREADS``) and, with ``--peer-src``, another checkout's ``src`` interleaved::

    python -m benchmarks.terrain_stages --threads 1 2 --repeats 3 [--peer-src /path/to/src]

Prints per stage the medians of wall time, process CPU time, the main thread's CPU time
(process minus main thread: the work the other threads did), the process' system CPU time
and its minor page faults (``getrusage``: the first touch of fresh memory, whose zeroing is
system time; on this virtual machine slow for huge pages, docs/performance.md), the plan's
peak memory above the warmed-up child and the digests of W, T and the path (equal between
peers when the change is bit for bit). Stages: the plan's own (``Plan.timings``) and the
pieces inside ``fast_marching`` and the geodesic (input scan, padding, march kernel,
unpadding, ...); on two threads the march kernel is the windows' driver and the cuts'
coarse march a piece of its own (its padding and march not counted twice).
Not part of ``make bench`` (a plan per child: minutes); docs/performance.md quotes it.
"""

from __future__ import annotations

import json
import os
import statistics
import subprocess
import sys
import textwrap
from pathlib import Path

from benchmarks._timing import ab_parser, interleaved_runs

ROOT = Path(__file__).resolve().parents[1]

_CHILD = textwrap.dedent(
    """
    import functools, hashlib, json, os, resource, time
    import numpy as np
    from scipy import ndimage
    import fm2uav
    from fm2uav.eikonal import _kernels, _parallel, fmm
    import fm2uav.planning.planner as pl

    def rss_mb():
        with open("/proc/self/statm") as f:
            return int(f.read().split()[1]) * os.sysconf("SC_PAGE_SIZE") / 2**20

    def digest(a):
        return hashlib.sha256(np.ascontiguousarray(a).tobytes()).hexdigest()[:12]

    def clocks():
        r = resource.getrusage(resource.RUSAGE_SELF)
        return (time.perf_counter(), time.process_time(), time.thread_time(), r.ru_stime,
                float(r.ru_minflt))

    rng = np.random.default_rng(0)
    n, nz, cell = N, 40, 15.0
    relief = ndimage.gaussian_filter(rng.standard_normal((n, n)), 25, mode="wrap")
    heights = (relief - relief.min()) / np.ptp(relief) * 25 * cell + cell
    warm = fm2uav.World.from_heightmap(heights[:40, :40], cell, nz)
    fm2uav.plan(warm, [5 * cell, 5 * cell, 35 * cell], [30 * cell, 30 * cell, 35 * cell])
    from fm2uav.planning.warmup import warm as warm_kernels
    warm_kernels(["edt_parallel", "fmm3d_o2_lean"])
    PIECES = {}

    CUTS = "  cuts (coarse march)"
    ACTIVE = []

    def wrapped(f, label):
        @functools.wraps(f)
        def w(*a, **k):
            ACTIVE.append(label)
            c0 = clocks()
            try:
                return f(*a, **k)
            finally:
                ACTIVE.pop()
                if label == CUTS or CUTS not in ACTIVE:  # not the coarse march's pieces
                    acc = PIECES.setdefault(label, [0.0] * 5)
                    for i, (x, y) in enumerate(zip(clocks(), c0)):
                        acc[i] += x - y
        return w

    def timed(mod, name, label):
        f = getattr(mod, name, None)
        if f is not None:
            setattr(mod, name, wrapped(f, label))

    # two threads: the slabs' set-up and the windows' driver (_parallel)
    for key in list(_parallel._DRIVES):
        _parallel._DRIVES[key] = wrapped(_parallel._DRIVES[key], "  march kernel")
    for name, label in [("slab_bounds", CUTS), ("_pad_slabs", "  padding"),
                        ("_inf_after", "  unpadding")]:
        timed(_parallel, name, label)

    for mod, name, label in [
            (fmm, "_as_speed", "  input scan"), (fmm, "_source_start", "  sources and ball"),
            (_kernels, "pad_grid", "  padding"), (_kernels, "pad_grid_parallel", "  padding"),
            (_kernels, "_plateau", "  plateau test"), (_kernels, "march3d_o2", "  march kernel"),
            (_kernels, "march3d_o1", "  march kernel"), (_kernels, "unpad_grid", "  unpadding"),
            (pl, "drop_ties", "  ties at the start"),
            (pl, "reaches_any", "  obstacles reached?"), (pl, "descend", "  descent"),
            (pl, "min_surface_clearances", "  clearance")]:
        timed(mod, name, label)
    MARKS = []

    class _Clock:  # the planner's stage marks, with the CPU clocks read at the same moments
        @staticmethod
        def perf_counter():
            c = clocks()
            MARKS.append(c)
            return c[0]

    pl.time = _Clock
    base = rss_mb()
    c0 = clocks()
    world = fm2uav.World.from_heightmap(heights, cell, nz)
    c1 = clocks()
    start = np.array([10 * cell, 10 * cell, 35 * cell])
    goal = np.array([(n - 10) * cell, (n - 10) * cell, 35 * cell])
    p = fm2uav.plan(world, start, goal)
    c2 = clocks()
    m = MARKS[-6:]
    stages = {"world build": [b - a for a, b in zip(c0, c1)]}
    for i, k in enumerate(["(checks)", "velocity_map", "fast_marching", "geodesic", "metrics"]):
        stages[k] = [b - a for a, b in zip(m[i], m[i + 1])]
    stages["plan"] = [b - a for a, b in zip(c1, c2)]
    stages["plan outside the march kernel"] = [
        a - b for a, b in zip(stages["plan"], PIECES["  march kernel"])]
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024 - base
    print(json.dumps({"stages": stages, "pieces": PIECES, "peak_mb": peak,
                      "digests": [digest(p.W), digest(p.T), digest(p.path)],
                      "load": os.getloadavg()[0]}))
    """
)

ORDER = ["world build", "(checks)", "velocity_map", "fast_marching", "  input scan",
         "  sources and ball", "  cuts (coarse march)", "  padding", "  plateau test",
         "  march kernel", "  unpadding",
         "  ties at the start", "geodesic", "  obstacles reached?", "  descent", "metrics",
         "  clearance", "plan", "plan outside the march kernel"]


def child(src: str, threads: int, n: int) -> dict:
    """One plan in a fresh process with ``src`` first on the path."""
    env = {**os.environ, "PYTHONPATH": src, "FM2UAV_THREADS": str(threads)}
    res = subprocess.run([sys.executable, "-c", _CHILD.replace("N, 40", f"{n}, 40")],
                         capture_output=True, text=True, env=env, check=True)
    return json.loads(res.stdout.strip().splitlines()[-1])


def main(argv: list[str] | None = None) -> int:
    ap = ab_parser(__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=1000, help="columns a side (bench: 1000)")
    args = ap.parse_args(argv)
    runs = interleaved_runs(args.repeats, args.threads, args.peer_src, str(ROOT / "src"),
                            lambda src, th: child(src, th, args.n))
    print("stage: wall / process CPU / main-thread CPU / system CPU [s] / minor page faults, "
          "medians of "
          f"{args.repeats}; per code and thread count")
    cols = list(runs)
    print("| stage | " + " | ".join(f"{c} {t} thread{'s' * (t > 1)}" for c, t in cols) + " |")
    print("|---" * (len(cols) + 1) + "|")
    for key in ORDER:
        cells = []
        for col in cols:
            vals = [r["stages"].get(key) or r["pieces"].get(key) for r in runs[col]]
            if any(v is None for v in vals):
                cells.append("")
                continue
            cells.append(" / ".join(f"{statistics.median(v[i] for v in vals):.3f}"
                                    for i in range(4))
                         + f" / {statistics.median(v[4] for v in vals):.0f}")
        print(f"| {key} | " + " | ".join(cells) + " |")
    for col in cols:
        rs = runs[col]
        print(f"{col[0]} {col[1]} threads: peak {statistics.median(r['peak_mb'] for r in rs):.0f}"
              f" MB, load {min(r['load'] for r in rs):.1f}-{max(r['load'] for r in rs):.1f}, "
              f"W/T/path {sorted({'/'.join(r['digests']) for r in rs})}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
