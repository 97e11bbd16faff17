"""Compiled wind march vs its pure-Python twin, the discrete equations, and seeded
property checks (hypothesis, derandomised).

The compiled solver (``_wind_kernels``) and the reference (``_wind_reference``)
implement the same discretisation with the same float operations up to their
order, so they agree to rounding; ``rtol = 1e-9`` leaves room for that and would
still catch a different stencil, order rule, pruning or label correction (which
change values at the 1e-4 level or more).
"""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from fm2uav.eikonal import _wind_kernels, _wind_sources, fmm
from fm2uav.eikonal import _wind_reference as reference
from fm2uav.eikonal.wind import zermelo_march
from fm2uav.eikonal._wind_reference import zermelo_march_reference

RTOL = 1e-9
SEEDED = settings(max_examples=25, deadline=None, derandomize=True)


def _same(actual, desired, rtol=RTOL):
    np.testing.assert_array_equal(np.isinf(actual), np.isinf(desired))
    fin = np.isfinite(desired)
    np.testing.assert_allclose(actual[fin], desired[fin], rtol=rtol, atol=1e-300)


def test_reference_constants_match_the_compiled_solver():
    assert reference.SOURCE_RADIUS_CELLS == fmm.SOURCE_INIT_CELLS
    assert reference.SOURCE_RADIUS_FRACTION == fmm.SOURCE_INIT_FRACTION
    assert reference.MAX_BALL_SOURCES == fmm.MAX_BALL_SOURCES
    assert reference.BALL_MAX_SPEED_RATIO == _wind_sources.BALL_MAX_SPEED_RATIO
    assert reference.ORDER2_MAX_SPEED_RATIO == _wind_kernels.ORDER2_MAX_SPEED_RATIO
    assert reference.ORDER2_MAX_WIND_CHANGE == _wind_kernels.ORDER2_MAX_WIND_CHANGE
    assert reference.CONE_TOL == _wind_kernels.CONE_TOL
    assert reference.REOPEN_RTOL == _wind_kernels.REOPEN_RTOL


def _random_case(rng, ndim, rough=True):
    """Random speeds with ~12 % walls, a wind up to 0.95 of the airspeed (per node or
    constant), 1-3 sources on passable nodes, random spacing."""
    shape = tuple(int(n) for n in rng.integers(3, 12 if ndim == 2 else 7, size=ndim))
    if rough:
        speed = rng.uniform(0.5, 3.0, shape)
    else:  # smooth: the balls are clean and factored
        axes = np.meshgrid(*[np.linspace(0, 1, n) for n in shape], indexing="ij")
        speed = 1.5 + 0.3 * np.sin(2 * axes[0]) * np.cos(axes[1])
    speed[rng.random(shape) < (0.12 if rough else 0.0)] = 0.0
    if rng.random() < 0.3:
        wind = rng.normal(size=ndim) * rng.uniform(0.1, 0.8)
    elif rough:
        wind = rng.normal(size=shape + (ndim,))
        wind *= (rng.uniform(0, 0.95, shape) * speed
                 / np.maximum(np.linalg.norm(wind, axis=-1), 1e-9))[..., None]
    else:
        axes = np.meshgrid(*[np.linspace(-1, 1, n) for n in shape], indexing="ij")
        ratio = rng.uniform(0.2, 0.9)
        comps = [-axes[1], axes[0]] + [0.2 * a for a in axes[2:]]
        wind = ratio * np.stack(comps, axis=-1) / 1.5
    w2 = np.sum(np.broadcast_to(wind, shape + (ndim,)) ** 2, axis=-1)
    free = np.argwhere((speed > 0) & (w2 < speed ** 2))
    if len(free) == 0:
        speed.flat[0] = 10.0
        free = np.argwhere((speed > 0) & (w2 < speed ** 2))
    src = free[rng.choice(len(free), size=min(int(rng.integers(1, 4)), len(free)),
                          replace=False)]
    spacing = tuple(rng.uniform(0.3, 2.0, size=ndim)) if rng.random() < 0.5 else 1.0
    return speed, wind, src, spacing


@pytest.mark.parametrize("seed", range(10))
@pytest.mark.parametrize("ndim", [2, 3])
@pytest.mark.parametrize("order", [1, 2])
@pytest.mark.parametrize("rough", [True, False])
def test_compiled_matches_reference(seed, ndim, order, rough):
    rng = np.random.default_rng([seed, ndim, order, rough])
    speed, wind, src, spacing = _random_case(rng, ndim, rough)
    T = zermelo_march(speed, src, wind, spacing=spacing, order=order).times
    R = zermelo_march_reference(speed, src, wind, spacing=spacing, order=order)
    _same(T, R)


