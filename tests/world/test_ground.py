"""World.ground_height / World.surface_height: continuous, vectorised, one meaning without terrain."""

import numpy as np
import pytest
from scipy import ndimage

import fm2uav
from fm2uav import World
from fm2uav.world.buildings import from_buildings


def test_ground_height_is_bilinear_between_columns_and_clamped_outside():
    h = np.array([[0.0, 4.0], [10.0, 30.0]])           # columns at x = 0, 5; y = 0, 5
    w = World.from_heightmap(h, 5.0, 8)
    assert w.ground_height(0.0, 0.0) == 0.0
    assert w.ground_height(2.5, 0.0) == pytest.approx(5.0)
    assert w.ground_height(2.5, 2.5) == pytest.approx((0 + 4 + 10 + 30) / 4)
    assert w.ground_height(-100.0, 0.0) == 0.0 and w.ground_height(100.0, 100.0) == 30.0
    # vectorised, broadcasting, shape kept
    z = w.ground_height(np.array([[0.0, 5.0], [2.5, 5.0]]), 0.0)
    assert z.shape == (2, 2)
    np.testing.assert_allclose(z, [[0.0, 10.0], [5.0, 10.0]])
    assert isinstance(w.ground_height(1.0, 1.0), float)


def test_ground_height_matches_map_coordinates_on_a_scenario():
    sc = fm2uav.scenarios.get_scenario("open-field")
    w = sc.world
    rng = np.random.default_rng(3)
    pts = rng.uniform(w.bounds[:2, 0], w.bounds[:2, 1], size=(200, 2))
    idx = (pts - np.asarray(w.origin[:2])) / np.asarray(w.spacing[:2])
    expected = ndimage.map_coordinates(w.terrain, idx.T, order=1, mode="nearest")
    np.testing.assert_array_equal(w.ground_height(pts[:, 0], pts[:, 1]), expected)


def test_without_terrain_the_ground_is_the_floor_of_the_grid():
    occ = np.zeros((6, 5, 4), bool)
    occ[2:4, 1:3, :3] = True                            # a block, top node k = 2
    w = World(occ, spacing=2.0, origin=(0.0, 0.0, 100.0))
    assert w.terrain is None
    np.testing.assert_array_equal(w.ground_height([0.0, 5.0], [0.0, 3.0]), [100.0, 100.0])
    # the block is a roof: z of its top node, read from the nearest column
    assert w.surface_height(5.0, 3.0) == 104.0
    assert w.surface_height(0.0, 0.0) == 100.0
    w2 = World(np.zeros((4, 3), bool), spacing=1.0)
    assert w2.ground_height(1.0, 1.0) == 0.0 and w2.surface_height(1.0, 1.0) == 0.0


def test_surface_height_counts_roofs_not_the_terrain_nodes():
    # a DEM world has no node above its ground: surface = ground everywhere
    h = np.array([[0.0, 4.0], [10.0, 30.0]])
    w = World.from_heightmap(h, 5.0, 8)
    xs = np.linspace(-1, 6, 15)
    X, Y = np.meshgrid(xs, xs, indexing="ij")
    np.testing.assert_array_equal(w.surface_height(X, Y), w.ground_height(X, Y))
    # buildings on flat ground: roofs where the footprints are, ground elsewhere
    square = {"type": "Feature", "properties": {"height": 12.0},
              "geometry": {"type": "Polygon",
                           "coordinates": [[[10, 10], [20, 10], [20, 20], [10, 20], [10, 10]]]}}
    wb = from_buildings([square], 2.0, shape=(20, 20, 10), origin=(0.0, 0.0, 0.0))
    assert wb.ground_height(15.0, 15.0) == 0.0
    assert wb.surface_height(15.0, 15.0) == 12.0        # top node z = 12 <= roof 12
    assert wb.surface_height(30.0, 30.0) == 0.0


def test_unknown_ground_follows_the_bilinear_stencil_of_the_grid():
    """Without a ground model, a point is over filled ground when a node of its bilinear
    cell (with a non-zero weight) is filled; on a node, only that node counts."""
    import numpy as np

    from fm2uav import World

    h = np.full((6, 5), 10.0)
    filled = np.zeros((6, 5), bool)
    filled[3, 2] = True
    w = World.from_heightmap(h, 10.0, 4).with_fields(filled=filled)
    assert w.ground is None
    x = np.array([30.0, 25.0, 35.0, 29.999, 20.0, 40.0, 30.0, 30.0, 15.0, 45.0])
    y = np.array([20.0, 15.0, 25.0, 20.0, 20.0, 20.0, 10.0, 30.0, 20.0, 20.0])
    want = [True, True, True, True, False, False, False, False, False, False]
    assert w.ground_filled(x, y).tolist() == want
    assert w.ground_source(x, y).tolist() == [-1 if v else 0 for v in want]
    # a world without filled nodes is known everywhere (synthetic terrain)
    assert not World.from_heightmap(h, 10.0, 4).ground_filled(x, y).any()
