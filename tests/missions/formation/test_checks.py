"""The reusable checkers: exact separation between samples, inside-terrain test."""

import numpy as np

from fm2uav import World
from fm2uav.missions.formation import inside_terrain, min_separation, pair_distances


def test_crossing_uavs_meet_between_samples():
    # two UAVs swap places along x: 1 m apart at both samples, 0 m in between
    pos = np.array([[[0.0, 0, 0], [1.0, 0, 0]], [[1.0, 0, 0], [0.0, 0, 0]]])
    np.testing.assert_allclose(pair_distances(pos), [1.0, 1.0])
    d, step, pair = min_separation(pos)
    assert d == 0.0 and step == 0 and pair == (0, 1)


def test_parallel_uavs_keep_their_distance():
    t = np.linspace(0, 1, 11)[:, None]
    a = np.hstack([t * 10, 0 * t, 0 * t])
    b = np.hstack([t * 10, 0 * t + 3.0, 0 * t + 4.0])
    d, _, _ = min_separation(np.stack([a, b], axis=1))
    assert abs(d - 5.0) < 1e-12


def test_inside_terrain():
    h = np.zeros((5, 5))
    h[2, 2] = 25.0
    w = World.from_heightmap(h, 10.0, 6)
    pts = np.array([
        [20.0, 20.0, 20.0],   # node (2, 2, 2) is terrain
        [20.0, 20.0, 31.0],   # above the peak
        [0.0, 0.0, 6.0],      # nearest node (0, 0, 1) free and above the ground
        [14.0, 20.0, 9.0],    # nearest node (1, 2, 1) free, but below the interpolated ground (10 m)
        [-1.0, 0.0, 30.0],    # outside the map
    ])
    np.testing.assert_array_equal(inside_terrain(w, pts), [True, False, False, True, True])
