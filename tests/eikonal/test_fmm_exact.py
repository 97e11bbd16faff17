"""Exact values of the Fast Marching Method on tiny grids, and input validation.

The value tests run on both the compiled solver and the pure-Python reference
(``solver`` fixture), so the hand-written expectations check the reference too.
Expected fields are derived by hand in the comments; only float rounding
separates them from the solvers' output (``rtol = 1e-12``).

Reminder of the discretisation (see ``fm2uav.eikonal._reference``): sources
are frozen at 0. With at most 64 sources, each source whose box of half-width
``R = max(2 max(h), 0.05 * extent)`` (extent: largest ``(n - 1) h`` of the grid;
``floor(R / h)`` nodes either side per axis, clipped) holds only speeds > 0 with
``max / min <= 1.5`` (``BALL_MAX_SPEED_RATIO``) is *clean*, and nodes with
``d <= R`` from it get a ball time (minimum over sources): the straight-ray time
``d / v`` if the box's speed is constant, else the factored equation
``T = T0 tau`` (``T0 = d / v_s``) marched on the box (``fm2uav.eikonal._sources``).
Along a strip that is the trapezoidal rule of the slowness ``s = 1 / v``: next
to the source ``T_1 = h (s_0 + s_1) / 2``, then (second order, ``tau_k = T_k /
(k h s_0)``) ``(1 + 3k/2) s_0 tau_k = s_k + k s_0 (2 tau_{k-1} - tau_{k-2} / 2)``,
so ``T_2 = h (s_0 + 2 s_1 + s_2) / 2`` (``_strip_ball`` below). If every source
is clean these ball nodes are frozen (final); otherwise they start in the band
and the march may lower them. The ball assumes a smooth speed, hence the ratio
rule: a slow wall or a speed jump inside the box is left to the march (it must
not be crossed for free). Positive speeds below
1e-150 count as 1e-150. First-order update along one axis: ``T1 + h / v``; two
axes with equal spacing: the root of ``(T - T1)^2 + (T - T2)^2 = (h / v)^2``.

On the small grids here ``0.05 * extent < 2 h`` unless said otherwise, so R = 2 h.
"""

from __future__ import annotations

import math
from fractions import Fraction

import numpy as np
import pytest
from .fmm_checks import SOLVERS, assert_same_field, distance_from

from fm2uav.errors import Fm2uavError, InputError
from fm2uav.eikonal import fast_marching

RTOL = 1e-12  # hand values vs float arithmetic: a few ulps
SQ2 = math.sqrt(2.0)
CORNER_1ST = 1.0 + 1.0 / SQ2  # two-axis first-order update from T1 = T2 = 1, h = v = 1


@pytest.fixture(params=sorted(SOLVERS))
def solver(request):
    return SOLVERS[request.param]


def _strip_ball(speeds, h: float = 1.0) -> list[float]:
    """Ball times [s] along a strip from a source at node 0 (module docstring).

    ``speeds`` [m/s] of nodes 0..K (the ball nodes), ``h`` [m]; exact fractions
    of the recurrence, rounded to float once at the end.
    """
    s = [1 / Fraction(v) for v in speeds]  # slowness [s/m]
    tau = [Fraction(1), (s[0] + s[1]) / (2 * s[0])]
    for k in range(2, len(s)):
        tau.append((s[k] + k * s[0] * (2 * tau[k - 1] - tau[k - 2] / 2)) / ((1 + Fraction(3, 2) * k) * s[0]))
    return [float(k * h * s[0] * t) for k, t in enumerate(tau)]


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


def test_strip_frozen_ball_is_kept_when_every_source_is_clean(solver):
    # speeds 1, 1.25, 1.5, 1, 0.5, 1 from the source at node 0, h = 1 (R = 2:
    # 0.05 * 5 < 2). The box is nodes 0..2, max/min = 1.5 / 1 = 1.5 <= 1.5 (the
    # limit itself is allowed), so the only source is clean and its ball frozen:
    # node 1 = (1 + 1/1.25)/2 = 0.9, node 2 = (1 + 2/1.25 + 1/1.5)/2 = 49/30,
    # although the stencil would give 0.8 and 0.8 + 2/3 = 22/15. The slower nodes
    # 3..5 lie outside the box and do not matter. Then node 3 = 49/30 + 1 = 79/30,
    # node 4 = 79/30 + 2 = 139/30, node 5 = 139/30 + 1 = 169/30.
    speed = np.array([[1.0], [1.25], [1.5], [1.0], [0.5], [1.0]])
    T = solver(speed, [(0, 0)], order=1)
    expected = np.array([[0.0], [0.9], [49 / 30], [79 / 30], [139 / 30], [169 / 30]])
    assert_same_field(T, expected, RTOL)
    np.testing.assert_allclose(_strip_ball([1.0, 1.25, 1.5]), expected[:3, 0], rtol=RTOL)


