"""Clearance: distance from path points to the nearest obstacle node."""

from __future__ import annotations

import numpy as np
from scipy import ndimage
from scipy.spatial import cKDTree

from ..world import World

__all__ = ["clearance_profile", "obstacle_tree"]


def obstacle_tree(world: World) -> cKDTree | None:
    """k-d tree of the world's boundary obstacle nodes [m], cached on the world.

    Only obstacle nodes with a free axis neighbour (or on the map border) can
    be the nearest obstacle node of a free point, so only those are indexed.
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

    Exact for obstacles taken as their grid nodes.

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
    tree = obstacle_tree(world)
    if tree is None:
        return np.full(len(pts), np.inf)
    d, _ = tree.query(pts)
    return np.asarray(d, dtype=float)
