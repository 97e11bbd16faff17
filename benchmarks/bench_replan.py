"""Re-planning with a :class:`fm2uav.planning.session.Planner` on the open field (issue 16 item 7).

Three cases, warm (one untimed call first, compile excluded), against a fresh
``fm2uav.plan`` of the same request in the same run (ratio = fresh / re-plan):

* ``move``: the vehicle moved; only the descent of the kept arrival times runs;
* ``obstacle``: a new obstacle (a 5x5-column tower) far from the goal, then a
  re-plan from the vehicle's position (W rebuilt, T re-marched where it can change);
* ``obstacle near goal``: the same tower next to the goal (little to re-use).

Bar: a warm re-plan on the open field <= 20 ms.
"""

from __future__ import annotations

import numpy as np

import fm2uav
from fm2uav.planning.session import Planner
from fm2uav.scenarios import open_field

from ._timing import median_time

BAR_S = 0.020


def _tower(world, cx: int, cy: int) -> np.ndarray:
    m = np.zeros(world.shape, bool)
    m[cx - 2 : cx + 3, cy - 2 : cy + 3, :20] = True  # 300 m tall
    return m & ~world.occupancy  # removing it must not dig into the terrain


def run(quick: bool = False) -> list[dict]:
    sc = open_field()
    shaping = fm2uav.Shaping(saturation_distance=150.0)
    reps = 3 if quick else 7
    s = Planner(sc.world, sc.goal, shaping=shaping)
    start = np.asarray(sc.start, float)
    fresh_s = median_time(lambda: fm2uav.plan(sc.world, start, sc.goal, shaping=shaping),
                          reps, warmup=True)[0]
    rows = []
    move_s = median_time(lambda: s.plan(start + (30.0, 30.0, 0.0)), reps, warmup=True)[0]
    rows.append({"benchmark": "replan", "case": "move (descent only)", "ours_s": move_s,
                 "peer": "fresh plan()", "peer_s": fresh_s, "ratio": fresh_s / move_s,
                 "bar": f"<= {BAR_S * 1e3:.0f} ms: {'met' if move_s <= BAR_S else 'NOT met'}",
                 "notes": "warm"})
    for label, (cx, cy) in (("obstacle far from goal", (40, 40)), ("obstacle near goal", (95, 75))):
        tower = _tower(sc.world, cx, cy)

        def cycle():
            s.add_obstacles(tower)
            p = s.plan(start)
            s.remove_obstacles(tower)
            return p

        cyc_s = median_time(cycle, reps, warmup=True)[0]
        s.add_obstacles(tower)
        reused = s.last_update["reused"]
        upd = median_time(lambda: s.plan(start), 1)[0]
        s.remove_obstacles(tower)
        half = cyc_s / 2.0  # one change + re-plan, the cycle has two changes
        rows.append({"benchmark": "replan", "case": f"{label} (change + re-plan)",
                     "ours_s": half, "peer": "fresh plan()", "peer_s": fresh_s,
                     "ratio": fresh_s / half,
                     "bar": f"<= {BAR_S * 1e3:.0f} ms: {'met' if half <= BAR_S else 'NOT met'}",
                     "notes": f"warm; {reused:.0%} of arrival times kept; descent {upd * 1e3:.1f} ms"})
    return rows
