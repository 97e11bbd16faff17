"""The goldens' numpy (tests/planning/golden_numpy.py): its float64 power, exp and log are the
C library's, on this machine's numpy directly or in the child with the AVX-512 loops off."""

from __future__ import annotations

from . import golden_numpy
from .golden_numpy import Computed, in_child, power_exp_log_off_libm, wide_features


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
