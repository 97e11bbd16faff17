"""World.from_buildings (GeoJSON footprints) and building heights (world/buildings.py)."""

from __future__ import annotations

import numpy as np
import pytest

from fm2uav import World
from fm2uav.errors import WorldError
from fm2uav.world.buildings import METRES_PER_LEVEL, building_height


def _sq(x0, y0, w, props):
    ring = [[x0, y0], [x0 + w, y0], [x0 + w, y0 + w], [x0, y0 + w], [x0, y0]]
    return {"type": "Feature", "geometry": {"type": "Polygon", "coordinates": [ring]},
            "properties": props}


def test_one_building_exact_occupancy():
    fc = {"type": "FeatureCollection", "features": [_sq(2.0, 3.0, 2.0, {"height": 3.0})]}
    w = World.from_buildings(fc, 1.0, shape=(8, 8, 6))
    expected = np.zeros((8, 8, 6), bool)
    expected[:, :, 0] = True  # ground layer z = 0
    expected[2:5, 3:6, :4] = True  # nodes x 2..4, y 3..5 (edges included), z 0..3
    np.testing.assert_array_equal(w.occupancy, expected)
    np.testing.assert_array_equal(w.terrain, np.zeros((8, 8)))
    assert w.spacing == (1.0, 1.0, 1.0)


def test_heights_from_levels_strings_and_default():
    assert building_height({"building:levels": 4}) == 4 * METRES_PER_LEVEL
    assert building_height({"height": "7.5 m", "building:levels": 99}) == 7.5
    assert building_height({"levels": "2"}, metres_per_level=4.0) == 8.0
    assert building_height({}, default_height=9) == 9.0
    with pytest.raises(WorldError, match="building:levels"):
        building_height({"name": "x"})
    with pytest.raises(WorldError):
        building_height({"height": "tall"})
    with pytest.raises(WorldError):
        building_height({"height": -3})


def test_levels_building_and_auto_extent():
    fc = {"type": "FeatureCollection", "features": [
        _sq(10.0, 10.0, 4.0, {"building:levels": 2}),
        {"type": "Feature", "properties": {"height": 2},
         "geometry": {"type": "MultiPolygon", "coordinates": [
             [[[20, 10], [22, 10], [22, 12], [20, 12], [20, 10]]]]}},
    ]}
    # in-memory GeoJSON without a crs member: the world's own metres (a *file* without
    # one is lon/lat per RFC 7946, see tests/world/test_vectors.py)
    w = World.from_buildings(fc, 1.0, margin=2.0)
    assert w.origin == (8.0, 8.0, 0.0)
    i, j = w.to_cell(np.array([12.0, 12.0, 0.0]))[:2]
    top = w.surface_index()[i, j]
    assert w.to_world(np.array([0.0, 0.0, top]))[2] == 6.0  # 2 levels x 3 m
    i2, j2 = w.to_cell(np.array([21.0, 11.0, 0.0]))[:2]
    assert w.surface_index()[i2, j2] == 2


def test_bad_buildings_raise_world_error():
    pt = {"type": "Feature", "geometry": {"type": "Point", "coordinates": [1, 1]},
          "properties": {"height": 3}}
    with pytest.raises(WorldError, match="Polygon"):
        World.from_buildings([pt], 1.0, shape=(4, 4, 4))
    with pytest.raises(WorldError, match="vertical nodes"):
        World.from_buildings([_sq(0, 0, 2, {"height": 50})], 1.0, shape=(4, 4, 10))
    with pytest.raises(WorldError):
        World.from_buildings({"type": "Nope"}, 1.0)
    with pytest.raises(WorldError):
        World.from_buildings([_sq(0, 0, 2, {"height": 5})], -1.0)
    with pytest.raises(WorldError, match="does not exist"):
        World.from_buildings("/no/such/file.geojson", 1.0)
