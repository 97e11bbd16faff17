"""Worlds: occupancy grids in metres, their builders, and world questions (clearance).

The built-in worlds of the papers live in :mod:`fm2uav.scenarios`.
"""

from .buildings import from_buildings
from .clearance import clearance_profile
from .dem import from_dem, from_lonlat_grid
from .images import world_from_image, world_from_ros_map
from .load import WorldSpec, load_world
from .terrain import open_field_heights
from .world import World, register_builders

# World.from_dem & co. call the builders through this registry: World never imports them
register_builders(from_dem=from_dem, from_lonlat_grid=from_lonlat_grid,
                  from_buildings=from_buildings, from_image=world_from_image,
                  from_ros_map=world_from_ros_map)

__all__ = [
    "World",
    "WorldSpec",
    "load_world",
    "clearance_profile",
    "open_field_heights",
]
