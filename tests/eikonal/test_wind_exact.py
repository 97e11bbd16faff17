"""Exact values of the wind march on tiny grids (full expected fields, derived by hand).

Every value test runs on the compiled solver and on the pure-Python reference
(``solver`` fixture). Reminder (``fm2uav.eikonal._wind_reference``): airspeed
``V``, wind ``w``; the time to fly ``d`` in a constant wind is the ``t`` of
``|d - w t| = V t``. With V = 5 m/s and w = (3, 0) m/s: 8 m/s downwind (1/8 s per
metre), 2 m/s upwind (1/2 s), 4 m/s across (1/4 s); the diagonal ``(1, 1)``:
``(1 - 3t)^2 + 1 = 25 t^2``, ``8 t^2 + 3 t - 1 = 0``, ``t = (sqrt 41 - 3) / 16``;
``(-1, 1)``: ``t = (sqrt 41 + 3) / 16``; in 3D ``(1, 1, 1)``: ``16 t^2 + 6 t - 3
= 0``, ``t = (sqrt 57 - 3) / 16``, ``(-1, 1, 1)``: ``(sqrt 57 + 3) / 16``; ``(0,
1, 1)``: ``sqrt 2 / 4``.

On grids this small the source ball (radius max(2 cells, 5 % of the extent))
holds the exact constant-wind times, and the first-order stencil reproduces them
too: a vertex candidate along a stencil direction is exact in a constant wind, and
linear interpolation of the (convex) exact field on a face never undercuts it.
(Order 2 without the ball extrapolates across the cone's tip next to the source,
as the isotropic stencil does; that is what the ball is for.)
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from fm2uav.eikonal.wind import zermelo_march
from fm2uav.eikonal._wind_reference import zermelo_march_reference

RTOL = 1e-12
INF = math.inf
S41 = math.sqrt(41.0)
S57 = math.sqrt(57.0)
#: (order, ball) pairs for which the ring values are exact
EXACT_RING = [(1, True), (2, True), (1, False)]


def _compiled(speed, sources, wind, **kw):
    return zermelo_march(speed, sources, wind, **kw).times


SOLVERS = {"compiled": _compiled, "reference": zermelo_march_reference}


@pytest.fixture(params=sorted(SOLVERS))
def solver(request):
    return SOLVERS[request.param]


def _same(actual, expected):
    expected = np.asarray(expected, dtype=float)
    assert actual.shape == expected.shape
    np.testing.assert_array_equal(np.isinf(actual), np.isinf(expected))
    fin = np.isfinite(expected)
    np.testing.assert_allclose(actual[fin], expected[fin], rtol=RTOL, atol=1e-15)


@pytest.mark.parametrize("order", [1, 2])
@pytest.mark.parametrize("ball", [True, False])
def test_strip_downwind_and_upwind(solver, order, ball):
    # 8 m/s downwind (+x), 2 m/s upwind; nodes 4..6 at 1/8 s per m, 2..0 at 1/2 s per m.
    # Beyond the ball (radius 2 cells) order 1 adds 1/8 s; order 2:
    # (4 * 2/8 - 1/8) / 3 + (2/3) (1/8) = 3/8 as well (a linear T is exact).
    T = solver(np.full((7, 1), 5.0), [(3, 0)], [3.0, 0.0], order=order, source_ball=ball)
    _same(T, [[1.5], [1.0], [0.5], [0.0], [0.125], [0.25], [0.375]])


@pytest.mark.parametrize("order", [1, 2])
def test_strip_crosswind(solver, order):
    # w across the strip: ground speed sqrt(5^2 - 3^2) = 4 m/s both ways (crabbing)
    T = solver(np.full((7, 1), 5.0), [(3, 0)], [0.0, 3.0], order=order)
    _same(T, [[0.75], [0.5], [0.25], [0.0], [0.25], [0.5], [0.75]])


@pytest.mark.parametrize("order", [1, 2])
def test_strip_along_z_in_3d_with_spacing(solver, order):
    # h = 2 m along z, wind along -z: 2 m/s towards +z, 8 m/s towards -z
    T = solver(np.full((1, 1, 5), 5.0), [(0, 0, 1)], [0.0, 0.0, -3.0], spacing=(1.0, 1.0, 2.0),
               order=order)
    _same(T, np.array([0.25, 0.0, 1.0, 2.0, 3.0]).reshape(1, 1, 5))


@pytest.mark.parametrize("order, ball", EXACT_RING)
def test_ring_2d(solver, order, ball):
    T = solver(np.full((3, 3), 5.0), [(1, 1)], [3.0, 0.0], order=order, source_ball=ball)
    up, down = (S41 + 3) / 16, (S41 - 3) / 16
    _same(T, [[up, 0.5, up],
              [0.25, 0.0, 0.25],
              [down, 0.125, down]])


@pytest.mark.parametrize("order, ball", EXACT_RING)
def test_ring_3d(solver, order, ball):
    # |w| / V = 0.6 is beyond the 3D stencil's causal limit 1/sqrt(3): label correction
    T = solver(np.full((3, 3, 3), 5.0), [(1, 1, 1)], [3.0, 0.0, 0.0], order=order,
               source_ball=ball)
    u2, d2 = (S41 + 3) / 16, (S41 - 3) / 16  # (-1, 1, 0), (1, 1, 0)
    u3, d3 = (S57 + 3) / 16, (S57 - 3) / 16  # (-1, 1, 1), (1, 1, 1)
    c = math.sqrt(2) / 4                     # (0, 1, 1)
    expected = np.array([
        [[u3, u2, u3], [u2, 0.5, u2], [u3, u2, u3]],        # x = 0: upwind
        [[c, 0.25, c], [0.25, 0.0, 0.25], [c, 0.25, c]],    # x = 1: across
        [[d3, d2, d3], [d2, 0.125, d2], [d3, d2, d3]],      # x = 2: downwind
    ])
    _same(T, expected)


@pytest.mark.parametrize("order", [1, 2])
def test_plane_wave_beyond_the_ball(solver, order):
    # a line of sources along x = 0, V = 2, w = (1, 0): T = x / 3 everywhere
    T = solver(np.full((6, 3), 2.0), [(0, 0), (0, 1), (0, 2)], [1.0, 0.0], order=order)
    _same(T, np.repeat(np.arange(6)[:, None] / 3.0, 3, axis=1))


def test_refused_node_blocks_a_strip(solver):
    # node 3 has V = 0.5 < |w| = 0.6: refused, so 3..5 are never reached; 0..2 fly
    # across the wind at sqrt(1 - 0.36) = 0.8 m/s
    speed = np.array([[1.0], [1.0], [1.0], [0.5], [1.0], [1.0]])
    T = solver(speed, [(0, 0)], [0.0, 0.6])
    _same(T, [[0.0], [1.25], [2.5], [INF], [INF], [INF]])


def test_refused_column_is_never_crossed(solver):
    speed = np.full((6, 5), 1.0)
    speed[3, :] = 0.4  # |w| = 0.5 >= 0.4 on the whole column
    T = solver(speed, [(0, 2)], [0.3, 0.4])
    assert np.all(np.isfinite(T[:3])) and np.all(np.isinf(T[3:]))


def test_no_corner_cutting_between_diagonal_walls(solver):
    # (1, 0) and (0, 1) impassable: the diagonal step to (1, 1) would squeeze between
    # them, so nothing but the source is reached
    speed = np.ones((3, 3))
    speed[1, 0] = speed[0, 1] = 0.0
    T = solver(speed, [(0, 0)], [0.1, 0.1])
    expected = np.full((3, 3), INF)
    expected[0, 0] = 0.0
    _same(T, expected)


def test_no_corner_cutting_in_3d(solver):
    # a corner step (1, 1, 1) needs all 8 nodes of its cube: one wall node is enough
    speed = np.ones((2, 2, 2))
    for p in [(1, 0, 0), (0, 1, 0), (0, 0, 1), (1, 1, 0), (1, 0, 1), (0, 1, 1)]:
        speed[p] = 0.0
    T = solver(speed, [(0, 0, 0)], [0.1, 0.0, 0.0])
    assert T[0, 0, 0] == 0.0 and np.isinf(T[1, 1, 1])


@pytest.mark.parametrize("ball, expected", [
    # ball nodes 1..5 are frozen from the start (as the isotropic solver: nodes frozen by
    # the initialisation are returned); the march pops 3, 4, 5 and stops
    (True, [INF, 1.0, 0.5, 0.0, 0.125, 0.25, INF]),
    (False, [INF, INF, INF, 0.0, 0.125, 0.25, INF]),
])
def test_early_stop(solver, ball, expected):
    T = solver(np.full((7, 1), 5.0), [(3, 0)], [3.0, 0.0], stop_at=[(5, 0)], source_ball=ball,
               order=1)
    _same(T, np.array(expected)[:, None])


def test_towards_the_source_is_the_opposite_wind(solver):
    # time to fly from each node *to* node 3: upwind legs now on the +x side
    T = solver(np.full((7, 1), 5.0), [(3, 0)], [3.0, 0.0], towards=True)
    _same(T, [[0.375], [0.25], [0.125], [0.0], [0.5], [1.0], [1.5]])
