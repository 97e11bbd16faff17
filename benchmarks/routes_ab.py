"""``plan_many`` on the routes benchmark's 10,000 starts, ours against a peer checkout (A/B).

The map, goal and starts of ``benchmarks/bench_routes.py`` (1000 x 1000 city, 2 m cells);
each run is a fresh child process (the kernels loaded from the numba cache, filled by an
untimed run of each code first; one warm-up ``plan_many`` of 50 starts, then the timed
call), the thread counts and, with
``--peer-src``, another checkout's ``src`` interleaved (``benchmarks/_timing.py``)::

    python -m benchmarks.routes_ab --threads 1 2 --repeats 3 [--peer-src /path/to/src]

Prints per code and thread count the medians of wall time and process CPU time (every
thread), the load average at the start of each run, and a digest of every route (path,
``w``, length, clearance): equal between peers when a change is bit for bit.
Not part of ``make bench`` (minutes); docs/performance.md quotes it.
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
    import hashlib, json, os, time
    import numpy as np
    from benchmarks.bench_routes import city_map, _starts
    from fm2uav import Shaping
    from fm2uav.planning.many import plan_many

    world = city_map(1000)
    goal, shaping = (1000.0, 1000.0), Shaping(exponent=0.5)
    starts = _starts(world, goal, COUNT, seed=1)
    plan_many(world, goal, starts[:50], shaping=shaping, threads=THREADS)
    load = os.getloadavg()[0]
    c0, t0 = time.process_time(), time.perf_counter()
    many = plan_many(world, goal, starts, shaping=shaping, threads=THREADS)
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    h = hashlib.sha256()
    for r in many.routes:
        h.update(r.path.tobytes() + r.w.tobytes() + repr((r.length, r.clearance)).encode())
    print(json.dumps({"wall": wall, "cpu": cpu, "load": load, "routes": int(many.ok.sum()),
                      "digest": h.hexdigest()[:16]}))
    """
)


def _run(src: str, threads: int, count: int) -> dict:
    env = {**os.environ, "PYTHONPATH": f"{src}{os.pathsep}{ROOT}"}
    code = _CHILD.replace("COUNT", str(count)).replace("THREADS", str(threads))
    out = subprocess.run([sys.executable, "-c", code], env=env, cwd=ROOT, check=True,
                         capture_output=True, text=True).stdout
    return json.loads(out.strip().splitlines()[-1])


def main(argv: list[str] | None = None) -> int:
    ap = ab_parser(__doc__.splitlines()[0])
    ap.add_argument("--count", type=int, default=10_000, help="starts (default 10000)")
    args = ap.parse_args(argv)
    for src in filter(None, (str(ROOT / "src"), args.peer_src)):  # compile (or load) first
        _run(src, args.threads[0], 60)
    runs = interleaved_runs(args.repeats, args.threads, args.peer_src, str(ROOT / "src"),
                            lambda src, th: _run(src, th, args.count))
    print("| code | threads | wall [s]: median (runs) | CPU [s] | load | routes | digest |")
    print("| --- | --- | --- | --- | --- | --- | --- |")
    for (name, th), rs in sorted(runs.items()):
        cells = [name, str(th),
                 f"{statistics.median(r['wall'] for r in rs):.2f} ("
                 + ", ".join(f"{r['wall']:.2f}" for r in rs) + ")",
                 f"{statistics.median(r['cpu'] for r in rs):.2f}",
                 ", ".join(f"{r['load']:.1f}" for r in rs), str(rs[0]["routes"]),
                 ", ".join(sorted({r["digest"] for r in rs}))]
        print("| " + " | ".join(cells) + " |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
