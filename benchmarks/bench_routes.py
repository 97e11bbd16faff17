"""Many routes from one wave (issue 27, deliverable 5): ``plan_many`` against single plans.

A seeded 1000 x 1000 city map (2 m cells: rectangular blocks cut by streets, about a
quarter built), the goal (the depot) near the centre, 10,000 starts drawn from the free
nodes the wave reaches (every one gets a route). Ours: one ``plan_many`` call, wall and
CPU time (every thread). Peer: ``plan()`` from a sample of the same starts, measured in
the same run, interleaved with ours, its median time per route extrapolated to all the
starts; the sampled routes are checked equal to ``plan_many``'s, element for element.

Bar: 10,000 routes in <= 10 s (wall).
"""

from __future__ import annotations

import statistics
import time

import numpy as np

from fm2uav import Shaping, World, plan
from fm2uav.planning.many import plan_many

BAR_S = 10.0


def city_map(n: int = 1000, seed: int = 0) -> World:
    """A seeded city: blocks of 20-60 m between streets 8-16 m wide, some blocks split."""
    rng = np.random.default_rng(seed)
    occ = np.zeros((n, n), bool)
    x = 0
    while x < n:
        w = int(rng.integers(10, 30))
        y = 0
        while y < n:
            h = int(rng.integers(10, 30))
            if rng.random() < 0.85:
                occ[x:x + w, y:y + h] = True
                if rng.random() < 0.3:  # a courtyard / alley
                    occ[x + w // 2 - 1:x + w // 2 + 1, y:y + h] = False
            y += h + int(rng.integers(4, 8))
        x += w + int(rng.integers(4, 8))
    c = n // 2
    occ[c - 10:c + 10, c - 10:c + 10] = False  # the depot's yard
    return World(occ, spacing=2.0)


def _starts(world: World, goal, count: int, seed: int) -> np.ndarray:
    from fm2uav.eikonal.fmm import fast_marching
    from fm2uav.planning.planner import shaped_velocity

    W = shaped_velocity(world, Shaping(exponent=0.5))
    T = fast_marching(W, [world.to_cell(np.asarray(goal))], spacing=world.spacing, order=1)
    free = np.argwhere(np.isfinite(T) & (W > 0))
    rng = np.random.default_rng(seed)
    return world.to_world(free[rng.choice(len(free), count, replace=False)].astype(float))


def run(quick: bool = False) -> list[dict]:
    n, count, sample, reps = (300, 400, 4, 1) if quick else (1000, 10_000, 12, 3)
    world = city_map(n)
    goal = (float(n), float(n))  # the centre: node (n/2, n/2) at 2 m
    shaping = Shaping(exponent=0.5)
    starts = _starts(world, goal, count, seed=1)
    picks = np.random.default_rng(2).choice(count, sample, replace=False)
    plan_many(world, goal, starts[:50], shaping=shaping)  # compile, caches
    walls, cpus, peer = [], [], []
    many = None
    for r in range(reps):  # interleaved: ours, then a share of the single plans
        c0, t0 = time.process_time(), time.perf_counter()
        many = plan_many(world, goal, starts, shaping=shaping)
        walls.append(time.perf_counter() - t0)
        cpus.append(time.process_time() - c0)
        for k in picks[r::reps]:
            t = time.perf_counter()
            single = plan(world, starts[k], goal, shaping=shaping)
            peer.append(time.perf_counter() - t)
            got = many.routes[k]
            assert np.array_equal(got.path, single.path) and got.length == single.length, k
    ours = statistics.median(walls)
    per_plan = statistics.median(peer)
    ok = int(many.ok.sum())
    return [{
        "benchmark": "routes",
        "case": f"{count} routes, city {n}x{n} (2 m), one wave",
        "ours_s": ours,
        "peer": f"{count} x plan() (median of {len(peer)}, extrapolated)",
        "peer_s": per_plan * count,
        "ratio": per_plan * count / ours,
        "bar": f"<= {BAR_S:g} s: {'met' if ours <= BAR_S else 'NOT met'}",
        "notes": (f"{ok}/{count} routes; CPU {statistics.median(cpus):.2f} s over "
                  f"{many.threads} threads (wall {', '.join(f'{w:.2f}' for w in walls)} s); "
                  f"{len(peer)} sampled routes equal to plan()'s"),
    }]
