"""The golden digests' elementary functions: numpy's float64 ``power``/``exp``/``log`` as its
baseline and AVX2 loops compute them (the C library's), not its AVX-512 loops.

``data/golden_plans.json`` and ``data/golden_many.json`` were written on machines without
AVX-512. Where the CPU has it, numpy dispatches float64 ``np.power``, ``np.exp`` and
``np.log`` to AVX-512 loops whose results differ from the C library's in the last bit for
~5 % of the arguments (measured on an AMD EPYC Zen 4, numpy 2.4: ``np.power(x, 1.5)``
differs from ``math.pow`` on 10,840 of 200,000 uniform x). The velocity map's exponent
(``W ** β`` with β ≠ 1) goes through ``np.power``, so a shaped plan's bytes are the
machine's, not the code's. The goldens pin the *code*: on such a machine each comparison
is computed in a child Python whose numpy has those loops switched off
(``NPY_DISABLE_CPU_FEATURES``, numpy's documented run-time switch), everything else
(numba's kernels, the thread count, the forced parallel paths) as in the test. Elsewhere
they run in this process, as before.

:func:`computed` gives one call's result; on an AVX-512 machine the first call of a test
module computes all of that module's calls (``wanted``) in one child.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path
from typing import Any, Callable

import numpy as np

ROOT = Path(__file__).resolve().parents[2]


def _umath():
    core = getattr(np, "_core", None) or np.core  # numpy 2 / numpy 1
    return core._multiarray_umath


def wide_features() -> list[str]:
    """numpy's dispatch targets above AVX2 that this CPU runs (empty: the goldens' loops)."""
    um = _umath()
    return [f for f in um.__cpu_dispatch__
            if (f.startswith("AVX512") or f == "X86_V4") and um.__cpu_features__.get(f)]


_CHILD = """
import importlib, json, sys
mod, fn = sys.argv[1].split(":")
func = getattr(importlib.import_module(mod), fn)
calls = json.loads(sys.stdin.read())
print(json.dumps([func(*args, **kw) for args, kw in calls]))
"""


def in_child(target: str, calls: list[tuple[tuple, dict]], disable: list[str]) -> list[Any]:
    """``module:function`` applied to each ``(args, kwargs)`` of ``calls`` (JSON values) in a
    child Python with numpy's ``disable`` features off; the results, JSON round-tripped."""
    env = {**os.environ, "NPY_DISABLE_CPU_FEATURES": " ".join(disable),
           "PYTHONPATH": os.pathsep.join([str(ROOT / "src"), str(ROOT),
                                          os.environ.get("PYTHONPATH", "")])}
    done = subprocess.run([sys.executable, "-c", _CHILD, target], input=json.dumps(calls),
                          capture_output=True, text=True, env=env, cwd=ROOT, timeout=900)
    assert done.returncode == 0, done.stderr[-3000:]
    return json.loads(done.stdout)


class Computed:
    """The results of ``func`` (a module-level function named ``target``) for the calls a
    test module asks for, computed as the goldens' numpy computes them (module docstring)."""

    def __init__(self, func: Callable, target: str, wanted: list[tuple[tuple, dict]]):
        self.func, self.target, self.wanted = func, target, wanted
        self._done: dict[str, Any] = {}

    @staticmethod
    def _key(args: tuple, kw: dict) -> str:
        return json.dumps([list(args), kw], sort_keys=True)

    def __call__(self, *args: Any, **kw: Any) -> Any:
        key = self._key(args, kw)
        if key not in self._done:
            disable = wide_features()
            if not disable:
                self._done[key] = json.loads(json.dumps(self.func(*args, **kw)))
            else:
                calls = [(a, k) for a, k in self.wanted if self._key(a, k) not in self._done]
                if key not in {self._key(a, k) for a, k in calls}:
                    calls.append((args, kw))
                for (a, k), r in zip(calls, in_child(self.target, calls, disable)):
                    self._done[self._key(a, k)] = r
        return self._done[key]


def power_exp_log_off_libm(n: int = 20000) -> int:
    """How many of ``n`` seeded uniform arguments numpy's float64 ``power`` (β = 1.5),
    ``exp`` and ``log`` give other bits than the C library's (``math``) for."""
    import math

    x = np.random.default_rng(0).random(n) + 1e-3
    return int(sum((f(x) != np.array([g(v) for v in x])).sum() for f, g in
                   [(lambda a: np.power(a, 1.5), lambda v: math.pow(v, 1.5)),
                    (np.exp, math.exp), (np.log, math.log)]))
