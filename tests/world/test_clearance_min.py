"""min_surface_clearance(s): the same minimum as surface_clearance, from fewer points."""

from __future__ import annotations

import numpy as np
import pytest

from fm2uav import World, scenarios
from fm2uav.world.clearance import (min_surface_clearance, min_surface_clearances,
                                    surface_clearance)


def _box_loop(world, pts):
    """The per-point measure written out: distance to the nearest obstacle cell box."""
    occ = world.occupancy
    centres = world.to_world(np.argwhere(occ))
    h = np.asarray(world.spacing)
    gap = np.maximum(np.abs(centres[None, :, :] - pts[:, None, :]) - 0.5 * h, 0.0)
    return np.sqrt((gap * gap).sum(axis=2)).min(axis=1)


@pytest.mark.parametrize("shape,spacing", [((50, 40), (1.0, 1.0)), ((50, 40), (2.0, 0.7)),
                                           ((20, 16, 8), (1.0, 1.5, 0.5))])
def test_box_clearance_and_its_minimum(shape, spacing):
    rng = np.random.default_rng(sum(shape))
    world = World(rng.random(shape) < 0.15, spacing=spacing)
    b = world.bounds
    pts = rng.uniform(b[:, 0], b[:, 1], (400, len(shape)))
    each = surface_clearance(world, pts)
    assert np.allclose(each, _box_loop(world, pts), rtol=0, atol=1e-12)
    paths = [pts[a:a + n] for a, n in ((0, 50), (50, 1), (51, 200), (251, 149))]
    mins = min_surface_clearances(world, paths + [np.zeros((0, len(shape)))])
    assert mins.tolist() == [float(surface_clearance(world, p).min()) for p in paths] + [np.inf]
    assert min_surface_clearance(world, pts) == each.min()


def test_a_path_along_a_wall_and_terrain_columns():
    occ = np.zeros((60, 30), bool)
    occ[:, 10] = True
    world = World(occ, spacing=1.0)
    x = np.linspace(1, 58, 300)
    path = np.column_stack([x, 13.0 + 0.3 * np.sin(x)])
    assert min_surface_clearance(world, path) == float(surface_clearance(world, path).min())
    assert min_surface_clearance(World(np.zeros((5, 5), bool), spacing=1.0), path[:3]) == np.inf
    sc = scenarios.open_field()
    p3 = np.column_stack([np.linspace(100, 1500, 50), np.linspace(200, 1100, 50),
                          np.full(50, 400.0)])
    assert min_surface_clearance(sc.world, p3) == float(surface_clearance(sc.world, p3).min())


def test_a_path_through_a_thick_building_keeps_the_nearest_point_outside():
    # inside a building only its rim counts (the boxes a free point can see); a point deep
    # inside must not hide the nearer point outside from the search
    occ = np.zeros((70, 60), bool)
    occ[10:40, 10:40] = True
    occ[:, 55] = True
    world = World(occ, spacing=1.0)
    path = np.array([[25.0, 25.0], [25.0, 48.0]])
    assert surface_clearance(world, path).tolist() == [13.5, 6.5]
    assert min_surface_clearances(world, [path, path[::-1]]).tolist() == [6.5, 6.5]
