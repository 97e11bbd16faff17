"""The unrolled corridor grid and the coverage of the flown FM² path."""

import math

import numpy as np
import pytest
import shapely
from shapely.geometry import Polygon

from fm2uav import FlightLevel, InputError, World
from fm2uav.missions.coverage import plan_coverage, zigzag
from fm2uav.missions.coverage.grid import corridor_grid
from fm2uav.scenarios.coverage import coverage_world

RECT = [(100, 100), (500, 100), (500, 260), (100, 260)]


def _flat(height=20.0, shape=(60, 40), nz=30):
    return World.from_heightmap(np.full(shape, height), 10.0, nz)


def _in_obstacle(world, path):
    idx = np.clip(np.floor(world.to_index(path) + 0.5).astype(int), 0,
                  np.asarray(world.shape) - 1)
    return world.occupancy[tuple(idx.T)]


def test_corridor_grid_geometry_exact():
    # 400 x 160 rectangle, D = 80, α = 0: bands at y = 140 (flown towards -x)
    # and y = 220, joined by a semicircle of radius 40 at x = 100
    world = _flat()
    zz = zigzag(RECT, 80.0, 0.0)
    cg = corridor_grid(world, zz, 20.0)
    g = cg.world
    # σ is arc length: the grid spans the whole zigzag, start and end are nodes
    total = (g.shape[0] - 1) * g.spacing[0]
    assert total == pytest.approx(2 * 400 + math.pi * 40, rel=1e-3)
    assert g.spacing[0] <= 10.0 and g.spacing[2] == 10.0
    # rows at 0, ±10 m strictly inside (-h, h), centre row on the zigzag
    np.testing.assert_allclose(cg.offsets, [-10.0, 0.0, 10.0])
    assert cg.centre == 1
    np.testing.assert_allclose(cg.to_map([[0.0, 0.0]]), [[500.0, 140.0]], atol=1e-9)
    np.testing.assert_allclose(cg.to_map([[total, 0.0]]), [[500.0, 220.0]], atol=1e-9)
    # normal = left of the direction of flight: flying -x on band 0, left is -y
    np.testing.assert_allclose(cg.to_map([[50.0, 10.0]]), [[450.0, 130.0]], atol=1e-9)
    # the turn's apex (half-way round the semicircle) is flown towards +y,
    # whose left is -x: outwards
    apex = 400 + math.pi * 40 / 2
    np.testing.assert_allclose(cg.to_map([[apex, 0.0]]), [[60.0, 180.0]], atol=0.05)
    np.testing.assert_allclose(cg.to_map([[apex, 10.0]]), [[50.0, 180.0]], atol=0.05)
    # from_map inverts to_map inside the corridor (σ to the skeleton's 1.25 m sampling)
    pts = np.array([[120.0, -7.0], [apex, 9.0], [700.0, 3.0]])
    back = cg.from_map(cg.to_map(pts))
    np.testing.assert_allclose(back[:, 0], pts[:, 0], atol=0.63)
    np.testing.assert_allclose(back[:, 1], pts[:, 1], atol=0.05)
    # the flat ground is sampled exactly: layers 0..2 (z <= 20 m) are obstacles
    assert g.occupancy[:, :, :3].all() and not g.occupancy[:, :, 3:].any()
    with pytest.raises(InputError, match="half-width"):
        corridor_grid(world, zz, 40.0)


def test_flat_world_path_is_the_zigzag_at_the_level():
    world = _flat(50.0)
    cp = plan_coverage(world, RECT, 80.0, level=FlightLevel(agl=100.0))
    zz = shapely.LineString(cp.zigzag.path(step=1.0))
    d = shapely.distance(shapely.points(cp.path[:, :2]), zz)
    assert d.max() < 0.2  # the ground track is the zigzag (its arcs sampled)
    assert cp.coverage > 0.9999
    assert np.abs(cp.agl_error).max() < 2.0  # level: 150 m, one 10 m layer
    assert cp.plan.length == pytest.approx(cp.zigzag.cost, rel=0.01)
    np.testing.assert_allclose(cp.path[0, :2], cp.zigzag.start, atol=1e-9)
    np.testing.assert_allclose(cp.path[-1, :2], cp.zigzag.goal, atol=1e-9)


