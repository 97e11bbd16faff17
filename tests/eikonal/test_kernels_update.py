"""The order-1 update on equal spacings (``_kernels._solve_iso``) against the general one.

The march uses ``_solve_iso`` where every axis has the same spacing and the order is 1
(one square root, no division); it must pick the same axes as ``_combine`` (an axis joins
while the solution is later than its time) and give the same time up to round-off.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from fm2uav.eikonal import _kernels

INF = math.inf


def _general(a, b, c, q):
    w = [1.0 if t < INF else 0.0 for t in (a, b, c)]
    return _kernels._combine(a, w[0], b, w[1], c, w[2], q)


@pytest.mark.parametrize("case", [
    (0.0, INF, INF, 1.0),          # one axis: 0 + 1
    (0.0, 0.0, INF, 1.0),          # two equal axes: 1/sqrt(2)
    (0.0, 0.0, 0.0, 1.0),          # three: 1/sqrt(3)
    (0.0, 1.0, INF, 1.0),          # (b - a)^2 = q: the one-axis solution, exactly at b
    (0.0, 0.9, 5.0, 1.0),          # two axes, the third too late
    (0.0, 0.1, 0.2, 4.0),          # three axes
    (2.0, 0.0, INF, 0.25),         # unsorted input
    (INF, INF, INF, 1.0),          # nothing upwind
])
def test_same_axes_and_time_as_the_general_update(case):
    a, b, c, q = case
    fast = _kernels._solve_iso(a, b, c, q)
    slow = _general(a, b, c, q)
    if slow == INF:
        assert fast == INF
    else:
        assert fast == pytest.approx(slow, rel=1e-14, abs=0.0)


def test_random_times_and_speeds():
    rng = np.random.default_rng(3)
    for _ in range(2000):
        taus = rng.uniform(0.0, 3.0, 3)
        taus[rng.random(3) < 0.2] = INF
        q = rng.uniform(0.01, 4.0)
        fast = _kernels._solve_iso(*taus, q)
        slow = _general(*taus, q)
        if slow == INF:
            assert fast == INF
        else:
            assert abs(fast - slow) <= 1e-12 * slow
            assert fast > min(taus)  # causal: later than its earliest upwind time
