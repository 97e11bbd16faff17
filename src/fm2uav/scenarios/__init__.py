"""Built-in scenarios of the source papers: a world with a start and a goal.

* ``"open-field"`` / ``"fissure"`` — :mod:`.field` (terrain-following paper,
  thesis ch. 4 and 6);
* ``"city"`` / ``"city-high"`` — :mod:`.city` (thesis ch. 3);
* ``"coverage"`` — :mod:`.coverage` (coverage paper 003, thesis ch. 5, areas S1-S4);
* ``"city2d"`` — :mod:`.city2d` (curvature study, seed 004);
* ``"jacksboro"`` — :mod:`.jacksboro` (a real DEM).

A new built-in world goes in its own module here and one entry of :data:`SCENARIOS`.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING, Any

from .._lazy import lazy_function, lazy_names
from ..errors import WorldError

if TYPE_CHECKING:  # loaded on first attribute access (PEP 562)
    import numpy as np

    from .field import OPEN_FIELD_CELL, OPEN_FIELD_HEIGHT_CELLS, fissure, open_field
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

__getattr__, __dir__ = lazy_names(__name__, {
    "Scenario": ".scenario",
    "open_field": ".field",
    "fissure": ".field",
    "OPEN_FIELD_CELL": ".field",
    "OPEN_FIELD_HEIGHT_CELLS": ".field",
})

#: Scenario name → factory ``f(seed=0) -> Scenario``. Every factory imports its module on
#: its first call, so the names are known (a mission file's ``world.scenario`` checked)
#: without loading numpy, the geodata libraries or the coverage kernels.
SCENARIOS: dict[str, Callable[..., Scenario]] = {
    "open-field": lazy_function(__name__, ".field", "open_field"),
    "fissure": lazy_function(__name__, ".field", "fissure"),
    "jacksboro": lazy_function(__name__, ".jacksboro", "jacksboro"),
    "city": lazy_function(__name__, ".city", "city"),
    "city-high": lazy_function(__name__, ".city", "city_high"),
    "coverage": lazy_function(__name__, ".coverage", "coverage"),
    "city2d": lazy_function(__name__, ".city2d", "city2d"),
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
    import numpy as np

    if not isinstance(seed, np.random.Generator):
        from .._validate import seed_value

        seed = seed_value(seed, "seed", where=("world.seed", "--seed"))
    return SCENARIOS[key](seed=seed, **kwargs)
