import math

import numpy as np
import pytest
from shapely.geometry import MultiPolygon, Polygon

from fm2uav import FlightLevel, InputError, World
from fm2uav.missions.coverage import as_area, plan_coverage, zigzag
from fm2uav.missions.coverage.area import check_inside_world

SQUARE = [(0, 0), (300, 0), (300, 300), (0, 300)]


@pytest.mark.parametrize(
    "area, match",
    [
        ([], "empty"),
        (Polygon(), "empty"),
        ([(0, 0), (10, 0)], "at least 3"),
        ([(0, 0), (10, 10), (0, 10), (10, 0)], "not a valid polygon"),  # bow-tie
        ([(0, 0), (5, 5), (10, 10)], "degenerate"),
        ([(0, 0), (0, 0), (0, 0), (0, 0)], "degenerate"),
        ([(0, 0), (np.nan, 0), (1, 1)], "NaN"),
        (MultiPolygon([Polygon(SQUARE), Polygon([(500, 0), (600, 0), (600, 100)])]), "2 separate"),
        ({"type": "Point", "coordinates": [0, 0]}, "not an area"),
        ("not an area", "must be"),
    ],
)
def test_bad_areas(area, match):
    with pytest.raises(InputError, match=match):
        as_area(area)


@pytest.mark.parametrize("d, match", [(0.0, "> 0"), (-5.0, "> 0"), (math.nan, "> 0"),
                                      (1000.0, "larger than the area"), (1e-3, "more than")])
def test_bad_spacing(d, match):
    with pytest.raises(InputError, match=match):
        zigzag(SQUARE, d, 0.3)


def test_geojson_feature_and_hole_accepted():
    feat = {"type": "Feature", "properties": {},
            "geometry": {"type": "Polygon",
                         "coordinates": [[[0, 0], [300, 0], [300, 300], [0, 300], [0, 0]],
                                         [[100, 100], [200, 100], [200, 200], [100, 100]]]}}
    p = as_area(feat)
    assert len(p.interiors) == 1
    assert zigzag(p, 60.0, 0.2).cost > 0


def test_area_outside_map():
    world = World(np.zeros((10, 10, 5), bool), spacing=10.0)
    with pytest.raises(InputError, match="outside the map"):
        check_inside_world(as_area([(500, 500), (600, 500), (600, 600)]), world)
    with pytest.raises(InputError, match="leaves the map"):
        check_inside_world(as_area([(50, 50), (150, 50), (150, 80)]), world)
    terrain = World.from_heightmap(np.full((20, 20), 5.0), 10.0, 12)
    with pytest.raises(InputError, match="outside the map"):
        plan_coverage(terrain, [(500, 500), (600, 500), (600, 600)], 20.0,
                      level=FlightLevel(agl=30.0))