@pytest.mark.parametrize(
    "order, expected",
    [
        # order 1: 1/1.25 = 0.8, 0.8 + 1/1.6 = 1.425, then + 1, + 2, + 1.
        (1, [0.0, 0.8, 1.425, 2.425, 4.425, 5.425]),
        # order 2: node 1 first order (no node -1): 0.8;
        # node 2 (speeds 1.6, 1.25, 1 along the stencil, max/min 1.6 <= 2):
        #   tau = (4*0.8 - 0)/3 = 16/15 -> 16/15 + (2/3)/1.6 = 89/60;
        # node 3 (1, 1.6, 1.25): tau = (4*89/60 - 4/5)/3 = 77/45 -> 77/45 + 2/3 = 107/45;
        # node 4 (0.5, 1, 1.6: max/min 3.2 > ORDER2_MAX_SPEED_RATIO = 2): first
        #   order, 107/45 + 1/0.5 = 197/45;
        # node 5 (1, 0.5, 1: ratio 2, allowed): tau = (4*197/45 - 107/45)/3 = 227/45
        #   -> 227/45 + 2/3 = 257/45.
        (2, [0.0, 0.8, 89 / 60, 107 / 45, 197 / 45, 257 / 45]),
    ],
)
def test_strip_speed_jump_of_1_6_in_the_box_disables_the_ball(solver, order, expected):
    # The strip above with 1.6 instead of 1.5 at node 2: max/min = 1.6 > 1.5, the
    # only source is not clean: no ball, the stencil alone.
    speed = np.array([[1.0], [1.25], [1.6], [1.0], [0.5], [1.0]])
    T = solver(speed, [(0, 0)], order=order)
    assert_same_field(T, np.array(expected).reshape(6, 1), RTOL)
    # exactly what the solver gives with the ball switched off
    assert_same_field(T, solver(speed, [(0, 0)], order=order, source_ball=False), RTOL)


def test_strip_band_ball_is_lowered_when_a_source_is_not_clean(solver):
    # Speeds 1, 1.25, 1.5, 1, 0.5, 1, then a speed-0 node and a second source at
    # node 7 (R = max(2, 0.05 * 7) = 2). The box of the source at 7 (nodes 5..7)
    # holds the speed-0 node 6, so it gets no ball; the source at 0 is clean
    # (box 0..2, max/min = 1.5), but its ball (0.9, 5/3) only enters the band:
    # the march lowers node 1 to 0 + 1/1.25 = 0.8 and node 2 to 0.8 + 1/1.5 =
    # 22/15, then node 3 = 22/15 + 1 = 37/15, node 4 = 37/15 + 2 = 67/15,
    # node 5 = 67/15 + 1 = 82/15; node 6 is a wall and node 7 a source.
    speed = np.array([[1.0], [1.25], [1.5], [1.0], [0.5], [1.0], [0.0], [1.0]])
    T = solver(speed, [(0, 0), (7, 0)], order=1)
    expected = np.array(
        [[0.0], [0.8], [22 / 15], [37 / 15], [67 / 15], [82 / 15], [np.inf], [0.0]]
    )
    assert_same_field(T, expected, RTOL)


def test_strip_ball_value_kept_when_lower(solver):
    # speeds 1, 0.8, 0.75, 1, 1 (box 0..2: max/min = 1/0.75 = 4/3 <= 1.5, clean):
    # the ball values (1 + 1.25)/2 = 1.125 and (1 + 2.5 + 4/3)/2 = 29/12 (frozen;
    # they are lower than the stencil's 1/0.8 = 1.25 and 1.125 + 4/3 = 59/24
    # anyway); beyond R = 2 the stencil continues: 29/12 + 1 = 41/12, + 1 = 53/12.
    speed = np.array([[1.0], [0.8], [0.75], [1.0], [1.0]])
    T = solver(speed, [(0, 0)], order=1)
    assert_same_field(T, np.array([[0.0], [1.125], [29 / 12], [41 / 12], [53 / 12]]), RTOL)


