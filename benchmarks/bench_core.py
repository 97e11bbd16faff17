"""Core benchmarks: our FMM vs scikit-fmm, FM² plans, JIT compile time.

Every case runs in a fresh child process so that its peak memory (``ru_maxrss``
minus the process' resident size before the case) is measured for our code and
for scikit-fmm's C++ alike. Times are medians over repeats after a warm-up.

Bars (issue "Foundation"): FMM ≥ 2× faster than scikit-fmm at the same order
on 2048² and 256³ (goal ≥ 4×); FM² plan on the open field ≤ 0.1 s after
warm-up (goal ≤ 0.05 s); 1000×1000×40 terrain plan ≤ 15 s and ≤ 2.5 GB peak
(issue 15: ≤ 8 s and ≤ 1 GB). Issue 15: the regional case, a 3000×3000-cell DEM (30 m) at 120 m above ground,
world build + plan ≤ 60 s and ≤ 6 GB peak.
"""

from __future__ import annotations

import json
import os
import statistics
import subprocess
import sys
import tempfile
import textwrap

CHILD_PRELUDE = textwrap.dedent(
    """
    import json, resource, statistics, sys, time
    import numpy as np

    def rss_mb():
        with open("/proc/self/statm") as fh:
            return int(fh.read().split()[1]) * resource.getpagesize() / 2**20

    def peak_mb():
        return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024

    def median_time(fn, repeats):
        times = []
        for _ in range(repeats):
            t = time.perf_counter(); fn(); times.append(time.perf_counter() - t)
        return statistics.median(times)

    def speed_field(shape):
        # smooth, strictly positive speed field, the same for both solvers
        from benchmarks.fields import smooth
        return smooth(shape)[0]
    """
)


def _child(code: str, env: dict | None = None, timeout: float = 1800) -> dict:
    """Run ``code`` (after the prelude) in a fresh interpreter; it prints one JSON line."""
    full = CHILD_PRELUDE + textwrap.dedent(code)
    res = subprocess.run(
        [sys.executable, "-c", full],
        capture_output=True,
        text=True,
        timeout=timeout,
        env={**os.environ, **(env or {})},
    )
    if res.returncode != 0:
        raise RuntimeError(f"benchmark child failed:\n{res.stderr[-3000:]}")
    return json.loads(res.stdout.strip().splitlines()[-1])


def _ours_fmm(shape: tuple[int, ...], order: int, repeats: int) -> dict:
    return _child(
        f"""
        from fm2uav import fast_marching
        shape = {shape!r}; v = speed_field(shape); src = [tuple(n // 2 for n in shape)]
        fast_marching(v[tuple(slice(0, 8) for _ in shape)], [tuple(4 for _ in shape)], order={order})
        base = rss_mb()
        t = median_time(lambda: fast_marching(v, src, order={order}, threads=1), {repeats})
        print(json.dumps({{"s": t, "peak_mb": peak_mb() - base}}))
        """
    )


def _skfmm(shape: tuple[int, ...], order: int, repeats: int) -> dict:
    return _child(
        f"""
        import skfmm
        shape = {shape!r}; v = speed_field(shape)
        # point source: the zero contour of phi is a circle of half a cell around the centre
        axes = np.meshgrid(*[np.arange(n) - n // 2 for n in shape], indexing="ij")
        phi = np.sqrt(sum(a.astype(float) ** 2 for a in axes)) - 0.5
        small = np.ones(tuple(9 for _ in shape)); small[tuple(4 for _ in shape)] = -1
        skfmm.travel_time(small, np.ones_like(small), order={order})  # warm-up
        base = rss_mb()
        t = median_time(lambda: skfmm.travel_time(phi, v, order={order}), {repeats})
        print(json.dumps({{"s": t, "peak_mb": peak_mb() - base}}))
        """
    )


