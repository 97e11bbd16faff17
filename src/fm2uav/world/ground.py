"""Ground height under path points, read from a world's terrain height map."""

from __future__ import annotations

import numpy as np

__all__ = ["terrain_along"]


def terrain_along(world, path: np.ndarray) -> np.ndarray | None:
    """Ground height [m] under each path point (bilinear), or None without terrain."""
    if world.terrain is None:
        return None
    from scipy import ndimage

    idx = world.to_index(path)[:, :2]
    return ndimage.map_coordinates(world.terrain, idx.T, order=1, mode="nearest")
