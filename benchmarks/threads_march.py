"""The march on 1 and 2 threads, our code against another checkout's, march by march (issue 27).

Each code runs in a child process of its own that stays up (its kernels loaded once) and
marches on request, so the marches of both codes and of every thread count alternate one
by one (a change of the machine's load hits them alike)::

    python -m benchmarks.threads_march --cases 2048x2048:fm2 2048x2048:smooth \\
        --threads 1 2 --repeats 7 [--peer-src /path/to/other/src] [--peer-cache DIR]

A case is ``SHAPE:FIELD``, the field ``constant`` (centre source), ``smooth`` or ``fm2``
(:mod:`benchmarks.fields`; ``fm2`` with ``@SEED`` for another seed), order 1 unless
``:2`` follows. Prints per case, code and thread count the medians of the wall time, the
process CPU time, the busiest thread's CPU time (``/proc/self/task/*/schedstat``), and on
two threads the set-up (the calling thread's CPU time in the parallel march outside the
windows' driver: cuts, padding, plateau, unpadding), the windows' CPU (both threads, in the
driver), their balance, the nodes re-opened, then the ratios one thread / two threads
(wall, CPU over the busiest thread, and the idle-machine estimate ``serial CPU / (set-up +
windows' CPU / balance)`` of ``benchmarks/bench_core.py``'s threads rows) and the digest
of the times (equal between codes when bit for bit). ``--peer-cache`` sets the peer's
``NUMBA_CACHE_DIR`` (an empty value: unset, numba's default next to its sources).
Only the thread counts asked for are warmed up (``--threads 1``: no parallel kernel is
loaded or compiled). ``--skfmm``: the first code's child also times scikit-fmm on the same
problem (the FM²-shaped rows of ``benchmarks/bench_core.py``: a half-cell circle around the
source, the walls masked) once a round, and each code's one-thread CPU time is compared with
its (CPU time of the calling thread, as those rows' notes). ``--first`` (root) runs the children in a session of their own at autogroup nice -20 and
nice -20: on a machine shared with other sessions (each its own autogroup, which plain
``nice`` does not cross) their processes then wait while a march runs, and the two
threads run at once as on an idle machine (not quite: the others still run between the
marches and take what the scheduler leaves them, a few per cent).
"""

from __future__ import annotations

import json
import os
import statistics
import subprocess
import sys
import textwrap
from pathlib import Path

from benchmarks._timing import ab_parser

ROOT = Path(__file__).resolve().parents[1]

_CHILD = textwrap.dedent(
    """
    import hashlib, json, os, sys, time
    import numpy as np
    from benchmarks import fields
    from fm2uav import fast_marching
    from benchmarks._march_spy import watch_parallel_march

    STATS = watch_parallel_march()

    def tasks():
        out = {}
        for tid in os.listdir("/proc/self/task"):
            try:
                with open(f"/proc/self/task/{tid}/schedstat") as f:
                    out[tid] = int(f.read().split()[0]) * 1e-9
            except OSError:  # a thread that ended
                pass
        return out

    cases = {}
    warm = set()
    for line in sys.stdin:
        case, th = line.split()
        th = int(th)
        if case not in cases:
            shape, field, *rest = case.split(":")
            shape = tuple(int(n) for n in shape.split("x"))
            if field == "constant":
                v, src = np.ones(shape), tuple(n // 2 for n in shape)
            elif field == "smooth":
                v, src = fields.smooth(shape)
            else:
                name, _, seed = field.partition("@")
                v, src = fields.fm2_shaped(shape, seed=int(seed or 0))
            cases[case] = (v, src, int(rest[0]) if rest else 1)
        v, src, order = cases[case]
        if th == 0:  # scikit-fmm on the same problem, CPU time of this thread
            import skfmm
            phi, vs = fields.skfmm_point_source(v, src)
            c = time.thread_time()
            skfmm.travel_time(phi, vs, order=order)
            print(json.dumps({"cpu": time.thread_time() - c}), flush=True)
            continue
        if (case, th) not in warm:  # kernels loaded, buffers kept
            warm.add((case, th))
            fast_marching(v, [src], order=order, threads=th)
        STATS.clear()
        a = tasks(); w = time.perf_counter(); c = time.process_time()
        T = fast_marching(v, [src], order=order, threads=th)
        w = time.perf_counter() - w; c = time.process_time() - c
        b = tasks()
        out = {"wall": w, "cpu": c, "busiest": max(b[t] - a.get(t, 0.0) for t in b),
               "load": os.getloadavg()[0],
               "digest": hashlib.sha256(T.tobytes()).hexdigest()[:12]}
        if "balance" in STATS:
            out.update(setup=STATS["setup"], windows=STATS["drive_cpu"],
                       balance=STATS["balance"], reopened=STATS["reopened"])
        print(json.dumps(out), flush=True)
    """
)

