"""Clearance: distance from path points to the nearest obstacle node."""

from __future__ import annotations

import numpy as np
from scipy import ndimage
from scipy.spatial import cKDTree

from .world import World
from ._clearance_kernels import column_clearance

__all__ = ["clearance_profile", "obstacle_tree", "column_surface"]


def column_surface(world: World) -> np.ndarray | None:
    """Top obstacle layer per column if the world is made of solid columns, else None.

    Terrain from a height map and extruded buildings are solid columns (every
    node below a column's top obstacle node is an obstacle); the clearance of
    such worlds has a fast exact search. Cached on the world.
    """
    key = "column_surface"
    if key not in world._cache:
        surf = None
        if world.ndim == 3:
            top = world.surface_index().astype(np.int64)
            k = np.arange(world.shape[2])
            if np.array_equal(world.occupancy, k[None, None, :] <= top[:, :, None]):
                surf = top
        world._cache[key] = surf
    return world._cache[key]


def obstacle_tree(world: World) -> cKDTree | None:
    """k-d tree of the world's boundary obstacle nodes [m], cached on the world.

    Only obstacle nodes with a free axis neighbour can be the nearest obstacle
    node of a free point, so only those are indexed (the tree is exact for
    points in free space, which is where paths are).
    ``None`` if the world has no obstacle.
    """
    key = "obstacle_tree"
    if key not in world._cache:
        occ = world.occupancy
        if not occ.any():
            world._cache[key] = None
        else:
            interior = ndimage.binary_erosion(occ, border_value=1)
            nodes = np.argwhere(occ & ~interior)
            world._cache[key] = cKDTree(world.to_world(nodes))
    return world._cache[key]


def clearance_profile(world: World, points: np.ndarray) -> np.ndarray:
    """Euclidean distance from each point to the nearest obstacle node [m].

    Exact for obstacles taken as their grid nodes. Column worlds (terrain,
    extruded buildings) use a compiled ring search over columns; other worlds a
    k-d tree of the boundary obstacle nodes (both cached on the world).

    Parameters
    ----------
    world : World
        The map.
    points : ndarray, shape (N, ndim)
        World coordinates [m].

    Returns
    -------
    ndarray, shape (N,)
        Clearance [m]; ``inf`` if the map has no obstacle.
    """
    pts = np.atleast_2d(np.asarray(points, dtype=float))
    if not world.occupancy.any():
        return np.full(len(pts), np.inf)
    surf = column_surface(world)
    if surf is not None:
        return column_clearance(np.ascontiguousarray(pts), surf, *world.spacing, *world.origin)
    tree = obstacle_tree(world)
    d, _ = tree.query(pts)
    return np.asarray(d, dtype=float)