def _eikonalfm(shape: tuple[int, ...], order: int, repeats: int, factored: bool) -> dict | None:
    """eikonalfm (pip wheel, C++) from the same point source; None if it is not installed.

    ``factored=False``: its plain Fast Marching (``eikonalfm.fast_marching``), the same
    equation and stencils as ours and scikit-fmm's. ``factored=True``: its factored
    solver (``factored_fast_marching``), which marches ``tau1`` of ``T = tau0 * tau1``
    (``tau0`` the distance to the source) over the whole grid; the time includes the
    product with ``tau0`` so that both give arrival times.
    """
    call = ("T = eikonalfm.factored_fast_marching(v, src, dx, {order}) * tau0"
            if factored else "T = eikonalfm.fast_marching(v, src, dx, {order})").format(order=order)
    return _child(
        f"""
        try:
            import eikonalfm
        except ImportError:
            print(json.dumps(None)); raise SystemExit
        shape = {shape!r}; v = speed_field(shape); src = tuple(n // 2 for n in shape)
        dx = (1.0,) * len(shape)
        tau0 = eikonalfm.distance(shape, dx, src, indexing="ij")
        small = np.ones(tuple(9 for _ in shape))
        eikonalfm.fast_marching(small, (4,) * len(shape), dx, {order})  # warm-up
        base = rss_mb()
        def run():
            {call}
        t = median_time(run, {repeats})
        print(json.dumps({{"s": t, "peak_mb": peak_mb() - base}}))
        """
    )


def _fmm_interleaved(shape: tuple[int, ...], order: int, repeats: int,
                     field: str = "smooth") -> dict:
    """Median times [s] of every solver, run in turn in one process (ours, then each peer,
    ``repeats`` rounds): on a shared machine a load change hits all of them alike, so the
    ratios hold where separate processes' times would not. Peers missing: left out.

    ``field``: ``"smooth"`` or ``"fm2"`` (:mod:`benchmarks.fields`; eikonalfm needs a
    positive speed everywhere and runs on the smooth field only). Also returns the median
    CPU time of the calling thread per solver (``"cpu"``: both solvers run on this thread).
    """
    return _child(
        f"""
        from fm2uav import fast_marching
        from benchmarks import fields
        import skfmm
        try:
            import eikonalfm
        except ImportError:
            eikonalfm = None
        shape = {shape!r}; order = {order}
        v, src = fields.smooth(shape) if {field!r} == "smooth" else fields.fm2_shaped(shape)
        dx = (1.0,) * len(shape)
        phi, vs = fields.skfmm_point_source(v, src)
        solvers = {{"ours": lambda: fast_marching(v, [src], order=order, threads=1),
                   "scikit-fmm": lambda: skfmm.travel_time(phi, vs, order=order)}}
        if eikonalfm is not None and {field!r} == "smooth":
            tau0 = eikonalfm.distance(shape, dx, src, indexing="ij")
            solvers["eikonalfm"] = lambda: eikonalfm.fast_marching(v, src, dx, order)
            solvers["eikonalfm factored"] = (
                lambda: eikonalfm.factored_fast_marching(v, src, dx, order) * tau0)
        small = tuple(slice(0, 9) for _ in shape)
        fast_marching(np.ones(v[small].shape), [(4,) * len(shape)], order=order)  # JIT warm-up
        times = {{name: [] for name in solvers}}
        cpu = {{name: [] for name in solvers}}
        for _ in range({repeats}):
            for name, fn in solvers.items():
                t, c = time.perf_counter(), time.thread_time()
                fn()
                times[name].append(time.perf_counter() - t)
                cpu[name].append(time.thread_time() - c)
        out = {{name: statistics.median(ts) for name, ts in times.items()}}
        out["cpu"] = {{name: statistics.median(ts) for name, ts in cpu.items()}}
        print(json.dumps(out))
        """
    )