NUMBERS = ["wall", "cpu", "busiest", "setup", "windows", "balance", "reopened"]


def _first() -> None:
    """In the child, a session of its own already: its autogroup and itself at nice -20."""
    with open("/proc/self/autogroup", "w") as f:
        f.write("-20")
    os.nice(-20)


class _Child:
    """A child process marching on request with ``src`` first on the path."""

    def __init__(self, src: str, env: dict, first: bool = False):
        path = os.pathsep.join([src, str(ROOT)])
        self.proc = subprocess.Popen([sys.executable, "-c", _CHILD], stdin=subprocess.PIPE,
                                     stdout=subprocess.PIPE, text=True,
                                     env={**env, "PYTHONPATH": path},
                                     start_new_session=first,
                                     preexec_fn=_first if first else None)

    def run(self, case: str, threads: int) -> dict:
        self.proc.stdin.write(f"{case} {threads}\n")
        self.proc.stdin.flush()
        line = self.proc.stdout.readline()
        if not line:
            raise RuntimeError(f"the child marching {case} on {threads} threads failed")
        return json.loads(line)

    def close(self) -> None:
        self.proc.stdin.close()
        self.proc.wait()


def main(argv: list[str] | None = None) -> int:
    ap = ab_parser(__doc__.splitlines()[0])
    ap.add_argument("--cases", nargs="+", default=["2048x2048:fm2"])
    ap.add_argument("--peer-cache", default=None,
                    help="the peer's NUMBA_CACHE_DIR (empty: unset)")
    ap.add_argument("--skfmm", action="store_true",
                    help="time scikit-fmm too (one-thread CPU ratios against it)")
    ap.add_argument("--first", action="store_true",
                    help="children at autogroup nice -20 (root): near-idle walls")
    args = ap.parse_args(argv)
    env = dict(os.environ)
    codes = {"ours": _Child(str(ROOT / "src"), env, args.first)}
    if args.peer_src:
        peer_env = dict(env)
        if args.peer_cache is not None:
            peer_env.pop("NUMBA_CACHE_DIR", None)
            if args.peer_cache:
                peer_env["NUMBA_CACHE_DIR"] = args.peer_cache
        codes["peer"] = _Child(args.peer_src, peer_env, args.first)
    try:
        for case in args.cases:
            runs: dict[tuple[str, int], list[dict]] = {}
            peer_cpu: list[float] = []
            for r in range(args.repeats):
                for th in args.threads:
                    # the two codes in turn, the first one alternating: in a fixed order the
                    # first child's two-thread marches read ~5 % faster (session 29: one
                    # change's A/B +6 % and -3 % with the roles swapped)
                    order = list(codes.items())
                    for name, child in (order if r % 2 == 0 else order[::-1]):
                        runs.setdefault((name, th), []).append(child.run(case, th))
                if args.skfmm:
                    peer_cpu.append(codes["ours"].run(case, 0)["cpu"])
            med = {key: {k: statistics.median(r[k] for r in rs) for k in NUMBERS if k in rs[0]}
                   for key, rs in runs.items()}
            loads = [r["load"] for rs in runs.values() for r in rs]
            print(f"{case}: medians of {args.repeats}, load {min(loads):.1f}-{max(loads):.1f}")
            for (name, th), m in med.items():
                cells = ", ".join(f"{k} {m[k]:.4g}" for k in NUMBERS if k in m)
                digests = " ".join(sorted({r["digest"] for r in runs[name, th]}))
                print(f"  {name} {th} thread{'s' * (th > 1)}: {cells}; digest {digests}")
            if peer_cpu:
                sk = statistics.median(peer_cpu)
                ratios = ", ".join(f"{name} {sk / med[name, 1]['cpu']:.3f}x" for name in codes
                                   if (name, 1) in med)
                print(f"  scikit-fmm CPU {sk:.4g} s; its CPU over one thread's: {ratios}")
            for name in codes:
                one, two = med.get((name, 1)), med.get((name, 2))
                if one and two and "balance" in two:
                    est = one["cpu"] / (two["setup"] + two["windows"] / two["balance"])
                    print(f"  {name} 1 -> 2 threads: wall {one['wall'] / two['wall']:.3f}x, "
                          f"CPU over the busiest thread {one['cpu'] / two['busiest']:.3f}x, "
                          f"idle estimate {est:.3f}x")
            sys.stdout.flush()
    finally:
        for child in codes.values():
            child.close()
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
