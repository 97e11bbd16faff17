"""plan() gives the bytes it gave before its stages went parallel (issue 27: W, T, the path,
every figure), and the same bytes on one thread and on two.

The digests in ``data/golden_plans.json`` were written by the code of commit dbf51f4
(``tests/planning/golden_plans.py``): 2D and 3D, obstacles and terrain, shaped, with walls,
the FMM distance, a flight level, orders 1 and 2.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

import fm2uav
from fm2uav import PlanOptions
from fm2uav.eikonal import _edt, _kernels

from .golden_plans import DATA, cases, digest, run

GOLDEN = json.loads(DATA.read_text())


def test_the_golden_file_pins_every_case():
    assert sorted(GOLDEN) == sorted(cases())
    for name, d in GOLDEN.items():  # digests of 64 hex digits, not placeholders
        assert all(len(d[k]) == 64 for k in ("W", "T", "path", "w", "speed_share")), name
        assert float(d["length"]) > 0 and d["summary"]["points"] > 2, name


@pytest.mark.parametrize("name", sorted(GOLDEN))
def test_plan_gives_the_golden_bytes(name):
    assert run(name) == GOLDEN[name]


@pytest.mark.parametrize("name", ["2d_obstacles", "2d_obstacles_walls", "3d_obstacles_shaped",
                                  "3d_terrain", "3d_terrain_level"])
@pytest.mark.parametrize("threads", [1, 2])
def test_parallel_distance_map_and_setup_give_the_golden_bytes(name, threads, monkeypatch):
    # the big-grid paths on a small world: the transform's lines and its division on
    # `threads`, the input scan on them (the lean padding changes V's dtype, below)
    monkeypatch.setattr(_edt, "EDT_PARALLEL_MIN_NODES", 0)
    monkeypatch.setattr(_kernels, "SETUP_PARALLEL_MIN_NODES", 0)
    _, _, _, kw = cases()[name]
    opts = kw.get("options", PlanOptions())
    opts = PlanOptions(order=opts.order, threads=threads)
    assert run(name, options=opts) == GOLDEN[name]


@pytest.mark.parametrize("name", ["2d_obstacles", "3d_obstacles", "3d_terrain"])
def test_the_lean_layout_pads_the_same_on_two_threads_as_on_one(name, monkeypatch):
    # the lean layout (float32 V, times a relative ~1e-8 from the float64 layout's) is a
    # big grid's; forced here, its padding on two threads gives what one thread gives
    monkeypatch.setattr(_kernels, "LEAN_NODES", 0)
    monkeypatch.setattr(_kernels, "SETUP_PARALLEL_MIN_NODES", 0)
    one = run(name, options=PlanOptions(threads=1))
    two = run(name, options=PlanOptions(threads=2))
    assert one == two
    assert one["W"] == GOLDEN[name]["W"]
    assert one["T"] != GOLDEN[name]["T"]  # the lean layout did run


def test_a_changed_plan_fails_the_comparison():
    # the comparison can fail: another exponent gives other bytes everywhere it can
    world, s, g, _ = cases()["2d_obstacles"]
    world._cache.clear()
    other = digest(fm2uav.plan(world, s, g, shaping=fm2uav.Shaping(exponent=1.0001)))
    mine = GOLDEN["2d_obstacles"]
    assert other["W"] != mine["W"] and other["T"] != mine["T"] and other["path"] != mine["path"]
    assert np.float64(other["length"]) != np.float64(mine["length"])