#: Peers of the FMM rows: (name in the table, runner, like-for-like note).
_FMM_PEERS = (
    ("scikit-fmm", lambda shape, order, rep: _skfmm(shape, order, rep),
     "zero contour of a half-cell circle around the source"),
    ("eikonalfm", lambda shape, order, rep: _eikonalfm(shape, order, rep, factored=False),
     "plain FMM from the point source"),
    ("eikonalfm factored", lambda shape, order, rep: _eikonalfm(shape, order, rep, factored=True),
     "factored equation tau0*tau1 (a different, more accurate scheme near the source)"),
)


def fmm_rows(quick: bool) -> list[dict]:
    """Our FMM against scikit-fmm and eikonalfm on 2048² and 160³ (issue 15), order 1 and 2.

    The same smooth speed field and a point source at the grid centre for all. Times:
    all solvers in turn in one child process (:func:`_fmm_interleaved`, medians); peak
    memory: each solver alone in its own child, one run. Bar (issue 15): >= 3x
    scikit-fmm at the same order (goal 4x); eikonalfm is reported, not barred. Then the
    FM²-shaped field (:func:`benchmarks.fields.fm2_shaped`, issue 27: >= 4x scikit-fmm),
    against scikit-fmm only, with the ratio of the thread CPU times beside the wall times'.
    """
    cases = [((256, 256), 3), ((32, 32, 32), 3)] if quick else [((2048, 2048), 5), ((160, 160, 160), 3)]
    rows = []
    for shape, repeats in cases:
        for order in (1, 2):
            times = _fmm_interleaved(shape, order, repeats)
            # quick (smoke test): every solver's memory run on the first case only (one
            # child process each: the same code for every case)
            run_mem = not quick or (shape, order) == (cases[0][0], 1)
            ours = _ours_fmm(shape, order, 1) if run_mem else {"peak_mb": None}
            for name, runner, note in _FMM_PEERS:
                if name not in times:  # eikonalfm missing: pip install '.[bench]'
                    continue
                peer = runner(shape, order, 1) if run_mem else {"peak_mb": None}
                rows.append(
                    {
                        "benchmark": "fmm",
                        "case": f"{'x'.join(map(str, shape))} order {order}",
                        "ours_s": times["ours"],
                        "peer": name,
                        "peer_s": times[name],
                        "ratio": times[name] / times["ours"],
                        "peak_mb": ours["peak_mb"],
                        "peer_peak_mb": peer["peak_mb"],
                        "bar": ">= 3x (goal 4x)" if name == "scikit-fmm" else "",
                        "notes": f"peer: {note}",
                    }
                )
    # quick: the FM²-shaped field in 2D at order 1 and in 3D at order 2 (both dimensions and
    # both orders, one child process each)
    fm2_cases = ([(cases[0], 1), (cases[1], 2)] if quick else
                 [(c, order) for c in cases for order in (1, 2)])
    for (shape, repeats), order in fm2_cases:
        times = _fmm_interleaved(shape, order, repeats, field="fm2")
        cpu = times["cpu"]
        rows.append({
            "benchmark": "fmm",
            "case": f"{'x'.join(map(str, shape))} FM²-shaped order {order}",
            "ours_s": times["ours"], "peer": "scikit-fmm", "peer_s": times["scikit-fmm"],
            "ratio": times["scikit-fmm"] / times["ours"],
            "bar": ">= 4x (issue 27)",
            "notes": (f"obstacles 25 % (speed 0, masked for the peer), W = (d/d_max)^0.5, "
                      f"source off-centre; thread CPU time ratio "
                      f"{cpu['scikit-fmm'] / cpu['ours']:.2f}x")})
    return rows


