"""The compile notice and the two-process warm-up of a first plan (``cli._first_use``)."""

from __future__ import annotations

from pathlib import Path

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


def test_run_checks_the_cache_once_its_mission_file_is_valid(monkeypatch, tmp_path):
    # `fm2uav run`: the notice (and its cache check) comes after the mission file is read
    import typer
    from typer.testing import CliRunner

    from fm2uav.cli import app

    calls = []

    def spy(**kwargs):
        calls.append(kwargs)
        raise typer.Exit(0)  # the plan itself is not this test's

    monkeypatch.setattr(_first_use, "announce_compile", spy)
    bad = tmp_path / "bad.yaml"
    bad.write_text("world:\n  scenario: city\nplanner:\n  alpha: -3\n", encoding="utf-8")
    res = CliRunner().invoke(app, ["run", str(bad), "--out", str(tmp_path / "a")])
    assert res.exit_code == 2 and "planner.alpha" in " ".join(res.output.split())
    assert calls == []
    example = Path(__file__).resolve().parents[2] / "examples" / "open_field_tff.yaml"
    res = CliRunner().invoke(app, ["run", str(example), "--quiet",
                                   "--out", str(tmp_path / "b")])
    assert res.exit_code == 0, res.output
    assert calls == [{"quiet": True}]
    assert not (tmp_path / "a").exists()


def test_a_mission_file_error_on_a_cold_cache_prints_no_compile_notice(tmp_path):
    import os
    import subprocess
    import sys

    bad = tmp_path / "bad.yaml"
    bad.write_text("world:\n  scenario: city\nplanner:\n  alpha: -3\n", encoding="utf-8")
    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path / "cold")}
    res = subprocess.run([sys.executable, "-m", "fm2uav", "run", str(bad)], env=env,
                         capture_output=True, text=True, timeout=120, cwd=tmp_path)
    assert res.returncode == 2
    assert "planner.alpha" in res.stderr and "Traceback" not in res.stderr
    assert "compiling kernels" not in res.stderr
    # the cache is cold for that process indeed (the check above can fail)
    res = subprocess.run([sys.executable, "-c", "from fm2uav import _jit; "
                          "print(_jit.likely_cold())"], env=env, capture_output=True,
                         text=True, timeout=120)
    assert res.stdout.split() == ["True"], res.stderr


def test_routes_checks_and_warms_the_batch_descent_too(monkeypatch, tmp_path):
    """``fm2uav routes`` on a cache where only plan_many's kernels are missing: cold (the
    notice), and the child compiles the march's group and ``many`` (descend_sweep,
    min_box_clearances); a plain plan's check stays warm there."""
    from fm2uav.planning import warmup

    missing = {("planning/_geodesic_kernels.py", "descend_sweep")}
    monkeypatch.setattr(_jit, "_cached", lambda rel, func, version: (rel, func) not in missing)
    monkeypatch.setattr(_jit, "_fired", False)
    assert not _jit.likely_cold() and _jit.likely_cold(_jit.ROUTES_KERNELS)
    assert set(_jit.ROUTES_KERNELS) > set(_jit.FIRST_PLAN_KERNELS)
    for rel, func in set(_jit.ROUTES_KERNELS) - set(_jit.FIRST_PLAN_KERNELS):
        assert f"def {func}(" in (Path(_jit.__file__).parent / rel).read_text()  # real names
    spawned = []

    class Done:
        def wait(self, timeout=None):
            return 0

        def poll(self):
            return 0

    monkeypatch.setattr(_first_use, "_spawn", lambda groups: spawned.append(groups) or Done())
    monkeypatch.setattr(warmup, "warm", lambda groups: {})
    from typer.testing import CliRunner

    from fm2uav.cli import app

    base = ["routes", "--scenario", "city2d", "--goal=-3.7630,40.3334", "--quiet"]
    res = CliRunner().invoke(app, [*base, "--starts", str(tmp_path / "missing.csv")])
    assert res.exit_code == 2 and "missing.csv: no such file" in res.output
    assert spawned == []  # a wrong path answers before the cache check
    starts = tmp_path / "s.csv"
    starts.write_text("lon,lat\n-3.7620,40.3340\n")
    res = CliRunner().invoke(app, [*base, "--starts", str(starts), "--out", str(tmp_path / "o")])
    assert res.exit_code in (0, 1), res.output
    assert spawned == [["fmm2d_o2", "many"]]
    assert "many" in GROUPS
