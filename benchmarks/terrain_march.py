"""The 1000 x 1000 x 40 terrain plan's march alone, 1 and 2 threads, CPU per thread (issue 27).

The march of ``benchmarks/terrain_stages.py``'s plan (the same world, W, goal and start:
``fast_marching(W, [goal], order=2, stop_at=[start])``), each run in a fresh child process
after a small warm-up march, the thread counts and, with ``--peer-src``, another checkout's
``src`` interleaved round by round::

    python -m benchmarks.terrain_march --threads 1 2 --repeats 3 [--peer-src /path/to/src]

Prints per code and thread count the medians of the wall time, the process CPU time, the
busiest thread's CPU time (``/proc/self/task/*/schedstat``), the system CPU time and the
minor page faults (``getrusage``: the first touch of the march's fresh buffers), and for two
threads the CPU of the windows (the parallel driver's calls: both threads, and the busier
one) and the march's statistics (slabs, windows, balance, nodes re-opened, updates raised),
the load average and the digest of the times (equal between codes and thread counts when bit
for bit). On a
loaded machine the walls are the queue for a core; the CPU times are what a thread spent.
Not part of ``make bench`` (a march per child: minutes); docs/performance.md quotes it.
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
    import glob, hashlib, json, os, resource, sys, time
    import numpy as np
    from scipy import ndimage
    import fm2uav
    from fm2uav.eikonal import _parallel, fast_marching
    from fm2uav.planning.params import PlanOptions, Shaping
    from fm2uav.planning.planner import plan_velocity

    rng = np.random.default_rng(0)
    n, nz, cell = 1000, 40, 15.0
    relief = ndimage.gaussian_filter(rng.standard_normal((n, n)), 25, mode="wrap")
    heights = (relief - relief.min()) / np.ptp(relief) * 25 * cell + cell
    world = fm2uav.World.from_heightmap(heights, cell, nz)
    W = plan_velocity(world, Shaping(), None, PlanOptions())
    goal = world.to_cell(np.array([(n - 10) * cell, (n - 10) * cell, 35 * cell]), what="goal")
    start = world.to_cell(np.array([10 * cell, 10 * cell, 35 * cell]), what="start")
    th = THREADS

    def tasks():
        out = {}
        for p in glob.glob("/proc/self/task/*/schedstat"):
            try:
                with open(p) as f:
                    out[p.split("/")[4]] = int(f.read().split()[0]) / 1e9
            except OSError:  # a thread that ended
                pass
        return out

    def spent(a, b):
        return {k: b[k] - a.get(k, 0.0) for k in b}

    WIN = {"win_cpu": 0.0, "win_busiest": 0.0}
    drive = _parallel._DRIVES[(3, 2)]

    def timed_drive(*args):
        t0 = tasks()
        out = drive(*args)
        d = spent(t0, tasks())
        WIN["win_cpu"] += sum(d.values())
        WIN["win_busiest"] += max(d.values())
        return out

    _parallel._DRIVES[(3, 2)] = timed_drive
    STATS = {}
    march = _parallel.march

    def kept_stats(*a, **k):
        T, s = march(*a, **k)
        STATS.update(s)
        return T, s

    _parallel.march = kept_stats
    # the kernels loaded (or compiled) before the timed march
    fast_marching(W[:200, :200], [(150, 150, 35)], spacing=cell, order=2, threads=th)
    WIN.update(win_cpu=0.0, win_busiest=0.0)
    STATS.clear()
    r0 = resource.getrusage(resource.RUSAGE_SELF)
    t0, w0, p0 = tasks(), time.perf_counter(), time.process_time()
    T = fast_marching(W, [goal], spacing=cell, order=2, stop_at=[start], threads=th)
    w1, p1 = time.perf_counter(), time.process_time()
    d = spent(t0, tasks())
    r1 = resource.getrusage(resource.RUSAGE_SELF)
    out = {"wall": w1 - w0, "cpu": p1 - p0, "busiest": max(d.values()),
           "system": r1.ru_stime - r0.ru_stime, "faults": r1.ru_minflt - r0.ru_minflt,
           "digest": hashlib.sha256(T.tobytes()).hexdigest()[:12], "load": os.getloadavg()[0]}
    if th > 1:
        out.update(WIN)
        out.update({k: STATS[k] for k in ("slabs", "windows", "balance", "reopened", "raised")})
    print(json.dumps(out))
    """
)

NUMBERS = ["wall", "cpu", "busiest", "system", "faults", "win_cpu", "win_busiest", "balance",
           "reopened", "raised", "windows", "slabs"]


def child(src: str, threads: int) -> dict:
    """One march in a fresh process with ``src`` first on the path."""
    env = {**os.environ, "PYTHONPATH": src}
    res = subprocess.run([sys.executable, "-c", _CHILD.replace("THREADS", str(threads))],
                         capture_output=True, text=True, env=env, check=True)
    return json.loads(res.stdout.strip().splitlines()[-1])


def main(argv: list[str] | None = None) -> int:
    ap = ab_parser(__doc__.splitlines()[0])
    args = ap.parse_args(argv)
    runs = interleaved_runs(args.repeats, args.threads, args.peer_src, str(ROOT / "src"),
                            lambda src, th: child(src, th))
    print(f"medians of {args.repeats} (times in s, CPU from /proc/self/task)")
    for (name, th), rs in runs.items():
        cells = [f"{k} {statistics.median(r[k] for r in rs):.4g}" for k in NUMBERS if k in rs[0]]
        loads = [r["load"] for r in rs]
        print(f"{name} {th} thread{'s' * (th > 1)}: " + ", ".join(cells)
              + f"; load {min(loads):.1f}-{max(loads):.1f}; digests "
              + " ".join(sorted({r['digest'] for r in rs})))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
