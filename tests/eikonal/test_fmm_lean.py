"""The lean layout of the march (big grids): float32 ``1 / speed^2``, result compacted
in place in the padded time buffer, the start given as a box (``_kernels.Start``).

Forced on small grids with ``LEAN_NODES = 0``; compared with the float64 layout of
the same march: bit for bit where ``1 / speed^2`` is exact in float32 (powers of
two), to ~1e-8 relative elsewhere.
"""

from __future__ import annotations

import numpy as np
import pytest

from fm2uav.eikonal import _kernels, fast_marching
from fm2uav.eikonal.restart import remarch

from .fmm_checks import assert_same_field


@pytest.fixture
def lean(monkeypatch):
    """Every march in the lean layout; records the layouts used."""
    used = []
    original = _kernels.march

    def spy(*args, **kwargs):
        T, frozen = original(*args, **kwargs)
        used.append(T.base is not None)  # lean: a view of the march's time buffer
        return T, frozen

    monkeypatch.setattr(_kernels, "LEAN_NODES", 0)
    monkeypatch.setattr(_kernels, "march", spy)
    return used


def _speeds(shape, seed):
    return np.random.default_rng(seed).uniform(0.5, 2.0, shape)


@pytest.mark.parametrize("order", [1, 2])
@pytest.mark.parametrize("shape", [(61, 47), (23, 19, 17)])
def test_powers_of_two_speeds_give_the_same_times_bit_for_bit(shape, order, lean):
    # 1 / v^2 of a power of two is exact in float32: the two layouts do the same
    # arithmetic (ball, walls, order-2 switching and all).
    rng = np.random.default_rng(1)
    speed = 2.0 ** rng.integers(-2, 3, shape).astype(float)
    speed[tuple(s // 3 for s in shape)] = 0.0  # a wall node
    src = [tuple(s // 2 for s in shape), (0,) * len(shape)]
    T = fast_marching(speed, src, order=order, spacing=0.7)
    assert lean == [True]
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(_kernels, "LEAN_NODES", 2**40)
        full = fast_marching(speed, src, order=order, spacing=0.7)
    np.testing.assert_array_equal(T, full)
    assert np.isinf(T[tuple(s // 3 for s in shape)])


@pytest.mark.parametrize("order", [1, 2])
@pytest.mark.parametrize("shape", [(80, 70), (30, 26, 22)])
def test_smooth_speeds_agree_to_float32_rounding(shape, order, lean):
    speed = _speeds(shape, 2)
    src = [tuple(s // 3 for s in shape)]
    T = fast_marching(speed, src, order=order)
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(_kernels, "LEAN_NODES", 2**40)
        full = fast_marching(speed, src, order=order)
    assert_same_field(T, full, 1e-7)
    assert lean == [True, False]  # the lean march, then the float64 one


def test_stop_at_and_the_result_buffer(lean):
    # the march stops once the stop node is frozen; nodes not frozen are inf
    speed = _speeds((40, 30, 20), 3)
    T = fast_marching(speed, [(2, 2, 2)], stop_at=[(20, 15, 10)])
    assert np.isfinite(T[20, 15, 10]) and np.isinf(T[39, 29, 19])
    assert T.flags.c_contiguous and T.flags.writeable
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(_kernels, "LEAN_NODES", 2**40)
        full = fast_marching(speed, [(2, 2, 2)], stop_at=[(20, 15, 10)])
    np.testing.assert_array_equal(np.isfinite(T), np.isfinite(full))
    assert_same_field(T, full, 1e-7)
    assert lean == [True, False]


def test_restart_over_the_whole_grid(lean):
    v = np.ones((40, 40, 12))
    T0 = fast_marching(v, [(3, 3, 3)], order=1)
    v2 = v.copy()
    v2[20:25, 10:30, :] = 0.0
    T1 = remarch(v2, [(3, 3, 3)], T0, v2 != v, order=1)
    np.testing.assert_array_equal(T1, fast_marching(v2, [(3, 3, 3)], order=1))
    assert all(lean)


@pytest.mark.parametrize("shape", [(50, 40), (20, 18, 16)])
def test_many_sources_and_a_wide_start_box(shape, lean):
    # sources far apart: the start box spans the grid; > 64 sources: no ball
    rng = np.random.default_rng(4)
    speed = _speeds(shape, 5)
    few = [(0,) * len(shape), tuple(s - 1 for s in shape)]
    many = [tuple(int(rng.integers(0, s)) for s in shape) for _ in range(80)]
    for src in (few, many):
        T = fast_marching(speed, src)
        with pytest.MonkeyPatch.context() as mp:
            mp.setattr(_kernels, "LEAN_NODES", 2**40)
            assert_same_field(T, fast_marching(speed, src), 1e-7)
        assert np.all(T[tuple(np.array(src).T)] == 0.0)
    assert lean == [True, False] * 2
