"""Fast Marching against analytic travel times: tolerance ∝ spacing, convergence rates.

All bounds below are in units of the grid spacing ``h`` (or ``h / v`` in time)
and come from measurements on these exact grids, given in the comments with the
margin added. Measured numbers (this discretisation, point source at a node,
frozen ball of radius ``R = max(2 h, 0.05 * extent)``, i.e. ``R = 0.05 m`` on
the unit domain once ``2 h <= 0.05``, n >= 41; exact straight-ray times at
constant speed, the factored equation where the speed varies, see
``test_sources.py`` for varying media):

* First order converges at rate ~1 on [0, 1]^2 with n = 41..321 (least-squares
  slope 0.98 max / 1.01 L1, every refinement 0.97..1.02). In 3D (n = 41..161)
  0.97 / 0.99.
* Second order converges at rate ~2 in 2D: slope 2.08 (max) / 2.02 (L1),
  refinement rates 1.95, 2.21, 2.04 (max); max error 9.6e-5 s at n = 321.
  The ball of fixed physical size, frozen, removes the O(h) error of the
  source singularity that a ball of a fixed number of cells (2 h) left (rate ~1
  before). In 3D the ball is still only 2 cells wide at n = 41 (R = 2 h), so
  41 -> 81 is pre-asymptotic (1.72 max / 0.84 L1); 81 -> 161 gives 2.06 / 1.85
  (and 161 -> 241, measured once outside the suite, 2.01 / 1.98).

A source keeps its ball only where the speed in its box varies by at most
``BALL_MAX_SPEED_RATIO = 1.5`` (max/min). Every source here passes: constant
speed, and the linear gradient varies by 2.1 / 1.9 = 1.105x within R = 0.05 m of
z = 0.5 (n >= 41). Re-measured after that rule came in: every field in this
module is bit-identical to the one without it (fmm.BALL_MAX_SPEED_RATIO set to
inf), so none of the numbers below moved.
"""

from __future__ import annotations

import functools
import math

import numpy as np
import pytest
import skfmm
from .fmm_checks import distance_from, error_norms, loglog_slope, node_coords

from fm2uav.eikonal import fast_marching
from fm2uav.eikonal.fmm import SOURCE_INIT_CELLS, SOURCE_INIT_FRACTION

NEAR_SOURCE = 0.1  # [m] error norms on the unit domain exclude r < 0.1


def _ball_radius(shape, spacing) -> float:
    """Straight-ray ball radius [m] of a single source on this grid."""
    extent = max((n - 1) * h for n, h in zip(shape, spacing))
    return max(SOURCE_INIT_CELLS * max(spacing), SOURCE_INIT_FRACTION * extent)


