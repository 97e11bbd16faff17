"""The ground along straight segments: every kink and top of the bilinear DEM (exact)."""

import numpy as np
import pytest

from fm2uav import World
from fm2uav.world.segments import ground_points, surface_points


def _brute(world, a, b, n=200_001):
    t = np.linspace(0.0, 1.0, n)
    p = a[None, :] + t[:, None] * (b - a)[None, :]
    return np.asarray(world.ground_height(p[:, 0], p[:, 1]), dtype=float)


@pytest.fixture(scope="module")
def rough():
    rng = np.random.default_rng(3)
    return World.from_heightmap(rng.uniform(0, 80, (30, 25)), 10.0, 12)


def test_the_maximum_and_minimum_are_exact_on_a_rough_grid(rough):
    rng = np.random.default_rng(1)
    b = rough.bounds
    lo, hi = [b[0, 0] - 20, b[1, 0] - 20], [b[0, 1] + 20, b[1, 1] + 20]  # also off the map
    a, c = rng.uniform(lo, hi, (16, 2)), rng.uniform(lo, hi, (16, 2))
    lp = ground_points(rough, a, c)
    mx, mn = lp.reduce(np.maximum, 16), lp.reduce(np.minimum, 16)
    for k in range(16):
        g = _brute(rough, a[k], c[k])
        # a fine sampler never finds more than the exact maximum, and gets within millimetres of it
        assert g.max() <= mx[k] + 1e-9 and g.max() >= mx[k] - 5e-3
        assert g.min() >= mn[k] - 1e-9 and g.min() <= mn[k] + 5e-3
    # sorted by segment then t, both ends of every segment present
    assert np.all(np.diff(lp.segment) >= 0)
    for k in range(16):
        t = lp.t[lp.segment == k]
        assert t[0] == 0.0 and t[-1] == 1.0 and np.all(np.diff(t) >= 0)


def test_a_sampler_at_a_fixed_step_misses_a_kink_the_exact_reading_does_not():
    h = np.zeros((5, 3))
    h[2, :] = 100.0  # a one-node ridge: kink at x = 20
    w = World.from_heightmap(h, 10.0, 12)
    a, b = np.array([[0.3, 5.0]]), np.array([[39.7, 5.0]])
    assert ground_points(w, a, b).reduce(np.maximum, 1)[0] == pytest.approx(100.0)
    t = np.arange(0, 1.0001, 0.07)
    p = a[0] + t[:, None] * (b[0] - a[0])
    assert np.asarray(w.ground_height(p[:, 0], p[:, 1])).max() < 99.0


def test_roofs_are_read_in_every_column_the_line_crosses():
    h = np.zeros((20, 20))
    w = World.from_heightmap(h, 5.0, 20)
    occ = np.array(w.occupancy)
    occ[10, 10, :9] = True  # a one-column tower, roof at z = 40
    w = World(occ, spacing=w.spacing, origin=w.origin, terrain=w.terrain)
    s = surface_points(w, [[2.0, 2.0]], [[90.0, 92.0]])
    assert s.reduce(np.maximum, 1)[0] == pytest.approx(40.0)
    # a line passing beside the column's cell sees no roof
    s2 = surface_points(w, [[2.0, 80.0]], [[90.0, 80.0]])
    assert s2.reduce(np.maximum, 1)[0] == pytest.approx(0.0)


def test_a_flat_world_and_zero_length_segments():
    w = World(np.zeros((10, 10, 4), bool), spacing=1.0, origin=(0, 0, 7.0))
    lp = ground_points(w, [[1, 1], [3, 3]], [[5, 5], [3, 3]])
    assert np.all(lp.z == 7.0) and lp.reduce(np.maximum, 2).tolist() == [7.0, 7.0]
