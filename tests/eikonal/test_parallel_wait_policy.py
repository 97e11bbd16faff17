"""How the parallel march sets up numba's OpenMP pool: sleep after a brief spin, the user's
settings kept (``fm2uav.eikonal._parallel``, its spin count in ``_tuning``, issue 27)."""

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