def _unit_domain_point_source(n: int, ndim: int, order: int):
    """Constant speed 1 m/s on [0, 1]^ndim with n nodes per axis, source at the centre.

    Returns ``(h, T, r)``: spacing [m], arrival time [s], exact distance [m].
    """
    h = 1.0 / (n - 1)
    shape = (n,) * ndim
    src = (n // 2,) * ndim
    T = fast_marching(np.ones(shape), [src], spacing=h, order=order)
    return h, T, distance_from(shape, (h,) * ndim, src)


# ------------------------------------------------- constant speed: error ∝ spacing
@pytest.mark.parametrize("h, v", [(1.0, 1.0), (0.05, 1.0), (15.0, 3.0)])
@pytest.mark.parametrize(
    "ndim, n, order, bound",
    [
        # max |T - r/v| over every node, in units of h/v. Measured: 2D 41^2: 0.891 (order 1),
        # 0.282 (order 2); 3D 21^3: 1.207, 0.259 (here R = 2 h, as before the 5 % rule,
        # and the numbers did not change). The first-order error grows like log(n),
        # so the bound holds for these grid sizes only; bounds add ~25% margin.
        (2, 41, 1, 1.1),
        (2, 41, 2, 0.35),
        (3, 21, 1, 1.5),
        (3, 21, 2, 0.35),
    ],
)
def test_constant_speed_error_proportional_to_spacing(ndim, n, order, bound, h, v):
    # The scheme is scale-invariant: for a fixed number of cells, the error in
    # seconds is exactly proportional to h / v (the ball radius is a multiple of
    # h or of the extent, both ∝ h). Checking three (h, v) pairs verifies that
    # spacing and speed enter in the right units.
    shape = (n,) * ndim
    src = (n // 2,) * ndim
    T = fast_marching(np.full(shape, v), [src], spacing=h, order=order)
    exact = distance_from(shape, (h,) * ndim, src) / v  # [s]
    err = np.abs(T - exact)
    assert err.max() <= bound * h / v
    # the ball is frozen (the only source is clean): its nodes keep the exact
    # straight-ray time d / v, for both orders
    ball = exact * v <= _ball_radius(shape, (h,) * ndim)
    assert ball.sum() > 1
    np.testing.assert_allclose(T[ball], exact[ball], rtol=1e-12, atol=0)


# ------------------------------------------------------------- convergence rates
RATE_CASES = {
    # ndim: node counts per axis on [0, 1]^ndim (spacing halves each step). From
    # n = 41 on, R = 0.05 m is fixed. 3D 161^3 (4.2 M nodes) takes ~1.5 s per order.
    2: (41, 81, 161, 321),
    3: (41, 81, 161),
}


@functools.lru_cache(maxsize=None)
def _rates(ndim: int, order: int) -> tuple[float, float, list[float], list[float]]:
    """LSQ slopes (max, L1) and the error lists over ``RATE_CASES[ndim]`` (cached)."""
    hs, emax, el1 = [], [], []
    for n in RATE_CASES[ndim]:
        h, T, r = _unit_domain_point_source(n, ndim, order)
        mx, l1 = error_norms(T, r, r >= NEAR_SOURCE)
        hs.append(h)
        emax.append(mx)
        el1.append(l1)
    return loglog_slope(hs, emax), loglog_slope(hs, el1), emax, el1


def _last_rate(err: list[float]) -> float:
    """Rate of the finest refinement (the spacing halves)."""
    return math.log2(err[-2] / err[-1])


@pytest.mark.parametrize(
    "ndim, order, min_slope_max, min_slope_l1, min_last",
    [
        # Least-squares log-log slopes (max, L1) and rate of the finest refinement
        # (max, L1), measured:
        #   2D order 1: 0.98, 1.01; last 0.99, 1.00
        #   2D order 2: 2.08, 2.02; last 2.04, 2.10
        #   3D order 1: 0.97, 0.99; last 0.98, 0.99
        #   3D order 2: 1.89, 1.34; last 2.06, 1.85  (41 -> 81 pre-asymptotic, see top)
        # Slope bounds: measured minus ~0.1 (~0.15 for order 2). The last-refinement
        # bound is 0.85 for order 1 and 1.7 for order 2 in both norms (3D L1 1.85:
        # margin 0.15).
        (2, 1, 0.88, 0.9, 0.85),
        (2, 2, 1.9, 1.85, 1.7),
        (3, 1, 0.85, 0.88, 0.85),
        (3, 2, 1.75, 1.2, 1.7),
    ],
)
def test_point_source_convergence_rate(ndim, order, min_slope_max, min_slope_l1, min_last):
    rate_max, rate_l1, emax, el1 = _rates(ndim, order)
    assert rate_max >= min_slope_max
    assert rate_l1 >= min_slope_l1
    assert _last_rate(emax) >= min_last
    assert _last_rate(el1) >= min_last
    # errors shrink at every refinement, not only on average
    assert all(b < a for a, b in zip(emax, emax[1:]))
    assert all(b < a for a, b in zip(el1, el1[1:]))


def test_order2_is_second_order_away_from_source():
    # Formerly a strict xfail (rate ~1 with a 2h ball that the march could lower).
    # Measured on [0, 1]^2, n = 41..321: LSQ slope 2.08 (max) / 2.02 (L1); max
    # error 7.0e-3, 1.8e-3, 3.9e-4, 9.6e-5 s. In 3D the finest refinement
    # (81 -> 161) gives 2.06 / 1.85.
    rate_max, rate_l1, emax, _ = _rates(2, 2)
    assert rate_max >= 1.7
    assert rate_l1 >= 1.7
    assert emax[-1] <= 1.5e-4  # measured 9.6e-5 s at n = 321 (h = 3.1e-3 m)
    _, _, emax3, el13 = _rates(3, 2)
    assert _last_rate(emax3) >= 1.7
    assert _last_rate(el13) >= 1.7


@pytest.mark.parametrize(
    "ndim, min_ratio, min_last_growth",
    [
        # Measured L1 ratios order1/order2: 2D 3.39, 6.32, 12.9, 27.7 (n = 41..321),
        # 3D 11.7, 10.5, 19.0 (n = 41..161). The gap widens ~2x per halving of h
        # because the orders differ by one; the last refinement widens it 2.14x
        # (2D) and 1.82x (3D). Bounds: min ratio 3 (2D) / 8 (3D), growth >= 1.5.
        (2, 3.0, 1.5),
        (3, 8.0, 1.5),
    ],
)
def test_order2_more_accurate_than_order1(ndim, min_ratio, min_last_growth):
    *_, el1_1 = _rates(ndim, 1)
    *_, el1_2 = _rates(ndim, 2)
    ratios = [a / b for a, b in zip(el1_1, el1_2)]
    assert min(ratios) >= min_ratio
    assert ratios[-1] >= min_last_growth * ratios[-2]
    if ndim == 2:  # monotone widening (3D 41 -> 81 is pre-asymptotic for order 2)
        assert all(b > a for a, b in zip(ratios, ratios[1:]))


# ----------------------------------------------------- linear speed gradient in z
def _gradient_case(n: int, ndim: int, order: int, v0: float = 1.0, g: float = 2.0):
    """v = v0 + g z on [0, 1]^ndim (z = last axis), source at the centre.

    Exact time (constant velocity gradient, e.g. Slotnick 1959): t = arccosh(1 + g^2 r^2 / (2 v_s v)) / g.
    Returns ``(h, T, exact, r, swapped)`` with ``swapped`` the exact time for the
    gradient along the first axis instead: what a solver mixing up axes would match.
    """
    h = 1.0 / (n - 1)
    shape = (n,) * ndim
    coords = node_coords(shape, (h,) * ndim)
    speed = v0 + g * coords[-1]  # [m/s], 1 .. 3
    src = (n // 2,) * ndim
    vs = speed[src]
    r = distance_from(shape, (h,) * ndim, src)
    exact = np.arccosh(1.0 + g * g * r * r / (2.0 * vs * speed)) / g
    T = fast_marching(speed, [src], spacing=h, order=order)
    v_x = v0 + g * coords[0]
    swapped = np.arccosh(1.0 + g * g * r * r / (2.0 * vs * v_x)) / g
    return h, T, exact, r, swapped


@pytest.mark.parametrize(
    "ndim, n, order, bound",
    [
        # max |T - t| over r >= 0.1, in units of h (speeds are 1..3 m/s, so h/v_min = h).
        # Measured: 2D 81^2: 0.672 (order 1), 0.0710 (order 2); 3D 41^3: 0.967, 0.1405
        # (3D 41 has R = 2 h only). Bounds add ~25%.
        (2, 81, 1, 0.85),
        (2, 81, 2, 0.09),
        (3, 41, 1, 1.2),
        (3, 41, 2, 0.18),
    ],
)
def test_linear_gradient_matches_analytic(ndim, n, order, bound):
    h, T, exact, r, swapped = _gradient_case(n, ndim, order)
    far = r >= NEAR_SOURCE
    mx, _ = error_norms(T, exact, far)
    assert mx <= bound * h
    # the test can fail: z is the last axis; the same gradient along x differs a lot
    # (measured 15.7 h in 2D, 9.3 h in 3D)
    assert np.abs(swapped - exact)[far].max() > 5 * bound * h


@pytest.mark.parametrize("ndim, n", [(2, 81), (3, 41)])
def test_linear_gradient_source_keeps_its_frozen_ball(ndim, n):
    # Box of the source (n // 2 nodes, z = 0.5 m): z in 0.5 +- R, R = 0.05 m, so
    # speeds 1.9 .. 2.1 m/s, max/min = 1.105 <= 1.5: clean. The ball nodes hold
    # the factored-equation times (the speed varies), frozen before the march,
    # the same for both orders. Measured max error against the analytic time in
    # the ball: 2.60e-6 s (2D 81^2) and 2.81e-6 s (3D 41^3), against 1.13e-5 s
    # for the straight-ray time r (1/v_s + 1/v) / 2 used before.
    h = 1.0 / (n - 1)
    shape = (n,) * ndim
    speed = 1.0 + 2.0 * node_coords(shape, (h,) * ndim)[-1]
    src = (n // 2,) * ndim
    r = distance_from(shape, (h,) * ndim, src)
    ball = r <= _ball_radius(shape, (h,) * ndim)
    assert math.isclose(_ball_radius(shape, (h,) * ndim), 0.05, rel_tol=1e-12)
    box = np.abs(np.stack(node_coords(shape, (h,) * ndim)) - 0.5).max(axis=0) <= 0.05 + 1e-12
    assert speed[box].max() / speed[box].min() <= 1.106
    straight = r * 0.5 * (1.0 / speed[src] + 1.0 / speed)
    # nodes frozen by the initialisation: stopping at the source marches nothing
    init = fast_marching(speed, [src], spacing=h, stop_at=[src])
    assert np.all(np.isfinite(init[ball]))
    exact = None
    for order in (1, 2):
        _, T, exact, *_ = _gradient_case(n, ndim, order)
        np.testing.assert_allclose(T[ball], init[ball], rtol=1e-12, atol=0)
    err = np.abs(init - exact)[ball].max()
    assert err <= 3.5e-6  # measured 2.60e-6 (2D) / 2.81e-6 (3D) s
    assert err < 0.3 * np.abs(straight - exact)[ball].max()  # measured 1.13e-5 s


@pytest.mark.parametrize(
    "order, min_slope",
    [
        # LSQ slopes over 2D n = 41..321, measured: order 1 L1 1.01 / max 0.99;
        # order 2 L1 2.02 / max 2.09 (refinement rates, max: 1.98, 2.21, 2.04;
        # max error 3.5e-3 .. 4.7e-5 s). The frozen ball holds the factored
        # equation's times (second order, ball error 2.6e-6 s), so the variable
        # speed does not cost the rate; the exact analytic time frozen in the ball
        # gives the same errors to 3 digits at n = 321. (The straight-ray ball used
        # before gave 2.11 / 2.16: its own error partly cancelled the march's.)
        (1, 0.88),
        (2, 1.8),
    ],
)
def test_linear_gradient_converges(order, min_slope):
    hs, emax, el1 = [], [], []
    for n in (41, 81, 161, 321):
        h, T, exact, r, _ = _gradient_case(n, 2, order)
        mx, l1 = error_norms(T, exact, r >= NEAR_SOURCE)
        hs.append(h)
        emax.append(mx)
        el1.append(l1)
    assert loglog_slope(hs, el1) >= min_slope
    assert loglog_slope(hs, emax) >= min_slope


# --------------------------------------------------------------- anisotropic spacing
@pytest.mark.parametrize(
    "shape, spacing, order, bound",
    [
        # 40 m x 40 m with (1.0, 0.5) m cells; 24 m cube with (2, 1, 0.5) m cells.
        # max |T - r| over every node in units of max(h); measured 0.671 / 0.202 (2D),
        # 0.557 / 0.193 (3D) for order 1 / 2 (R = 2 max(h) on both grids). Bounds
        # add 25-40%.
        ((41, 81), (1.0, 0.5), 1, 0.85),
        ((41, 81), (1.0, 0.5), 2, 0.27),
        ((13, 25, 49), (2.0, 1.0, 0.5), 1, 0.75),
        ((13, 25, 49), (2.0, 1.0, 0.5), 2, 0.27),
    ],
)
def test_anisotropic_spacing_vs_exact_distance(shape, spacing, order, bound):
    src = tuple(n // 2 for n in shape)
    T = fast_marching(np.ones(shape), [src], spacing=spacing, order=order)
    r = distance_from(shape, spacing, src)
    assert np.abs(T - r).max() <= bound * max(spacing)
    # the test can fail: swapping the spacing of two axes moves the nodes far away
    wrong = distance_from(shape, spacing[::-1], src)
    assert np.abs(wrong - r).max() > 10 * bound * max(spacing)


# ------------------------------------------------------------------ wall with a gap
@pytest.mark.parametrize(
    "order, bound",
    [
        # Error in units of h at n = 81 (h = 1/80 m). The gap acts as a second point
        # source without a ball, so its singularity error is carried behind the wall:
        # measured at P 2.60 h (order 1), 1.13 h (order 2); behind the wall
        # (x >= 0.6) at most 2.83 h and 1.28 h. Bounds: 3.5 h (+24%) and 1.5 h (+17%).
        (1, 3.5),
        (2, 1.5),
    ],
)
def test_wall_with_single_gap_detour(order, bound):
    # Unit square, wall of speed 0 along x = 0.5 with one free node at y = 0.8.
    # S = (0.25, 0.2), P = (0.75, 0.2): the shortest path bends through the gap G,
    # length |S - G| + |G - P| = 2 * hypot(0.25, 0.6) = 1.3 m (vs 0.5 m straight).
    n = 81
    h = 1.0 / (n - 1)
    speed = np.ones((n, n))
    iw, ig = n // 2, round(0.8 * (n - 1))
    speed[iw, :] = 0.0
    speed[iw, ig] = 1.0
    S = (round(0.25 * (n - 1)), round(0.2 * (n - 1)))
    P = (round(0.75 * (n - 1)), round(0.2 * (n - 1)))
    T = fast_marching(speed, [S], spacing=h, order=order)

    gap = np.array([iw, ig]) * h
    x, y = node_coords((n, n), (h, h))
    behind = np.linalg.norm(np.array(S) * h - gap) + np.hypot(x - gap[0], y - gap[1])
    exact_P = behind[P]
    assert math.isclose(exact_P, 1.3, rel_tol=1e-12)
    assert abs(T[P] - exact_P) <= bound * h
    region = x >= 0.6  # every node there sees the gap in a straight line
    assert np.abs(T - behind)[region].max() <= bound * h
    # a wave leaking through the wall would arrive ~0.8 m early
    assert T[P] > 0.5 + 50 * h
    assert np.all(np.isinf(T[speed == 0]))


# ------------------------------------------------------- accuracy vs scikit-fmm
@pytest.mark.parametrize(
    "ndim, n, order, max_ratio, l1_ratio",
    [
        # ours / skfmm error (max, L1) over r >= 0.1, measured:
        # 2D n=161: order 1 0.627, 0.558; order 2 0.249, 0.215.
        # 3D n=41:  order 1 0.870, 0.841; order 2 0.461, 0.194.
        # (Absolute, 2D n=161 order 2: ours max 3.9e-4 / L1 2.3e-4 s, skfmm 1.6e-3 /
        # 1.1e-3 s; at n=321 ours 9.6e-5 vs skfmm 7.5e-4, ratio 0.13.)
        # Bounds add ~25%, except 3D order 1, kept at "at least as accurate" (1.0,
        # margin 15-19%).
        (2, 161, 1, 0.8, 0.7),
        (2, 161, 2, 0.32, 0.28),
        (3, 41, 1, 1.0, 1.0),
        (3, 41, 2, 0.6, 0.25),
    ],
)
def test_accuracy_vs_skfmm(ndim, n, order, max_ratio, l1_ratio):
    # skfmm has no point sources: it marches from the zero level set of phi. The
    # closest equivalent is a circle (sphere) of radius r0 = h/2 around the source
    # node: phi = r - r0 is the exact signed distance, phi < 0 only at the source
    # node, and skfmm's travel time approximates r - r0. (With a larger r0 = 2h
    # skfmm receives exact data over a ring of nodes; measured ratios then: 2D
    # 0.71 / 0.65 (order 1), 0.38 / 0.41 (order 2); 3D n=41 1.02 / 1.05 and
    # 1.23 / 0.62, where our ball is only 2h wide.)
    h, T, r = _unit_domain_point_source(n, ndim, order)
    r0 = 0.5 * h
    T_sk = np.asarray(skfmm.travel_time(r - r0, np.ones_like(r), dx=h, order=order))
    far = r >= NEAR_SOURCE
    ours_max, ours_l1 = error_norms(T, r, far)
    sk_max, sk_l1 = error_norms(T_sk, r - r0, far)
    assert ours_max <= max_ratio * sk_max
    assert ours_l1 <= l1_ratio * sk_l1
