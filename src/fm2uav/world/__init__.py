"""Worlds: occupancy grids in metres, their builders, and world questions (clearance).

The built-in worlds of the papers live in :mod:`fm2uav.scenarios`.
"""

from .clearance import clearance_profile
from .load import WorldSpec, load_world
from .terrain import open_field_heights
from .world import World

__all__ = [
    "World",
    "WorldSpec",
    "load_world",
    "clearance_profile",
    "open_field_heights",
]