def plan_rows(quick: bool) -> list[dict]:
    rows = []
    r = _child(
        f"""
        import fm2uav
        sc = fm2uav.scenarios.open_field()
        fm2uav.plan(sc.world, sc.start, sc.goal)            # JIT warm-up (+ cache fill)
        warm = median_time(lambda: fm2uav.plan(sc.world, sc.start, sc.goal), {3 if quick else 11})
        def cold():
            sc.world._cache.clear()
            fm2uav.plan(sc.world, sc.start, sc.goal)
        cold_t = median_time(cold, {3 if quick else 7})
        p = fm2uav.plan(sc.world, sc.start, sc.goal)
        print(json.dumps({{"warm": warm, "cold": cold_t, "timings": p.timings,
                          "peak_mb": peak_mb()}}))
        """
    )
    stages = ", ".join(f"{k} {v * 1e3:.1f} ms" for k, v in r["timings"].items() if k != "total")
    rows.append({"benchmark": "plan", "case": "open field 120x90x40, cached distance map",
                 "ours_s": r["warm"], "bar": "<= 0.1 s (goal 0.05 s)", "notes": stages})
    rows.append({"benchmark": "plan", "case": "open field 120x90x40, distance map recomputed",
                 "ours_s": r["cold"], "bar": "<= 0.1 s (goal 0.05 s)"})
    n = 200 if quick else 1000
    r = _child(
        f"""
        import fm2uav
        from scipy import ndimage
        rng = np.random.default_rng(0)
        n, nz, cell = {n}, 40, 15.0
        relief = ndimage.gaussian_filter(rng.standard_normal((n, n)), 25, mode="wrap")
        heights = (relief - relief.min()) / np.ptp(relief) * 25 * cell + cell
        # warm-up first (JIT: the small plan's kernels and the big grid's own), so the
        # peak above the base is the world and the plan, not the loaded machine code
        warm = fm2uav.World.from_heightmap(heights[:40, :40], cell, nz)
        fm2uav.plan(warm, [5 * cell, 5 * cell, 35 * cell], [30 * cell, 30 * cell, 35 * cell])
        from fm2uav.planning.warmup import warm as warm_kernels
        warm_kernels(["edt_parallel", "fmm3d_o2_lean", "fmm3d_parallel"])
        base = rss_mb()
        t0 = time.perf_counter()
        world = fm2uav.World.from_heightmap(heights, cell, nz)
        t_world = time.perf_counter() - t0
        start = np.array([10 * cell, 10 * cell, 35 * cell])
        goal = np.array([(n - 10) * cell, (n - 10) * cell, 35 * cell])
        t0 = time.perf_counter()
        p = fm2uav.plan(world, start, goal)
        t_plan = time.perf_counter() - t0
        print(json.dumps({{"plan": t_plan, "world": t_world, "timings": p.timings,
                          "peak_mb": peak_mb() - base, "length": p.length}}))
        """
    )
    stages = ", ".join(f"{k} {v:.2f} s" for k, v in r["timings"].items() if k != "total")
    rows.append({"benchmark": "plan", "case": f"terrain {n}x{n}x40 (15 m cells)",
                 "ours_s": r["plan"], "peak_mb": r["peak_mb"],
                 "bar": "<= 5 s on 2 threads (issue 27), <= 1 GB (issue 15; was 15 s, 2.5 GB)",
                 "notes": f"{stages}; world build {r['world']:.2f} s"})
    return rows


#: The regional case (issue 15): a synthetic DEM of this many cells a side at 30 m.
REGIONAL_CELLS = 3000


