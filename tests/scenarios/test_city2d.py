"""The 2D city map of the curvature study and its start/goal pairs."""

import numpy as np
from scipy import ndimage

from fm2uav.scenarios import get_scenario
from fm2uav.scenarios.city2d import city2d_pairs, city2d_world


def test_city_map():
    w = city2d_world()
    assert w.ndim == 2 and w.shape == (201, 151) and w.spacing == (2.0, 2.0)
    free = ~w.occupancy
    assert 0.25 < free.mean() < 0.5
    _, n = ndimage.label(free)
    assert n == 1  # every free node is reachable
    assert w.occupancy[w.to_cell((196.0, 150.0))]  # the Centre Pompidou
    assert not w.occupancy[w.to_cell((130.0, 150.0))]  # its piazza
    assert city2d_world() is w


def test_pairs_are_seeded_free_and_far_apart():
    w = city2d_world()
    s, g = city2d_pairs(24, 0)
    s2, g2 = city2d_pairs(24, 0)
    assert np.array_equal(s, s2) and np.array_equal(g, g2)
    assert not np.array_equal(s, city2d_pairs(24, 1)[0])
    assert s.shape == g.shape == (24, 2)
    assert np.all(np.linalg.norm(s - g, axis=1) >= 150.0)
    for p in np.vstack([s, g]):
        assert not w.occupancy[w.to_cell(p)]


def test_registered_scenario():
    sc = get_scenario("city2d")
    assert sc.world is city2d_world()
    assert np.array_equal(sc.start, city2d_pairs(1, 0)[0][0])
