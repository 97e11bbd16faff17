"""A ridge between the route and home, for the safe-return tests (autopilot, io, cli).

``ridge_plan()`` plans 100 → 1000 m east over a valley with a 150 m ridge at x = 620 m
(40 m above ground, floor 30 m, ceiling 120 m): no single firmware return altitude
stays under the ceiling, so the mission carries its planned safe return.
"""

from __future__ import annotations

import numpy as np


def ridge_world():
    """1200 x 800 m in 20 m columns: a valley at 0 m, a 150 m ridge across x = 620 m."""
    from fm2uav import World

    x = np.arange(60) * 20.0
    h = (150.0 * np.exp(-((x - 620.0) / 200.0) ** 2))[:, None] * np.ones((1, 40))
    return World.from_heightmap(h, (20.0, 20.0, 10.0), 32)


def ridge_plan():
    """The route over the ridge (module docstring)."""
    from fm2uav import FlightLevel
    from fm2uav.missions.route import plan_route

    lev = FlightLevel(agl=40.0, min_agl=30.0, max_agl=120.0)
    return plan_route(ridge_world(), (100.0, 400.0, 40.0), (1000.0, 400.0, 40.0),
                      level=lev).plan


def build(p, returns=None, **kw):
    """``build_with_returns`` of a plan (ArduPilot, 10 min endurance unless ``kw`` says)."""
    from fm2uav.autopilot.build import ExportOptions
    from fm2uav.autopilot.safe_return import ReturnOptions, build_with_returns

    opt = ExportOptions(**{"firmware": "ardupilot", "endurance_s": 600.0, **kw})
    return build_with_returns(p.path, p.world, opt, returns or ReturnOptions(), plan=p,
                              w=p.w, agl=40.0, profile=p.profile)