def regional_rows(quick: bool) -> list[dict]:
    """Terrain following over a 90 km DEM: ``fm2uav.plan`` picks the regional (coarse-to-fine)
    path by itself (``PlanOptions.storage="auto"``); world build and plan in a fresh child."""
    # quick: a small map, where "auto" would pick the full grid, so ask for the regional path
    n, storage = (300, "regional") if quick else (REGIONAL_CELLS, "auto")
    r = _child(
        f"""
        import fm2uav
        from scipy import ndimage
        n, cell, dz, agl = {n}, 30.0, 20.0, 120.0
        rng = np.random.default_rng(0)
        relief = ndimage.gaussian_filter(rng.standard_normal((n, n)), 40.0, mode="wrap")
        heights = (relief - relief.min()) / np.ptp(relief) * 1200.0 + 200.0
        del relief
        def world_of(h):
            nz = int(np.ceil((h.max() + agl + 10 * dz - 180.0) / dz)) + 1
            return fm2uav.World.from_heightmap(h, (cell, cell, dz), nz, origin=(0, 0, 180.0))
        def at(w, i, j):
            return [i * cell, j * cell, float(w.ground_height(i * cell, j * cell)) + agl]
        level = fm2uav.FlightLevel(agl=agl)
        warm = world_of(heights[:80, :80])                   # JIT warm-up (+ cache fill)
        fm2uav.plan(warm, at(warm, 5, 5), at(warm, 70, 70), level=level,
                    options=fm2uav.PlanOptions(storage="regional"))
        base = rss_mb()
        t0 = time.perf_counter()
        world = world_of(heights)
        t_world = time.perf_counter() - t0
        t0 = time.perf_counter()
        p = fm2uav.plan(world, at(world, 10, 10), at(world, n - 11, n - 11), level=level,
                        options=fm2uav.PlanOptions(storage="{storage}"))
        t_plan = time.perf_counter() - t0
        hag = p.height_above_ground()[p.phase == "cruise"]
        print(json.dumps({{"plan": t_plan, "world": t_world, "timings": p.timings,
                          "peak_mb": peak_mb() - base, "length": p.length,
                          "shape": list(world.shape), "storage": p.params.get("storage", "full"),
                          "regional": p.params.get("regional"), "min_cruise_agl": float(hag.min()),
                          "clearance": p.clearance}}))
        """
    )
    stages = ", ".join(f"{k} {v:.2f} s" for k, v in r["timings"].items() if k != "total")
    nx, ny, nz = r["shape"]
    return [{"benchmark": "plan", "case": f"regional {nx}x{ny}x{nz} DEM (30 m, 120 m AGL)",
             "ours_s": r["plan"] + r["world"], "peak_mb": r["peak_mb"],
             "bar": "<= 60 s, <= 6 GB",
             "notes": (f"storage {r['storage']}; world build {r['world']:.2f} s, plan "
                       f"{r['plan']:.2f} s ({stages}); length {r['length'] / 1e3:.2f} km, "
                       f"lowest cruise AGL {r['min_cruise_agl']:.1f} m; {r['regional']}")}]


def regional_vs_full_rows(quick: bool) -> list[dict]:
    """DEMs small enough for the full grid planned both ways: length ratio, safety, times.

    Two reliefs of the same size: smooth (features ~15 cells) and rough (~5 cells, finer
    than the coarse stage resolves)."""
    n = 160 if quick else 400
    rows = []
    for name, sigma, relief_m in (("smooth", 15.0, 600.0), ("rough", 5.0, 500.0)):
        r = _child(
            f"""
            import fm2uav
            from scipy import ndimage
            from fm2uav.analysis.safety import safety_summary
            n, cell, dz, agl = {n}, 30.0, 20.0, 120.0
            rng = np.random.default_rng(0)
            relief = ndimage.gaussian_filter(rng.standard_normal((n, n)), {sigma}, mode="wrap")
            h = (relief - relief.min()) / np.ptp(relief) * {relief_m} + 200.0
            nz = int(np.ceil((h.max() + agl + 10 * dz - 180.0) / dz)) + 1
            world = fm2uav.World.from_heightmap(h, (cell, cell, dz), nz, origin=(0, 0, 180.0))
            def at(i, j):
                return [i * cell, j * cell, float(world.ground_height(i * cell, j * cell)) + agl]
            level = fm2uav.FlightLevel(agl=agl)
            out = {{}}
            for storage in ("full", "regional", "full", "regional"):   # 1st of each: warm-up
                world._cache.clear()
                t0 = time.perf_counter()
                p = fm2uav.plan(world, at(10, 10), at(n - 11, n - 11), level=level,
                                options=fm2uav.PlanOptions(storage=storage))
                s = safety_summary(world, p.path, requested=agl, phase=p.phase, level=level)
                out[storage] = {{"s": time.perf_counter() - t0, "length": p.length,
                                "cruise_min": s["height_above_ground"]["cruise"]["min_m"],
                                "ok": all(c["ok"] for c in s["checks"].values())}}
            out["shape"] = list(world.shape)
            print(json.dumps(out))
            """
        )
        f, g = r["full"], r["regional"]
        nx, ny, nz = r["shape"]
        rows.append({
            "benchmark": "plan",
            "case": f"regional vs full plan, {name} {nx}x{ny}x{nz} DEM (120 m AGL)",
            "ours_s": g["s"], "peer": "full grid", "peer_s": f["s"], "ratio": f["s"] / g["s"],
            "bar": "length within 1 %, same safety checks",
            "notes": (f"relief sigma {sigma:g} cells, {relief_m:g} m; length regional/full "
                      f"{g['length'] / f['length']:.4f} ({g['length']:.0f} / {f['length']:.0f} m); "
                      f"lowest cruise AGL {g['cruise_min']:.1f} / {f['cruise_min']:.1f} m; safety "
                      f"checks {'ok' if g['ok'] else 'FAILED'} / {'ok' if f['ok'] else 'FAILED'}")})
    return rows


