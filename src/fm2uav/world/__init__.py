"""Worlds: occupancy grids in metres, their builders, and world questions (clearance).

The built-in worlds of the papers live in :mod:`fm2uav.scenarios`. The names below are
imported on first access (:func:`fm2uav._lazy.lazy_names`): a mission file's schema
(:mod:`fm2uav.world.load`) loads without the builders, the clearance kernels and
the geodata libraries, so ``fm2uav run`` reports a bad field at once.
"""

from __future__ import annotations

from functools import partial
from typing import TYPE_CHECKING

from .._lazy import lazy_function, lazy_names
from ._registry import register_builders

if TYPE_CHECKING:  # loaded on first attribute access (PEP 562)
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

__getattr__, __dir__ = lazy_names(__name__, {
    "World": ".world",
    "WorldSpec": ".load",
    "load_world": ".load",
    "clearance_profile": ".clearance",
    "open_field_heights": ".terrain",
    "from_buildings": ".buildings",
    "from_dem": ".dem",
    "from_lonlat_grid": ".dem",
    "world_from_image": ".images",
    "world_from_ros_map": ".images",
})

_lazy_fn = partial(lazy_function, __name__)

# World.from_dem & co. call the builders through this registry: World never imports them
register_builders(from_dem=_lazy_fn(".dem", "from_dem"),
                  from_lonlat_grid=_lazy_fn(".dem", "from_lonlat_grid"),
                  from_buildings=_lazy_fn(".buildings", "from_buildings"),
                  from_image=_lazy_fn(".images", "world_from_image"),
                  from_ros_map=_lazy_fn(".images", "world_from_ros_map"))