def test_strip_second_order_by_hand_frozen_ball(solver):
    # speeds 1, 1.25, 1.5, 1, h = 1, order 2 (clean: max/min = 1.5). Frozen ball:
    # node 1 = 0.9, node 2 = 49/30.
    # node 3: T1 = 49/30, T2 = 0.9 <= T1 -> tau = (4*49/30 - 9/10)/3 = 169/90, a = 9/4
    #         -> 169/90 + (2/3)(1/1) = 229/90
    speed = np.array([[1.0], [1.25], [1.5], [1.0]])
    T = solver(speed, [(0, 0)], order=2)
    assert_same_field(T, np.array([[0.0], [0.9], [49 / 30], [229 / 90]]), RTOL)


def test_strip_second_order_by_hand_band_ball(solver):
    # speeds 1, 1.25, 1.5, 1, 0, 1, h = 1, order 2, sources at 0 and 5; the box of
    # the source at 5 (nodes 3..5) holds the speed-0 node 4, so the ball of the
    # clean source 0 (0.9, 5/3) is only in the band.
    # node 1: no second upwind node (index -1) -> first order 0 + 1/1.25 = 0.8 (< ball 0.9)
    # node 2: tau = (4*0.8 - 0)/3 = 16/15, a = 9/4 -> 16/15 + (2/3)(1/1.5) = 68/45
    #         (< ball 5/3)
    # node 3: tau = (4*68/45 - 4/5)/3 = 236/135 -> 236/135 + (2/3)(1/1) = 326/135
    speed = np.array([[1.0], [1.25], [1.5], [1.0], [0.0], [1.0]])
    T = solver(speed, [(0, 0), (5, 0)], order=2)
    expected = np.array([[0.0], [0.8], [68 / 45], [326 / 135], [np.inf], [0.0]])
    assert_same_field(T, expected, RTOL)


@pytest.mark.parametrize("n, reach", [(101, 5), (21, 2)])
@pytest.mark.parametrize("h", [1.0, 0.5])
def test_ball_radius_is_five_percent_of_the_extent(solver, n, reach, h):
    # A strip of n nodes, speed 1 at the source (node 0), 1.5 elsewhere (max/min =
    # 1.5: clean); order 1. R = max(2 h, 0.05 (n - 1) h): n = 101 -> 5 h, n = 21 ->
    # 2 h. Ball nodes (k <= reach) are frozen at the strip recurrence (module
    # docstring): 5/6 h, 3/2 h, then (n = 101) 47/22 h, 214/77 h, ...; beyond them
    # the stencil adds h / 1.5 = (2/3) h per node.
    speed = np.full((n, 1), 1.5)
    speed[0, 0] = 1.0
    T = solver(speed, [(0, 0)], spacing=h, order=1)
    ball = _strip_ball(speed[: reach + 1, 0], h)
    assert math.isclose(ball[1], 5 / 6 * h, rel_tol=RTOL)
    assert math.isclose(ball[2], 3 / 2 * h, rel_tol=RTOL)
    k = np.arange(n, dtype=float)
    expected = np.where(
        k <= reach, np.pad(ball, (0, n - reach - 1)), ball[-1] + 2 / 3 * (k - reach) * h
    )
    assert_same_field(T, expected.reshape(n, 1), RTOL)


