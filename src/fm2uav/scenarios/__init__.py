"""Built-in scenarios of the source papers: a world with a start and a goal.

* ``"open-field"`` / ``"fissure"`` — :mod:`.open_field` (terrain-following paper,
  thesis ch. 4 and 6);
* ``"city"`` / ``"city-high"`` — :mod:`.city` (thesis ch. 3);
* ``"coverage"`` — :mod:`.coverage` (coverage paper 003, thesis ch. 5, areas S1-S4);
* ``"city2d"`` — :mod:`.city2d` (curvature study, seed 004);
* ``"jacksboro"`` — :mod:`.jacksboro` (a real DEM).

A new built-in world goes in its own module here and one entry of :data:`SCENARIOS`.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from ..errors import WorldError
from .city import city, city_high
from .coverage import coverage
from .open_field import OPEN_FIELD_CELL, OPEN_FIELD_HEIGHT_CELLS, fissure, open_field
from .scenario import Scenario

__all__ = [
    "Scenario",
    "open_field",
    "fissure",
    "get_scenario",
    "SCENARIOS",
    "OPEN_FIELD_CELL",
    "OPEN_FIELD_HEIGHT_CELLS",
]


def _city2d(seed: int | np.random.Generator = 0) -> Scenario:
    """2D city map of the curvature study (see :mod:`fm2uav.scenarios.city2d`)."""
    from .city2d import city2d

    return city2d(seed)


def _jacksboro(seed: int | np.random.Generator = 0) -> Scenario:
    """Real DEM of the Jacksboro fault (see :mod:`fm2uav.scenarios.jacksboro`)."""
    from .jacksboro import jacksboro

    return jacksboro(seed)


#: Scenario name → factory ``f(seed=0) -> Scenario``.
SCENARIOS: dict[str, Callable[..., Scenario]] = {
    "open-field": open_field,
    "fissure": fissure,
    "jacksboro": _jacksboro,
    "city": city,
    "city-high": city_high,
    "coverage": coverage,
    "city2d": _city2d,
}


def get_scenario(name: str, seed: int | np.random.Generator = 0, **kwargs: Any) -> Scenario:
    """Build the built-in scenario called ``name`` (see :data:`SCENARIOS`).

    ``"open_field"`` and different case are accepted as ``"open-field"``.
    """
    key = str(name).strip().lower().replace("_", "-").replace(" ", "-")
    if key not in SCENARIOS:
        raise WorldError(
            f"unknown scenario {name!r}; valid names are: {', '.join(sorted(SCENARIOS))}"
        )
    if not isinstance(seed, np.random.Generator):
        from .._validate import seed_value

        seed = seed_value(seed, "seed", where=("world.seed", "--seed"))
    return SCENARIOS[key](seed=seed, **kwargs)
