"""Curvature study benchmarks (seed 004): Table 1 and the Fréchet distance.

* Table 1: the same start/goal pairs on the 2D city map solved by FM²
  (``plan()``: velocity shaping, both waves, descent, metrics) and by each
  lattice reference (Dubins, elastica, Reeds–Shepp forward; compiled Dijkstra
  with the cached control set), in one run. ``ours_s`` is FM²'s total over the
  pairs, ``peer_s`` the reference's, ``ratio`` = how many times FM² is faster.
  Bar (seed): FM² ≥ 220× faster than the Dubins reference. A row with the
  A* variant of the Dubins search (same paths, fewer states) is given too.
* Fréchet: our compiled discrete Fréchet distance vs similaritymeasures on
  two 1000-point curves. Bar: ≥ 50×.
"""

from __future__ import annotations

from ._timing import median_time

import time

import numpy as np




def _table1(quick: bool) -> list[dict]:
    from fm2uav.baselines.reference import build_primitives, dubins_length, reference_path
    from fm2uav.baselines.reference.lattice import DEFAULT_XI, default_radius
    from fm2uav.planning import Shaping, plan
    from fm2uav.world import World
    from fm2uav.scenarios.city2d import city2d_pairs, city2d_world

    world = city2d_world()
    n = 2 if quick else 24
    starts, goals = city2d_pairs(n, 0, world=world)
    models = ("dubins",) if quick else ("dubins", "elastica", "rs")
    alpha, beta = 0.5, 0.5

    # warm-up: JIT of both pipelines, control sets built (cached, not timed)
    shaping = Shaping(saturation=alpha, exponent=beta)
    plan(world, starts[0], goals[0], shaping=shaping)
    xi_c = DEFAULT_XI / world.spacing[0]
    for m in models:
        build_primitives(m, xi_c, max_int=4, radius=default_radius(xi_c, 4, m))
    tiny = World(np.zeros((12, 12), bool), spacing=world.spacing[0])
    reference_path(tiny, (2, 2), (20, 20), model="dubins")

    fm2 = sum(
        median_time(lambda s=s, g=g: plan(world, s, g, shaping=shaping), 5)[0]
        for s, g in zip(starts, goals)
    )
    rows = []
    for m in models:
        t = time.perf_counter()
        for s, g in zip(starts, goals):
            reference_path(world, s, g, model=m)
        peer = time.perf_counter() - t
        rows.append({
            "benchmark": "table1_fm2_vs_reference",
            "case": f"city2d {n} pairs",
            "ours_s": fm2,
            "peer": f"lattice {m} (Dijkstra)",
            "peer_s": peer,
            "ratio": peer / fm2,
            "bar": ">= 220x (dubins, seed)" if m == "dubins" else "",
            "notes": f"FM² alpha={alpha} beta={beta}, median of 5 per pair; reference 1 run per pair",
        })
    t = time.perf_counter()
    for s, g in zip(starts, goals):
        reference_path(world, s, g, model="dubins", heuristic=True)
    peer = time.perf_counter() - t
    rows.append({
        "benchmark": "table1_fm2_vs_reference",
        "case": f"city2d {n} pairs",
        "ours_s": fm2,
        "peer": "lattice dubins (A*)",
        "peer_s": peer,
        "ratio": peer / fm2,
        "notes": "same optimum as Dijkstra, goal-directed",
    })

    # accuracy of the Dubins lattice in free space (note only)
    free = World(np.zeros((90, 90), bool), spacing=1.0)
    cases = [((10, 10, 0.0), (70, 40, 0.0)), ((10, 10, np.pi / 2), (60, 70, 0.0)),
             ((70, 15, np.arctan2(1, 2)), (20, 70, np.pi / 2))]
    errs = []
    for s, g in cases[: 1 if quick else 3]:
        r = reference_path(free, s[:2], g[:2], model="dubins", xi=5.0, start_heading=s[2],
                           goal_heading=g[2])
        errs.append(r.cost / dubins_length(s, g, 5.0) - 1.0)
    rows[0]["notes"] += f"; free-space Dubins excess over exact: max {100 * max(errs):.2f}%"
    return rows


def _frechet(quick: bool) -> list[dict]:
    from fm2uav.analysis.similarity import frechet_distance

    n = 300 if quick else 1000
    t = np.linspace(0.0, 1.0, n)
    P = np.c_[t, np.sin(6 * t)]
    Q = np.c_[t, np.sin(6 * t + 0.3)]
    frechet_distance(P, Q)  # JIT
    ours = median_time(lambda: frechet_distance(P, Q), 7)[0]
    row = {"benchmark": "frechet", "case": f"2 curves x {n} points", "ours_s": ours}
    try:
        import similaritymeasures as sm
    except ImportError:
        row["notes"] = "similaritymeasures not installed"
        return [row]
    peer = median_time(lambda: sm.frechet_dist(P, Q), 1 if quick else 3)[0]
    assert abs(sm.frechet_dist(P, Q) - frechet_distance(P, Q)) < 1e-12
    row.update(peer="similaritymeasures.frechet_dist", peer_s=peer, ratio=peer / ours,
               bar=">= 50x")
    return [row]


def run(quick: bool = False) -> list[dict]:
    """Benchmark rows (see module docstring)."""
    return _frechet(quick) + _table1(quick)


if __name__ == "__main__":
    import sys

    for r in run(quick="--quick" in sys.argv):
        print(r)