@pytest.mark.parametrize("order", [1, 2])
@pytest.mark.parametrize("n_sources", [64, 65])
def test_more_than_64_sources_get_no_ball(solver, order, n_sources):
    # Sources at every third node of a strip (n = 3 k - 2 nodes: first and last
    # are sources), speed 1 at the sources and 1.5 elsewhere, h = 1; every other
    # node is 1 from its nearest source (and 2 from the next). With 64 sources
    # every source is clean (R = max(2, 0.05 * 189) = 9.45, boxes hold speeds 1
    # and 1.5 only: max/min = 1.5): the frozen ball gives min(1, 2) * (1 + 1/1.5)/2
    # = 5/6. With 65 (> MAX_BALL_SOURCES) the sources are plain T = 0 nodes and
    # the stencil gives 0 + 1/1.5 = 2/3 (for order 2 too: the node beyond the
    # source is not frozen earlier than the source, so no second-order term
    # applies).
    n = 3 * n_sources - 2
    speed = np.full((n, 1), 1.5)
    sources = [(i, 0) for i in range(0, n, 3)]
    assert len(sources) == n_sources
    speed[np.array(sources)[:, 0], 0] = 1.0
    T = solver(speed, sources, order=order)
    expected = np.full((n, 1), 5 / 6 if n_sources <= 64 else 2 / 3)
    expected[np.array(sources)[:, 0], 0] = 0.0
    assert_same_field(T, expected, RTOL)


# ----------------------------------------------------------------------- 2D blocks
@pytest.mark.parametrize("order", [1, 2])
@pytest.mark.parametrize("h", [1.0, 0.25])
def test_3x3_centre_source_gets_exact_ball(solver, order, h):
    # The whole 3x3 block lies in the ball (corner distance sqrt(2) h <= 2 h) and
    # the source is clean, so every node is frozen at its exact distance (the
    # stencil would only offer larger values anyway: corners (1 + 1/sqrt 2) h).
    T = solver(np.ones((3, 3)), [(1, 1)], spacing=h, order=order)
    expected = h * np.array([[SQ2, 1.0, SQ2], [1.0, 0.0, 1.0], [SQ2, 1.0, SQ2]])
    assert_same_field(T, expected, RTOL)


@pytest.mark.parametrize(
    "corner, clean",
    [(1.5, True), (0.7, True), (1.6, False), (0.6, False), (1e-3, False), (0.0, False)],
)
def test_box_corner_outside_the_ball_decides_cleanliness(solver, corner, clean):
    # 5x5, speed 1, source (2, 2), R = 2 (0.05 * 4 < 2): the box is the whole grid.
    # The corner (0, 0) is 2 sqrt 2 > R from the source, outside the ball, but
    # inside the box, so its speed alone decides: 1.5 and 0.7 (max/min 1.5, 1.43)
    # keep the ball, 1.6, 0.6 (1.67), a slow node 1e-3 and a wall 0 remove it.
    # Seen at the diagonal node (1, 1): ball sqrt 2 (frozen), else the first-order
    # stencil from T1 = T2 = 1: 1 + 1/sqrt 2.
    speed = np.ones((5, 5))
    speed[0, 0] = corner
    T = solver(speed, [(2, 2)], order=1)
    assert math.isclose(T[1, 1], SQ2 if clean else CORNER_1ST, rel_tol=RTOL)
    no_ball = solver(speed, [(2, 2)], order=1, source_ball=False)
    assert math.isclose(no_ball[1, 1], CORNER_1ST, rel_tol=RTOL)
    if not clean:
        assert_same_field(T, no_ball, RTOL)


