"""The plateau of the march (``_kernels._plateau``): where many nodes have the grid's
largest speed (an FM² map's saturated W = 1, a constant-speed grid), the march takes
their ``1 / speed^2`` from a register, a bit mask telling which nodes (none for a
uniform grid). The times must be those of the march that reads every speed, bit for
bit: the same value enters the same arithmetic.
"""

from __future__ import annotations

import numpy as np
import pytest

from fm2uav.eikonal import _kernels, fast_marching
from fm2uav.eikonal.restart import remarch


@pytest.fixture
def paths(monkeypatch):
    """Records the plateau path of every march: 'none', 'uniform' or 'mask'."""
    used = []
    original = _kernels._plateau

    def spy(*args, **kwargs):
        U, qp = original(*args, **kwargs)
        used.append("none" if qp == 0.0 else "uniform" if U.size == 1 else "mask")
        return U, qp

    monkeypatch.setattr(_kernels, "_plateau", spy)
    return used


@pytest.fixture
def separate(monkeypatch):
    """2D marches in the separate arrays, whose plateau mask these tests check: by default
    a 2D map that is not uniform marches interleaved and reads every speed
    (``_kernels._buffers``, tests/eikonal/test_kernels_layout.py)."""
    original = _kernels._buffers
    monkeypatch.setattr(_kernels, "_buffers", lambda speed, shape3, npad, lean, interleave, **kw:
                        original(speed, shape3, npad, lean, False, **kw))


def _without_plateau(fn):
    """``fn()`` with the plateau switched off (every speed read from the grid)."""
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(_kernels, "_plateau", lambda *args, **kwargs: (_kernels._NO_BITS, 0.0))
        return fn()


def _plateau_field(shape, seed, vmax=1.3, share=0.7, walls=0.08):
    """Speed ``vmax`` on ~``share`` of the nodes, random lower speeds between them, walls."""
    rng = np.random.default_rng(seed)
    v = np.where(rng.random(shape) < share, vmax, rng.uniform(0.4 * vmax, vmax, shape))
    v[rng.random(shape) < walls] = 0.0
    return v


def _sources(v):
    """Two free nodes, one near the middle, one near a corner."""
    free = np.argwhere(v > 0)
    mid = np.asarray(v.shape) // 2
    a = free[np.argmin(((free - mid) ** 2).sum(axis=1))]
    b = free[np.argmin((free ** 2).sum(axis=1))]
    return [tuple(int(x) for x in a), tuple(int(x) for x in b)]


CASES = [((67, 53), 1.0), ((67, 53), (0.7, 1.1)), ((19, 23, 17), 1.0),
         ((19, 23, 17), (1.0, 0.8, 1.2))]


@pytest.mark.parametrize("order", [1, 2])
@pytest.mark.parametrize("shape,spacing", CASES)
@pytest.mark.parametrize("seed", [0, 1])
def test_mask_gives_the_times_of_the_march_that_reads_every_speed(shape, spacing, order,
                                                                   seed, paths, separate):
    v = _plateau_field(shape, seed)
    src = _sources(v)
    T = fast_marching(v, src, order=order, spacing=spacing)
    assert paths == ["mask"]
    ref = _without_plateau(lambda: fast_marching(v, src, order=order, spacing=spacing))
    np.testing.assert_array_equal(T, ref)
    assert np.isinf(T[v == 0]).all() and np.isfinite(T[v > 0]).any()


@pytest.mark.parametrize("order", [1, 2])
@pytest.mark.parametrize("shape,spacing", CASES)
@pytest.mark.parametrize("speed", [1.0, 0.37])
def test_uniform_grid_reads_no_speed_and_gives_the_same_times(shape, spacing, order, speed,
                                                               paths):
    rng = np.random.default_rng(3)
    v = np.full(shape, speed)
    v[rng.random(shape) < 0.1] = 0.0  # walls do not break the uniform path
    src = _sources(v)
    T = fast_marching(v, src, order=order, spacing=spacing, source_ball=False)
    assert paths == ["uniform"]
    ref = _without_plateau(
        lambda: fast_marching(v, src, order=order, spacing=spacing, source_ball=False))
    np.testing.assert_array_equal(T, ref)


