"""Clearance: distance from path points to obstacles.

Two questions:

* :func:`surface_clearance` — the **honest** one: distance [m] from each point
  to the continuous terrain/building surface (terrain = the bilinear ground of
  :meth:`World.ground_height`, triangulated four triangles per cell around the
  cell centre — for a world with a source-DEM ground model, that DEM sampled a
  quarter pixel apart; buildings = their true footprints extruded up to their
  roofs when the world keeps them (``World.buildings``,
  :class:`~fm2uav.world.building_model.BuildingModel`), else their grid
  columns as boxes up to the roof of :meth:`World.surface_height`). Never more
  than the exact vertical height
  above the surface. No-fly zones are not surfaces and do not
  count (see :mod:`fm2uav.world.zones`). Worlds that are not made of solid
  columns (and 2D worlds) measure to their obstacle *cells* as boxes.
* :func:`clearance_profile` — distance to the nearest obstacle *node* (the
  grid's view, including zone nodes); kept for the FM² internals and tests.
"""

from __future__ import annotations

from itertools import chain
from typing import Any

import numpy as np
from scipy import ndimage
from scipy.spatial import cKDTree

from .world import World
from ._clearance_kernels import column_clearance, min_box_clearances, surface_distance

__all__ = ["clearance_profile", "obstacle_tree", "column_surface", "surface_clearance",
           "min_surface_clearance", "min_surface_clearances", "base_occupancy"]


def base_occupancy(world: World) -> np.ndarray:
    """The world's terrain/building obstacles: ``occupancy`` without no-fly-zone nodes."""
    from .zones import zone_voxels

    mask = zone_voxels(world)
    return world.occupancy if mask is None else world.occupancy & ~mask


def _is_columns(world: World) -> bool:
    """True if the non-zone obstacles are solid columns (terrain, extruded buildings)."""
    key = "base_is_columns"
    if key not in world._cache:
        from .zones import zone_voxels

        if world.ndim == 3 and zone_voxels(world) is None:  # one compiled pass
            world._cache[key] = column_surface(world) is not None
            return world._cache[key]
        occ = base_occupancy(world)
        ok = False
        if world.ndim == 3:
            has = occ.any(axis=2)
            nz = occ.shape[2]
            top = np.where(has, nz - 1 - np.argmax(occ[:, :, ::-1], axis=2), -1)
            k = np.arange(nz)
            ok = bool(np.array_equal(occ, k[None, None, :] <= top[:, :, None]))
        world._cache[key] = ok
    return world._cache[key]


#: Largest number of ground samples the clearance search triangulates.
_GRID_CAP = 16_000_000


def _ground_grid(world: World) -> tuple[np.ndarray, float, float, float, float]:
    """Height grid [m], origin and spacing of the ground the surface is made of."""
    model = getattr(world, "ground", None)
    if model is not None:
        # the source DEM sampled on a world grid a quarter pixel apart (cached)
        key = "clearance_ground_grid"
        if key not in world._cache:
            b = world.bounds
            g = max(0.25 * model.pixel_m,
                    float(np.sqrt((b[0, 1] - b[0, 0]) * (b[1, 1] - b[1, 0]) / _GRID_CAP)))
            xs = np.arange(b[0, 0], b[0, 1] + g, g)
            ys = np.arange(b[1, 0], b[1, 1] + g, g)
            X, Y = np.meshgrid(xs, ys, indexing="ij")
            h = np.ascontiguousarray(model.height(X, Y), dtype=float)
            world._cache[key] = (h, float(xs[0]), float(ys[0]), g, g)
        return world._cache[key]
    if world.terrain is not None:
        return (np.ascontiguousarray(world.terrain, dtype=float), world.origin[0],
                world.origin[1], world.spacing[0], world.spacing[1])
    b = world.bounds
    hx = max(float(b[0, 1] - b[0, 0]), world.spacing[0])
    hy = max(float(b[1, 1] - b[1, 0]), world.spacing[1])
    return np.full((2, 2), float(world.origin[2])), float(b[0, 0]), float(b[1, 0]), hx, hy


def min_surface_clearance(world: World, points: np.ndarray) -> float:
    """``surface_clearance(world, points).min()`` [m]: :func:`min_surface_clearances` of one
    path (``inf`` for no points, or on a world without obstacles and without terrain)."""
    return float(min_surface_clearances(world, [points])[0])


def min_surface_clearances(world: World, paths: list[Any]) -> np.ndarray:
    """``surface_clearance(world, path).min()`` [m] of each path, the same numbers, faster.

    On worlds measured to their obstacle cells (2D, not solid columns) only the points
    that can hold a path's minimum are measured exactly, in one compiled pass over every
    path (:func:`~fm2uav.world._clearance_kernels.min_box_clearances`): with ``d`` the
    distance from a point's nearest node to the nearest rim node (an obstacle node with
    a free axis neighbour; one cached distance transform) and ``e`` the point's
    distance to that node, its clearance lies in ``[d - e - r, d + e]`` (``r`` half a
    cell diagonal). A point whose lower bound exceeds its path's smallest upper bound
    (or smallest exact distance) cannot be the nearest; the others are measured against
    the obstacle cells (boxes) around them.

    Parameters
    ----------
    paths : list of array_like, shape (N, ndim)
        World coordinates [m].

    Returns
    -------
    ndarray, shape (len(paths),)
        ``inf`` for a path without points, or on a world without obstacles and terrain.
    """
    pts_list = [np.atleast_2d(np.asarray(p, dtype=float)) for p in paths]
    out = np.full(len(pts_list), np.inf)
    if world.ndim == 3 and _is_columns(world):
        for k, pts in enumerate(pts_list):
            if len(pts):
                out[k] = float(surface_clearance(world, pts).min())
        return out
    occ = base_occupancy(world)
    lens = np.array([len(p) for p in pts_list], dtype=np.int64)
    if not occ.any() or lens.sum() == 0:
        return out
    rim = _box_rim(world)
    if not rim.any():
        return out
    key = "rim_distance"
    if key not in world._cache:
        world._cache[key] = ndimage.distance_transform_edt(~rim, sampling=world.spacing)
    pad = (1,) * (3 - world.ndim)
    dist = world._cache[key].reshape(world.shape + pad)
    rim = rim.reshape(world.shape + pad)
    pts = np.zeros((int(lens.sum()), 3))
    pts[:, :world.ndim] = np.concatenate([p for p in pts_list if len(p)])
    offsets = np.concatenate(([0], np.cumsum(lens)))
    o = tuple(world.origin) + (0.0,) * len(pad)
    h = tuple(world.spacing) + (1.0,) * len(pad)
    half_diag = 0.5 * float(np.linalg.norm(np.asarray(world.spacing, dtype=float)))
    return min_box_clearances(pts, offsets, dist, rim, *o, *h, half_diag)


