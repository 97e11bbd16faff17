"""Exact values of the Fast Marching Method on tiny grids, and input validation.

The value tests run on both the compiled solver and the pure-Python reference
(``solver`` fixture), so the hand-written expectations check the reference too.
Expected fields are derived by hand in the comments; only float rounding
separates them from the solvers' output (``rtol = 1e-12``).

Reminder of the discretisation (see ``fm2uav.eikonal._reference``): the source
is frozen at 0; if the box of half-width ``R = 2 max(h)`` around it holds no
speed-0 node, nodes with ``d <= R`` start in the band at
``d * (1/v_s + 1/v) / 2``; the march may lower them. First-order update along
one axis: ``T1 + h / v``; two axes with equal spacing: the root of
``(T - T1)^2 + (T - T2)^2 = (h / v)^2``.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from fmm_checks import SOLVERS, assert_same_field

from fm2uav.errors import Fm2uavError, InputError
from fm2uav.eikonal import fast_marching

RTOL = 1e-12  # hand values vs float arithmetic: a few ulps
SQ2 = math.sqrt(2.0)
CORNER_1ST = 1.0 + 1.0 / SQ2  # two-axis first-order update from T1 = T2 = 1, h = v = 1


@pytest.fixture(params=sorted(SOLVERS))
def solver(request):
    return SOLVERS[request.param]


# ------------------------------------------------------------------ 1D-like strips
@pytest.mark.parametrize("order", [1, 2])
@pytest.mark.parametrize("h, v", [(1.0, 1.0), (0.5, 1.0), (1.0, 2.0), (15.0, 3.0)])
@pytest.mark.parametrize(
    "shape, axis", [((6, 1), 0), ((1, 6), 1), ((6, 1, 1), 0), ((1, 6, 1), 1), ((1, 1, 6), 2)]
)
def test_strip_constant_speed_is_exact(solver, shape, axis, h, v, order):
    # Along a strip the wave is a plane: T_i = i h / v at every node, for the
    # straight-ray ball (i <= 2) and for both stencils (a linear T is exact).
    speed = np.full(shape, v)
    T = solver(speed, [(0,) * len(shape)], spacing=h, order=order)
    expected = (np.arange(6) * h / v).reshape(shape)
    assert_same_field(T, expected, RTOL)


def test_strip_first_order_sums_node_slowness(solver):
    # speeds 1, 2, 4, 1, 0.5, 1 from the source at node 0, h = 1.
    # Ball (R = 2): node 1 gets 1*(1 + 1/2)/2 = 0.75, node 2 gets 2*(1 + 1/4)/2 = 1.25,
    # but the march lowers both: node 1 = 0 + 1/2, node 2 = 0.5 + 1/4 = 0.75, then
    # node 3 = 0.75 + 1, node 4 = 1.75 + 2, node 5 = 3.75 + 1.
    speed = np.array([[1.0], [2.0], [4.0], [1.0], [0.5], [1.0]])
    T = solver(speed, [(0, 0)], order=1)
    assert_same_field(T, np.array([[0.0], [0.5], [0.75], [1.75], [3.75], [4.75]]), RTOL)


def test_strip_ball_value_kept_when_lower(solver):
    # speeds 1, 0.5, 0.25, 1, 1: the ball values 1*(1 + 2)/2 = 1.5 and
    # 2*(1 + 4)/2 = 5.0 are lower than the stencil (2.0 and 1.5 + 4 = 5.5), so
    # they stay; beyond R = 2 the stencil continues: 5 + 1, 6 + 1.
    speed = np.array([[1.0], [0.5], [0.25], [1.0], [1.0]])
    T = solver(speed, [(0, 0)], order=1)
    assert_same_field(T, np.array([[0.0], [1.5], [5.0], [6.0], [7.0]]), RTOL)


def test_strip_second_order_by_hand(solver):
    # speeds 1, 2, 4, 1, h = 1, order 2.
    # node 1: no second upwind node (index -1) -> first order 0 + 1/2 = 0.5 (< ball 0.75)
    # node 2: tau = (4*0.5 - 0)/3 = 2/3, a = 9/4 -> 2/3 + (2/3)(1/4) = 5/6 (< ball 1.25)
    # node 3: tau = (4*5/6 - 1/2)/3 = 17/18 -> 17/18 + (2/3)(1/1) = 29/18
    speed = np.array([[1.0], [2.0], [4.0], [1.0]])
    T = solver(speed, [(0, 0)], order=2)
    assert_same_field(T, np.array([[0.0], [0.5], [5 / 6], [29 / 18]]), RTOL)


# ----------------------------------------------------------------------- 2D blocks
@pytest.mark.parametrize("order", [1, 2])
@pytest.mark.parametrize("h", [1.0, 0.25])
def test_3x3_centre_source_gets_exact_ball(solver, order, h):
    # The whole 3x3 block lies in the ball (corner distance sqrt(2) h <= 2 h), so
    # every node starts with its exact distance; the stencil only offers larger
    # values (edges: h; corners: (1 + 1/sqrt 2) h > sqrt(2) h), so they stay.
    T = solver(np.ones((3, 3)), [(1, 1)], spacing=h, order=order)
    expected = h * np.array([[SQ2, 1.0, SQ2], [1.0, 0.0, 1.0], [SQ2, 1.0, SQ2]])
    assert_same_field(T, expected, RTOL)


def _blocked_corner_grid():
    """3x4 grid, source (1, 1), speed 0 at (2, 3): the source box (half-width 2)
    holds a speed-0 node, so there is no ball and the pure stencil shows."""
    speed = np.ones((3, 4))
    speed[2, 3] = 0.0
    return speed


def test_3x4_first_order_stencil_by_hand(solver):
    # (0,1), (2,1), (1,0), (1,2): one axis, 0 + 1 = 1.
    # corners (0,0), (2,0), (0,2), (2,2): two axes with T1 = T2 = 1 -> 1 + 1/sqrt 2.
    # (1,3): only (1,2) frozen when it is computed -> 1 + 1 = 2.
    # (0,3): taus a = 1 + 1/sqrt 2 (from (0,2)) and b = 2 (from (1,3)); a + 1 > b so
    #        both axes: (T - a)^2 + (T - b)^2 = 1 -> T = (a + b + sqrt(2 - (a - b)^2)) / 2.
    # (2,3): speed 0 -> inf.
    a, b = CORNER_1ST, 2.0
    t03 = (a + b + math.sqrt(2.0 - (a - b) ** 2)) / 2.0
    expected = np.array(
        [
            [CORNER_1ST, 1.0, CORNER_1ST, t03],
            [1.0, 0.0, 1.0, 2.0],
            [CORNER_1ST, 1.0, CORNER_1ST, np.inf],
        ]
    )
    T = solver(_blocked_corner_grid(), [(1, 1)], order=1)
    assert_same_field(T, expected, RTOL)


def test_3x4_second_order_stencil_by_hand(solver):
    # Same grid, order 2. Second-order terms need two frozen upwind nodes in a row:
    # (1,3): tau = (4*1 - 0)/3 = 4/3, a = 9/4 -> 4/3 + 2/3 = 2 (same as order 1: T is linear)
    # corners: the next node beyond (1,0)/(0,1) is another corner, not frozen -> first order.
    # (0,3): y-axis (0,2), (0,1) frozen, 1 <= a: tau = (4a - 1)/3, weight 9/4; x-axis from
    #        (1,3) only ((2,3) is blocked): tau = 2, weight 1. One-sided tau + 2/3 > 2, so
    #        solve 9/4 (T - tau)^2 + (T - 2)^2 = 1 (larger root).
    a = CORNER_1ST
    tau = (4.0 * a - 1.0) / 3.0
    A, B, C = 9 / 4 + 1.0, 9 / 4 * tau + 2.0, 9 / 4 * tau**2 + 4.0
    t03 = (B + math.sqrt(B * B - A * (C - 1.0))) / A
    expected = np.array(
        [
            [CORNER_1ST, 1.0, CORNER_1ST, t03],
            [1.0, 0.0, 1.0, 2.0],
            [CORNER_1ST, 1.0, CORNER_1ST, np.inf],
        ]
    )
    T = solver(_blocked_corner_grid(), [(1, 1)], order=2)
    assert_same_field(T, expected, RTOL)


@pytest.mark.parametrize("order", [1, 2])
def test_anisotropic_spacing_by_hand(solver, order):
    # 3x2 grid, spacing (1, 2), source (0,0), speed 0 at (2,1) (no ball).
    # (1,0) = 1, (0,1) = 2, (2,0) = 2 (order 2: (4*1 - 0)/3 + 2/3 = 2 as well).
    # (1,1): taus 1 (y, weight 1/4) and 2 (x, weight 1); one-sided 1 + 2 = 3 > 2 so
    #        (T-1)^2/4 + (T-2)^2 = 1 -> 1.25 T^2 - 4.5 T + 3.25 = 0 -> T = 2.6.
    #        Neither axis has a second upwind node inside the grid: same for order 2.
    speed = np.ones((3, 2))
    speed[2, 1] = 0.0
    T = solver(speed, [(0, 0)], spacing=(1.0, 2.0), order=order)
    assert_same_field(T, np.array([[0.0, 2.0], [1.0, 2.6], [2.0, np.inf]]), RTOL)


# ------------------------------------------------------------- unreachable regions
@pytest.mark.parametrize("order", [1, 2])
def test_walled_pocket_is_inf(solver, order):
    speed = np.ones((8, 8))
    speed[4:7, 4:7] = 0.0
    speed[5, 5] = 1.0  # free node inside a closed ring of speed 0
    T = solver(speed, [(0, 0)], order=order)
    assert T[5, 5] == np.inf
    assert np.all(np.isinf(T[speed == 0]))
    reachable = speed > 0
    reachable[5, 5] = False
    assert np.all(np.isfinite(T[reachable]))


def test_no_diagonal_leak(solver):
    # The corner (0,0) touches the source region only diagonally: the stencil uses
    # axis neighbours, so the wave must not pass between (1,0) and (0,1).
    speed = np.ones((5, 5))
    speed[1, 0] = speed[0, 1] = 0.0
    T = solver(speed, [(3, 3)], order=1)
    assert T[0, 0] == np.inf
    assert np.isfinite(T[1, 1])


def test_3d_pocket_is_inf(solver):
    speed = np.ones((6, 6, 6))
    speed[2:5, 2:5, 2:5] = 0.0
    speed[3, 3, 3] = 1.0
    T = solver(speed, [(0, 0, 0)], order=2)
    assert T[3, 3, 3] == np.inf
    assert np.isfinite(T[5, 5, 5]) and np.isfinite(T[1, 1, 1])


# ------------------------------------------------------------------ multiple sources
def test_two_sources_on_a_strip_meet_in_the_middle(solver):
    # Two plane waves on a strip: T = distance to the nearer end, exactly.
    T = solver(np.ones((7, 1)), [(0, 0), (6, 0)], order=2)
    assert_same_field(T, np.array([[0.0], [1], [2], [3], [2], [1], [0]]), RTOL)


@pytest.mark.parametrize("order", [1, 2])
@pytest.mark.parametrize(
    "shape, sources",
    [((31, 31), [(5, 5), (25, 20)]), ((15, 15, 15), [(2, 2, 2), (12, 10, 9), (3, 12, 7)])],
)
def test_multiple_sources_give_min_of_single_fields(order, shape, sources):
    h, v = 2.0, 4.0  # [m], [m/s]
    speed = np.full(shape, v)
    T = fast_marching(speed, sources, spacing=h, order=order)
    singles = np.min([fast_marching(speed, [s], spacing=h, order=order) for s in sources], axis=0)
    # Only nodes where the fronts meet differ: there the update combines both
    # fronts, which is at most (1 - 1/sqrt 2) h / v ~ 0.29 h/v (2D) or
    # (1 - 1/sqrt 3) h / v ~ 0.42 h/v (3D) below the one-front update, plus a little
    # downstream accumulation (measured: at most 0.33 h/v). 0.5 h/v is the bound.
    np.testing.assert_allclose(T, singles, rtol=0, atol=0.5 * h / v)
    if order == 1:
        # The first-order upwind scheme is monotone: an extra source never raises T.
        assert np.all(T <= singles * (1 + 1e-12))
    # Away from the meeting zone the fields are identical.
    assert np.mean(T == singles) > 0.75


# -------------------------------------------------------------------------- stop_at
def test_stop_at_on_a_strip(solver):
    # Frozen in order 1, 2, 3: the march stops when node 3 is frozen; node 4
    # is in the band (ball, or neighbour of 3) and is returned as inf.
    T = solver(np.ones((6, 1)), [(0, 0)], order=2, stop_at=[(3, 0)])
    assert_same_field(T, np.array([[0.0], [1], [2], [3], [np.inf], [np.inf]]), RTOL)


def test_stop_at_source_returns_only_sources(solver):
    # The stop node is frozen before the march starts: ball nodes are not frozen.
    T = solver(np.ones((5, 5)), [(2, 2)], stop_at=[(2, 2)])
    expected = np.full((5, 5), np.inf)
    expected[2, 2] = 0.0
    assert_same_field(T, expected, RTOL)


@pytest.mark.parametrize("order", [1, 2])
@pytest.mark.parametrize("stops", [[(14, 3)], [(14, 3), (2, 17)], [(10, 10, 1)]])
def test_stop_at_freezes_exactly_the_earlier_nodes(solver, order, stops):
    rng = np.random.default_rng(7)
    shape = (16, 20) if len(stops[0]) == 2 else (12, 12, 4)
    speed = rng.uniform(0.5, 2.0, size=shape)  # distinct times: no ties at the stop time
    source = (1,) * len(shape)
    full = solver(speed, [source], order=order)
    T = solver(speed, [source], order=order, stop_at=stops)
    t_stop = max(full[s] for s in stops)
    done = np.isfinite(T)
    # every stop node is frozen, with its full-run value
    assert all(done[s] for s in stops)
    # frozen nodes keep exactly the values of the full run (same march so far)
    np.testing.assert_array_equal(T[done], full[done])
    # nodes are frozen in order of time: all earlier ones done, later ones not
    assert np.all(done[full < t_stop])
    assert not np.any(done[full > t_stop])
    assert 0 < done.sum() < done.size


def test_stop_at_unreachable_node_runs_to_the_end(solver):
    speed = np.ones((6, 6))
    speed[3, :] = 0.0
    full = solver(speed, [(0, 0)])
    T = solver(speed, [(0, 0)], stop_at=[(5, 5)])
    assert_same_field(T, full, 0.0)
    assert np.isfinite(T[2, 5]) and T[5, 5] == np.inf


# -------------------------------------------------------------- API conventions
def test_output_dtype_shape_and_input_untouched():
    speed = np.arange(1, 13, dtype=np.int32).reshape(3, 4)  # integer speeds accepted
    before = speed.copy()
    T = fast_marching(speed, np.array([[0, 0]]), order=1)
    assert T.dtype == np.float64 and T.shape == (3, 4)
    np.testing.assert_array_equal(speed, before)


def test_axis_order_x_first():
    # Transposing the grid (and the spacing and the source) transposes the result:
    # no hidden axis swap.
    rng = np.random.default_rng(3)
    speed = rng.uniform(0.2, 2.0, size=(7, 9))
    T = fast_marching(speed, [(2, 3)], spacing=(0.7, 1.3))
    Tt = fast_marching(np.ascontiguousarray(speed.T), [(3, 2)], spacing=(1.3, 0.7))
    np.testing.assert_allclose(Tt.T, T, rtol=1e-12)
    # A Fortran-ordered input gives the same field.
    np.testing.assert_array_equal(
        fast_marching(np.asfortranarray(speed), [(2, 3)], spacing=(0.7, 1.3)), T
    )


def test_single_layer_3d_equals_2d():
    rng = np.random.default_rng(4)
    speed = rng.uniform(0.2, 2.0, size=(7, 9))
    T2 = fast_marching(speed, [(2, 3)], spacing=(0.7, 1.3))
    T3 = fast_marching(speed[:, :, None], [(2, 3, 0)], spacing=(0.7, 1.3, 0.5))
    np.testing.assert_array_equal(T3[:, :, 0], T2)


# --------------------------------------------------------------------- validation
_V = np.ones((4, 5))


def _with(value, at=(0, 0)):
    speed = _V.copy()
    speed[at] = value
    return speed


@pytest.mark.parametrize(
    "kwargs, phrase",
    [
        (dict(speed=_with(-1.0), sources=[(1, 1)]), "speed must be >= 0"),
        (dict(speed=_with(np.nan), sources=[(1, 1)]), "speed must be finite"),
        (dict(speed=_with(np.inf), sources=[(1, 1)]), "speed must be finite"),
        (dict(speed=np.ones(5), sources=[(1,)]), "2D or 3D"),
        (dict(speed=np.ones((3, 3), dtype=bool), sources=[(1, 1)]), "numeric"),
        (dict(speed=np.ones((0, 3)), sources=[(0, 0)]), "empty"),
        (dict(speed=_V, sources=[(1, 1)], spacing=0.0), "spacing must be finite and > 0"),
        (dict(speed=_V, sources=[(1, 1)], spacing=(1.0, -1.0)), "spacing must be finite and > 0"),
        (dict(speed=_V, sources=[(1, 1)], spacing=np.nan), "spacing must be finite and > 0"),
        (dict(speed=_V, sources=[(1, 1)], spacing=(1.0, 1.0, 1.0)), "one per axis"),
        (dict(speed=_V, sources=[(1, 1)], order=3), "order must be 1 or 2"),
        (dict(speed=_V, sources=[(1, 1)], order=0), "order must be 1 or 2"),
        (dict(speed=_V, sources=[(4, 0)]), "outside the grid"),
        (dict(speed=_V, sources=[(0, -1)]), "outside the grid"),
        (dict(speed=_with(0.0, (1, 1)), sources=[(1, 1)]), "has speed 0"),
        (dict(speed=_V, sources=[(1, 1, 1)]), "length 2"),
        (dict(speed=_V, sources=[(1,)]), "length 2"),
        (dict(speed=_V, sources=[(1, 1), (1,)]), "length 2"),
        (dict(speed=_V, sources=[]), "non-empty"),
        (dict(speed=_V, sources=[(1.5, 1)]), "non-integer"),
        (dict(speed=_V, sources=[("a", "b")]), "integer grid indices"),
        (dict(speed=_V, sources=[(True, False)]), "integer grid indices"),
        (dict(speed=_V, sources=[(0, 0)], stop_at=[(9, 9)]), "stop_at"),
        (dict(speed=_V, sources=[(0, 0)], stop_at=[(0.5, 1)]), "non-integer"),
    ],
    ids=lambda x: x if isinstance(x, str) else None,
)
def test_bad_input_raises_input_error(kwargs, phrase):
    with pytest.raises(InputError, match=phrase) as info:
        fast_marching(kwargs.pop("speed"), kwargs.pop("sources"), **kwargs)
    # one hierarchy, still a ValueError for callers that do not know fm2uav
    assert isinstance(info.value, Fm2uavError) and isinstance(info.value, ValueError)


def test_error_messages_say_where():
    with pytest.raises(InputError, match=r"found -2 at index \[.*0.*3.*\]"):
        fast_marching(_with(-2.0, (0, 3)), [(1, 1)])
    with pytest.raises(InputError, match=r"source \[2, 2\] has speed 0"):
        fast_marching(_with(0.0, (2, 2)), [(0, 0), (2, 2)])
    with pytest.raises(InputError, match=r"\[7, 1\] lies outside the grid of shape \(4, 5\)"):
        fast_marching(_V, [(0, 0), (7, 1)])