@pytest.mark.parametrize(
    "order, column",
    [
        # Hand values at (50..56, 50), derived below.
        (1, [0.0, 1.0, 2.0, 1002.0, 1003.0, 1004.0, 1005.0]),
        (2, [0.0, 1.0, 2.0, 1002.0, 1003.0, 1004.0, 1005.0]),
    ],
)
def test_slow_wall_inside_the_box_is_not_crossed_for_free(solver, order, column):
    # Regression: 101x101, speed 1, a full row x = 53 of speed 1e-3, source
    # (50, 50). R = max(2, 0.05 * 100) = 5, so the box (rows 45..55) holds the wall
    # and the old rule (only speed 0 made a box unclean) gave the ball node (55, 50)
    # the straight-ray time 5 * (1 + 1)/2 = 5 and (56, 50) 6.0: the wall crossed
    # for free. Now max/min = 1000 > 1.5: not clean at R = 5; the halved radius
    # 2.5 (box rows 48..52, speed 1 only) is, so the ball is the 21 nodes within
    # 2.5 of the source, exact (constant speed), and the wall costs its crossing
    # time h / v = 1000 s.
    # Down the column y = 50 every update is one-sided (the side nodes are later):
    # order 1: 1, 2, then 2 + 1000 = 1002 on the wall, + 1 per row: 1005 at x = 56.
    # order 2: 1 (no second upwind node), (4*1 - 0)/3 + 2/3 = 2; every stencil
    # that touches the wall (rows 53, 54, 55) spans speeds 1 and 1e-3, max/min
    # 1000 > ORDER2_MAX_SPEED_RATIO = 2, so it falls back to first order:
    # 1002, 1003, 1004; row 56 (speeds 1, 1, 1): tau = (4*1004 - 1003)/3 = 3013/3
    # -> 3013/3 + 2/3 = 1005. Without that fallback the extrapolation
    # (4 T1 - T2)/3, which assumes T smooth, charged the wall node only 2/3 of
    # h / v (669 on the wall, 892 behind it).
    # Physically the wave needs >= 1000 s to cross the 1 m of the wall.
    speed = np.ones((101, 101))
    speed[53, :] = 1e-3
    T = solver(speed, [(50, 50)], order=order)
    np.testing.assert_allclose(T[50:57, 50], column, rtol=RTOL, atol=0)
    behind = T[54:]
    assert np.all(behind >= 1000.0)
    # the ball: exactly the nodes within 2.5 of the source, frozen at d / v
    init = solver(speed, [(50, 50)], order=order, stop_at=[(50, 50)])
    d = distance_from((101, 101), (1.0, 1.0), (50, 50))
    np.testing.assert_array_equal(np.isfinite(init), d <= 2.5)
    np.testing.assert_allclose(init[d <= 2.5], d[d <= 2.5], rtol=RTOL, atol=0)
    # in front of the wall nothing depends on what lies behind it: the wall nodes
    # are later than every node of rows <= 52 (at most 72 s, measured), so they
    # are never upwind there; a slow half-space from row 53 on (same ball) gives
    # the same front
    half = speed.copy()
    half[53:] = 1e-3
    front = solver(half, [(50, 50)], order=order)
    np.testing.assert_allclose(T[:53], front[:53], rtol=RTOL, atol=0)


@pytest.mark.parametrize("order", [1, 2])
def test_source_ball_false_gives_the_pure_stencil(solver, order):
    # 3x3, speed 1, centre source: with the ball every node is frozen at its exact
    # distance (test above); without it the stencil shows: axis neighbours 0 + 1,
    # corners 1 + 1/sqrt 2 (both orders: no second upwind node inside the grid).
    T = solver(np.ones((3, 3)), [(1, 1)], order=order, source_ball=False)
    c = CORNER_1ST
    assert_same_field(T, np.array([[c, 1.0, c], [1.0, 0.0, 1.0], [c, 1.0, c]]), RTOL)


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
    # downstream accumulation (measured max |T - singles|: 2D 0.33 / 0.16 h/v for
    # order 1 / 2, 3D 0.26 / 0.15 h/v). 0.5 h/v is the bound.
    np.testing.assert_allclose(T, singles, rtol=0, atol=0.5 * h / v)
    if order == 1:
        # The first-order upwind scheme is monotone: an extra source never raises T.
        assert np.all(T <= singles * (1 + 1e-12))
    # Away from the meeting zone the fields are identical (measured share of equal
    # nodes: 0.87 in 2D, 0.81-0.82 in 3D).
    assert np.mean(T == singles) > 0.75


# ------------------------------------------------------- frozen ball vs band ball
def _two_source_grid(v_source: float, obstacle: float | None):
    """21x21, speed 1.5 [m/s] except v_source at the sources A = (5, 5) and
    B = (15, 15); with ``obstacle`` (a speed) the node (15, 17) gets that speed.
    It lies inside B's box (R = max(2, 0.05 * 20) = 2); a speed that breaks
    max/min <= 1.5 there (0, a slow node, a fast node) makes B not clean, and
    A's ball is then only banded."""
    speed = np.full((21, 21), 1.5)
    speed[5, 5] = speed[15, 15] = v_source
    if obstacle is not None:
        speed[15, 17] = obstacle
    return speed, [(5, 5), (15, 15)]