def jit_rows(quick: bool) -> list[dict]:
    """Compile time with an empty numba cache, then load time from the cache."""
    cache = tempfile.mkdtemp(prefix="fm2uav-numba-")
    code = """
        t = time.perf_counter()
        import fm2uav
        sc = fm2uav.scenarios.open_field()
        fm2uav.plan(sc.world, sc.start, sc.goal)
        fm2uav.fast_marching(np.ones((5, 5)), [(2, 2)], order=1)
        print(json.dumps({"s": time.perf_counter() - t}))
        """
    env = {"NUMBA_CACHE_DIR": cache}
    cold = _child(code, env)
    warm = _child(code, env)
    return [
        {"benchmark": "jit", "case": "import + first plan, empty numba cache", "ours_s": cold["s"],
         "notes": "one-off compile of the kernels"},
        {"benchmark": "jit", "case": "import + first plan, numba cache filled", "ours_s": warm["s"],
         "notes": "every later process"},
    ]


def threads_rows(quick: bool, repeats: int = 5, children: int = 2) -> list[dict]:
    """The parallel march (issue 27): ``threads=2`` against ``threads=1``, order 1 and 2.

    2048² and 160³ with constant speed (centre source), the smooth field and the
    FM²-shaped field (:mod:`benchmarks.fields`), and the smaller grids around the size
    below which the march stays serial (``PARALLEL_MIN_NODES``). Interleaved in one child,
    ``repeats`` rounds, and the same again in ``children`` children one after the other: on
    this host the ratios swung 5-10 % between runs minutes apart (session 38: 160³ FM²-shaped
    order 2 1.38x and 1.59x), so a row gives the medians over every child's rounds and its
    notes each child's ratio. Three ratios: wall time (what a user waits; on a busy
    machine the second thread waits for a core), process CPU time (the work both threads
    do) and serial CPU over the busiest thread's CPU time (from ``/proc/self/task``; an
    upper bound of the idle machine's wall ratio: the threads' waits at the barriers are
    not in it). The windows' ``balance`` (nodes frozen over the sum of each window's
    busiest thread's share, from the march's stats) gives the idle-machine estimate
    ``CPU 1 thread / (set-up + CPU of the windows / balance)``, the set-up being the
    calling thread's CPU time in the march outside the windows (slab cuts, padding, the
    plateau, unpadding: one thread, or both waiting): the critical path if every freeze
    cost the same and the barriers nothing (on the idle machine it was ~10 % above the
    measured wall ratio). Bar (issue 27): >= 1.6x on 2048² and 160³.

    First rows give the machine's ceiling for these ratios, measured in a child of their own
    just before (:mod:`benchmarks.march_pair`): two serial marches at once, in two
    processes, against one alone (1.00x: two full cores for this work; at 1.30x no
    two-thread march could pass 2 / 1.30 = 1.54x). Each row names the threading layer numba
    ran the regions on (OpenMP unless the user chose another: ``fm2uav._numba``; TBB's late
    second thread cost 10-20 % of these ratios, docs/performance.md).
    """
    cases = ([("256x256", "smooth", 1), ("32x32x32", "smooth", 1), ("256x256", "smooth", 2)]
             if quick else
             [(s, f, 1) for s in ("2048x2048", "160x160x160") for f in ("constant", "smooth", "fm2")]
             + [("512x512", "smooth", 1), ("1024x1024", "smooth", 1)]
             + [(s, f, 2) for s in ("2048x2048", "160x160x160") for f in ("smooth", "fm2")])
    pair_cases = ["256x256:fm2"] if quick else ["2048x2048:fm2", "160x160x160:fm2"]
    pair_repeats = 1 if quick else 3
    pairs = _child(
        f"""
        from benchmarks import march_pair
        print(json.dumps([march_pair.measure(c, 1, {pair_repeats}) for c in {pair_cases!r}]))
        """
    )
    code = (
        f"""
        import os
        from fm2uav import fast_marching
        from fm2uav.eikonal import _parallel
        from benchmarks import fields
        from benchmarks._march_spy import watch_parallel_march

        # the windows' balance of the last parallel march, the calling thread's CPU outside
        # the windows (the set-up: serial) and the windows' CPU
        stats = watch_parallel_march()

        def task_cpu():
            out = {{}}
            for tid in os.listdir("/proc/self/task"):
                try:
                    f = open(f"/proc/self/task/{{tid}}/stat").read().rsplit(")", 1)[1].split()
                except OSError:
                    continue
                out[tid] = (int(f[11]) + int(f[12])) / os.sysconf("SC_CLK_TCK")
            return out

        out = []
        for case, field, order in {cases!r}:
            shape = tuple(int(n) for n in case.split("x"))
            if field == "constant":
                v, src = np.ones(shape), tuple(n // 2 for n in shape)
            else:
                v, src = getattr(fields, "smooth" if field == "smooth" else "fm2_shaped")(shape)
            stats.clear()
            for th in (1, 2):  # JIT and first-touch warm-up
                fast_marching(v, [src], order=order, threads=th)
            runs = {{1: [], 2: []}}
            for _ in range({repeats}):
                for th in (1, 2):
                    stats.clear()
                    a = task_cpu(); w = time.perf_counter(); c = time.process_time()
                    fast_marching(v, [src], order=order, threads=th)
                    w = time.perf_counter() - w; c = time.process_time() - c
                    b = task_cpu()
                    busiest = max(b[t] - a.get(t, 0.0) for t in b)
                    # idle-machine estimate: the set-up (one thread) + the windows' CPU over
                    # their balance (the serial march: its CPU)
                    est = (stats["setup"] + stats["drive_cpu"] / stats["balance"]
                           if "balance" in stats else c)
                    runs[th].append((w, c, busiest, est))
            out.append(dict(case=case, field=field, order=order, nodes=int(v.size),
                            parallel=_parallel.on_slabs(v.size, len(shape) == 3, order),
                            serial=runs[1], threads2=runs[2], balance=stats.get("balance", 1.0),
                            setup=stats.get("setup", 0.0)))
        import numba
        try:  # the layer numba ran the parallel regions on (none if every case was serial)
            layer = numba.threading_layer()
        except ValueError:
            layer = "none started"
        print(json.dumps(dict(marches=out, layer=layer)))
        """
    )
    runs = [_child(code) for _ in range(children)]
    res = runs[0]
    rows = [_pair_row(p, pair_repeats) for p in pairs]
    for i, r in enumerate(res["marches"]):
        every = [run["marches"][i] for run in runs]
        (w1, c1, _, _), (w2, c2, b2, e2) = (
            [statistics.median(x[j] for m in every for x in m[key]) for j in range(4)]
            for key in ("serial", "threads2"))
        each = ", ".join(f"{_wall_ratio(m):.2f}x" for m in every)
        big = r["case"] in ("2048x2048", "160x160x160")
        rows.append({
            "benchmark": "fmm threads",
            "case": f"{r['case']} {r['field']} order {r['order']}, 2 threads",
            "ours_s": w2, "peer": "fm2uav 1 thread", "peer_s": w1, "ratio": w1 / w2,
            "bar": ">= 1.6x (issue 27)" if big else ("never slower" if r["parallel"] else ""),
            "notes": (f"{'parallel' if r['parallel'] else 'serial (below its floor, on_slabs)'}; "
                      f"medians of {children} children x {repeats} rounds, each child {each}; "
                      f"CPU 1 thread {c1:.3f} s, 2 threads {c2:.3f} s (ratio {c1 / c2:.2f}x); "
                      f"busiest thread {b2:.3f} s ({c1 / max(b2, 1e-9):.2f}x); windows' balance "
                      f"{r['balance']:.2f}, set-up {1e3 * r['setup']:.0f} ms: idle-machine "
                      f"estimate {c1 / max(e2, 1e-9):.2f}x; numba threading layer "
                      f"{res['layer']}; load average {os.getloadavg()[0]:.1f}")})
    return rows