def _box_rim(world: World) -> np.ndarray:
    """The obstacle nodes with a free axis neighbour (cached): the nearest obstacle cell
    of a free point is always one of them."""
    key = "box_rim"
    if key not in world._cache:
        occ = base_occupancy(world)
        world._cache[key] = np.ascontiguousarray(occ & ~ndimage.binary_erosion(
            occ, border_value=1))
    return world._cache[key]


def _box_tree(world: World) -> tuple[cKDTree, np.ndarray]:
    """KD-tree of the obstacle cells' centres on the obstacles' rim (cached), and the centres."""
    key = "box_tree"
    if key not in world._cache:
        nodes = np.argwhere(_box_rim(world))
        world._cache[key] = (cKDTree(world.to_world(nodes)), world.to_world(nodes))
    return world._cache[key]


def _box_distances(world: World, pts: np.ndarray, d_node: np.ndarray) -> np.ndarray:
    """Distance [m] from each point to the nearest obstacle cell box, given its distance
    ``d_node`` to the nearest obstacle cell centre (every box within ``d_node`` plus half a
    cell diagonal is measured)."""
    tree, centres = _box_tree(world)
    h = np.asarray(world.spacing, dtype=float)
    half_diag = 0.5 * float(np.linalg.norm(h))
    out = np.empty(len(pts))
    if len(pts) == 0:
        return out
    chunk = 4096  # points per vectorised batch (bounds the candidate arrays)
    for a in range(0, len(pts), chunk):
        p = pts[a:a + chunk]
        near = tree.query_ball_point(p, d_node[a:a + chunk] + half_diag)
        counts = np.fromiter((len(c) for c in near), dtype=np.int64, count=len(near))
        idx = np.fromiter(chain.from_iterable(near), dtype=np.int64, count=int(counts.sum()))
        owner = np.repeat(np.arange(len(p)), counts)
        gap = np.maximum(np.abs(centres[idx] - p[owner]) - 0.5 * h, 0.0)
        dist = np.sqrt((gap * gap).sum(axis=1))
        out[a:a + chunk] = np.minimum.reduceat(dist, np.concatenate(([0], np.cumsum(counts)[:-1])))
    return out


def _cell_box_clearance(world: World, pts: np.ndarray) -> np.ndarray:
    """Distance to the nearest obstacle cell (box of one spacing around its node)."""
    occ = base_occupancy(world)
    if not occ.any():
        return np.full(len(pts), np.inf)
    d_node, _ = _box_tree(world)[0].query(pts)
    return _box_distances(world, pts, d_node)


def surface_clearance(world: World, points: np.ndarray) -> np.ndarray:
    """Distance [m] from each point to the terrain / building surface (continuous).

    See the module docstring for the surface model. Negative values are
    points below the surface (minus their depth under it, measured vertically).

    Parameters
    ----------
    world : World
    points : ndarray, shape (N, ndim)
        World coordinates [m].

    Returns
    -------
    ndarray, shape (N,)
        ``inf`` for a world without obstacles and without terrain.
    """
    pts = np.atleast_2d(np.asarray(points, dtype=float))
    if world.ndim == 2 or not _is_columns(world):
        return _cell_box_clearance(world, pts)
    from .ground import roof_heights

    heights, ox, oy, hx, hy = _ground_grid(world)
    model = getattr(world, "buildings", None)
    if model is not None:  # terrain from the grid search, buildings from their footprints
        above = pts[:, 2] - np.asarray(world.ground_height(pts[:, 0], pts[:, 1]), dtype=float)
        no_roofs = np.full((2, 2), -np.inf)
        terrain = surface_distance(np.ascontiguousarray(pts), np.ascontiguousarray(above),
                                   heights, ox, oy, hx, hy, no_roofs, world.origin[0],
                                   world.origin[1], world.spacing[0], world.spacing[1])
        return np.minimum(terrain, model.distance(pts))
    above = pts[:, 2] - np.asarray(world.surface_height(pts[:, 0], pts[:, 1]), dtype=float)
    roofs = np.ascontiguousarray(roof_heights(world), dtype=float)
    return surface_distance(np.ascontiguousarray(pts), np.ascontiguousarray(above), heights,
                            ox, oy, hx, hy, roofs, world.origin[0], world.origin[1],
                            world.spacing[0], world.spacing[1])


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
            top = world.surface_index()  # also finds whether the columns are solid
            solid = world._cache.get("columns_solid")
            if solid is None:
                from ._columns import column_tops

                solid = column_tops(world.occupancy)[1]
            if solid:
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
