"""Worlds: occupancy grids in metres, builders and the built-in scenarios."""

from .scenarios import SCENARIOS, Scenario, fissure, get_scenario, open_field
from .terrain import open_field_heights
from .world import World

__all__ = [
    "World",
    "Scenario",
    "open_field",
    "fissure",
    "get_scenario",
    "SCENARIOS",
    "open_field_heights",
]
