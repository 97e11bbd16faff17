"""clearance_profile: exact distances to obstacle nodes."""

import numpy as np
import pytest

from fm2uav import World
from fm2uav.world import clearance_profile


def test_single_obstacle_node_exact():
    occ = np.zeros((10, 10, 5), bool)
    occ[3, 4, 2] = True
    w = World(occ, spacing=(2.0, 1.0, 0.5), origin=(100.0, 0.0, 0.0))
    pts = np.array([[106.0, 4.0, 1.0], [100.0, 0.0, 0.0], [110.5, 9.0, 2.0]])
    target = np.array([106.0, 4.0, 1.0])
    np.testing.assert_allclose(clearance_profile(w, pts), np.linalg.norm(pts - target, axis=1))


def test_matches_brute_force_on_random_map():
    rng = np.random.default_rng(1)
    occ = rng.random((15, 12, 6)) < 0.15
    w = World(occ, spacing=(1.0, 1.5, 2.0))
    pts = rng.random((50, 3)) * (np.array(occ.shape) - 1) * w.spacing
    obst = w.to_world(np.argwhere(occ))
    brute = np.min(np.linalg.norm(pts[:, None] - obst[None], axis=2), axis=1)
    np.testing.assert_allclose(clearance_profile(w, pts), brute)


def test_no_obstacle_is_inf():
    w = World(np.zeros((4, 4), bool), spacing=1.0)
    assert np.all(np.isinf(clearance_profile(w, [[1.0, 1.0]])))


def test_cache_is_per_world():
    occ = np.zeros((5, 5), bool)
    occ[0, 0] = True
    a = World(occ, spacing=1.0)
    occ2 = occ.copy()
    occ2[0, 0] = False
    occ2[4, 4] = True
    b = World(occ2, spacing=1.0)
    assert clearance_profile(a, [[0.0, 1.0]])[0] == pytest.approx(1.0)
    assert clearance_profile(b, [[0.0, 1.0]])[0] == pytest.approx(np.hypot(4, 3))


def test_column_world_search_matches_kdtree():
    # a height-map world (solid columns) uses the ring search; compare it with
    # brute force over all obstacle nodes at random points (some inside the
    # terrain) and with the k-d tree of boundary nodes at the free points
    # (the tree is exact only for free points, which paths are)
    from fm2uav.world.clearance import column_surface, obstacle_tree

    rng = np.random.default_rng(5)
    heights = rng.random((23, 17)) * 9.0
    heights[5:9, 3:6] = 0.0
    w = World.from_heightmap(heights, (2.0, 1.5, 1.0), 14, origin=(10.0, -5.0, 0.0))
    assert column_surface(w) is not None
    pts = w.to_world(rng.random((300, 3)) * (np.array(w.shape) - 1))
    obst = w.to_world(np.argwhere(w.occupancy))
    brute = np.min(np.linalg.norm(pts[:, None] - obst[None], axis=2), axis=1)
    got = clearance_profile(w, pts)
    np.testing.assert_allclose(got, brute, rtol=1e-12)
    free = ~w.occupancy[tuple(np.floor(w.to_index(pts) + 0.5).astype(int).T)]
    tree_d, _ = obstacle_tree(w).query(pts[free])
    np.testing.assert_allclose(got[free], tree_d, rtol=1e-12)


def test_non_column_world_uses_tree():
    from fm2uav.world.clearance import column_surface

    occ = np.zeros((6, 6, 6), bool)
    occ[2, 2, 4] = True  # a floating block: not a solid column
    w = World(occ, spacing=1.0)
    assert column_surface(w) is None
    assert clearance_profile(w, [[2.0, 2.0, 1.0]])[0] == pytest.approx(3.0)