@pytest.mark.parametrize("obstacle", [0.0, 0.5, 2.4])
@pytest.mark.parametrize("order", [1, 2])
def test_ball_frozen_when_all_clean_lowered_in_band_mode(solver, order, obstacle):
    # Both boxes hold speeds 1 and 1.5 (max/min = 1.5): both sources clean. Around A
    # the factored ball gives, on the axes, (1 + 1/1.5)/2 = 5/6 at d = 1 and
    # (1 + 2/1.5 + 1/1.5)/2 = 3/2 at d = 2 (strip recurrence), and on the diagonal
    # (d = sqrt 2, first order from the two axis neighbours, T0 = sqrt 2, tau_1 =
    # 5/6, alpha = 1/sqrt 2 + sqrt 2, beta = 5 sqrt 2 / 6 per axis):
    # 2 (alpha tau - beta)^2 = (2/3)^2 -> tau = 7/9, T = 7 sqrt(2) / 9. All frozen:
    # more than the march finds (e.g. 0 + 1/1.5 = 2/3 at d = 1: the wave leaves
    # the slow source node at once).
    d = distance_from((21, 21), (1.0, 1.0), (5, 5))
    ball = (d <= 2.0) & (d > 0)  # A's ball nodes (all nearer to A than to B)
    T_frozen = solver(*_two_source_grid(1.0, obstacle=None), order=order)
    for dist, value in [(1.0, 5 / 6), (2.0, 3 / 2), (SQ2, 7 * SQ2 / 9)]:
        ring = ball & np.isclose(d, dist)
        assert ring.sum() == 4
        np.testing.assert_allclose(T_frozen[ring], value, rtol=RTOL, atol=0)
    # the same for either order (the ball does not depend on the march's order),
    # frozen before the march (stop at the sources: nothing else is marched)
    init = solver(*_two_source_grid(1.0, obstacle=None), order=order, stop_at=[(5, 5), (15, 15)])
    np.testing.assert_allclose(init[ball], T_frozen[ball], rtol=RTOL, atol=0)
    # Band mode (B's box: a wall 0, a slow node 0.5 (max/min 3) or a fast node
    # 2.4 (1.6x the background, max/min 2.4)): the march lowers A's axis nodes,
    # at d = 1 from 5/6 to 0 + 1/1.5 = 2/3 and at d = 2 from 3/2 to 2/3 + 2/3 =
    # 4/3 (order 2 too: (4 * 2/3 - 0)/3 + (2/3)/1.5 = 4/3, T being linear along
    # the axis), while the diagonal keeps its ball value 7 sqrt(2)/9 =
    # 1.0999, below the stencil's 2/3 (1 + 1/sqrt 2) = 1.1381.
    T_band = solver(*_two_source_grid(1.0, obstacle=obstacle), order=order)
    for dist, value in [(1.0, 2 / 3), (2.0, 4 / 3), (SQ2, 7 * SQ2 / 9)]:
        ring = ball & np.isclose(d, dist)
        np.testing.assert_allclose(T_band[ring], value, rtol=RTOL, atol=0)
    assert 7 * SQ2 / 9 < 2 / 3 * CORNER_1ST


def test_band_ball_keeps_values_lower_than_the_stencil(solver):
    # The same grid at constant speed 1, B not clean (band mode): A's ball values
    # are still used where the stencil offers more, e.g. the diagonal neighbour
    # keeps sqrt(2) (stencil: 1 + 1/sqrt 2); first order never undercuts the
    # exact distance, so the whole ball stays exact.
    speed, sources = _two_source_grid(1.0, obstacle=0.0)
    speed[speed > 0] = 1.0
    T = solver(speed, sources, order=1)
    d = distance_from((21, 21), (1.0, 1.0), (5, 5))
    ball = d <= 2.0
    np.testing.assert_allclose(T[ball], d[ball], rtol=RTOL, atol=0)
    # B is not clean: its diagonal neighbour has the two-axis stencil value
    assert math.isclose(T[16, 16], CORNER_1ST, rel_tol=RTOL)


# ------------------------------------------------------------------- MIN_SPEED
@pytest.mark.parametrize("tiny", [1e-150, 1e-170, 5e-324])
def test_tiny_speed_is_raised_to_min_speed_not_a_wall(solver, tiny):
    # speeds 1, 1, 1, tiny, 1, h = 1, order 1: ball (R = 2) 1, 2; node 3: 2 + 1/1e-150
    # = 1e150 (2 is lost in rounding), node 4: 1e150 + 1 = 1e150. Without the floor,
    # 1/tiny^2 overflows to inf and node 3 would act as a wall (T = inf beyond).
    speed = np.array([[1.0], [1.0], [1.0], [tiny], [1.0]])
    T = solver(speed, [(0, 0)], order=1)
    assert_same_field(T, np.array([[0.0], [1.0], [2.0], [1e150], [1e150]]), RTOL)


