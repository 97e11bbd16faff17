"""Coverage benchmarks: the seeds' DE and the whole coverage plan on the 118x87x40 map.

Bars (issue "Coverage path planning"): DE ≤ 0.3 s (seeds: 3.79 s in Matlab; goal
0.1 s); whole coverage plan (DE + zigzag + W + FM² + coverage report) on
118x87x40 ≤ 1 s (seeds: DE 3.79 s + FM² 0.36 s). Peers: scipy's
differential_evolution with the same settings on the same cost function, and
the seeds' published times.
"""

from __future__ import annotations

from ._timing import median_time





def run(quick: bool = False) -> list[dict]:
    from fm2uav import FlightLevel
    from fm2uav.missions.coverage import ZigzagCost, differential_evolution, plan_coverage, scipy_de
    from fm2uav.scenarios.coverage import (
        COVERAGE_AGL,
        COVERAGE_AREAS,
        COVERAGE_SPACING,
        coverage_area,
        coverage_world,
    )

    repeats = 1 if quick else 5
    names = ["S1"] if quick else list(COVERAGE_AREAS)
    world = coverage_world(0)
    rows = []
    # warm-up: numba kernels, shapely, the world's caches
    level = FlightLevel(agl=COVERAGE_AGL)
    plan_coverage(world, coverage_area("S1"), COVERAGE_SPACING, level=level)
    for n in names:
        poly = coverage_area(n)
        f = ZigzagCost.of(poly, COVERAGE_SPACING)
        de = median_time(lambda: differential_evolution(f, seed=0), repeats)[0]
        sp = median_time(lambda: scipy_de(f, seed=0), repeats)[0]
        rows.append({"benchmark": "coverage_de", "case": f"{n} D=80 Np=20 G=30",
                     "ours_s": de, "peer": "scipy DE (same settings)", "peer_s": sp,
                     "ratio": sp / de, "bar": "<= 0.3 s (seeds 3.79 s)"})
        whole = median_time(lambda: plan_coverage(world, poly, COVERAGE_SPACING, level=level),
                            repeats)[0]
        rows.append({"benchmark": "coverage_plan", "case": f"{n} 118x87x40 agl=100",
                     "ours_s": whole, "peer": "seeds (Matlab, DE + FM²)", "peer_s": 3.79 + 0.36,
                     "ratio": (3.79 + 0.36) / whole, "bar": "<= 1 s",
                     "notes": "DE + zigzag + W + FM² + coverage report"})
    return rows


if __name__ == "__main__":
    for r in run():
        print(r)
