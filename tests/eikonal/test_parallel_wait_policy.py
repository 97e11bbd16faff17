"""How the parallel march sets up numba's thread pool: OpenMP first among the threading
layers, sleep after a brief spin, the user's settings kept (``fm2uav.eikonal._parallel``, its spin count in ``_tuning``, issue 27)."""

from __future__ import annotations

import json
import os
import subprocess
import sys

import pytest

from fm2uav.eikonal import _tuning

_KEYS = ("OMP_WAIT_POLICY", "GOMP_SPINCOUNT")
_PROBE = ("import json, os, fm2uav.eikonal; "
          f"print(json.dumps({{k: os.environ.get(k) for k in {_KEYS!r}}}))")


def _after_import(**given: str) -> dict:
    """The two variables as a fresh process has them after ``import fm2uav.eikonal``."""
    env = {k: v for k, v in os.environ.items() if k not in _KEYS}
    env.update(given)
    out = subprocess.run([sys.executable, "-c", _PROBE], env=env, capture_output=True,
                         text=True, check=True, timeout=120)
    return json.loads(out.stdout.strip().splitlines()[-1])


@pytest.mark.parametrize(
    ("given", "expected"),
    [
        # nothing set: sleep at the barriers after a brief spin
        ({}, {"OMP_WAIT_POLICY": "PASSIVE", "GOMP_SPINCOUNT": str(_tuning.SPIN_COUNT)}),
        # the user's policy stays, with libgomp's own spin count for it
        ({"OMP_WAIT_POLICY": "ACTIVE"}, {"OMP_WAIT_POLICY": "ACTIVE", "GOMP_SPINCOUNT": None}),
        ({"OMP_WAIT_POLICY": "PASSIVE"},
         {"OMP_WAIT_POLICY": "PASSIVE", "GOMP_SPINCOUNT": None}),
        # the user's spin count stays
        ({"GOMP_SPINCOUNT": "0"}, {"OMP_WAIT_POLICY": "PASSIVE", "GOMP_SPINCOUNT": "0"}),
    ],
)
def test_wait_policy_defaults_and_the_users_settings(given, expected):
    assert _after_import(**given) == expected


def test_spin_count_is_brief():
    """libgomp spins ~100,000 times a millisecond (its own estimate): the spin stays well
    under a millisecond, short against a busy machine's time slice."""
    assert 0 < _tuning.SPIN_COUNT <= 20_000


_LAYER_PROBE = ("import numba, numpy as np; from fm2uav import fast_marching; "
                "fast_marching(np.ones((1024, 1024)), [(0, 0)], order=1, threads=2); "
                "print(numba.threading_layer())")


def _layer(**given: str) -> str:
    """The threading layer a fresh process's parallel march ran on (1024^2: on the slabs)."""
    keys = ("NUMBA_THREADING_LAYER", "NUMBA_THREADING_LAYER_PRIORITY", "FM2UAV_THREADS")
    env = {k: v for k, v in os.environ.items() if k not in keys}
    env.update(given)
    out = subprocess.run([sys.executable, "-c", _LAYER_PROBE], env=env, capture_output=True,
                         text=True, check=True, timeout=300)
    return out.stdout.strip().splitlines()[-1]


def test_the_march_runs_on_openmp_first_whatever_else_the_machine_has():
    # numba's own order puts TBB first: with a system libtbb (OpenCV, VTK pull it in) the
    # march's second thread joined each window's region ~130 us late
    pytest.importorskip("numba.np.ufunc.omppool", reason="numba's OpenMP layer not built here")
    assert _layer() == "omp"


def test_the_users_threading_layer_is_kept():
    assert _layer(NUMBA_THREADING_LAYER="workqueue") == "workqueue"
