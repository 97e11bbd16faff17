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


def test_exact_on_a_reprojected_geotiff(rough_tif):
    w = World.from_dem(str(rough_tif), (120.0, 120.0, 40.0))
    assert w.ground is not None
    rng = np.random.default_rng(2)
    b = w.bounds
    a, c = (rng.uniform([b[0, 0], b[1, 0]], [b[0, 1], b[1, 1]], (6, 2)) for _ in range(2))
    mx = ground_points(w, a, c).reduce(np.maximum, 6)
    for k in range(6):
        g = _brute(w, a[k], c[k], n=20_001)
        assert g.max() <= mx[k] + 1e-6 and g.max() >= mx[k] - 0.05


def test_two_dems_in_priority_order_are_read_on_both_sides_of_their_seam():
    from fm2uav.world.ground_model import GroundLayer, GroundModel

    rng = np.random.default_rng(4)
    z1 = rng.uniform(0, 50, (20, 20))
    valid = np.ones_like(z1, bool)
    valid[:, 10:] = False  # the first DEM measures the western half only
    z2 = rng.uniform(100, 150, (20, 20))  # the fill DEM, much higher
    tr = (10.0, 0.0, 0.0, 0.0, -10.0, 200.0)  # 10 m pixels, north-up, x 0..200, y 0..200
    crs = "EPSG:32630"
    layers = (GroundLayer(z1, valid, tr, crs, crs, 10.0, "a"),
              GroundLayer(z2, np.ones_like(z2, bool), tr, crs, crs, 10.0, "b"))
    occ = np.zeros((20, 20, 30), bool)
    w = World(occ, spacing=10.0, terrain=np.zeros((20, 20)), crs=crs,
              ground=GroundModel(layers))
    a, c = np.array([[5.0, 100.0], [5.0, 20.0]]), np.array([[195.0, 110.0], [60.0, 180.0]])
    mx = ground_points(w, a, c).reduce(np.maximum, 2)
    for k in range(2):
        g = _brute(w, a[k], c[k], n=100_001)
        assert g.max() <= mx[k] + 1e-6 and g.max() >= mx[k] - 0.05
