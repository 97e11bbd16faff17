"""Fast Marching against analytic travel times: tolerance ∝ spacing, convergence rates.

All bounds below are in units of the grid spacing ``h`` (or ``h / v`` in time)
and come from measurements on these exact grids, given in the comments with the
margin added. Measured numbers (this discretisation, point source at a node,
straight-ray ball of radius 2h):

* First order converges like ``h log(1/h)`` for a point source (the error made
  in the high-curvature region near the source is carried outward), so the
  observed rate on [0, 1]^2 with n = 41..321 is 0.69 (L1) / 0.73 (max) and
  creeps towards 1 as h shrinks.
* Second order converges at rate ~1, not 2: the straight-ray ball has a radius
  that shrinks with h (2h), and the band values of the ball may still be
  lowered by the march, so the O(h) error made a few cells from the source
  (where the front curvature is ~1/h) is never removed. Freezing a ball of
  fixed physical radius gives rate ~2.05 (checked by hand, not part of the
  solver). ``test_order2_is_second_order_away_from_source`` records this as a
  strict xfail.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import skfmm
from fmm_checks import distance_from, error_norms, loglog_slope, node_coords

from fm2uav.eikonal import fast_marching

NEAR_SOURCE = 0.1  # [m] error norms on the unit domain exclude r < 0.1


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
        # max |T - r/v| over every node, in units of h/v. Measured: 2D 41^2: 0.89 (order 1),
        # 0.28 (order 2); 3D 21^3: 1.21, 0.26. The first-order error grows like log(n),
        # so the bound holds for these grid sizes only; bounds add ~25% margin.
        (2, 41, 1, 1.1),
        (2, 41, 2, 0.35),
        (3, 21, 1, 1.5),
        (3, 21, 2, 0.35),
    ],
)
def test_constant_speed_error_proportional_to_spacing(ndim, n, order, bound, h, v):
    # The scheme is scale-invariant: for a fixed number of cells, the error in
    # seconds is exactly proportional to h / v. Checking three (h, v) pairs
    # verifies that spacing and speed enter in the right units.
    shape = (n,) * ndim
    src = (n // 2,) * ndim
    T = fast_marching(np.full(shape, v), [src], spacing=h, order=order)
    exact = distance_from(shape, (h,) * ndim, src) / v  # [s]
    err = np.abs(T - exact)
    assert err.max() <= bound * h / v
    # the ball: nodes within 2h of the source hold the exact straight-ray time
    ball = exact * v <= 2 * h
    if order == 1:  # the first-order stencil never undercuts the ball values
        np.testing.assert_allclose(T[ball], exact[ball], rtol=1e-12, atol=0)


# ------------------------------------------------------------- convergence rates
RATE_CASES = {
    # ndim: node counts per axis on [0, 1]^ndim (spacing halves each step)
    2: (41, 81, 161, 321),
    3: (21, 41, 81),
}


def _rates(ndim: int, order: int) -> tuple[float, float, list[float], list[float]]:
    hs, emax, el1 = [], [], []
    for n in RATE_CASES[ndim]:
        h, T, r = _unit_domain_point_source(n, ndim, order)
        mx, l1 = error_norms(T, r, r >= NEAR_SOURCE)
        hs.append(h)
        emax.append(mx)
        el1.append(l1)
    return loglog_slope(hs, emax), loglog_slope(hs, el1), emax, el1


@pytest.mark.parametrize(
    "ndim, order, min_rate_max, min_rate_l1",
    [
        # least-squares log-log slopes, measured: 2D order 1: max 0.73, L1 0.69;
        # 2D order 2: 0.97, 0.92; 3D order 1: 0.66, 0.61; 3D order 2: 0.91, 0.71.
        # Bounds are the measured slopes minus ~0.1.
        (2, 1, 0.62, 0.6),
        (2, 2, 0.87, 0.82),
        (3, 1, 0.55, 0.5),
        (3, 2, 0.8, 0.6),
    ],
)
def test_point_source_convergence_rate(ndim, order, min_rate_max, min_rate_l1):
    rate_max, rate_l1, emax, el1 = _rates(ndim, order)
    assert rate_max >= min_rate_max
    assert rate_l1 >= min_rate_l1
    # errors shrink at every refinement, not only on average
    assert all(b < a for a, b in zip(emax, emax[1:]))
    assert all(b < a for a, b in zip(el1, el1[1:]))


@pytest.mark.parametrize("ndim", [2, 3])
def test_order2_more_accurate_than_order1(ndim):
    # Measured L1 ratios order1/order2: 2D 3.4 .. 5.5 (n = 41 .. 321), 3D 11 .. 13.
    # The gap widens with n because order 1 carries an extra log(1/h) factor.
    *_, el1_1 = _rates(ndim, 1)
    *_, el1_2 = _rates(ndim, 2)
    ratios = [a / b for a, b in zip(el1_1, el1_2)]
    assert min(ratios) >= 3.0
    assert ratios[-1] > ratios[0]


@pytest.mark.xfail(
    strict=True,
    reason="order 2 converges at rate ~1: the straight-ray ball has radius 2h (shrinks "
    "with h) and its band values may be lowered by the march. Passes once the source "
    "initialisation keeps a fixed physical radius (measured rate ~2.05 when frozen).",
)
def test_order2_is_second_order_away_from_source():
    rate_max, rate_l1, *_ = _rates(2, 2)
    assert rate_l1 >= 1.5


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
        # Measured: 2D 81^2: 0.77 (order 1), 0.144 (order 2); 3D 41^3: 0.97, 0.137.
        (2, 81, 1, 1.0),
        (2, 81, 2, 0.2),
        (3, 41, 1, 1.25),
        (3, 41, 2, 0.2),
    ],
)
def test_linear_gradient_matches_analytic(ndim, n, order, bound):
    h, T, exact, r, swapped = _gradient_case(n, ndim, order)
    far = r >= NEAR_SOURCE
    mx, _ = error_norms(T, exact, far)
    assert mx <= bound * h
    # the test can fail: z is the last axis; the same gradient along x differs a lot
    assert np.abs(swapped - exact)[far].max() > 5 * bound * h


@pytest.mark.parametrize("order", [1, 2])
def test_linear_gradient_converges(order):
    # Same error behaviour as constant speed (measured L1 slopes 2D n = 41..321:
    # 0.72 order 1, 0.91 order 2); bounds ~0.1 below.
    hs, el1 = [], []
    for n in (41, 81, 161, 321):
        h, T, exact, r, _ = _gradient_case(n, 2, order)
        hs.append(h)
        el1.append(error_norms(T, exact, r >= NEAR_SOURCE)[1])
    assert loglog_slope(hs, el1) >= (0.63 if order == 1 else 0.8)


# --------------------------------------------------------------- anisotropic spacing
@pytest.mark.parametrize(
    "shape, spacing, order, bound",
    [
        # 40 m x 40 m with (1.0, 0.5) m cells; 24 m cube with (2, 1, 0.5) m cells.
        # max |T - r| over every node in units of max(h); measured 0.67 / 0.20 (2D),
        # 0.56 / 0.19 (3D) for order 1 / 2.
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
        # source, so the first-order h log(1/h) error appears twice: measured at P
        # 2.74 h (order 1), 1.05 h (order 2); behind the wall (x >= 0.6) at most
        # 2.97 h and 1.19 h. Bounds: 3.5 h and 1.5 h.
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
        # 2D n=161: order 1 0.91, 0.90; order 2 1.17, 0.96.
        # 3D n=41:  order 1 0.87, 0.84; order 2 0.46, 0.19.
        # "At least as accurate" (ratio <= 1) holds everywhere except the 2D
        # second-order max norm, where skfmm is 17% better; that one is bounded
        # at 1.25 so it cannot silently degrade further.
        (2, 161, 1, 1.0, 1.0),
        (2, 161, 2, 1.25, 1.0),
        (3, 41, 1, 1.0, 1.0),
        (3, 41, 2, 1.0, 1.0),
    ],
)
def test_accuracy_vs_skfmm(ndim, n, order, max_ratio, l1_ratio):
    # skfmm has no point sources: it marches from the zero level set of phi. The
    # closest equivalent is a circle (sphere) of radius r0 = h/2 around the source
    # node: phi = r - r0 is the exact signed distance, phi < 0 only at the source
    # node, and skfmm's travel time approximates r - r0. (With a larger r0 = 2h
    # skfmm receives exact data over a ring of nodes and is more accurate than ours:
    # ratios ~1.04 for order 1 and ~1.8 for 2D order 2.)
    h, T, r = _unit_domain_point_source(n, ndim, order)
    r0 = 0.5 * h
    T_sk = np.asarray(skfmm.travel_time(r - r0, np.ones_like(r), dx=h, order=order))
    far = r >= NEAR_SOURCE
    ours_max, ours_l1 = error_norms(T, r, far)
    sk_max, sk_l1 = error_norms(T_sk, r - r0, far)
    assert ours_max <= max_ratio * sk_max
    assert ours_l1 <= l1_ratio * sk_l1