def test_speed_above_min_speed_is_not_changed(solver):
    speed = np.array([[1.0], [1.0], [1.0], [1e-140], [1.0]])
    T = solver(speed, [(0, 0)], order=1)
    assert_same_field(T, np.array([[0.0], [1.0], [2.0], [1e140], [1e140]]), RTOL)


@pytest.mark.parametrize("order", [1, 2])
def test_wall_of_tiny_speed_is_crossed(solver, order):
    # A full row of speed 1e-170 across a 2D grid: the far side is reached (very
    # late), with the same field as for a row of speed MIN_SPEED = 1e-150; a row of
    # speed 0 blocks it.
    speed = np.ones((12, 9))
    speed[6, :] = 1e-170
    T = solver(speed, [(2, 4)], spacing=0.5, order=order)
    assert np.all(np.isfinite(T))
    assert np.all(T[7:] > 1e149)
    speed_min = speed.copy()
    speed_min[6, :] = 1e-150
    np.testing.assert_array_equal(T, solver(speed_min, [(2, 4)], spacing=0.5, order=order))
    speed[6, :] = 0.0
    assert np.all(np.isinf(solver(speed, [(2, 4)], spacing=0.5, order=order)[6:]))


# -------------------------------------------------------------------------- stop_at
def test_stop_at_on_a_strip(solver):
    # Nodes 1, 2 are the frozen ball; node 3 is frozen first by the march, which
    # stops there; node 4 is in the band (neighbour of 3) and is returned as inf.
    T = solver(np.ones((6, 1)), [(0, 0)], order=2, stop_at=[(3, 0)])
    assert_same_field(T, np.array([[0.0], [1], [2], [3], [np.inf], [np.inf]]), RTOL)


def test_stop_at_source_returns_the_initially_frozen_nodes(solver):
    # The stop node is frozen before the march starts, so nothing is marched: the
    # result holds the source and its frozen ball (d <= R = 2, exact distance).
    T = solver(np.ones((5, 5)), [(2, 2)], stop_at=[(2, 2)])
    d = distance_from((5, 5), (1.0, 1.0), (2, 2))
    assert_same_field(T, np.where(d <= 2.0, d, np.inf), RTOL)
    # a stop node inside the frozen ball: the same
    assert_same_field(solver(np.ones((5, 5)), [(2, 2)], stop_at=[(2, 4)]), T, RTOL)


def test_stop_at_source_in_band_mode_returns_only_the_source(solver):
    # A speed-0 node in the box: no ball (ball nodes would only be banded anyway).
    speed = np.ones((5, 5))
    speed[0, 0] = 0.0
    T = solver(speed, [(2, 2)], stop_at=[(2, 2)])
    expected = np.full((5, 5), np.inf)
    expected[2, 2] = 0.0
    assert_same_field(T, expected, RTOL)


