"""Reusable "is this formation flight correct?" checks (used by the mission and the tests).

* :func:`pair_distances` / :func:`min_separation`: distances between UAVs whose
  trajectories are sampled at common times and straight between samples — the
  minimum between two samples is found exactly (the relative motion is linear).
* :func:`inside_terrain`: a point is inside the terrain if its nearest grid
  node is an obstacle or, when the world has a height map, if it lies below
  the bilinearly interpolated ground.
"""

from __future__ import annotations

import numpy as np
from scipy import ndimage

from ...world import World

__all__ = ["pair_distances", "min_separation", "segment_min_distance", "inside_terrain"]


def segment_min_distance(rel: np.ndarray) -> np.ndarray:
    """Smallest norm of a piecewise-linear relative motion on each time step.

    Parameters
    ----------
    rel : ndarray, shape (n_t, ..., ndim)
        Relative position of one UAV with respect to another at each sample [m].

    Returns
    -------
    ndarray, shape (n_t - 1, ...)
        ``min over τ in [0, 1] of |rel[m] + τ (rel[m+1] - rel[m])|``.
    """
    r0 = rel[:-1]
    d = rel[1:] - r0
    dd = np.einsum("...k,...k->...", d, d)
    tau = np.where(dd > 0, -np.einsum("...k,...k->...", r0, d) / np.where(dd > 0, dd, 1.0), 0.0)
    tau = np.clip(tau, 0.0, 1.0)
    closest = r0 + tau[..., None] * d
    return np.sqrt(np.einsum("...k,...k->...", closest, closest))


def pair_distances(positions: np.ndarray) -> np.ndarray:
    """Smallest distance between any two UAVs at each sample [m].

    Parameters
    ----------
    positions : ndarray, shape (n_t, n_uav, ndim)

    Returns
    -------
    ndarray, shape (n_t,)
        ``inf`` for a single UAV.
    """
    pos = np.asarray(positions, dtype=float)
    n = pos.shape[1]
    if n < 2:
        return np.full(pos.shape[0], np.inf)
    i, k = np.triu_indices(n, 1)
    rel = pos[:, i, :] - pos[:, k, :]
    return np.sqrt((rel**2).sum(axis=-1)).min(axis=1)


def min_separation(positions: np.ndarray) -> tuple[float, int, tuple[int, int]]:
    """Exact smallest distance between two UAVs over the whole piecewise-linear flight.

    Returns
    -------
    distance : float
        [m]; ``inf`` for a single UAV.
    step : int
        Index ``m`` of the time step ``[m, m + 1]`` where it occurs.
    pair : tuple of int
        The two UAVs.
    """
    pos = np.asarray(positions, dtype=float)
    n = pos.shape[1]
    if n < 2:
        return float("inf"), 0, (0, 0)
    i, k = np.triu_indices(n, 1)
    rel = pos[:, i, :] - pos[:, k, :]
    if pos.shape[0] == 1:
        d = np.sqrt((rel**2).sum(axis=-1))
    else:
        d = segment_min_distance(rel)
    m, p = np.unravel_index(int(np.argmin(d)), d.shape)
    return float(d[m, p]), int(m), (int(i[p]), int(k[p]))


def inside_terrain(world: World, points: np.ndarray) -> np.ndarray:
    """Whether each point is inside an obstacle / below the ground.

    Parameters
    ----------
    world : World
    points : ndarray, shape (..., ndim)
        World coordinates [m]; points outside the map count as inside.

    Returns
    -------
    ndarray of bool, shape (...)
    """
    pts = np.asarray(points, dtype=float)
    flat = pts.reshape(-1, world.ndim)
    idx = world.to_index(flat)
    shape = np.asarray(world.shape)
    outside = np.any((idx < -1e-9) | (idx > shape - 1 + 1e-9), axis=1)
    nn = np.clip(np.floor(idx + 0.5).astype(np.int64), 0, shape - 1)
    bad = world.occupancy[tuple(nn.T)] | outside
    if world.terrain is not None and world.ndim == 3:
        ground = ndimage.map_coordinates(world.terrain, idx[:, :2].T, order=1, mode="nearest")
        bad |= flat[:, 2] <= ground
    return bad.reshape(pts.shape[:-1])
