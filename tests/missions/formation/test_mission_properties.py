"""Seeded properties on random terrains built with World.from_heightmap.

Whatever the relief, shape, number of followers, flight level and speeds: the
leader reaches the goal, no two UAVs ever come closer than dist/2 (exactly,
between samples too) and no UAV is ever inside the terrain.
"""

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.ndimage import gaussian_filter

from fm2uav import FlightLevel, FormationConfig, World
from fm2uav.missions.formation import fly_formation, inside_terrain, min_separation

CELL = 10.0
NZ = 16


def random_world(seed: int, relief: float) -> World:
    """48 x 36 columns of 10 m; smooth random hills up to ``relief`` x the room below
    the clearance under the ceiling."""
    rng = np.random.default_rng(seed)
    noise = gaussian_filter(rng.standard_normal((48, 36)), sigma=rng.uniform(2.0, 5.0))
    noise = (noise - noise.min()) / max(np.ptp(noise), 1e-12)
    top = (NZ - 4) * CELL
    return World.from_heightmap(noise * relief * top, CELL, NZ, name=f"random-{seed}")


def _height_over(world: World, x: float, y: float, above: float) -> float:
    i, j = int(round(x / CELL)), int(round(y / CELL))
    ground = world.terrain[max(i - 1, 0):i + 2, max(j - 1, 0):j + 2].max()
    return float(min(ground + above, (NZ - 1) * CELL - 2 * CELL))


@settings(max_examples=10, deadline=None, derandomize=True)
@given(
    seed=st.integers(0, 2**16),
    relief=st.floats(0.3, 0.95),
    shape=st.sampled_from(["triangle", "v", "line"]),
    n=st.integers(1, 3),
    level=st.sampled_from([None, 30.0, 40.0]),
    dist=st.floats(15.0, 30.0),
    speed=st.floats(5.0, 12.0),
    y0=st.floats(100.0, 250.0),
    y1=st.floats(100.0, 250.0),
)
def test_random_terrain_flights_are_safe(seed, relief, shape, n, level, dist, speed, y0, y1):
    world = random_world(seed, relief)
    start = (90.0, y0, _height_over(world, 90.0, y0, 40.0))
    goal = (420.0, y1, _height_over(world, 420.0, y1, 40.0))
    cfg = FormationConfig(shape=shape, n_followers=n, dist=dist, leader_speed=speed,
                          clearance=20.0)
    r = fly_formation(world, start, goal, config=cfg,
                      level=None if level is None else FlightLevel(agl=level, p2=1.5))
    assert r.completed
    d, _, _ = min_separation(r.positions)
    assert d >= dist / 2
    assert not inside_terrain(world, r.positions).any()
    assert np.all(np.isfinite(r.positions))
    np.testing.assert_allclose(r.positions[-1, 0], goal, atol=1e-6)