@pytest.mark.parametrize("seed", range(6))
@pytest.mark.parametrize("ndim", [2, 3])
def test_compiled_matches_reference_with_stop_and_towards(seed, ndim):
    rng = np.random.default_rng([seed, ndim, 7])
    speed, wind, src, spacing = _random_case(rng, ndim, rough=seed % 2 == 0)
    stops = np.argwhere(speed > 0)[rng.choice(int((speed > 0).sum()), size=2)]
    kw = dict(spacing=spacing, order=1 + seed % 2, stop_at=stops, towards=True)
    T = zermelo_march(speed, src, wind, **kw).times
    R = zermelo_march_reference(speed, src, wind, **kw)
    _same(T, R)


def test_compiled_matches_reference_with_many_sources_no_ball():
    rng = np.random.default_rng(5)
    speed = rng.uniform(1.0, 2.0, (14, 12))
    src = np.argwhere(rng.random((14, 12)) < 0.45)[:70]  # > 64 sources: no ball
    assert len(src) > 64
    T = zermelo_march(speed, src, [0.4, -0.3]).times
    _same(T, zermelo_march_reference(speed, src, [0.4, -0.3]))


# ------------------------------------------------------------ the discrete equations
def _fixed_point_residual(speed, wind, src, spacing, T):
    """max |T(y) - min over y's stencil of the scheme's candidates| / T(y) (order 1)."""
    ndim = speed.ndim
    shape = speed.shape + (1,) * (3 - ndim)
    h = tuple(np.broadcast_to(np.asarray(spacing, float), (ndim,))) + (1.0,) * (3 - ndim)
    w3 = np.zeros(shape + (3,))
    w3[..., :ndim] = np.broadcast_to(wind, speed.shape + (ndim,)).reshape(shape + (ndim,))
    grid = reference._Grid(speed.reshape(shape), w3, h, ndim)
    march = reference._March(grid, 1)
    T3 = T.reshape(shape)
    times = {p: float(T3[p]) for p in itertools.product(*map(range, shape))
             if np.isfinite(T3[p])}
    march.frozen = {p: True for p in times}
    sources = {tuple(s) + (0,) * (3 - ndim) for s in src}
    worst = 0.0
    for y, ty in times.items():
        if y in sources:
            continue
        best = math.inf
        for k, o in enumerate(march.offs):
            v = tuple(y[i] + o[i] for i in range(3))
            if v in times:
                best = min(best, march.evaluate(times, y, k))
        worst = max(worst, abs(ty - best) / ty)
    return worst


@pytest.mark.parametrize("seed", range(8))
@pytest.mark.parametrize("ndim", [2, 3])
def test_order1_solves_the_discrete_equations(seed, ndim):
    # every reached node equals the smallest candidate of its stencil with the final
    # values, also where the stencil is not acute (winds up to 0.95 V: label correction)
    rng = np.random.default_rng([seed, ndim, 11])
    speed, wind, src, spacing = _random_case(rng, ndim, rough=True)
    res = zermelo_march(speed, src, wind, spacing=spacing, order=1, source_ball=False)
    assert _fixed_point_residual(speed, wind, src, spacing, res.times) < 1e-12


def test_label_correction_is_needed_and_works():
    # a strong crosswind (0.9 V): nodes are re-opened, and the result is still the
    # discrete solution; without the corrections a plain march would stop short of it
    speed = np.ones((15, 13))
    wind = np.array([0.0, 0.9])
    res = zermelo_march(speed, [(7, 6)], wind, order=1, source_ball=False)
    assert res.reopened > 0
    assert _fixed_point_residual(speed, wind, [(7, 6)], 1.0, res.times) < 1e-12


# ------------------------------------------------------------ early stop
@pytest.mark.parametrize("seed", range(8))
@pytest.mark.parametrize("ndim", [2, 3])
def test_early_stop_equals_the_full_march_on_settled_nodes(seed, ndim):
    rng = np.random.default_rng([seed, ndim, 3])
    speed, wind, src, spacing = _random_case(rng, ndim, rough=seed % 2 == 0)
    order = 1 + seed % 2
    full = zermelo_march(speed, src, wind, spacing=spacing, order=order).times
    reach = np.argwhere(np.isfinite(full))
    stops = reach[rng.choice(len(reach), size=min(2, len(reach)), replace=False)]
    part = zermelo_march(speed, src, wind, spacing=spacing, order=order, stop_at=stops).times
    settled = np.isfinite(part)
    assert np.all(settled[tuple(stops.T)])
    assert part[settled].tobytes() == full[settled].tobytes()


