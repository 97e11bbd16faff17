"""Shared worlds and a cached fissure flight for the formation tests."""

from __future__ import annotations

import numpy as np
import pytest

import fm2uav
from fm2uav import FlightLevel, World
from fm2uav.missions.formation import fly_formation


def corridor_world(width_cells: int = 8, length: tuple[int, int] = (20, 40)) -> World:
    """60 x 40 x 14 nodes of 10 m: flat ground, two walls up to 125 m (just below the
    130 m ceiling, so the clearance band closes them) leaving a corridor along y = 20."""
    h = np.zeros((60, 40))
    lo = 20 - width_cells // 2
    hi = 20 + width_cells // 2
    h[length[0]:length[1], :lo] = 125.0
    h[length[0]:length[1], hi + 1:] = 125.0
    return World.from_heightmap(h, 10.0, 14, name="corridor")


@pytest.fixture(scope="session")
def corridor():
    return corridor_world()


@pytest.fixture(scope="session")
def fissure():
    return fm2uav.scenarios.fissure()


@pytest.fixture(scope="session")
def fissure_level(fissure):
    """Thesis case 2 (flight level 7 cells) with the planner's p1/p2."""
    return fly_formation(fissure.world, fissure.start, fissure.goal,
                         level=FlightLevel(agl=7 * 15.0, p2=1.5))


@pytest.fixture(scope="session")
def fissure_free(fissure):
    """Thesis case 1 (no flight level)."""
    return fly_formation(fissure.world, fissure.start, fissure.goal)
