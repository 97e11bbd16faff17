"""remarch: re-using the arrival times a local speed change cannot reach."""

from __future__ import annotations

import numpy as np
import pytest

from fm2uav.eikonal import fast_marching
from fm2uav.eikonal.restart import remarch


@pytest.mark.parametrize("order", [1, 2])
@pytest.mark.parametrize("seed", [0, 1, 2])
def test_remarch_equals_full_march_2d(order, seed):
    rng = np.random.default_rng(seed)
    v = 0.5 + rng.random((60, 50))
    src = [(3, 4)]
    T0 = fast_marching(v, src, spacing=(1.0, 0.7), order=order)
    v2 = v.copy()
    i, j = rng.integers(25, 45, size=2)
    v2[i : i + 6, j : j + 3] = 0.0  # a new obstacle far from the source
    v2[50:55, 10:14] *= 1.7  # and a faster patch
    T1 = remarch(v2, src, T0, v2 != v, spacing=(1.0, 0.7), order=order)
    full = fast_marching(v2, src, spacing=(1.0, 0.7), order=order)
    assert np.array_equal(np.isinf(T1), np.isinf(full))
    fin = np.isfinite(full)
    np.testing.assert_allclose(T1[fin], full[fin], rtol=1e-12, atol=1e-12)


def test_remarch_obstacle_removed_3d():
    v = np.ones((24, 20, 10))
    v[10:12, :, :] = 0.0
    v[10:12, 15:18, 3:6] = 1.0  # a hole
    src = [(2, 2, 2)]
    T0 = fast_marching(v, src, order=2)
    v2 = v.copy()
    v2[10:12, 2:5, 2:5] = 1.0  # a second hole
    T1 = remarch(v2, src, T0, v2 != v, order=2)
    full = fast_marching(v2, src, order=2)
    fin = np.isfinite(full)
    assert np.array_equal(fin, np.isfinite(T1))
    np.testing.assert_allclose(T1[fin], full[fin], rtol=1e-12)
    assert T1[20, 3, 3] < T0[20, 3, 3]  # the new hole is a shortcut


def test_remarch_near_source_and_stop():
    v = np.ones((40, 40))
    T0 = fast_marching(v, [(20, 20)], order=2)
    v2 = v.copy()
    v2[21, 21] = 0.3  # inside the source ball: full march
    np.testing.assert_allclose(
        remarch(v2, [(20, 20)], T0, v2 != v), fast_marching(v2, [(20, 20)], order=2)
    )
    v3 = v.copy()
    v3[35:38, 5:30] = 0.0
    T3 = remarch(v3, [(20, 20)], T0, v3 != v, stop_at=[(39, 20)])
    assert np.isfinite(T3[39, 20])
    ref = fast_marching(v3, [(20, 20)], order=2)
    assert T3[39, 20] == pytest.approx(ref[39, 20], rel=1e-12)
    assert np.array_equal(remarch(v, [(20, 20)], T0, np.zeros_like(v, bool)), T0)


def test_remarch_bad_shapes():
    from fm2uav.errors import InputError

    with pytest.raises(InputError, match="must have the speed's shape"):
        remarch(np.ones((5, 5)), [(0, 0)], np.zeros((4, 5)), np.zeros((5, 5), bool))
