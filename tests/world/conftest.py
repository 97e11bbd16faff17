"""Small worlds and plans shared by the world tests (fast: tens of thousands of nodes)."""

import numpy as np
import pytest

from fm2uav import FlightLevel, World, plan


def hill_world(crs=None, origin=(0.0, 0.0, 0.0)) -> World:
    """41 x 31 x 24 nodes of 10 m with a Gaussian hill (max 90 m) in the middle."""
    x = np.arange(41)[:, None] * 10.0
    y = np.arange(31)[None, :] * 10.0
    h = 10.0 + 80.0 * np.exp(-((x - 200) ** 2 + (y - 150) ** 2) / (2 * 70.0**2))
    h = h + origin[2]
    return World.from_heightmap(h, 10.0, 24, origin=origin, name="hill") if crs is None else \
        World(occupancy=World.from_heightmap(h, 10.0, 24, origin=origin).occupancy,
              spacing=10.0, origin=origin, terrain=h, crs=crs, name="hill-utm")


@pytest.fixture(scope="session")
def hill():
    return hill_world()


@pytest.fixture(scope="session")
def hill_plan(hill):
    """A plan across the hill (relative frame)."""
    return plan(hill, (20.0, 20.0, 150.0), (380.0, 280.0, 150.0))


@pytest.fixture(scope="session")
def hill_tff(hill):
    """A terrain-following plan (60 m above ground) across the hill."""
    return plan(hill, (20.0, 20.0, 70.0), (380.0, 280.0, 70.0),
                level=FlightLevel(agl=60.0, p2=1.5))