def test_obstacle_beside_a_band_is_not_entered():
    # a tower one cell beside band 0 (y = 150 m) rising through the flight level
    h = np.full((60, 40), 20.0)
    occ = World.from_heightmap(h, 10.0, 30).occupancy.copy()
    occ[29:32, 15, :26] = True
    world = World(occ, spacing=10.0, terrain=h)
    cp = plan_coverage(world, RECT, 80.0, level=FlightLevel(agl=100.0), angle=0.0)
    assert not _in_obstacle(world, cp.path).any()
    # clearance is to the tower's surface (its cell box, face at y = 145 m), not to its
    # nodes (y = 150 m): the corridor path bends to y = 143.2 m, 1.8 m from the face
    assert cp.plan.clearance > 1.5
    assert cp.coverage >= 0.995


def test_bad_grid_options():
    world = _flat()
    with pytest.raises(InputError, match="grid"):
        plan_coverage(world, RECT, 80.0, level=FlightLevel(agl=100.0), grid="bands")
    with pytest.raises(InputError, match="corridor"):
        plan_coverage(world, RECT, 80.0, level=FlightLevel(agl=100.0), corridor=0.5)


def _map_polygon(rng, holes):
    """A random star-shaped polygon in the middle of the 1180 x 870 m coverage map."""
    while True:
        n = int(rng.integers(5, 14))
        ang = np.sort(rng.uniform(0, 2 * np.pi, n))
        r = rng.uniform(100, 260, n)
        p = Polygon(np.column_stack([r * np.cos(ang), r * np.sin(ang)]) + [590.0, 435.0])
        if not p.is_valid or p.area < 2e4:
            continue
        if holes:
            c = p.representative_point()
            hole = shapely.Point(c.x, c.y).buffer(rng.uniform(20, 60), quad_segs=4)
            if p.buffer(-5).contains(hole):
                p = Polygon(p.exterior.coords, [hole.exterior.coords])
        return p


def test_random_polygons_flown_path_covers_the_area():
    """Judged: coverage of the polygon >= 99.5 %, here by the flown FM² path.

    Seeded random non-convex polygons (every other one with a hole) over the
    mountainous coverage map, D in [40, 100] m, DE angle, 100 m AGL.
    """
    world = coverage_world(0)
    rng = np.random.default_rng(5)
    worst = 1.0
    for k in range(10):
        p = _map_polygon(rng, holes=k % 2 == 1)
        d = float(rng.uniform(40, 100))
        cp = plan_coverage(world, p, d, level=FlightLevel(agl=100.0), seed=k)
        worst = min(worst, cp.coverage)
        assert cp.coverage >= 0.995, (k, d, cp.coverage)
        assert cp.zigzag_coverage >= 0.999
        # never inside the terrain, on the level (10 m layers), in the corridor
        assert not _in_obstacle(world, cp.path).any()
        assert np.abs(cp.agl_error).mean() < 10.0
        dev = shapely.distance(shapely.points(cp.path[:, :2]), cp.zigzag.line())
        assert dev.max() <= 0.25 * d
    assert worst >= 0.998  # the margin measured: >= 99.99 % on this set


def test_coverage_flies_the_requested_height_above_the_continuous_ground():
    """The coverage path gets the final altitude profile (issue 13), like every plan."""
    x = np.arange(60) * 10.0
    y = np.arange(40) * 10.0
    h = 20.0 + 40.0 * np.sin(x[:, None] / 90.0) * np.cos(y[None, :] / 70.0) + 40.0
    world = World.from_heightmap(h, 10.0, 40)
    cp = plan_coverage(world, RECT, 80.0, level=FlightLevel(agl=100.0), angle=0.0)
    agl = cp.path[:, 2] - world.ground_height(cp.path[:, 0], cp.path[:, 1])
    cruise = cp.plan.profile.phase == "cruise"
    assert agl[cruise].min() >= 100.0 - 2.0 - 1e-6
    assert abs(np.median(agl[cruise]) - 100.0) < 5.0
    flat = plan_coverage(world, RECT, 80.0, level=FlightLevel(agl=100.0, heights="fm2"), angle=0.0)
    assert cp.coverage == pytest.approx(flat.coverage, abs=1e-3)  # same ground track
