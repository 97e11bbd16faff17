"""Terrain-following benchmarks: flight-level shaping, TFF plans, DEM loading.

Peer for a TFF plan: the same plan without the flight level (plain FM² on the
same world), so ``ratio`` = plain / TFF time shows what the flight level costs.
Times are medians after a warm-up (JIT, cached distance map).
"""

from __future__ import annotations

from ._timing import median_time





def run(quick: bool = False) -> list[dict]:
    import fm2uav
    from fm2uav.planning import base_velocity
    from fm2uav.planning.flight_level import flight_level_speed

    reps = 1 if quick else 5
    rows: list[dict] = []
    sc = fm2uav.scenarios.open_field()
    w = sc.world
    W = base_velocity(w)
    level = fm2uav.FlightLevel(agl=150.0, p1=0.5, p2=1.3)
    rows.append({
        "benchmark": "tff", "case": "flight_level_speed open-field 120x90x40 (capped)",
        "ours_s": median_time(lambda: flight_level_speed(W, w, level), reps, warmup=True)[0],
    })
    tff = median_time(lambda: fm2uav.plan(w, sc.start, sc.goal, level=level), reps, warmup=True)[0]
    plain = median_time(lambda: fm2uav.plan(w, sc.start, sc.goal), reps, warmup=True)[0]
    rows.append({
        "benchmark": "tff", "case": "plan open-field level 10 (0.5, 1.3)", "ours_s": tff,
        "peer": "plan without flight level", "peer_s": plain, "ratio": plain / tff,
    })
    if quick:
        return rows
    from fm2uav.scenarios.jacksboro import jacksboro_dem
    from fm2uav.world.dem import from_dem

    z, bounds = jacksboro_dem()
    rows.append({
        "benchmark": "tff", "case": "from_dem jacksboro 344x403 -> 194x206x49 (UTM)",
        "ours_s": median_time(lambda: from_dem(z, (150.0, 150.0, 30.0), crs="EPSG:4326",
                                           bounds=bounds), 3, warmup=True)[0],
    })
    jb = fm2uav.scenarios.get_scenario("jacksboro")
    jb_level = fm2uav.FlightLevel(agl=300.0, p1=0.5, p2=1.3)
    tff = median_time(lambda: fm2uav.plan(jb.world, jb.start, jb.goal, level=jb_level), 3,
                      warmup=True)[0]
    plain = median_time(lambda: fm2uav.plan(jb.world, jb.start, jb.goal), 3, warmup=True)[0]
    rows.append({
        "benchmark": "tff", "case": "plan jacksboro 194x206x49 agl 300 m (0.5, 1.3)",
        "ours_s": tff, "peer": "plan without flight level", "peer_s": plain,
        "ratio": plain / tff,
    })
    from fm2uav.experiments.tff import run_tff

    rows.append({
        "benchmark": "tff", "case": "reproduce tff cases (6 plans + metrics, no figures)",
        "ours_s": median_time(lambda: run_tff("open-field", 0, "capped"), 3, warmup=True)[0],
    })
    return rows


if __name__ == "__main__":
    for r in run(quick=False):
        print(r)