@pytest.mark.parametrize("order", [1, 2])
@pytest.mark.parametrize("shape", [(61, 47), (21, 18, 16)])
def test_lean_layout_plateau_is_the_float32_value_of_the_grid(shape, order, paths):
    # 1 / 1.3^2 is not exact in float32: the plateau's value must be rounded as the
    # lean layout rounds the speed grid, or the times would move by ~1e-8
    v = _plateau_field(shape, 5, vmax=1.3)
    src = _sources(v)
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(_kernels, "LEAN_NODES", 0)
        T = fast_marching(v, src, order=order)
        ref = _without_plateau(lambda: fast_marching(v, src, order=order))
    assert paths == ["mask"]
    np.testing.assert_array_equal(T, ref)


def test_restart_keeps_the_plateau_times(paths, separate):
    v = _plateau_field((50, 44), 2)
    src = _sources(v)[:1]
    T0 = fast_marching(v, src, order=1)
    v2 = v.copy()
    v2[20:24, 5:30] = 0.0
    v2[tuple(src[0])] = 1.3
    changed = v2 != v
    T1 = remarch(v2, src, T0, changed, order=1)
    ref = _without_plateau(lambda: remarch(v2, src, T0, changed, order=1))
    np.testing.assert_array_equal(T1, ref)
    assert "mask" in paths


@pytest.mark.parametrize("shape3", [(13, 9, 1), (5, 7, 6), (1, 17, 1)])
def test_plateau_bits_mark_the_padded_nodes_at_the_largest_speed(shape3):
    rng = np.random.default_rng(7)
    v = np.where(rng.random(shape3) < 0.6, 2.0, rng.uniform(0.0, 1.9, shape3))
    two = shape3[2] == 1
    pshape = (shape3[0] + 2, shape3[1] + 2) if two else tuple(n + 2 for n in shape3)
    npad = int(np.prod(pshape))
    bits = np.zeros(npad // 8 + 1, dtype=np.uint8)
    count = _kernels.plateau_bits(v.reshape(-1), 2.0, *shape3, bits)
    mask = np.zeros(pshape, dtype=bool)
    inner = (slice(1, -1),) * len(pshape)
    mask[inner] = (v == 2.0).reshape(tuple(n - 2 for n in pshape))
    expected = np.packbits(mask.reshape(-1), bitorder="little")
    np.testing.assert_array_equal(bits[: expected.size], expected)
    assert count == int((v == 2.0).sum())


@pytest.mark.parametrize("share,path", [(0.3, "none"), (0.8, "mask")])
def test_mask_only_above_the_share_that_pays(share, path, paths, separate):
    v = _plateau_field((60, 60), 4, share=share, walls=0.0)
    fast_marching(v, [(30, 30)], order=1)
    assert paths == [path]


def test_speed_range_ignores_walls():
    assert _kernels.speed_range(np.array([0.0, 2.0, 0.5, 0.0])) == (0.5, 2.0)
    lo, hi = _kernels.speed_range(np.zeros(4))
    assert lo == np.inf and hi == 0.0


@pytest.mark.parametrize("order", [1, 2])
def test_a_2d_map_with_a_plateau_marches_interleaved_without_the_mask(order, paths):
    # the interleaved layout reads a speed beside each time faster than the mask spares
    # it (docs/performance.md): a mixed 2D map builds no mask, and its times are those
    # of the separate arrays with the mask
    v = _plateau_field((67, 53), 0)
    src = _sources(v)
    T = fast_marching(v, src, order=order)
    assert paths == ["none"]
    with pytest.MonkeyPatch.context() as mp:
        original = _kernels._buffers
        mp.setattr(_kernels, "_buffers", lambda speed, shape3, npad, lean, interleave, **kw:
                   original(speed, shape3, npad, lean, False, **kw))
        ref = fast_marching(v, src, order=order)
    assert paths == ["none", "mask"]
    np.testing.assert_array_equal(T, ref)