def _wall_ratio(march: dict) -> float:
    """One child's wall ratio of a case of :func:`threads_rows`: the median of its rounds on
    one thread over that on two."""
    return (statistics.median(r[0] for r in march["serial"])
            / statistics.median(r[0] for r in march["threads2"]))


def _pair_row(pair: dict, repeats: int) -> dict:
    """The row of :func:`benchmarks.march_pair.measure`: two serial marches at once."""
    case = pair["case"].replace(":fm2", " FM²-shaped")
    return {
        "benchmark": "fmm threads",
        "case": f"the machine: two serial marches at once, {case} order {pair['order']}",
        "ours_s": pair["pair_s"], "peer": "one alone", "peer_s": pair["alone_s"],
        "ratio": pair["alone_s"] / pair["pair_s"],
        "bar": "1.00x: two full cores",
        "notes": (f"benchmarks.march_pair, two processes, medians of {repeats}: each march "
                  f"{pair['ratio']:.2f}x as long as alone, so a two-thread march's ceiling "
                  f"on this machine now is {2 / pair['ratio']:.2f}x"),
    }


def run(quick: bool = False) -> list[dict]:
    """All core benchmark rows (see module docstring)."""
    # the cold-compile measurement takes ~20 s whatever the size: full runs only
    return (fmm_rows(quick) + threads_rows(quick) + plan_rows(quick) + regional_rows(quick)
            + regional_vs_full_rows(quick) + ([] if quick else jit_rows(quick)))


#: ``python -m benchmarks.bench_core big`` runs only the big-map rows (issue 15, deliverable 3).
GROUPS = {"fmm": fmm_rows, "threads": threads_rows, "plan": plan_rows,
          "big": lambda quick: big_rows(quick), "jit": jit_rows}


def big_rows(quick: bool) -> list[dict]:
    """The terrain 1000x1000x40 row of :func:`plan_rows` and the regional row."""
    return ([r for r in plan_rows(quick) if r["case"].startswith("terrain")]
            + regional_rows(quick) + regional_vs_full_rows(quick))


if __name__ == "__main__":
    from benchmarks.run import print_table

    quick = "--quick" in sys.argv
    names = [a for a in sys.argv[1:] if not a.startswith("--")]
    print_table(run(quick) if not names else [r for n in names for r in GROUPS[n](quick)])
