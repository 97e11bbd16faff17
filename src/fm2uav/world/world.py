"""The :class:`World`: an occupancy grid with its geometry in metres.

Conventions (see the project architecture):

* arrays are indexed ``[ix, iy]`` or ``[ix, iy, iz]`` (x first);
* the grid is node-centred: node ``i`` sits at world coordinate
  ``origin + i * spacing`` [m] on every axis;
* occupancy ``True`` = obstacle;
* all points given to / returned by the API are world coordinates in metres,
  ``to_index`` / ``to_world`` / ``to_cell`` convert to grid indices.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..errors import InputError, PointError, WorldError
from ._registry import BUILDERS as _BUILDERS
from ._registry import register_builders  # noqa: F401  (re-exported: was defined here)

__all__ = ["World", "register_builders"]


#: ids of occupancy arrays made by World's own builders, which World may keep without the
#: defensive copy (a 3000 x 3000 x 78 DEM world's grid is 0.7 GB: the copy doubled the
#: peak and took seconds of page faults).
_BUILT: set[int] = set()


def _readonly(arr: np.ndarray) -> np.ndarray:
    arr.setflags(write=False)
    return arr


def _fmt_point(p: np.ndarray) -> str:
    return "(" + ", ".join(f"{v:.6g}" for v in np.asarray(p, dtype=float).ravel()) + ")"


def _fmt_bounds(b: np.ndarray) -> str:
    axes = "xyz"
    return ", ".join(f"{axes[i]} in [{lo:.6g}, {hi:.6g}]" for i, (lo, hi) in enumerate(b))


def _height_map(value: Any, what: str, heights: str) -> np.ndarray:
    """A float copy of the height map ``value`` [m]; WorldError naming ``what`` if not numeric."""
    try:
        return np.array(value, dtype=float, copy=True)
    except (TypeError, ValueError):
        raise WorldError(
            f"{what} must be a numeric (nx, ny) array of {heights} in metres, "
            f"got {type(value).__name__}"
        ) from None


def _per_axis(value: Any, ndim: int, what: str, *, positive: bool) -> tuple[float, ...]:
    """A number or ``ndim`` numbers → tuple of ``ndim`` finite floats."""
    try:
        arr = np.atleast_1d(np.asarray(value, dtype=float))
    except (TypeError, ValueError):
        raise WorldError(
            f"World {what} must be a number or {ndim} numbers (one per axis, metres), "
            f"got {value!r}"
        ) from None
    if arr.ndim != 1 or arr.size not in (1, ndim):
        raise WorldError(
            f"World {what} must have one value per axis: the occupancy grid is {ndim}D, "
            f"so give {ndim} numbers (or one number for all axes), got {value!r}"
        )
    if arr.size == 1:
        arr = np.repeat(arr, ndim)
    if not np.all(np.isfinite(arr)):
        raise WorldError(f"World {what} must be finite on every axis, got {tuple(arr.tolist())}")
    if positive and np.any(arr <= 0):
        raise WorldError(
            f"World {what} must be > 0 metres on every axis, got {tuple(arr.tolist())}; "
            "give the cell size in metres, e.g. spacing=(15.0, 15.0, 15.0)"
        )
    return tuple(float(a) for a in arr)


@dataclass(frozen=True, eq=False)
class World:
    """An occupancy grid in world coordinates.

    Attributes
    ----------
    occupancy:
        ``(nx, ny)`` or ``(nx, ny, nz)`` bool array, ``True`` = obstacle.
        Stored as a read-only copy.
    spacing:
        Node spacing per axis [m] (a single number is broadcast to all axes).
    origin:
        World coordinates of node ``(0, 0[, 0])`` [m]; ``None`` → zeros.
    terrain:
        Optional ``(nx, ny)`` ground height in world z [m] (read-only copy).
    crs:
        Optional coordinate reference system of x/y (e.g. ``"EPSG:25830"``).
    name:
        Human-readable name.
    filled:
        Optional ``(nx, ny)`` bool array: ``True`` where the terrain height was
        not in the source data but filled (DEM nodata with ``nodata="fill"``).
        A start, goal or take-off there is refused (see
        :func:`fm2uav.world.load.check_points`). Read-only copy.
    georef:
        Optional :class:`~fm2uav.world.geo.Georef`: CRS with EPSG code,
        vertical reference of z, source files with SHA-256 (worlds built from
        real data).
    ground:
        Optional :class:`~fm2uav.world.ground_model.GroundModel`: the DEM at
        its own (finer) resolution; :meth:`ground_height` reads it instead of
        ``terrain`` when present (FM² keeps planning on ``terrain``).
    buildings:
        Optional :class:`~fm2uav.world.building_model.BuildingModel`: the building
        footprints themselves with their roofs; :meth:`surface_height` and the
        clearance read them instead of the (dilated, one-vertical-cell) grid columns
        when present (FM² keeps planning on the grid).
    zones:
        No-fly zones and operating areas (:class:`fm2uav.world.zones.Zone`)
        whose nodes are part of ``occupancy``; build with
        :func:`fm2uav.world.zones.with_zones`. Default ``()``.
    _cache:
        Private scratch dictionary where other modules may cache arrays derived
        from this (immutable) world, e.g. the distance transform. It is not an
        ``__init__`` argument, so ``dataclasses.replace`` gives the new world a
        fresh, empty cache.
    """

    occupancy: np.ndarray
    spacing: tuple[float, ...]
    origin: tuple[float, ...] | None = None
    terrain: np.ndarray | None = None
    crs: str | None = None
    name: str = ""
    filled: np.ndarray | None = None
    georef: Any = None
    ground: Any = None
    zones: tuple = ()
    buildings: Any = None
    _cache: dict = field(default_factory=dict, init=False, repr=False, compare=False)

    # ------------------------------------------------------------------ validation
    def __post_init__(self) -> None:
        occ = np.asarray(self.occupancy)
        if occ.dtype != bool:
            raise WorldError(
                f"World occupancy must be a bool array (True = obstacle), got dtype "
                f"{occ.dtype}; convert it first, e.g. `occupancy > 0` or `occupancy.astype(bool)`"
            )
        if occ.ndim not in (2, 3):
            raise WorldError(
                f"World occupancy must be 2D (nx, ny) or 3D (nx, ny, nz), got {occ.ndim}D "
                f"with shape {occ.shape}"
            )
        if occ.size == 0:
            raise WorldError(
                f"World occupancy is empty (shape {occ.shape}); every axis needs at least one node"
            )
        if id(occ) in _BUILT:  # made by a builder of this class: nobody else holds it
            _BUILT.discard(id(occ))
            occ = _readonly(occ)
        else:
            occ = _readonly(np.array(occ, dtype=bool, copy=True))
        ndim = occ.ndim
        spacing = _per_axis(self.spacing, ndim, "spacing", positive=True)
        origin = (
            (0.0,) * ndim
            if self.origin is None
            else _per_axis(self.origin, ndim, "origin", positive=False)
        )
        terrain = self.terrain
        if terrain is not None:
            t = _height_map(terrain, "World terrain", "heights")
            if t.shape != occ.shape[:2]:
                raise WorldError(
                    f"World terrain must have shape (nx, ny) = {occ.shape[:2]} to match the "
                    f"occupancy grid, got {t.shape}"
                )
            if not np.all(np.isfinite(t)):
                bad = np.argwhere(~np.isfinite(t))[0]
                raise WorldError(
                    f"World terrain has a non-finite height at column {tuple(bad.tolist())}; "
                    "fill the gaps (e.g. interpolate the DEM) before building the world"
                )
            terrain = _readonly(t)
        if self.crs is not None and not isinstance(self.crs, str):
            raise WorldError(
                f"World crs must be a string such as 'EPSG:4326' or None, got {self.crs!r}"
            )
        filled = self.filled
        if filled is not None:
            fm = np.asarray(filled)
            if fm.dtype != bool or fm.shape != occ.shape[:2]:
                raise WorldError(
                    f"World filled must be a bool (nx, ny) = {occ.shape[:2]} mask of filled "
                    f"terrain columns, got dtype {fm.dtype} and shape {fm.shape}"
                )
            filled = _readonly(np.array(fm, dtype=bool, copy=True))
        set_ = object.__setattr__
        set_(self, "filled", filled)
        set_(self, "zones", tuple(self.zones or ()))
        set_(self, "occupancy", occ)
        set_(self, "spacing", spacing)
        set_(self, "origin", origin)
        set_(self, "terrain", terrain)
        set_(self, "name", str(self.name))

    def __repr__(self) -> str:  # arrays summarised, not printed
        return (
            f"World(name={self.name!r}, shape={self.shape}, spacing={self.spacing}, "
            f"origin={self.origin}, obstacles={int(self.occupancy.sum())}/{self.occupancy.size}, "
            f"terrain={'yes' if self.terrain is not None else 'no'}, crs={self.crs!r}"
            + (f", filled={int(self.filled.sum())}" if self.filled is not None else "") + ")"
        )

    def with_fields(self, **changes: Any) -> World:
        """``dataclasses.replace(self, **changes)`` sharing the read-only occupancy grid.

        A new world (fresh cache) with other fields, e.g. ``crs``, ``name``, ``georef``;
        unless ``occupancy`` is among the changes, the grid is not copied (it is
        read-only in both).
        """
        import dataclasses

        if "occupancy" in changes:
            return dataclasses.replace(self, **changes)
        _BUILT.add(id(self.occupancy))
        try:
            return dataclasses.replace(self, **changes)
        finally:
            _BUILT.discard(id(self.occupancy))

    # ------------------------------------------------------------------ geometry
    @property
    def ndim(self) -> int:
        """Number of axes (2 or 3)."""
        return int(self.occupancy.ndim)

    @property
    def shape(self) -> tuple[int, ...]:
        """Number of nodes per axis ``(nx, ny[, nz])``."""
        return tuple(int(n) for n in self.occupancy.shape)

    @property
    def free(self) -> np.ndarray:
        """``~occupancy``: ``True`` where the space is free."""
        return ~self.occupancy

    @property
    def bounds(self) -> np.ndarray:
        """``(ndim, 2)`` array of ``[min, max]`` world coordinates of the nodes [m]."""
        o = np.asarray(self.origin, dtype=float)
        hi = o + (np.asarray(self.shape, dtype=float) - 1.0) * np.asarray(self.spacing)
        return np.stack([o, hi], axis=1)

    def _as_points(self, points: Any, what: str) -> np.ndarray:
        try:
            p = np.asarray(points, dtype=float)
        except (TypeError, ValueError):
            raise InputError(
                f"{what} must be numeric coordinates of shape (..., {self.ndim}), got {points!r}"
            ) from None
        if p.ndim == 0 or p.shape[-1] != self.ndim:
            raise InputError(
                f"{what} must have {self.ndim} coordinates per point (the world is {self.ndim}D, "
                f"order x, y{', z' if self.ndim == 3 else ''}), got array of shape {p.shape}"
            )
        return p

    def to_index(self, points: Any) -> np.ndarray:
        """World coordinates [m] ``(..., ndim)`` → continuous grid indices ``(..., ndim)``."""
        p = self._as_points(points, "points")
        return (p - np.asarray(self.origin)) / np.asarray(self.spacing)

    def to_world(self, indices: Any) -> np.ndarray:
        """Grid indices (int or float) ``(..., ndim)`` → world coordinates [m]."""
        i = self._as_points(indices, "indices")
        return np.asarray(self.origin) + i * np.asarray(self.spacing)

    def contains(self, points: Any) -> np.ndarray | bool:
        """Whether the point(s) [m] lie inside :attr:`bounds` (a tiny tolerance allowed).

        Returns a bool for one point and a bool array of shape ``(...)`` otherwise.
        """
        idx = self.to_index(points)
        tol = 1e-9
        ok = np.all(
            (idx >= -tol) & (idx <= np.asarray(self.shape) - 1 + tol) & np.isfinite(idx), axis=-1
        )
        return bool(ok) if np.ndim(ok) == 0 else ok

    def to_cell(
        self, points: Any, what: str = "point"
    ) -> tuple[int, ...] | list[tuple[int, ...]]:
        """Nearest grid node of world point(s) [m].

        One point ``(ndim,)`` → a tuple of ints usable as ``occupancy[cell]``;
        several points ``(m, ndim)`` → a list of such tuples.

        Raises
        ------
        PlanningError
            If a point lies outside the map (``what`` names it in the message).
        """
        p = self._as_points(points, what)
        if p.ndim > 2:
            raise InputError(
                f"{what} must be one point ({self.ndim},) or a list of points (m, {self.ndim}), "
                f"got array of shape {p.shape}"
            )
        flat = np.atleast_2d(p)
        if not np.all(np.isfinite(flat)):
            bad = flat[~np.all(np.isfinite(flat), axis=1)][0]
            raise InputError(f"{what} has non-finite coordinates {_fmt_point(bad)}; give metres")
        inside = np.atleast_1d(self.contains(flat))
        if not np.all(inside):
            bad = flat[~inside][0]
            raise PointError(
                f"{what} {_fmt_point(bad)} m lies outside the map, whose bounds are "
                f"{_fmt_bounds(self.bounds)} m; move the {what} inside these bounds "
                "or build a larger world"
            )
        # floor(x + 0.5): the same nearest-node rule as planning.geodesic
        idx = np.floor(self.to_index(flat) + 0.5).astype(np.int64)
        idx = np.clip(idx, 0, np.asarray(self.shape) - 1)
        cells = [tuple(int(v) for v in row) for row in idx]
        return cells[0] if p.ndim == 1 else cells

    # ------------------------------------------------------------------ terrain
    def surface_index(self) -> np.ndarray:
        """``(nx, ny)`` int array: z index of the topmost obstacle node of each column.

        ``-1`` where a column has no obstacle. Only defined for 3D worlds.
        """
        if self.ndim != 3:
            raise WorldError(
                f"surface_index() needs a 3D world (nx, ny, nz); this world is {self.ndim}D "
                f"with shape {self.shape}"
            )
        key = "surface_index"
        if key not in self._cache:
            from ._columns import column_tops

            top, solid = column_tops(self.occupancy)
            self._cache[key] = _readonly(top)
            self._cache["columns_solid"] = solid
        return self._cache[key]

    def ground_height(self, x: Any, y: Any) -> np.ndarray | float:
        """Ground height (world z [m]) at ``(x, y)`` [m], continuous.

        The terrain (:attr:`terrain`) interpolated bilinearly between the
        columns (edge columns outside the map). **Without terrain the ground is
        the floor of the grid**, ``origin[2]`` (0 for a 2D world). ``x`` and
        ``y`` broadcast together (vectorised); two numbers give a float. See
        :mod:`fm2uav.world.ground`.

        Examples
        --------
        >>> import numpy as np
        >>> w = World.from_heightmap(np.array([[0.0, 0.0], [10.0, 10.0]]), 5.0, 4)
        >>> w.ground_height(2.5, 0.0)
        5.0
        """
        from .ground import ground_height

        return ground_height(self, x, y)

    def ground_source(self, x: Any, y: Any) -> np.ndarray:
        """Which DEM measures the ground at ``(x, y)`` [m]: 0 = ``world.dem``, k = the k-th
        ``world.dem_fill``, -1 = unknown (filled nodata); see
        :func:`fm2uav.world.ground.ground_source`."""
        from .ground import ground_source

        return ground_source(self, x, y)

    def ground_filled(self, x: Any, y: Any) -> np.ndarray:
        """Whether the ground at ``(x, y)`` [m] is unknown (filled DEM nodata), as a bool
        array of the broadcast shape; see :func:`fm2uav.world.ground.ground_source`."""
        from .ground import ground_filled

        return ground_filled(self, x, y)

    def surface_height(self, x: Any, y: Any) -> np.ndarray | float:
        """Height (world z [m]) of the ground or a roof at ``(x, y)``, whichever is higher.

        Ground as :meth:`ground_height`; roofs are the topmost obstacle nodes
        above the ground, read from the nearest column. See
        :mod:`fm2uav.world.ground`.
        """
        from .ground import surface_height

        return surface_height(self, x, y)

    # ------------------------------------------------------------------ builders
    @classmethod
    def from_heightmap(
        cls,
        heights_m: Any,
        cell_size: float | Sequence[float],
        height_cells: int,
        *,
        origin: Sequence[float] | None = None,
        name: str = "",
    ) -> World:
        """Build a 3D world from a ground-height map.

        Parameters
        ----------
        heights_m:
            ``(nx, ny)`` ground height [m] in world z (same datum as ``origin[2]``).
        cell_size:
            Node spacing [m]: one number (same horizontally and vertically) or
            ``(dx, dy, dz)``.
        height_cells:
            Number of vertical nodes ``nz`` (>= 1).
        origin:
            World coordinates ``(x0, y0, z0)`` of node ``(0, 0, 0)`` [m]; default zeros.

        Node ``(i, j, k)`` is an obstacle iff ``z0 + k * dz <= heights_m[i, j]``.
        The height map is stored as :attr:`terrain`.
        """
        h = _height_map(heights_m, "heights_m", "ground heights")
        if h.ndim != 2:
            raise WorldError(
                f"heights_m must be a 2D (nx, ny) array of ground heights in metres, got "
                f"{h.ndim}D with shape {h.shape}"
            )
        if h.size == 0:
            raise WorldError(f"heights_m is empty (shape {h.shape}); give at least one column")
        if not np.all(np.isfinite(h)):
            bad = np.argwhere(~np.isfinite(h))
            raise WorldError(
                f"heights_m has {len(bad)} NaN/inf value(s), first at column "
                f"{tuple(bad[0].tolist())}; fill the gaps (e.g. interpolate the DEM) first"
            )
        try:
            cs = np.atleast_1d(np.asarray(cell_size, dtype=float))
        except (TypeError, ValueError):
            raise WorldError(
                f"cell_size must be a number or (dx, dy, dz) in metres, got {cell_size!r}"
            ) from None
        if cs.ndim != 1 or cs.size not in (1, 3):
            raise WorldError(
                f"cell_size must be a number or (dx, dy, dz) in metres, got {cell_size!r}"
            )
        if not np.all(np.isfinite(cs)) or np.any(cs <= 0):
            raise WorldError(
                f"cell_size must be finite and > 0 metres, got {tuple(cs.tolist())}; "
                "e.g. cell_size=15.0 for 15 m cells"
            )
        spacing = tuple(float(c) for c in np.broadcast_to(cs, (3,)))
        if isinstance(height_cells, bool) or not isinstance(height_cells, (int, np.integer)):
            raise WorldError(
                f"height_cells must be an integer number of vertical nodes, got {height_cells!r}"
            )
        nz = int(height_cells)
        if nz < 1:
            raise WorldError(f"height_cells must be >= 1 (number of vertical nodes), got {nz}")
        if origin is None:
            org = (0.0, 0.0, 0.0)
        else:
            o = np.atleast_1d(np.asarray(origin, dtype=float))
            if o.shape != (3,) or not np.all(np.isfinite(o)):
                raise WorldError(
                    f"origin must be three finite numbers (x0, y0, z0) in metres, got {origin!r}"
                )
            org = tuple(float(v) for v in o)
        dz = spacing[2]
        z = org[2] + np.arange(nz) * dz
        ceiling = float(z[-1])
        if np.any(h >= ceiling):
            i, j = np.unravel_index(int(np.argmax(h)), h.shape)
            need = int(np.floor((float(h[i, j]) - org[2]) / dz)) + 2
            raise WorldError(
                f"terrain reaches {h[i, j]:.6g} m at column ({i}, {j}), at or above the top node "
                f"z = {ceiling:.6g} m of a {nz}-node-high world, so that column has no free space; "
                f"use height_cells >= {need} (or a larger cell_size / lower the heights)"
            )
        occ = z[None, None, :] <= h[:, :, None]
        _BUILT.add(id(occ))
        try:
            return cls(occupancy=occ, spacing=spacing, origin=org, terrain=h, name=name)
        finally:
            _BUILT.discard(id(occ))

    @classmethod
    def from_dem(
        cls, source: Any, cell_size: float | Sequence[float], ceiling: float | None = None,
        **kwargs: Any,
    ) -> World:
        """Build a 3D world from a DEM (any GDAL raster, tiles, or an array), geo-referenced.

        See :func:`fm2uav.world.dem.from_dem` for the parameters (CRS handling,
        masks, ``bbox`` crop, ``sea_level``, nodata rule, ``ceiling`` altitude [m]).
        """
        return _BUILDERS["from_dem"](source, cell_size, ceiling, **kwargs)

    @classmethod
    def from_lonlat_grid(
        cls, z: Any, lon: Any, lat: Any, cell_size: float | Sequence[float],
        ceiling: float | None = None, **kwargs: Any,
    ) -> World:
        """Build a 3D world from an elevation array ``z[i_lat, i_lon]`` and lon/lat vectors.

        The xarray layout (``da.values, da.lon.values, da.lat.values``):
        longitudes 0..360 or -180..180, latitudes in either order. See
        :func:`fm2uav.world.dem.from_lonlat_grid`.
        """
        return _BUILDERS["from_lonlat_grid"](z, lon, lat, cell_size, ceiling, **kwargs)

    @classmethod
    def from_buildings(cls, footprints: Any, cell_size: float | Sequence[float], **kwargs: Any) -> World:
        """Build a 3D world from building footprints with heights.

        ``footprints``: a vector file (GeoJSON, GeoPackage, Shapefile, KML/KMZ;
        lon/lat per RFC 7946 unless it declares a CRS) or in-memory GeoJSON.
        See :func:`fm2uav.world.buildings.from_buildings` for the parameters
        (``height`` [m], else ``building:levels`` x 3 m, else ``default_height``).
        """
        return _BUILDERS["from_buildings"](footprints, cell_size, **kwargs)

    @classmethod
    def from_image(cls, path: Any, resolution: float, **kwargs: Any) -> World:
        """A 2D world from a picture (dark pixels = obstacles), ``resolution`` [m/pixel].

        See :func:`fm2uav.world.images.world_from_image` (``threshold``, ``negate``,
        ``origin``).
        """
        return _BUILDERS["from_image"](path, resolution, **kwargs)

    @classmethod
    def from_ros_map(cls, yaml_path: Any, **kwargs: Any) -> World:
        """A 2D world from a ROS ``map_server`` map (``map.yaml`` + PGM/PNG image).

        See :func:`fm2uav.world.images.world_from_ros_map` (thresholds, negate,
        unknown cells = obstacles by default).
        """
        return _BUILDERS["from_ros_map"](yaml_path, **kwargs)