def test_early_stop_stops_early_in_a_causal_grid():
    speed = np.ones((60, 60))
    res = zermelo_march(speed, [(5, 5)], [0.3, 0.2], stop_at=[(10, 10)])
    assert np.isinf(res.times).sum() > 3000 and res.pops < 400


# ------------------------------------------------------------ properties
@st.composite
def grids(draw):
    """A small 2D grid: speeds with walls, a constant or per-node wind, one source;
    no ball (it depends on how smooth the speed is, which breaks the comparisons)."""
    nx, ny = draw(st.integers(3, 9)), draw(st.integers(3, 9))
    seed = draw(st.integers(0, 2**32 - 1))
    rng = np.random.default_rng(seed)
    speed = rng.uniform(0.5, 3.0, (nx, ny))
    speed[rng.random((nx, ny)) < 0.15] = 0.0
    ratio = draw(st.floats(0.0, 0.95))
    if draw(st.booleans()):
        wind = rng.normal(size=2)
        wind *= ratio * 0.5 / max(np.linalg.norm(wind), 1e-9)
    else:
        wind = rng.normal(size=(nx, ny, 2))
        wind *= (ratio * speed / np.maximum(np.linalg.norm(wind, axis=-1), 1e-9))[..., None]
    w2 = np.sum(np.broadcast_to(wind, (nx, ny, 2)) ** 2, axis=-1)
    free = np.argwhere((speed > 0) & (w2 < speed ** 2))
    if len(free) == 0:
        speed[0, 0] = 5.0
        free = np.argwhere((speed > 0) & (w2 < speed ** 2))
    src = tuple(free[rng.integers(len(free))])
    return speed, wind, src


def _march(speed, wind, src, **kw):
    return zermelo_march(speed, [src], wind, order=1, source_ball=False, **kw).times


@SEEDED
@given(case=grids(), gain=st.floats(1.0, 3.0))
def test_faster_airspeed_is_never_later(case, gain):
    speed, wind, src = case
    T = _march(speed, wind, src)
    faster = speed * np.where(np.random.default_rng(0).random(speed.shape) < 0.5, gain, 1.0)
    T2 = _march(faster, wind, src)
    assert np.all(T2 <= T * (1 + 1e-12))


@SEEDED
@given(case=grids(), extra=st.integers(0, 80))
def test_another_source_is_never_later(case, extra):
    speed, wind, src = case
    T = _march(speed, wind, src)
    reach = np.argwhere(np.isfinite(T))
    other = tuple(reach[extra % len(reach)])
    T2 = zermelo_march(speed, [src, other], wind, order=1, source_ball=False).times
    assert np.all(T2 <= T * (1 + 1e-12))


@SEEDED
@given(case=grids(), extra=st.integers(0, 80))
def test_a_wall_is_never_earlier(case, extra):
    speed, wind, src = case
    T = _march(speed, wind, src)
    walled = speed.copy()
    cells = np.argwhere(speed > 0)
    cell = tuple(cells[extra % len(cells)])
    if cell == src:
        return
    walled[cell] = 0.0
    T2 = _march(walled, wind, src)
    assert np.all(T2 >= T * (1 - 1e-12))


@SEEDED
@given(case=grids())
def test_every_reached_node_has_an_earlier_neighbour(case):
    # causality of the scheme: a candidate is never below all of its vertices
    speed, wind, src = case
    T = _march(speed, wind, src)
    nx, ny = T.shape
    for i, j in np.argwhere(np.isfinite(T)):
        if (i, j) == src:
            continue
        around = [T[a, b] for a in range(max(i - 1, 0), min(i + 2, nx))
                  for b in range(max(j - 1, 0), min(j + 2, ny)) if (a, b) != (i, j)]
        assert min(around) < T[i, j]


@SEEDED
@given(case=grids(), k=st.integers(-3, 3))
def test_scaling_speed_and_wind_divides_times(case, k):
    speed, wind, src = case
    c = 2.0 ** k
    T = _march(speed, wind, src)
    T2 = _march(speed * c, np.asarray(wind) * c, src)
    _same(T2, T / c, rtol=1e-12)


@SEEDED
@given(case=grids())
def test_towards_is_the_opposite_wind(case):
    speed, wind, src = case
    T = _march(speed, wind, src, towards=True)
    assert T.tobytes() == _march(speed, -np.asarray(wind), src).tobytes()
