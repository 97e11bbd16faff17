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

__all__ = ["ground_height", "surface_height", "roof_heights", "terrain_along", "ground_bulge"]


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
    model = getattr(world, "buildings", None)
    if model is not None:  # the footprints themselves (world/building_model.py)
        return _out(np.maximum(ground, model.roof_at(xa, ya)), scalar)
    roofs = roof_heights(world)
    if world.ndim != 3 or not np.isfinite(roofs).any():
        return _out(ground, scalar)
    nx, ny = world.shape[:2]
    # floor(i + 0.5): the nearest-node rule of World.to_cell
    i = np.clip(np.floor((xa - world.origin[0]) / world.spacing[0] + 0.5), 0, nx - 1)
    j = np.clip(np.floor((ya - world.origin[1]) / world.spacing[1] + 0.5), 0, ny - 1)
    roof = roofs[i.astype(np.int64), j.astype(np.int64)]
    return _out(np.maximum(ground, roof), scalar)


def terrain_along(world: World, path: np.ndarray) -> np.ndarray | None:
    """Ground height [m] under each path point (bilinear), or None without terrain."""
    if world.terrain is None:
        return None
    p = np.asarray(path, dtype=float)
    return np.asarray(ground_height(world, p[:, 0], p[:, 1]), dtype=float)


def _grid_index(world: World, x: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Continuous index of world points in the grid the ground is bilinear on (the source
    DEM's pixel centres, or the world's terrain nodes): smooth between whole numbers."""
    model = getattr(world, "ground", None)
    if model is not None:
        return model.pixel_index(x, y)
    return ((np.asarray(x, dtype=float) - world.origin[0]) / world.spacing[0],
            (np.asarray(y, dtype=float) - world.origin[1]) / world.spacing[1])


def ground_bulge(world: World, a: Any, b: Any) -> tuple[np.ndarray, np.ndarray]:
    """How far the ground rises above, and drops below, the straight line between its
    heights at the ends of each chord ``a[i]`` → ``b[i]`` (x, y [m]): ``(rise, drop)`` [m],
    both >= 0.

    Exact for the bilinear ground (:func:`ground_height`): along a straight chord it is a
    quadratic between the chord's crossings of the grid's whole rows and columns (the
    source DEM's pixel centres, or the terrain nodes), so the extremes lie at those
    crossings or at a piece's vertex; each piece is read at its ends and middle and its
    quadratic solved (a DEM in another CRS than the world bends the chord by far less
    than a millimetre over a pixel). Reading a few points per chord missed centimetres
    at pixel edges — enough to put a path exactly at a zone's ceiling inside it.
    """
    pa = np.atleast_2d(np.asarray(a, dtype=float))[:, :2]
    pb = np.atleast_2d(np.asarray(b, dtype=float))[:, :2]
    k = len(pa)
    if k == 0 or (getattr(world, "ground", None) is None and world.terrain is None):
        return np.zeros(k), np.zeros(k)
    r0, c0 = _grid_index(world, pa[:, 0], pa[:, 1])
    r1, c1 = _grid_index(world, pb[:, 0], pb[:, 1])
    # breakpoints: t where the row or the column index crosses a whole number
    ts = [np.zeros(k), np.ones(k)]
    for u0, u1 in ((r0, r1), (c0, c1)):
        lo, hi = np.minimum(u0, u1), np.maximum(u0, u1)
        first = np.floor(lo) + 1.0
        n = np.maximum(np.ceil(hi) - first, 0).astype(int)
        du = np.where(np.abs(u1 - u0) > 1e-12, u1 - u0, np.nan)
        for j in range(int(n.max()) if n.size else 0):
            v = first + j
            t = np.where(j < n, (v - u0) / du, np.nan)
            ts.append(np.where((t > 0) & (t < 1), t, np.nan))
    t = np.sort(np.column_stack(ts), axis=1)  # NaNs last
    ta, tb = t[:, :-1], t[:, 1:]
    ok = np.isfinite(ta) & np.isfinite(tb) & (tb > ta)
    tm = 0.5 * (ta + tb)
    fr = np.stack([ta, tm, tb], axis=-1)  # (k, pieces, 3)
    fr = np.where(ok[..., None], fr, 0.0)
    d = pb - pa
    q = pa[:, None, None, :] + fr[..., None] * d[:, None, None, :]
    g = np.asarray(ground_height(world, q[..., 0].ravel(), q[..., 1].ravel()),
                   dtype=float).reshape(fr.shape)
    g_end = np.asarray(ground_height(world, np.r_[pa[:, 0], pb[:, 0]],
                                     np.r_[pa[:, 1], pb[:, 1]]), dtype=float)
    lin = g_end[:k, None, None] + fr * (g_end[k:] - g_end[:k])[:, None, None]
    h = g - lin  # the ground above the chord's straight line, per piece at ends and middle
    # the quadratic through the three values: h(s) = h0 + B s + C s^2, s in [0, 1]
    h0, hm, h1 = h[..., 0], h[..., 1], h[..., 2]
    C = 2.0 * (h0 + h1) - 4.0 * hm
    B = h1 - h0 - C
    with np.errstate(divide="ignore", invalid="ignore"):
        s = np.where(np.abs(C) > 1e-12, -B / (2.0 * C), np.nan)
    inside = np.isfinite(s) & (s > 0) & (s < 1)
    hv = np.where(inside, h0 + B * s + C * s * s, np.nan)
    vals = np.concatenate([h0, h1, hv], axis=1)
    vals = np.where(np.concatenate([ok, ok, ok & inside], axis=1), vals, np.nan)
    rise = np.nanmax(np.concatenate([vals, np.zeros((k, 1))], axis=1), axis=1)
    drop = np.nanmax(np.concatenate([-vals, np.zeros((k, 1))], axis=1), axis=1)
    return np.maximum(rise, 0.0), np.maximum(drop, 0.0)
