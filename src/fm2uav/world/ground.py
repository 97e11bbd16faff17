"""Ground and surface heights of a world, continuous in x, y.

The one home of "how high is the ground here": :meth:`World.ground_height` and
:meth:`World.surface_height` call these functions.

* **Ground** (:func:`ground_height`): the world's terrain height map
  (``World.terrain``, one height per column) interpolated bilinearly between
  the column nodes, clamped to the edge columns outside the map — or, for a
  world built from a DEM finer than its cells, the DEM itself at its own
  resolution (``World.ground``, :mod:`fm2uav.world.ground_model`). A world
  without terrain has its ground at the **floor of the grid**: ``origin[2]``,
  the z of the lowest node layer (``0`` for a 2D world, which has no z).
* **Surface** (:func:`surface_height`): the ground or a roof, whichever is
  higher. A world built from building footprints keeps them
  (``World.buildings``, :mod:`fm2uav.world.building_model`): the roof is then
  that of the footprint under the point (edge included). Otherwise roofs are
  what the occupancy grid holds above the ground: in each
  column, the z of the topmost obstacle node when it is above the column's
  ground; read from the nearest column (roofs have sharp edges, so they are
  not interpolated). The grid resolves a roof to one vertical cell (the true
  roof lies in ``[z_top, z_top + dz)``).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np
from scipy import ndimage

if TYPE_CHECKING:
    from .world import World

__all__ = ["ground_height", "ground_filled", "ground_source", "has_unknown_ground",
           "surface_height", "surface_and_ground", "roof_heights", "terrain_along"]


def _xy(world: World, x: Any, y: Any) -> tuple[np.ndarray, np.ndarray, bool]:
    from ..errors import InputError

    try:
        xa, ya = np.broadcast_arrays(np.asarray(x, dtype=float), np.asarray(y, dtype=float))
    except (TypeError, ValueError):
        raise InputError(
            f"x and y must be numbers or arrays of the same shape (metres), got {x!r}, {y!r}"
        ) from None
    return xa, ya, xa.ndim == 0


def _out(values: np.ndarray, scalar: bool) -> np.ndarray | float:
    return float(values) if scalar else values


def ground_height(world: World, x: Any, y: Any) -> np.ndarray | float:
    """Ground height (world z [m]) at ``(x, y)`` [m]; see the module docstring.

    ``x`` and ``y`` broadcast together; one number each gives a float.
    """
    xa, ya, scalar = _xy(world, x, y)
    model = getattr(world, "ground", None)
    if model is not None:  # the DEM at its own resolution (world/ground_model.py)
        return _out(np.asarray(model.height(xa, ya), dtype=float), scalar)
    if world.terrain is None:
        floor = float(world.origin[2]) if world.ndim == 3 else 0.0
        return _out(np.full(xa.shape, floor), scalar)
    ix = (xa - world.origin[0]) / world.spacing[0]
    iy = (ya - world.origin[1]) / world.spacing[1]
    z = ndimage.map_coordinates(
        world.terrain, np.stack([ix.ravel(), iy.ravel()]), order=1, mode="nearest"
    )
    return _out(z.reshape(xa.shape), scalar)


def ground_source(world: World, x: Any, y: Any) -> np.ndarray:
    """Which DEM measures the ground at ``(x, y)`` [m]: 0 for ``world.dem``, k for the k-th
    ``world.dem_fill``, -1 where the ground is unknown (filled nodata).

    The rule of :meth:`ground_height`'s bilinear stencil: the ground is measured where
    every sample with a non-zero weight is (the source DEM's four pixels, or the
    planning grid's four nodes against ``World.filled`` when the world keeps no ground
    model). A world without ``filled`` nodes and without a ground model is measured
    everywhere (synthetic terrain is known by construction).
    """
    xa, ya, _ = _xy(world, x, y)
    model = getattr(world, "ground", None)
    if model is not None:
        return np.asarray(model.source(xa, ya), dtype=np.int8)
    filled = getattr(world, "filled", None)
    out = np.zeros(xa.shape, dtype=np.int8)
    if filled is None or not filled.any():
        return out
    nx, ny = filled.shape
    ix = np.clip((xa - world.origin[0]) / world.spacing[0], 0, nx - 1)
    iy = np.clip((ya - world.origin[1]) / world.spacing[1], 0, ny - 1)
    i0 = np.minimum(np.floor(ix).astype(np.int64), max(nx - 2, 0))
    j0 = np.minimum(np.floor(iy).astype(np.int64), max(ny - 2, 0))
    fx, fy = ix - i0, iy - j0
    bad = np.zeros(xa.shape, dtype=bool)
    for di, dj, w in ((0, 0, (1 - fx) * (1 - fy)), (1, 0, fx * (1 - fy)),
                      (0, 1, (1 - fx) * fy), (1, 1, fx * fy)):
        ii, jj = np.minimum(i0 + di, nx - 1), np.minimum(j0 + dj, ny - 1)
        bad |= (w > 1e-12) & filled[ii, jj]
    out[bad] = -1
    return out


def has_unknown_ground(world: World) -> bool:
    """Whether some ground of the map is unknown (filled): a filled node, or nodata pixels
    of the DEM between the nodes (counted when the world was built)."""
    filled = getattr(world, "filled", None)
    if filled is not None and bool(np.asarray(filled).any()):
        return True
    g = getattr(world, "georef", None)
    return any(s.role == "dem" and s.details.get("filled_pixels_between_nodes", 0) > 0
               for s in (getattr(g, "sources", ()) or ()))


def ground_filled(world: World, x: Any, y: Any) -> np.ndarray:
    """Whether the ground at ``(x, y)`` [m] is unknown: filled nodata that no DEM measures
    (see :func:`ground_source`)."""
    return ground_source(world, x, y) < 0


def roof_heights(world: World) -> np.ndarray:
    """``(nx, ny)`` z [m] of the roof of each column, ``-inf`` where there is none.

    A roof is the topmost obstacle node of a column when it is above the
    column's ground (the terrain node height, or the floor without terrain);
    nodes of no-fly zones (``World.zones``) do not count.
    Cached on the world; 2D worlds have no roofs.
    """
    key = "roof_heights"
    cached = world._cache.get(key)
    if cached is None:
        if world.ndim != 3:
            cached = np.full(world.shape, -np.inf)
        else:
            from .zones import terrain_surface_index

            top = terrain_surface_index(world)  # no-fly zone nodes are not roofs
            z_top = world.origin[2] + top * world.spacing[2]
            ground = world.terrain if world.terrain is not None else world.origin[2]
            tol = 1e-9 * world.spacing[2]
            cached = np.where((top >= 0) & (z_top > ground + tol), z_top, -np.inf)
        cached.setflags(write=False)
        world._cache[key] = cached
    return cached


def surface_height(world: World, x: Any, y: Any) -> np.ndarray | float:
    """Height (world z [m]) of the ground or a roof at ``(x, y)``, whichever is higher.

    Ground as :func:`ground_height` (bilinear); roofs from the world's building
    footprints when it keeps them, else from the nearest column
    (:func:`roof_heights`). ``x`` and ``y`` broadcast together.
    """
    xa, ya, scalar = _xy(world, x, y)
    ground = np.asarray(ground_height(world, xa, ya), dtype=float)
    return _out(_surface_over(world, xa, ya, ground), scalar)


def surface_and_ground(world: World, x: Any, y: Any) -> tuple[np.ndarray, np.ndarray]:
    """``(surface_height, ground_height)`` at ``(x, y)`` [m] as arrays, the ground read once
    (a DEM world's ground costs a reprojection per point)."""
    xa, ya, _ = _xy(world, x, y)
    ground = np.asarray(ground_height(world, xa, ya), dtype=float)
    return np.asarray(_surface_over(world, xa, ya, ground), dtype=float), ground


def _surface_over(world: World, xa: np.ndarray, ya: np.ndarray,
                  ground: np.ndarray) -> np.ndarray:
    """The surface over ``ground`` (the ground height at ``(xa, ya)`` [m]): roofs added."""
    model = getattr(world, "buildings", None)
    if model is not None:  # the footprints themselves (world/building_model.py)
        return np.maximum(ground, model.roof_at(xa, ya))
    roofs = roof_heights(world)
    if world.ndim != 3 or not np.isfinite(roofs).any():
        return ground
    nx, ny = world.shape[:2]
    # floor(i + 0.5): the nearest-node rule of World.to_cell
    i = np.clip(np.floor((xa - world.origin[0]) / world.spacing[0] + 0.5), 0, nx - 1)
    j = np.clip(np.floor((ya - world.origin[1]) / world.spacing[1] + 0.5), 0, ny - 1)
    roof = roofs[i.astype(np.int64), j.astype(np.int64)]
    return np.maximum(ground, roof)


def terrain_along(world: World, path: np.ndarray) -> np.ndarray | None:
    """Ground height [m] under each path point (bilinear), or None without terrain."""
    if world.terrain is None:
        return None
    p = np.asarray(path, dtype=float)
    return np.asarray(ground_height(world, p[:, 0], p[:, 1]), dtype=float)

