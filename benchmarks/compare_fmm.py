"""Side-by-side timing of our exact FMM and scikit-fmm, in one process.

Independent of ``benchmarks/run.py``: both solvers run in this one process,
alternately (ours, scikit-fmm, ours, ...; the first of each pair alternates
too), on the same speed field with the source at the grid centre, so that a
change of machine load hits both alike. Three speed fields per grid:

* ``constant``: 1 everywhere;
* ``sinusoidal``: ``1 + 0.4 sum_k sin(3 x_k)`` on the unit cube, as
  ``benchmarks/bench_core.py``'s ``speed_field``;
* ``smooth random``: ``0.2 + g`` with ``g`` a Gaussian-filtered (sigma 4
  cells) uniform random field (seed 0) scaled to ``[0, 1]``;
* ``fm2-shaped``: obstacles (speed 0, masked for scikit-fmm), ``W = (d/d_max)^0.5``
  outside, the source off-centre (``benchmarks.fields.fm2_shaped``).

scikit-fmm gets ``phi = |x - centre| - 0.5`` (its zero contour half a cell
around the centre node) and ``travel_time(phi, speed, order)``; we get
``fast_marching(speed, [centre], order=order)``. Prints one markdown table:
wall-clock min and median [ms] of each solver, the speed-up (scikit-fmm /
ours) of the wall-clock medians and minima, and that of the medians of the
CPU time of the calling thread (``time.thread_time``; both solvers run on
this one thread, and on a machine with more runnable processes than cores it
leaves out the time spent waiting for a core), with the 1-minute load average
(``os.getloadavg``) before and after each case.

Usage::

    python benchmarks/compare_fmm.py                 # 2048^2 and 160^3, 7 repeats
    python benchmarks/compare_fmm.py --repeats 3 --shapes 512x512 40x40x40
"""

from __future__ import annotations

import argparse
import os
import statistics
import time

import numpy as np

FIELDS = ("constant", "sinusoidal", "smooth random", "fm2-shaped")


def _fields():
    """``benchmarks.fields``, also when this file runs as a script (``python benchmarks/...``)."""
    try:
        from benchmarks import fields
    except ImportError:  # run as a script: its folder is on sys.path
        import fields
    return fields


def speed(shape: tuple[int, ...], field: str) -> np.ndarray:
    """Speed field ``field`` on a grid of ``shape`` [m/s]."""
    if field == "constant":
        return np.ones(shape)
    if field == "sinusoidal":
        axes = np.meshgrid(*[np.linspace(0, 1, n) for n in shape], indexing="ij")
        v = np.ones(shape)
        for a in axes:
            v += 0.4 * np.sin(3.0 * a)
        return v
    if field == "smooth random":
        from scipy.ndimage import gaussian_filter

        g = gaussian_filter(np.random.default_rng(0).random(shape), 4)
        return 0.2 + (g - g.min()) / (g.max() - g.min())
    if field == "fm2-shaped":
        fm2_shaped = _fields().fm2_shaped

        return fm2_shaped(shape)[0]
    raise ValueError(f"unknown field {field!r}")


def source(shape: tuple[int, ...], field: str) -> tuple[int, ...]:
    """The source node of a field: the centre, off-centre on the FM²-shaped map."""
    if field == "fm2-shaped":
        fm2_shaped = _fields().fm2_shaped

        return fm2_shaped(shape)[1]
    return tuple(n // 2 for n in shape)


def _time(fn) -> tuple[float, float]:
    """Wall-clock and thread CPU time of one call [s]."""
    t, c = time.perf_counter(), time.thread_time()
    fn()
    return time.perf_counter() - t, time.thread_time() - c


def compare(shape: tuple[int, ...], field: str, order: int, repeats: int) -> dict:
    """Interleaved timings of both solvers on one case; min/median in seconds."""
    import skfmm

    from fm2uav import fast_marching

    skfmm_point_source = _fields().skfmm_point_source

    v = speed(shape, field)
    src = source(shape, field)
    phi, vs = skfmm_point_source(v, src)
    ours = lambda: fast_marching(v, [src], order=order)  # noqa: E731
    peer = lambda: skfmm.travel_time(phi, vs, order=order)  # noqa: E731
    ours()  # warm-up (compilation, page faults)
    peer()
    load0 = os.getloadavg()[0]
    t_ours, t_peer = [], []
    for r in range(repeats):
        if r % 2 == 0:
            t_ours.append(_time(ours))
            t_peer.append(_time(peer))
        else:
            t_peer.append(_time(peer))
            t_ours.append(_time(ours))
    load1 = os.getloadavg()[0]
    wall_o, cpu_o = zip(*t_ours)
    wall_p, cpu_p = zip(*t_peer)
    return {
        "ours_min": min(wall_o), "ours_med": statistics.median(wall_o),
        "peer_min": min(wall_p), "peer_med": statistics.median(wall_p),
        "cpu_ratio": statistics.median(cpu_p) / statistics.median(cpu_o),
        "cpu_ratio_min": min(cpu_p) / min(cpu_o),
        "load": (load0, load1),
    }


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=7, help="timed runs per solver and case")
    ap.add_argument("--shapes", nargs="+", default=["2048x2048", "160x160x160"],
                    help="grid shapes, e.g. 2048x2048 160x160x160")
    ap.add_argument("--orders", nargs="+", type=int, default=[1, 2])
    ap.add_argument("--fields", nargs="+", default=list(FIELDS), choices=FIELDS)
    args = ap.parse_args(argv)
    print(f"load average at start: {' '.join(f'{x:.2f}' for x in os.getloadavg())}, "
          f"{os.cpu_count()} CPUs, {args.repeats} interleaved repeats\n")
    print("| grid | speed | order | ours min / median [ms] | scikit-fmm min / median [ms] "
          "| speed-up wall medians / minima | speed-up CPU medians / minima | load 1 min |")
    print("|---|---|---|---|---|---|---|---|")
    for s in args.shapes:
        shape = tuple(int(n) for n in s.split("x"))
        for order in args.orders:
            for field in args.fields:
                r = compare(shape, field, order, args.repeats)
                print(f"| {s} | {field} | {order} "
                      f"| {r['ours_min'] * 1e3:.0f} / {r['ours_med'] * 1e3:.0f} "
                      f"| {r['peer_min'] * 1e3:.0f} / {r['peer_med'] * 1e3:.0f} "
                      f"| {r['peer_med'] / r['ours_med']:.2f}x / {r['peer_min'] / r['ours_min']:.2f}x "
                      f"| {r['cpu_ratio']:.2f}x / {r['cpu_ratio_min']:.2f}x "
                      f"| {r['load'][0]:.2f} -> {r['load'][1]:.2f} |", flush=True)


if __name__ == "__main__":
    main()
