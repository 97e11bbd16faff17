"""The registry of :class:`~fm2uav.world.world.World`'s builders (no numpy: the package's
``__init__`` fills it at import, and a mission file's schema imports the package).

The functions behind World's ``from_dem``, ``from_lonlat_grid``, ``from_buildings``,
``from_image`` and ``from_ros_map``, by name. They live in their own modules (dem.py,
buildings.py, images.py), which import World; ``fm2uav/world/__init__.py`` registers them,
so :mod:`fm2uav.world.world` never imports its builders (imports go one way: the acyclic
contract in pyproject.toml).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

__all__ = ["BUILDERS", "register_builders"]

#: Classmethod name → the function behind it.
BUILDERS: dict[str, Callable[..., Any]] = {}


def register_builders(**builders: Callable[..., Any]) -> None:
    """Register the functions behind World's ``from_*`` classmethods, by classmethod name."""
    BUILDERS.update(builders)