@pytest.mark.parametrize("order", [1, 2])
@pytest.mark.parametrize("stops", [[(14, 3)], [(14, 3), (2, 17)], [(10, 10, 1)]])
def test_stop_at_freezes_exactly_the_earlier_nodes(solver, order, stops):
    rng = np.random.default_rng(7)
    shape = (16, 20) if len(stops[0]) == 2 else (12, 12, 4)
    # distinct times (no ties at the stop time); max/min <= 1.3/0.9 = 1.44 <= 1.5,
    # so the source is clean and has a frozen ball
    speed = rng.uniform(0.9, 1.3, size=shape)
    source = (1,) * len(shape)
    full = solver(speed, [source], order=order)
    T = solver(speed, [source], order=order, stop_at=stops)
    t_stop = max(full[s] for s in stops)
    done = np.isfinite(T)
    # every stop node is frozen, with its full-run value
    assert all(done[s] for s in stops)
    # frozen nodes keep exactly the values of the full run (same march so far)
    np.testing.assert_array_equal(T[done], full[done])
    # The clean source's ball (d <= R = 2 on these grids) is frozen before the
    # march, whatever its times; after that, nodes are frozen in order of time:
    # all earlier ones done, later ones not.
    ball = distance_from(shape, (1.0,) * len(shape), source) <= 2.0
    # (the ball really is frozen before the march: stopping at the source returns it)
    initial = np.isfinite(solver(speed, [source], order=order, stop_at=[source]))
    np.testing.assert_array_equal(initial, ball)
    assert np.all(done[ball])
    assert np.all(done[full < t_stop])
    assert not np.any(done[(full > t_stop) & ~ball])
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
    # max/min <= 1.3/0.9 < 1.5: the source keeps its (frozen) ball, whose box and
    # distances use the per-axis spacing too
    speed = rng.uniform(0.9, 1.3, size=(7, 9))
    T = fast_marching(speed, [(2, 3)], spacing=(0.7, 1.3))
    Tt = fast_marching(np.ascontiguousarray(speed.T), [(3, 2)], spacing=(1.3, 0.7))
    np.testing.assert_allclose(Tt.T, T, rtol=1e-12)
    # A Fortran-ordered input gives the same field.
    np.testing.assert_array_equal(
        fast_marching(np.asfortranarray(speed), [(2, 3)], spacing=(0.7, 1.3)), T
    )


def test_single_layer_3d_equals_2d():
    rng = np.random.default_rng(4)
    speed = rng.uniform(0.9, 1.3, size=(7, 9))  # clean source: with its ball
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
        # order must be a real int: no bool, no float (even integral), no string
        (dict(speed=_V, sources=[(1, 1)], order=2.0), r"order must be 1 or 2, got 2\.0$"),
        (dict(speed=_V, sources=[(1, 1)], order=1.0), r"order must be 1 or 2, got 1\.0$"),
        (dict(speed=_V, sources=[(1, 1)], order=True), r"order must be 1 or 2, got True$"),
        (dict(speed=_V, sources=[(1, 1)], order=np.float64(2.0)), "order must be 1 or 2"),
        (dict(speed=_V, sources=[(1, 1)], order=np.bool_(True)), "order must be 1 or 2"),
        (dict(speed=_V, sources=[(1, 1)], order="2"), "order must be 1 or 2"),
        (dict(speed=_V, sources=[(1, 1)], order=None), "order must be 1 or 2"),
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


def test_numpy_integer_order_accepted():
    T = fast_marching(_V, [(1, 1)], order=np.int64(2))
    np.testing.assert_array_equal(T, fast_marching(_V, [(1, 1)], order=2))
    T1 = fast_marching(_V, [(1, 1)], order=np.uint8(1))
    np.testing.assert_array_equal(T1, fast_marching(_V, [(1, 1)], order=1))


def test_error_messages_print_plain_numbers():
    # no numpy reprs such as "np.float64(nan)" or "np.int64(0)" in messages
    with pytest.raises(InputError, match=r"found -2 at index \[0, 3\]$"):
        fast_marching(_with(-2.0, (0, 3)), [(1, 1)])
    with pytest.raises(InputError, match=r"found nan at index \[0, 0\]$"):
        fast_marching(_with(np.nan), [(1, 1)])
    with pytest.raises(InputError, match=r"found inf at index \[2, 1\]$"):
        fast_marching(_with(np.inf, (2, 1)), [(1, 1)])
    with pytest.raises(InputError, match=r"got \(1\.0, -1\.0\)$"):
        fast_marching(_V, [(1, 1)], spacing=np.array([1.0, -1.0]))


def test_error_message_numpy_order_is_plain():
    with pytest.raises(InputError, match=r"order must be 1 or 2, got 3$"):
        fast_marching(_V, [(1, 1)], order=np.int64(3))


def test_error_messages_say_where():
    with pytest.raises(InputError, match=r"found -2 at index \[.*0.*3.*\]"):
        fast_marching(_with(-2.0, (0, 3)), [(1, 1)])
    with pytest.raises(InputError, match=r"source \[2, 2\] has speed 0"):
        fast_marching(_with(0.0, (2, 2)), [(0, 0), (2, 2)])
    with pytest.raises(InputError, match=r"\[7, 1\] lies outside the grid of shape \(4, 5\)"):
        fast_marching(_V, [(0, 0), (7, 1)])
