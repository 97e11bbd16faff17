"""plan() gives the bytes it gave before its stages went parallel (issue 27: W, T, the path,
every figure), and the same bytes on one thread and on two.

The digests in ``data/golden_plans.json`` were written by the code of commit dbf51f4
(``tests/planning/golden_plans.py``): 2D and 3D, obstacles and terrain, shaped, with walls,
the FMM distance, a flight level, orders 1 and 2. Where numpy runs AVX-512 loops the plans
are made in a child Python with them off (tests/planning/golden_numpy.py says why).
"""

from __future__ import annotations

import json

import pytest

from . import golden_numpy
from .golden_numpy import Computed, in_child, power_exp_log_off_libm, wide_features
from .golden_plans import DATA, cases, run_case

GOLDEN = json.loads(DATA.read_text())
PARALLEL = ["2d_obstacles", "2d_obstacles_walls", "3d_obstacles_shaped", "3d_terrain",
            "3d_terrain_level"]
LEAN = ["2d_obstacles", "3d_obstacles", "3d_terrain"]
#: every plan of this module, made in one child where numpy runs AVX-512 loops
RUN = Computed(run_case, "tests.planning.golden_plans:run_case",
               [((name,), {}) for name in sorted(GOLDEN)]
               + [((name,), {"threads": t, "force_parallel": True})
                  for name in PARALLEL for t in (1, 2)]
               + [((name,), {"threads": t, "lean": True}) for name in LEAN for t in (1, 2)]
               + [(("2d_obstacles",), {"exponent": 1.0001})])


def test_the_golden_file_pins_every_case():
    assert sorted(GOLDEN) == sorted(cases())
    for name, d in GOLDEN.items():  # digests of 64 hex digits, not placeholders
        assert all(len(d[k]) == 64 for k in ("W", "T", "path", "w", "speed_share")), name
        assert float(d["length"]) > 0 and d["summary"]["points"] > 2, name


@pytest.mark.parametrize("name", sorted(GOLDEN))
def test_plan_gives_the_golden_bytes(name):
    assert RUN(name) == GOLDEN[name]


@pytest.mark.parametrize("name", PARALLEL)
@pytest.mark.parametrize("threads", [1, 2])
def test_parallel_distance_map_and_setup_give_the_golden_bytes(name, threads):
    # the big-grid paths on a small world: the transform's lines and its division on
    # `threads`, the input scan on them (the lean padding changes V's dtype, below)
    assert RUN(name, threads=threads, force_parallel=True) == GOLDEN[name]


@pytest.mark.parametrize("name", LEAN)
def test_the_lean_layout_pads_the_same_on_two_threads_as_on_one(name):
    # the lean layout (float32 V, times a relative ~1e-8 from the float64 layout's) is a
    # big grid's; forced here, its padding on two threads gives what one thread gives
    one = RUN(name, threads=1, lean=True)
    two = RUN(name, threads=2, lean=True)
    assert one == two
    assert one["W"] == GOLDEN[name]["W"]
    assert one["T"] != GOLDEN[name]["T"]  # the lean layout did run


def test_a_changed_plan_fails_the_comparison():
    # the comparison can fail: another exponent gives other bytes everywhere it can
    other = RUN("2d_obstacles", exponent=1.0001)
    mine = GOLDEN["2d_obstacles"]
    assert other["W"] != mine["W"] and other["T"] != mine["T"] and other["path"] != mine["path"]
    assert float(other["length"]) != float(mine["length"])


# ------------------------------------------- the goldens' numpy (golden_numpy.py)
def test_the_goldens_numpy_computes_power_exp_and_log_as_the_c_library():
    disable = wide_features()
    if disable:  # this numpy's own loops differ (the reason for the child), the child's not
        assert power_exp_log_off_libm() > 0
        assert in_child("tests.planning.golden_numpy:power_exp_log_off_libm",
                        [((), {})], disable) == [0]
    else:
        assert power_exp_log_off_libm() == 0


def test_computed_runs_in_this_process_where_numpy_has_no_wide_loops(monkeypatch):
    seen = []

    def f(a, b=0):
        seen.append((a, b))
        return {"sum": a + b}

    monkeypatch.setattr(golden_numpy, "wide_features", lambda: [])
    run = Computed(f, "unused:unused", [((1,), {"b": 2})])
    assert run(1, b=2) == {"sum": 3} and run(1, b=2) == {"sum": 3} and run(4) == {"sum": 4}
    assert seen == [(1, 2), (4, 0)]  # each call once, the wanted list not run ahead


def test_computed_makes_a_modules_calls_in_one_child_elsewhere(monkeypatch):
    children = []

    def counted(target, calls, disable):
        children.append([a for a, _ in calls])
        return in_child(target, calls, disable)

    monkeypatch.setattr(golden_numpy, "wide_features", lambda: ["X86_V4", "AVX512_SKX"])
    monkeypatch.setattr(golden_numpy, "in_child", counted)
    run = Computed(power_exp_log_off_libm,
                   "tests.planning.golden_numpy:power_exp_log_off_libm",
                   [((300,), {}), ((200,), {})])
    assert run(200) == 0 and run(300) == 0 and children == [[(300,), (200,)]]
    assert run(100) == 0 and children == [[(300,), (200,)], [(100,)]]  # one not wanted: alone


def test_the_writer_computes_the_digests_as_the_comparison_does(monkeypatch, tmp_path):
    # golden_plans.main (--write) takes the child with numpy's wide loops off where this
    # CPU has them, as the comparison does, and this process elsewhere
    from . import golden_plans

    children = []

    def child(target, calls, disable):
        children.append((target, [a for a, _ in calls], disable))
        return [{"case": a[0], "where": "child"} for a, _ in calls]

    def here(name):
        return {"case": name, "where": "here"}

    two = lambda: {"a": None, "b": None}  # noqa: E731
    monkeypatch.setattr(golden_numpy, "in_child", child)
    data = tmp_path / "golden.json"
    for wide, where in ((["X86_V4"], "child"), ([], "here")):
        monkeypatch.setattr(golden_numpy, "wide_features", lambda wide=wide: wide)
        assert golden_plans.main(["--write"], two, here, data, "m:f") == 0
        assert json.loads(data.read_text()) == {n: {"case": n, "where": where} for n in "ab"}
    assert children == [("m:f", [("a",), ("b",)], ["X86_V4"])]
