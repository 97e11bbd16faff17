"""The fissure scenario and its cached flights for the formation tests (the corridor world
is shared with tests/viz: tests/conftest.py)."""

from __future__ import annotations

import pytest

import fm2uav
from fm2uav import FlightLevel
from fm2uav.missions.formation import fly_formation


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
