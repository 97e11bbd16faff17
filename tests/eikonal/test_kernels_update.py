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


def _exact_root(taus, weights, q, digits=60):
    """The causal root of ``sum_m w_m (T - tau_m)^2 = q`` in ``digits``-digit decimals (the
    axes join in order of their times while the root is later than the next one, as the
    march's rule): the reference the double-precision update is measured against."""
    from decimal import Decimal, localcontext

    with localcontext() as ctx:
        ctx.prec = digits
        pairs = sorted((Decimal(t), Decimal(w)) for t, w in zip(taus, weights) if w > 0)
        qd = Decimal(q)
        t = pairs[0][0] + (qd / pairs[0][1]).sqrt()
        A = B = C = Decimal(0)
        for i, (tau, w) in enumerate(pairs):
            if i and t <= tau:
                break
            A, B, C = A + w, B + w * tau, C + w * tau * tau
            disc = B * B - A * (C - qd)
            if disc < 0:
                break
            t = (B + disc.sqrt()) / A
        return t


@pytest.mark.parametrize("big", [1e2, 1e3, 1e4])
def test_the_update_is_exact_to_a_few_ulps_at_late_times(big):
    """The time ``T`` of a late node (``big`` seconds) from upwind times a step apart: the
    quadratic solved in ``T - tau_1`` is within a few ulps of ``T`` of the exact root, two
    and three axes, equal and unequal spacings. Solved in ``T`` itself, its discriminant
    cancelled terms of size ``T^2`` (at ``T = 1e4 s`` the time was off by ~1e-8 s, a
    thousand times an ulp, and the parallel march's repairs differed from the serial march
    by 1.4e-11 relative on 2048^2)."""
    rng = np.random.default_rng(int(big))
    worst = 0.0
    for _ in range(300):
        q = rng.uniform(0.2, 4.0)
        weights = rng.uniform(0.3, 3.0, 3)
        taus = big + np.concatenate([[0.0], rng.uniform(0.0, 0.8, 2)]) * np.sqrt(q)
        exact = _exact_root(taus, weights, q)
        for w, three in ((weights, True), (np.array([weights[0], weights[1], 0.0]), False)):
            if three:
                got = _kernels._combine(taus[0], w[0], taus[1], w[1], taus[2], w[2], q)
            else:
                got = _kernels._combine(taus[0], w[0], taus[1], w[1], INF, 0.0, q)
                exact = _exact_root(taus[:2], w[:2], q)
            worst = max(worst, abs(float(got) - float(exact)) / math.ulp(float(exact)))
        iso = _kernels._solve_iso(*taus, q)
        worst = max(worst, abs(iso - float(_exact_root(taus, [1.0] * 3, q)))
                    / math.ulp(iso))
    assert worst <= 8.0, worst


def test_a_later_upwind_time_never_gives_an_earlier_time():
    """Monotone: raising an upwind time by ulps never lowers the update. The case that was
    not (2D, spacing 0.676 x 0.801 m, T ~ 150 s): the x-axis time 149.80818611051222 gave
    150.47676489791675, the lower 149.80818611050958 gave 150.4767648979181."""
    ihx, ihy = 1.0 / 0.6761986342678142 ** 2, 1.0 / 0.8010902444454241 ** 2
    ty = 149.6884469028306
    q = 1.0 / 0.7168584563212624 ** 2
    lo = _kernels._combine(149.80818611050958, ihx, ty, ihy, INF, 0.0, q)
    hi = _kernels._combine(149.80818611051222, ihx, ty, ihy, INF, 0.0, q)
    assert hi >= lo
    rng = np.random.default_rng(5)
    for _ in range(200):
        big = 10.0 ** rng.uniform(1, 4)
        q = rng.uniform(0.2, 4.0)
        ta, tb = big, big + rng.uniform(0.0, 0.7) * math.sqrt(q)
        prev = -INF
        for k in range(40):  # ta raised ulp by ulp: the update never comes out lower
            t = _kernels._combine(ta, 1.3, tb, 0.8, INF, 0.0, q)
            assert t >= prev
            prev = t
            ta = math.nextafter(ta, INF)
