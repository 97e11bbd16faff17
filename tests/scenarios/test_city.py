"""The thesis' city scenario: fifteen seeded buildings (scenarios/city.py)."""

from __future__ import annotations

import numpy as np
import pytest

from fm2uav.scenarios import get_scenario
from fm2uav.scenarios.city import city_buildings


@pytest.mark.parametrize("seed", [0, 1, 2, 3])
def test_city_matches_thesis_description(seed):
    fc = city_buildings(seed)
    feats = fc["features"]
    assert len(feats) == 15
    widths = [f["properties"]["width"] for f in feats]
    heights = [f["properties"]["height"] for f in feats]
    assert min(widths) >= 20 and max(widths) <= 60
    assert min(heights) >= 220 and max(heights) <= 390
    sc = get_scenario("city", seed=seed)
    w = sc.world
    assert w.spacing == (5.0, 5.0, 5.0) and w.name == "city"
    # each building column is occupied up to its height
    for f in feats:
        ring = np.array(f["geometry"]["coordinates"][0])
        c = ring[:4].mean(axis=0)
        i, j = w.to_cell(np.array([c[0], c[1], 0.0]))[:2]
        top_z = w.surface_index()[i, j] * 5.0
        assert top_z == pytest.approx(f["properties"]["height"], abs=5.0)
    for p in (sc.start, sc.goal):
        assert not w.occupancy[w.to_cell(p)]
    high = get_scenario("city-high", seed=seed)
    assert high.world is w  # cached, shared
    assert high.start[2] > 390.0 > sc.start[2]


def test_city_is_seeded():
    a = get_scenario("city", seed=5).world.occupancy
    b = get_scenario("city", seed=5).world.occupancy
    c = get_scenario("city", seed=6).world.occupancy
    np.testing.assert_array_equal(a, b)
    assert (a != c).any()
    g = np.random.default_rng(5)
    assert city_buildings(g) == city_buildings(np.random.default_rng(5))
