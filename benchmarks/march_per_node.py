"""The 3D march's cost per node as the terrain grid grows, on the terrain's W and on one speed
(issue 27).

The world of ``benchmarks/terrain_stages.py`` (a Gaussian-filtered relief of ``n x n`` cells of
15 m, 40 layers; the relief's correlation length scaled with ``n`` so that every size has the
same landscape) at several sizes. The march from the goal corner of the terrain plan over the
whole grid, on one thread, order 1 and 2, on two speed maps:

* ``terrain``: the plan's W (``d / d_max``, 0 at the ground: the front lags near it, so the
  band is sheared, wide and scattered in memory);
* ``uniform``: speed 1 in every free node (the same obstacles; a spherical front, no speed read);
* ``jittered``: speed 1 - 0.01 u (u uniform in [0, 1), seed 0) in every free node: the front of
  ``uniform``, the speeds read as on the terrain's W (no plateau register).

Each case in a fresh child process, the march run twice there and the faster run kept (the
second reuses memory the first freed)::

    python -m benchmarks.march_per_node [--sizes 250 500 1000] [--orders 1 2]

Prints per case the wall time [s], the nodes frozen and the time per frozen node [ns]. Not part
of ``make bench`` (minutes); docs/performance.md quotes it.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import textwrap

_CHILD = textwrap.dedent(
    """
    import json, sys, time
    import numpy as np
    from scipy import ndimage
    import fm2uav
    from fm2uav.eikonal import fast_marching, velocity_map
    n, order, field = int(sys.argv[1]), int(sys.argv[2]), sys.argv[3]
    nz, cell = 40, 15.0
    rng = np.random.default_rng(0)
    relief = ndimage.gaussian_filter(rng.standard_normal((n, n)), 25 * n / 1000, mode="wrap")
    heights = (relief - relief.min()) / np.ptp(relief) * 25 * cell + cell
    world = fm2uav.World.from_heightmap(heights, cell, nz)
    W = velocity_map(world.occupancy, spacing=world.spacing, threads=1)
    if field == "uniform":
        W = (W > 0).astype(np.float64)
    elif field == "jittered":
        W = (W > 0) * (1.0 - 0.01 * np.random.default_rng(0).random(W.shape))
    goal = (n - 1 - n // 100, n - 1 - n // 100, 35)
    best = np.inf
    for _ in range(2):
        t0 = time.perf_counter()
        T = fast_marching(W, [goal], spacing=world.spacing, order=order, threads=1)
        best = min(best, time.perf_counter() - t0)
    print(json.dumps({"wall": best, "frozen": int(np.isfinite(T).sum()), "nodes": int(W.size)}))
    """
)


#: The speed maps, in the order printed.
FIELDS = ("terrain", "uniform", "jittered")


def run_case(n: int, order: int, field: str) -> dict:
    """One case in a fresh child: ``{"wall", "frozen", "nodes"}``."""
    out = subprocess.run([sys.executable, "-c", _CHILD, str(n), str(order), field],
                         capture_output=True, text=True, check=True).stdout
    return json.loads(out.splitlines()[-1])


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", type=int, nargs="+", default=[250, 500, 1000],
                    help="cells a side (n x n x 40)")
    ap.add_argument("--orders", type=int, nargs="+", default=[1, 2])
    args = ap.parse_args(argv)
    print("| grid | order | speed | wall [s] | frozen nodes | ns per frozen node |")
    print("|---|---|---|---|---|---|")
    for n in args.sizes:
        for order in args.orders:
            for field in FIELDS:
                r = run_case(n, order, field)
                print(f"| {n}x{n}x40 | {order} | {field} | {r['wall']:.4g} | {r['frozen']} | "
                      f"{1e9 * r['wall'] / max(r['frozen'], 1):.0f} |", flush=True)


if __name__ == "__main__":
    main()
