"""FM² vs OMPL RRT timing in the thesis' city (thesis §3.3.1: FM² 1.2 s, RRT 5 s, Matlab),
and the cost of the Dubins-airplane feasibility check.

FM² is timed on a fresh World each run (the distance map is not reused from a
cache); RRT / RRT-Connect stop at their first solution and include OMPL's
shortcut smoothing; RRT* runs for a fixed 1 s budget, so its ratio only says
how long it was given. Medians over ``repeats`` runs after one warm-up.
"""

from __future__ import annotations

from ._timing import median_time


import numpy as np




def run(quick: bool = False) -> list[dict]:
    from fm2uav import Shaping, World, plan
    from fm2uav.experiments.city import city_missions, horizontal_slice
    from fm2uav.baselines.rrt import RRTOptions, plan_rrt
    from fm2uav.vehicles import check_feasibility

    repeats = 1 if quick else 5
    missions = city_missions(0)
    rows: list[dict] = []
    cases = [("low", "city low altitude, 2D slice 100x100 of 5 m")]
    if not quick:
        cases.append(("high", "city high altitude, 3D 100x100x90 of 5 m"))
    planners = ("rrt",) if quick else ("rrt", "rrtconnect", "rrtstar")
    for mission, label in cases:
        sc = missions[mission]
        if mission == "low":
            base = horizontal_slice(sc.world, float(sc.start[2]))
            s, g = sc.start[:2], sc.goal[:2]
        else:
            base = sc.world
            s, g = sc.start, sc.goal

        def fresh() -> World:
            return World(base.occupancy, spacing=base.spacing, origin=base.origin)

        shaping = Shaping(exponent=1.0, walls=True)
        plan(fresh(), s, g, shaping=shaping)  # JIT warm-up
        fm_s, p = median_time(lambda: plan(fresh(), s, g, shaping=shaping), repeats)
        for name in planners:
            budget = 1.0 if name == "rrtstar" else 10.0
            plan_rrt(base, s, g, planner=name, options=RRTOptions(time_limit=budget))  # warm-up
            rr_s, r = median_time(
                lambda: plan_rrt(base, s, g, planner=name, options=RRTOptions(time_limit=budget)),
                repeats)
            rows.append({
                "benchmark": "feasibility/fm2-vs-rrt",
                "case": f"{label}: FM² W^1 vs {r.planner}+shortcut",
                "ours_s": fm_s,
                "peer": f"OMPL {r.planner} + PathSimplifier",
                "peer_s": rr_s,
                "ratio": rr_s / fm_s,
                "notes": (f"FM² clearance {p.clearance:.1f} m, length {p.length:.0f} m; "
                          f"{r.planner} clearance {r.clearance:.1f} m, length {r.length:.0f} m"
                          + ("; RRT* uses its whole 1 s budget" if name == "rrtstar" else "")),
            })
        path3 = p.path if p.path.shape[1] == 3 else np.column_stack(
            [p.path, np.full(len(p.path), float(sc.start[2]))])
        check_feasibility(path3, "disco", world=sc.world, w=p.w)
        ck_s, rep = median_time(lambda: check_feasibility(path3, "disco", world=sc.world, w=p.w),
                            repeats)
        rows.append({
            "benchmark": "feasibility/dubins-check",
            "case": f"{label}: Dubins tracking + geometric + speed profile (disco, dt 0.05 s)",
            "ours_s": ck_s,
            "notes": f"{len(rep.tracking.t)} steps, separation {rep.tracking.max_separation:.2f} m",
        })
    return rows


if __name__ == "__main__":
    for row in run(quick=False):
        print(row)
