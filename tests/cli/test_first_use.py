"""The compile notice and the two-process warm-up of a first plan (``cli._first_use``)."""

from __future__ import annotations

from fm2uav import _jit
from fm2uav.cli import _first_use
from fm2uav.planning.warmup import GROUPS


def test_the_child_warms_the_march_the_plan_will_use():
    assert _first_use.fmm_group(order=2, ndim=3) == "fmm3d_o2"
    assert _first_use.fmm_group(order="1", ndim=2) == "fmm2d_o1"
    assert _first_use.fmm_group(order=5, ndim=3) == "fmm3d_o2"  # refused later, by the plan
    for order in (1, 2):
        for ndim in (2, 3):
            assert _first_use.fmm_group(order=order, ndim=ndim) in GROUPS


def test_a_warm_cache_says_nothing_and_starts_nothing(monkeypatch, capsys):
    monkeypatch.setattr(_jit, "likely_cold", lambda *a, **k: False)
    monkeypatch.setattr(_first_use, "_spawn", lambda groups: (_ for _ in ()).throw(
        AssertionError("no warm-up child on a warm cache")))
    assert _first_use.announce_compile(quiet=False, child_group="fmm3d_o2") is False
    assert capsys.readouterr().err == ""


def test_a_cold_cache_says_so_once(monkeypatch, capsys):
    monkeypatch.setattr(_jit, "likely_cold", lambda *a, **k: True)
    monkeypatch.setattr(_jit, "_fired", False)
    assert _first_use.announce_compile(quiet=False) is True
    assert _first_use.announce_compile(quiet=False) is True  # said already: not again
    err = capsys.readouterr().err
    assert err.count("compiling kernels, first use only") == 1
    assert _jit.announced()
