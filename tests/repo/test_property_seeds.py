"""Every property test is seeded: a hypothesis ``@given`` test runs with ``derandomize=True``
(``@settings(..., derandomize=True)``, the e2e ``@FUZZ`` settings) or a fixed ``@seed(N)``, so
a run is the same on every machine and a CI failure reproduces (brief: "everything random
takes a seed")."""

from __future__ import annotations

import importlib
import inspect
from pathlib import Path

from hypothesis import settings

ROOT = Path(__file__).resolve().parents[2]


def _modules_with_given() -> list[str]:
    names = []
    for f in sorted((ROOT / "tests").rglob("*.py")):
        if "given" in f.read_text(encoding="utf-8"):
            names.append(".".join(f.relative_to(ROOT).with_suffix("").parts))
    return names


def unseeded_property_tests() -> list[str]:
    """``module::test`` of every hypothesis test under tests/ that is not seeded."""
    bad = []
    for name in _modules_with_given():
        mod = importlib.import_module(name)
        for attr, obj in vars(mod).items():
            fn = obj
            if inspect.isclass(obj):  # test classes: their methods
                fns = [(f"{attr}.{k}", v) for k, v in vars(obj).items() if callable(v)]
            else:
                fns = [(attr, fn)]
            for label, f in fns:
                if not getattr(f, "is_hypothesis_test", False):
                    continue
                s = getattr(f, "_hypothesis_internal_use_settings", settings.default)
                if not (s.derandomize or getattr(f, "_hypothesis_internal_use_seed", None)
                        is not None):
                    bad.append(f"{name}::{label}")
    return bad


def test_every_property_test_is_seeded():
    assert len(_modules_with_given()) >= 5  # the scan finds the property tests
    bad = unseeded_property_tests()
    assert not bad, ("property tests without a fixed seed; add derandomize=True to their "
                     "@settings (or @seed(N)):\n" + "\n".join(bad))


def test_the_scan_sees_an_unseeded_test(tmp_path, monkeypatch):
    from hypothesis import given
    from hypothesis import strategies as st

    # derandomize=False said outright: under CI hypothesis loads its "ci" profile, whose
    # derandomize=True every unset @settings inherits (a scan run there sees no loose test)
    @settings(max_examples=2, derandomize=False)
    @given(st.integers())
    def test_loose(x):
        pass

    @settings(max_examples=2, derandomize=True)
    @given(st.integers())
    def test_tight(x):
        pass

    mod = type(importlib)("tests.fake_given")
    mod.test_loose, mod.test_tight = test_loose, test_tight
    monkeypatch.setitem(__import__("sys").modules, "tests.fake_given", mod)
    monkeypatch.setattr(__import__(__name__, fromlist=["x"]), "_modules_with_given",
                        lambda: ["tests.fake_given"])
    assert unseeded_property_tests() == ["tests.fake_given::test_loose"]
