"""Buildings as their true footprints: roofs, chords and the clearance to the prisms.

The world's grid blocks every column a footprint's cell touches (dilated by up to a
cell); the safety figures must come from the footprints themselves (issue 25: a
Swiss-grid Shapefile reported 4.9 m where the path kept 6.4 m).
"""

from __future__ import annotations

import numpy as np
import pyogrio
import pytest
import shapely
from pyproj import Transformer

from fm2uav.world import World
from fm2uav.world.building_model import BuildingModel
from fm2uav.world.clearance import surface_clearance


def test_prism_distance_exact_cases():
    m = BuildingModel((shapely.box(0, 0, 10, 10), shapely.box(30, 0, 40, 10)),
                      np.array([20.0, 50.0]))
    pts = np.array([
        [15.0, 5.0, 10.0],   # beside the first wall: 5 m
        [5.0, 5.0, 23.0],    # over the first roof: 3 m
        [13.0, 14.0, 24.0],  # past the roof's corner: sqrt(9 + 16 + 16)
        [5.0, 5.0, 15.0],    # inside, 5 m below the roof
        [25.0, 5.0, 45.0],   # between: 10 m from the first (over its roof), 5 m from the second
        [10.0, 5.0, 5.0],    # on the wall: 0 below the roof -> inside, depth 15
    ])
    d = m.distance(pts)
    assert d == pytest.approx([5.0, 3.0, np.sqrt(41.0), -5.0, 5.0, -15.0])
    assert m.roof_at([5.0, 10.0, 20.0], [5.0, 10.0, 5.0]).tolist() == [20.0, 20.0, -np.inf]
    # a chord from (-5, 12) to (12, -5) cuts the first footprint's corner (0..10): roof 20
    along = m.roof_along([[-5.0, 12.0], [12.0, 20.0], [20.0, 5.0]], [[12.0, -5.0], [28, 20.0],
                                                                    [35.0, 5.0]])
    assert along.tolist() == [20.0, -np.inf, 50.0]


def test_prism_distance_matches_brute_force():
    rng = np.random.default_rng(1)
    polys = [shapely.Polygon(c + rng.uniform(-8, 8, (6, 2))).convex_hull
             for c in rng.uniform(0, 200, (12, 2))]
    roofs = rng.uniform(10, 60, len(polys))
    m = BuildingModel(tuple(polys), roofs)
    pts = np.column_stack([rng.uniform(-20, 220, 400), rng.uniform(-20, 220, 400),
                           rng.uniform(0, 90, 400)])
    brute = np.full(len(pts), np.inf)
    for g, r in zip(polys, roofs):
        dh = shapely.distance(shapely.points(pts[:, :2]), g)
        dz = pts[:, 2] - r
        d = np.where((dh == 0) & (dz < 0), dz, np.hypot(dh, np.maximum(dz, 0)))
        brute = np.minimum(brute, d)
    assert m.distance(pts) == pytest.approx(brute, abs=1e-9)


@pytest.fixture(scope="module")
def swiss_town(tmp_path_factory):
    """Blocks on round Swiss-grid coordinates (EPSG:2056), as a Shapefile and as lon/lat
    GeoJSON: on a grid whose origin is the footprints' corner, every edge lies on nodes."""
    d = tmp_path_factory.mktemp("swiss")
    e0, n0 = 2683000.0, 1248000.0
    polys = [shapely.box(e0 + 60 * i, n0 + 60 * j, e0 + 60 * i + 35, n0 + 60 * j + 35)
             for i in range(3) for j in range(3)]
    heights = np.array([20.0 + 5 * k for k in range(9)])
    shp = d / "town.shp"
    pyogrio.raw.write(str(shp), np.array(shapely.to_wkb(polys), dtype=object),
                      field_data=[heights], fields=["height"], geometry_type="Polygon",
                      crs="EPSG:2056", driver="ESRI Shapefile")
    tr = Transformer.from_crs("EPSG:2056", "EPSG:4326", always_xy=True)
    ll = [shapely.transform(g, lambda xy: np.column_stack(tr.transform(xy[:, 0], xy[:, 1])))
          for g in polys]
    gj = d / "town.geojson"
    pyogrio.raw.write(str(gj), np.array(shapely.to_wkb(ll), dtype=object),
                      field_data=[heights], fields=["height"], geometry_type="Polygon",
                      crs="EPSG:4326", driver="GeoJSON")
    return shp, gj, polys, heights


@pytest.mark.parametrize("which", ["shp", "geojson"])
def test_clearance_and_roofs_equal_the_file_in_its_own_crs(swiss_town, which):
    shp, gj, polys, heights = swiss_town
    src = shp if which == "shp" else gj
    w = World.from_buildings(src, 2.0, margin=20.0, all_touched=True)
    # the grid's columns are dilated (up to a cell): the safety figures must not be
    rng = np.random.default_rng(7)
    to_w = Transformer.from_crs("EPSG:2056", w.crs, always_xy=True)
    pts2056 = np.column_stack([rng.uniform(2682985, 2683170, 300),
                               rng.uniform(1247985, 1248170, 300), rng.uniform(1, 70, 300)])
    x, y = to_w.transform(pts2056[:, 0], pts2056[:, 1])
    pts = np.column_stack([x, y, pts2056[:, 2]])
    outside = ~np.any([shapely.intersects_xy(g, pts2056[:, 0], pts2056[:, 1]) & (
        pts2056[:, 2] < h) for g, h in zip(polys, heights)], axis=0)
    d = surface_clearance(w, pts[outside])
    q = pts2056[outside]
    ref = np.full(len(q), np.inf)
    for g, h in zip(polys, heights):  # distance to the prisms, and to the flat ground z = 0
        dh = shapely.distance(shapely.points(q[:, :2]), g)
        ref = np.minimum(ref, np.hypot(dh, np.maximum(q[:, 2] - h, 0.0)))
    ref = np.minimum(ref, q[:, 2])
    assert d == pytest.approx(ref, abs=0.01)
    # over a roof the surface is the roof itself (not one vertical cell below it)
    cx, cy = to_w.transform(2683017.5, 1248017.5)
    assert w.surface_height(cx, cy) == pytest.approx(heights[0])
