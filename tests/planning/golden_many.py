"""Routes of ``plan_many`` pinned bit for bit (``data/golden_many.json``).

The digests were written by the code of commit ad6df06 (before the descent's node
directions were cached and its batch of routes compiled, issue 27 deliverable 5): the
faster code must give the same bytes. Each case is a seeded map, a goal, a few hundred
starts (some of them failing) and the keyword arguments of ``plan_many``; every route is
digested from its path, ``w``, length, clearance and altitude profile, every failure from
its reason and message. Rewritten once since, by the update's quadratic solved in
``T - tau`` instead of ``T`` (session 41, ``_kernels._combine``): the same routes failed,
the others' points moved by at most 2.0e-9 m and their lengths by at most 7.7e-12 relative
(2d_city_order2_walls).

Regenerate only when a change of the numbers is intended, and say so in the commit::

    PYTHONPATH=src python -m tests.planning.golden_many --write
"""

from __future__ import annotations

import hashlib
import sys
from pathlib import Path
from typing import Any

import numpy as np

from fm2uav import FlightLevel, PlanOptions, Shaping, World
from fm2uav.planning.many import RouteFailure, plan_many

from benchmarks.bench_routes import city_map

from . import golden_plans
from .golden_plans import _obstacles_3d, _terrain

DATA = Path(__file__).resolve().parent / "data" / "golden_many.json"


def _starts(world: World, count: int, seed: int) -> np.ndarray:
    """``count`` uniform points in the map's bounds [m] (some in obstacles: failures)."""
    rng = np.random.default_rng(seed)
    return rng.uniform(world.bounds[:, 0], world.bounds[:, 1], (count, world.ndim))


def cases() -> dict[str, tuple[World, tuple[float, ...], np.ndarray, dict[str, Any]]]:
    """Name -> ``(world, goal [m], starts [m], plan_many keyword arguments)``."""
    city, w3, wt = city_map(160, seed=5), _obstacles_3d(), _terrain()
    goal_t = (28 * 15.0, 22 * 15.0, 17 * 15.0)
    st = _starts(wt, 60, 3)
    st[:, 2] = goal_t[2]
    return {
        "2d_city": (city, (161.0, 159.0), _starts(city, 300, 1),
                    {"shaping": Shaping(exponent=0.5)}),
        "2d_city_order2_walls": (city, (159.0, 161.0), _starts(city, 120, 2),
                                 {"shaping": Shaping(walls=True, exponent=1.5),
                                  "options": PlanOptions(order=2)}),
        "3d_obstacles": (w3, (240.0, 200.0, 30.0), _starts(w3, 120, 4), {}),
        "3d_terrain_level": (wt, goal_t, st, {"level": FlightLevel(agl=60.0)}),
    }


def _route_digest(r: Any) -> str:
    h = hashlib.sha256()
    if isinstance(r, RouteFailure):
        h.update(f"{r.reason}\n{r.message}".encode())
        return "fail:" + h.hexdigest()
    arrays = [r.path, r.w]
    if r.profile is not None:
        p = r.profile
        arrays += [p.path, p.s, p.surface, p.required, p.phase.astype(str).astype("U16")]
        h.update(repr((p.vertical_start_m, p.vertical_goal_m, p.climb_out_m, p.descent_m,
                       p.lifted_m)).encode())
    for a in arrays:
        a = np.ascontiguousarray(a)
        h.update(f"{a.dtype.str}{a.shape}".encode() + a.tobytes())
    h.update(repr((float(r.length), float(r.clearance))).encode())
    return h.hexdigest()


def run(name: str, **extra: Any) -> list[str]:
    """The digest of every route of case ``name`` planned now (``extra``: more keywords)."""
    world, goal, starts, kw = cases()[name]
    world._cache.clear()
    many = plan_many(world, goal, starts, **{**kw, **extra})
    return [_route_digest(r) for r in many.routes]


def run_case(name: str, threads: int | None = None, step: float | None = None) -> list[str]:
    """:func:`run` with arguments a child Python can be given (tests/planning/golden_numpy.py):
    ``threads`` (``plan_many``'s), ``step`` another descent step [cells] (order 2)."""
    extra: dict[str, Any] = {}
    if threads is not None:
        extra["threads"] = threads
    if step is not None:
        extra["options"] = PlanOptions(step=step)
    return run(name, **extra)


def main(argv: list[str]) -> int:
    """Print the digests of every case, or (``--write``) write them."""
    return golden_plans.main(argv, cases, run, DATA, "tests.planning.golden_many:run")


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
