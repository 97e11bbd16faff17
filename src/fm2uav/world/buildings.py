"""Worlds made of buildings: footprints with heights, alone or on a DEM.

* :func:`from_buildings` (also ``World.from_buildings``) rasterises building
  footprints (``Polygon`` / ``MultiPolygon`` features of any vector file
  :func:`fm2uav.world.vectors.read_vectors` reads — GeoJSON in lon/lat per
  RFC 7946, GeoPackage, Shapefile, KML/KMZ — or in-memory GeoJSON) with a
  height into an occupancy grid: node ``(i, j, k)`` is an obstacle iff its
  column is covered by a footprint and ``z <= roof``, or iff it is at or below
  the ground. A column is covered when its node lies inside (or on the edge
  of) the footprint; with ``all_touched=True`` (used for real data by
  :func:`fm2uav.world.load.load_world`) when the node's cell (node ± half a
  cell) touches it, so that a building smaller than a cell still blocks it.
* On flat ground the roof is ``z0 + height``. On a DEM world (``terrain=``)
  it is the highest ground under the footprint plus the height: a building
  on a slope is never lower than its uphill side.
* Lon/lat data are reprojected to the local UTM zone (or to the DEM world's
  CRS); the world records the source file with its SHA-256 and how many
  buildings took each height rule (``World.georef``).
* The urban case study of thesis ch. 3 built with it is
  :mod:`fm2uav.scenarios.city`.

Heights
-------
A feature's height is read from its properties, first match wins:

1. ``height`` — metres; a number or a string such as ``"25"``, ``"25 m"``,
   ``"25.5m"`` (OpenStreetMap ``height=*`` convention);
2. ``building:levels`` (or ``levels``, or ``building_l`` as a Shapefile
   truncates it) — number of storeys, multiplied by
   ``metres_per_level`` (default :data:`METRES_PER_LEVEL` = 3.0 m, the storey
   height the OpenStreetMap "Simple 3D buildings" guidance uses to derive a
   height from a level count);
3. otherwise ``default_height`` if given (mission file
   ``world.default_height``, CLI ``--default-height``), else a
   :class:`WorldError` saying how many buildings lack a height.

Heights in feet (``"40 ft"``, ``"40'"``) are converted to metres.
"""

from __future__ import annotations

import dataclasses
import re
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
import shapely

from ..errors import WorldError
from .geo import check_lonlat_bbox, check_size, make_georef
from .vectors import read_vectors
from .world import World

__all__ = [
    "METRES_PER_LEVEL",
    "from_buildings",
    "building_height",
    "height_and_rule",
    "HEIGHT_RULES",
]

#: Storey height used with ``building:levels`` [m] (OSM Simple 3D buildings).
METRES_PER_LEVEL = 3.0
_NUM = re.compile(r"^\s*([-+]?\d+(?:[.,]\d+)?)\s*(m|meters|metres|ft|feet|')?\s*$", re.IGNORECASE)
_FOOT = 0.3048


def _parse_number(value: Any, what: str, idx: int) -> float:
    if isinstance(value, bool):
        raise WorldError(f"building {idx}: {what} must be a number, got {value!r}")
    if isinstance(value, (int, float, np.integer, np.floating)):
        v = float(value)
    elif isinstance(value, str):
        m = _NUM.match(value)
        if m is None:
            raise WorldError(
                f"building {idx}: cannot read {what} {value!r}; give metres as a number "
                "such as 25 or '25 m'"
            )
        v = float(m.group(1).replace(",", "."))
        if (m.group(2) or "").lower() in ("ft", "feet", "'"):
            v *= _FOOT
    else:
        raise WorldError(f"building {idx}: {what} must be a number, got {value!r}")
    if not np.isfinite(v) or v <= 0:
        raise WorldError(f"building {idx}: {what} must be finite and > 0, got {value!r}")
    return v


def building_height(
    properties: Mapping[str, Any] | None,
    *,
    metres_per_level: float = METRES_PER_LEVEL,
    default_height: float | None = None,
    index: int = 0,
) -> float:
    """Height [m] of one building from its properties (see module doc).

    Raises
    ------
    WorldError
        No usable ``height`` / ``building:levels`` and no ``default_height``.
    """
    return height_and_rule(properties, metres_per_level=metres_per_level,
                           default_height=default_height, index=index)[0]


#: The height rules, in the order they are tried.
HEIGHT_RULES = ("height", "building:levels", "default_height")


def _blank(v: Any) -> bool:
    return v is None or (isinstance(v, str) and not v.strip()) or (
        isinstance(v, float) and not np.isfinite(v))


def height_and_rule(
    properties: Mapping[str, Any] | None,
    *,
    metres_per_level: float = METRES_PER_LEVEL,
    default_height: float | None = None,
    index: int = 0,
) -> tuple[float, str]:
    """``(height [m], rule)`` of one building; ``rule`` is one of :data:`HEIGHT_RULES`.

    Raises
    ------
    WorldError
        No usable ``height`` / ``building:levels`` and no ``default_height``;
        an unreadable value (names the building and the value).
    """
    props = dict(properties or {})
    if not _blank(props.get("height")):
        return _parse_number(props["height"], "height", index), "height"
    for key in ("building:levels", "levels", "building_l"):  # building_l: Shapefile's 10 chars
        if not _blank(props.get(key)):
            return _parse_number(props[key], key, index) * float(metres_per_level), \
                "building:levels"
    if default_height is not None:
        return _parse_number(default_height, "default_height", index), "default_height"
    raise WorldError(
        f"building {index} has neither 'height' (m) nor 'building:levels' in its properties "
        f"{sorted(props)}; add one, or set world.default_height (CLI --default-height)"
    )


def _cell_size(cell_size: Any) -> np.ndarray:
    cs = np.broadcast_to(np.asarray(cell_size, dtype=float), (3,)).copy() if np.ndim(
        cell_size) <= 1 else None
    if cs is None or cs.shape != (3,) or not np.all(np.isfinite(cs)) or np.any(cs <= 0):
        raise WorldError(f"world.cell_size (--cell-size) must be > 0 metres (one number or "
                         f"dx, dy, dz), got {cell_size!r}")
    return cs


def _heights(props: Sequence[Mapping[str, Any]], metres_per_level: float,
             default_height: float | None, ids: Sequence[str]) -> tuple[list[float], dict]:
    """Heights [m] and how many took each rule; one error for all missing heights."""
    heights, counts, missing = [], dict.fromkeys(HEIGHT_RULES, 0), []
    for i, p in enumerate(props):
        try:
            h, rule = height_and_rule(p, metres_per_level=metres_per_level,
                                      default_height=default_height, index=i)
        except WorldError:
            if default_height is None and all(_blank(p.get(k)) for k in
                                              ("height", "building:levels", "levels",
                                               "building_l")):
                missing.append(i)
                heights.append(float("nan"))
                continue
            raise
        heights.append(h)
        counts[rule] += 1
    if missing:
        first = missing[0]
        raise WorldError(
            f"{len(missing)} of {len(props)} buildings have neither 'height' nor "
            f"'building:levels' (first: building {first}{ids[first]}); set world.default_height "
            "(CLI --default-height) to the height in metres to assume for them")
    return heights, counts


def _feature_id(p: Mapping[str, Any]) -> str:
    for k in ("@id", "osm_id", "id", "name"):
        if not _blank(p.get(k)):
            return f" {k}={p[k]}"
    return ""


def from_buildings(
    footprints: Any,
    cell_size: float | tuple[float, float, float],
    *,
    shape: tuple[int, int, int] | None = None,
    origin: tuple[float, float, float] | None = None,
    height_cells: int | None = None,
    metres_per_level: float = METRES_PER_LEVEL,
    default_height: float | None = None,
    margin: float = 0.0,
    name: str = "",
    crs: Any = None,
    terrain: World | None = None,
    all_touched: bool = False,
    bbox: Sequence[float] | None = None,
    agl: float | None = None,
    top: float | None = None,
    layer: str | None = None,
    ground_elevation: float | None = None,
) -> World:
    """Build a 3D world from building footprints with heights (see the module docstring).

    Parameters
    ----------
    footprints : path, dict or list
        A vector file (any format :func:`~fm2uav.world.vectors.read_vectors`
        reads; GeoJSON files are lon/lat unless they declare a CRS), or
        in-memory GeoJSON (a FeatureCollection dict or a list of Features)
        whose coordinates are the world's x/y metres unless it has a ``crs``
        member or ``crs`` is given.
    cell_size : float or (dx, dy, dz)
        Node spacing [m] (ignored with ``terrain``: its grid is used).
    shape : (nx, ny, nz), optional
        Grid size. Default: the footprints' bounding box plus ``margin`` (or
        ``bbox``), and ``height_cells`` (or enough nodes for the tallest
        roof, plus ``agl``) vertically.
    origin : (x0, y0, z0), optional
        World coordinates of node (0, 0, 0) [m]; ``z0`` is the ground level
        (the ground layer is an obstacle). Default: bounding box corner minus
        ``margin``, z0 = 0.
    height_cells : int, optional
        Number of vertical nodes when ``shape`` is not given.
    metres_per_level : float
        Storey height for ``building:levels`` [m]. Default 3.0.
    default_height : float, optional
        Height [m] of buildings without height information.
    margin : float
        Free border around the footprints' bounding box [m] (auto extent only).
    name : str
        World name.
    crs : optional
        CRS of data that declare none (e.g. an old GeoJSON in UTM metres).
    terrain : World, optional
        A DEM world (with ``crs`` and ``terrain``) to put the buildings on.
    all_touched : bool
        Cover every column whose cell touches a footprint (conservative for
        real data) instead of the columns whose node is inside it. Default
        False (exact on the synthetic city).
    bbox : (west, south, east, north), optional
        Lon/lat box [deg] that sets the extent (buildings outside are left out).
    agl : float, optional
        Requested height above the roofs [m]: the default grid leaves room for it.
    top : float, optional
        Highest requested altitude [m] (start/goal): the default grid reaches it.
    layer : str, optional
        Read only this layer of the file.
    ground_elevation : float, optional
        Altitude of the flat ground above mean sea level [m] (without ``terrain``):
        the grid's floor ``z0`` (unless ``origin`` gives one) and the datum of every
        altitude. Without it (and without ``terrain``) z is the height above the
        ground, whose altitude is unknown (``World.georef.amsl`` is False): missions
        are then written relative to home.

    Returns
    -------
    World
        ``terrain`` is the bare ground (flat ``z0``, or the DEM's); ``georef``
        counts the buildings per height rule.

    Raises
    ------
    WorldError
        Bad geometry, missing heights, a building taller than the grid, bad sizes.
    """
    cs = _cell_size(cell_size) if terrain is None else np.asarray(terrain.spacing, dtype=float)
    _check_level_and_terrain(metres_per_level, terrain)
    z0 = _ground_elevation(ground_elevation, terrain)
    box = None if bbox is None else check_lonlat_bbox(bbox, "world.bbox (--bbox)")
    data, polys = _read_footprints(footprints, terrain, crs, layer)
    ids = [_feature_id(p) for p in data.properties]
    heights, counts = _heights(data.properties, metres_per_level, default_height, ids)
    world_crs = data.crs
    org, nx, ny, ground = _horizontal_grid(terrain, polys, heights, box, world_crs, cs, shape,
                                           origin, height_cells, margin, agl, top, z0)
    roof, outside, off_grid, model = _roofs(polys, heights, ground, org, cs, all_touched,
                                            terrain)
    _report_left_out(data, outside, off_grid)
    surface = np.maximum(roof, ground)
    nz = _vertical_nodes(terrain, shape, height_cells, org, cs, float(surface.max()), agl, top)
    check_size((nx, ny, nz), cs)
    occ = _occupancy(surface, org, cs, nz, heights, ids, agl,
                     height_cells is not None and terrain is None and shape is None)
    georef = _buildings_georef(data, polys, counts, metres_per_level, default_height, outside,
                               off_grid, all_touched, terrain, world_crs, org,
                               ground_elevation is not None)
    return World(
        occupancy=occ, spacing=tuple(float(c) for c in cs), origin=tuple(float(v) for v in org),
        terrain=ground, crs=world_crs, name=name or (terrain.name if terrain is not None else ""),
        filled=None if terrain is None else terrain.filled, georef=georef,
        ground=None if terrain is None else terrain.ground, buildings=model,
    )


def _occupancy(surface: np.ndarray, org: np.ndarray, cs: np.ndarray, nz: int,
               heights: Sequence[float], ids: list[str], agl: Any,
               given_height_cells: bool) -> np.ndarray:
    """The (nx, ny, nz) obstacle grid under ``surface`` [m] (ground and roofs), its top
    checked to clear the tallest roof (:func:`_check_headroom`)."""
    smax = float(surface.max())
    zs = org[2] + np.arange(nz) * cs[2]
    _check_headroom(smax, zs, heights, ids, org, cs, nz, agl, given_height_cells)
    return zs[None, None, :] <= surface[:, :, None]


def _check_level_and_terrain(metres_per_level: float, terrain: World | None) -> None:
    """Refuse a non-positive storey height [m] or a terrain that is not a 3D DEM world."""
    if not (np.isfinite(metres_per_level) and metres_per_level > 0):
        raise WorldError(f"metres_per_level must be > 0, got {metres_per_level!r}")
    if terrain is not None and (terrain.ndim != 3 or terrain.terrain is None):
        raise WorldError("terrain= must be a 3D world with a terrain height map (a DEM world)")


def _ground_elevation(value: Any, terrain: World | None) -> float:
    """The flat ground's altitude z0 [m]: ``ground_elevation`` or 0 (refused on a DEM)."""
    if value is None:
        return 0.0
    if terrain is not None:
        raise WorldError("world.ground_elevation (--ground-elevation) is for buildings without "
                         "a DEM; on a DEM the ground is the DEM's: leave it out")
    try:
        v = float(value)
    except (TypeError, ValueError):
        v = float("nan")
    if not (np.isfinite(v) and -500.0 <= v <= 9000.0):
        raise WorldError(f"world.ground_elevation (--ground-elevation) must be the ground's "
                         f"altitude above sea level in metres, -500..9000, got {value!r}")
    return v


def _horizontal_grid(terrain: World | None, polys: list[Any], heights: Sequence[float], box: Any,
                     world_crs: Any, cs: np.ndarray, shape: Any, origin: Any, height_cells: Any,
                     margin: float, agl: Any, top: Any, z0: float = 0.0
                     ) -> tuple[np.ndarray, int, int, np.ndarray]:
    """Origin [m], horizontal node counts and ground heights [m]: the terrain's, or flat at z0."""
    if terrain is not None:
        org = np.asarray(terrain.origin, dtype=float)
        nx, ny = terrain.shape[:2]
        return org, nx, ny, np.asarray(terrain.terrain, dtype=float)
    org, nx, ny = _flat_grid(polys, heights, box, world_crs, cs, shape, origin, height_cells,
                             margin, agl, top, z0)
    return org, nx, ny, np.full((nx, ny), org[2])


def _read_footprints(footprints: Any, terrain: World | None, crs: Any, layer: str | None
                     ) -> tuple[Any, list[Any]]:
    """The footprint features (in the terrain's CRS, or an automatic metric one) and polygons."""
    target = terrain.crs if terrain is not None else "auto"
    data = read_vectors(footprints, target_crs=target, crs=crs, role="buildings", layer=layer)
    polys = list(data.geometries)
    if not polys and data.skipped:
        raise WorldError(
            f"{data.source.path}: building footprints must be Polygon or MultiPolygon features, "
            "got only " + ", ".join(f"{n} {k}" for k, n in sorted(data.skipped.items())))
    return data, polys


def _flat_grid(polys: list[Any], heights: Sequence[float], box: Any, world_crs: Any,
               cs: np.ndarray, shape: Any, origin: Any, height_cells: Any, margin: float,
               agl: Any, top: Any, z0: float = 0.0) -> tuple[np.ndarray, int, int]:
    """Origin [m] and horizontal node counts of a world on flat ground (no terrain).

    Default extent: ``box`` (lon/lat) or the footprints' bounds plus ``margin`` [m]; the
    3D size is checked against memory before the roofs are rasterised.
    """
    if shape is None:
        if box is not None and world_crs is not None:
            from .dem_read import _bbox_in

            minx, miny, maxx, maxy = _bbox_in(world_crs, box)
            mg = 0.0
        elif polys:
            minx, miny, maxx, maxy = shapely.total_bounds(np.array(polys, dtype=object))
            mg = float(margin)
        else:
            raise WorldError("no buildings given and no shape=; give the grid size "
                             "(nx, ny, nz)")
        if origin is None:
            origin = (minx - mg, miny - mg, z0)
        nx = int(np.ceil((maxx + mg - origin[0]) / cs[0] - 1e-9)) + 1
        ny = int(np.ceil((maxy + mg - origin[1]) / cs[1] - 1e-9)) + 1
    else:
        if len(shape) != 3 or any(int(n) < 1 for n in shape):
            raise WorldError(f"shape must be three positive node counts (nx, ny, nz), "
                             f"got {shape!r}")
        nx, ny = int(shape[0]), int(shape[1])
    org = np.array([0.0, 0.0, z0]) if origin is None else np.asarray(origin, dtype=float)
    if org.shape != (3,) or not np.all(np.isfinite(org)):
        raise WorldError(f"origin must be three finite numbers (x0, y0, z0) in metres, got "
                         f"{origin!r}")
    check_size((nx, ny), cs[:2])
    # refuse a 3D grid beyond memory before the (nx, ny) roof pass (seconds on 1e8 columns)
    check_size((nx, ny, _nz_estimate(heights, shape, height_cells, agl,
                                      None if top is None else float(top) - org[2], cs[2])), cs)
    return org, nx, ny


def _vertical_nodes(terrain: World | None, shape: Any, height_cells: Any, org: np.ndarray,
                    cs: np.ndarray, smax: float, agl: Any, top: Any) -> int:
    """Number of vertical nodes: the terrain's (raised to leave room above the roofs), the
    given ``shape`` / ``height_cells``, or enough for the tallest roof ``smax`` [m] + ``agl``."""
    if terrain is not None:
        nz0 = terrain.shape[2]
        z_top = org[2] + (nz0 - 1) * cs[2]
        need = smax + (0.0 if agl is None else float(agl)) + (10.0 if agl is not None else 2.0) * cs[2]
        if top is not None:
            need = max(need, float(top) + 5 * cs[2])
        nz = max(nz0, int(np.ceil((need - org[2]) / cs[2] - 1e-9)) + 1) if need > z_top else nz0
    elif shape is not None:
        nz = int(shape[2])
    elif height_cells is not None:
        nz = int(height_cells)
    else:
        rel = smax - org[2]
        if agl is None:
            nz = int(np.ceil(rel / cs[2])) + 3
        else:
            nz = int(np.ceil((rel + float(agl)) / cs[2])) + 10
        if top is not None:
            nz = max(nz, int(np.ceil((float(top) - org[2]) / cs[2])) + 5)
    return nz


def _check_headroom(smax: float, zs: np.ndarray, heights: Sequence[float], ids: list[str],
                    org: np.ndarray, cs: np.ndarray, nz: int, agl: Any,
                    given_height_cells: bool) -> None:
    """Refuse a grid whose top node ``zs[-1]`` [m] is not above the tallest roof (or, with the
    user's ``height_cells``, leaves no room for ``agl`` above it)."""
    if smax >= zs[-1]:
        i = int(np.nanargmax(np.where(np.isfinite(heights), heights, -1))) if heights else 0
        need_n = int(np.ceil((smax - org[2]) / cs[2])) + 2
        raise WorldError(
            f"the tallest roof reaches {smax:.6g} m (building {i}{ids[i] if ids else ''}, "
            f"{heights[i]:.6g} m tall), at or above the top node z = {zs[-1]:.6g} m of the grid; "
            f"use at least {need_n} vertical nodes (world.height_cells / shape)")
    if agl is not None and given_height_cells:
        if smax + float(agl) >= zs[-1]:
            need_n = int(np.ceil((smax + float(agl) - org[2]) / cs[2])) + 2
            raise WorldError(
                f"world.height_cells = {nz} leaves no room to fly {float(agl):g} m above the "
                f"tallest roof ({smax:.1f} m); use world.height_cells >= {need_n} or leave it out "
                "(the default follows the requested height above ground)")


def _buildings_georef(data: Any, polys: list[Any], counts: Any, metres_per_level: float,
                      default_height: float | None, outside: Any, off_grid: Any,
                      all_touched: bool, terrain: World | None, world_crs: Any,
                      org: np.ndarray, ground_given: bool = False) -> Any:
    """The georeference of a buildings world, its source file noting the height rules used;
    on flat ground, whether z is an altitude (``ground_given``) or a height above the ground."""
    details = {
        "buildings": len(polys),
        "height_rule": counts,
        "metres_per_level": float(metres_per_level),
        **({"default_height": float(default_height)} if default_height is not None else {}),
        "outside_map": outside,
        **({"not_on_a_node": off_grid} if off_grid else {}),
        "footprint_rule": "cells touched" if all_touched else "node inside",
        "roof": "highest ground under the footprint + height" if terrain is not None
        else "ground z0 + height",
    }
    src = dataclasses.replace(data.source, details={**data.source.details, **details})
    georef = None
    if terrain is not None and getattr(terrain, "georef", None) is not None:
        georef = terrain.georef.with_sources(src)
    elif world_crs is not None:
        if ground_given:
            vertical = (f"metres above mean sea level: flat ground at {org[2]:g} m (given: "
                        "world.ground_elevation / --ground-elevation), roofs at its height "
                        "plus the buildings'")
        else:
            vertical = ("height above the flat ground (no DEM and no world.ground_elevation / "
                        "--ground-elevation: its altitude above sea level is unknown, so "
                        "missions are relative to home)")
        georef = make_georef(
            world_crs, vertical=vertical, vertical_assumed=True,
            reprojection=data.source.details.get("reprojection", ""), sources=(src,),
            amsl=ground_given)
    return georef


def _nz_estimate(heights: Sequence[float], shape: Any, height_cells: Any, agl: Any, top: Any,
                 dz: float) -> int:
    """Vertical node count the flat-ground grid will get (as below, ground z0 = 0)."""
    if shape is not None:
        return int(shape[2])
    if height_cells is not None:
        return int(height_cells)
    hs = [float(h) for h in heights if np.isfinite(h)]
    rel = max(hs) if hs else 0.0
    nz = (int(np.ceil(rel / dz)) + 3 if agl is None
          else int(np.ceil((rel + float(agl)) / dz)) + 10)
    return max(nz, int(np.ceil(float(top) / dz)) + 5) if top is not None else nz


def _report_left_out(data: Any, outside: int, off_grid: int) -> None:
    """Warn (GeodataWarning, one line) about footprints that did not become buildings:
    empty / zero-area / invalid / non-polygon features, footprints outside the grid and
    footprints smaller than a cell that cover no node (issue 17: never silently)."""
    import warnings

    from .dem import GeodataWarning

    if not len(data.geometries) and not data.skipped:  # an empty file on a DEM (no error)
        warnings.warn(f"buildings {data.source.path or '(given)'}: the file has no features, "
                      "so no building is drawn (the world is the terrain alone); check the "
                      "file given as world.buildings / --buildings", GeodataWarning,
                      stacklevel=3)
        return
    names = {"invalid": "invalid (e.g. zero-area)"}
    parts = [f"{n} {names.get(k, k)} feature(s)" for k, n in sorted(data.skipped.items())]
    if outside:
        parts.append(f"{outside} footprint(s) outside the grid (enlarge shape / world.bbox)")
    if off_grid:
        parts.append(f"{off_grid} footprint(s) covering no grid node (smaller than a cell, or "
                     "zero area; use a finer cell size or all_touched)")
    if parts:
        warnings.warn(f"buildings {data.source.path or '(given)'}: left out "
                      + ", ".join(parts), GeodataWarning, stacklevel=3)


def _roofs(polys: Sequence[Any], heights: Sequence[float], ground: np.ndarray, org: np.ndarray,
           cs: np.ndarray, all_touched: bool, terrain: World | None = None
           ) -> tuple[np.ndarray, int, int, Any]:
    """Roof altitude per column (-inf where no building), counts outside / off-grid, and the
    :class:`~fm2uav.world.building_model.BuildingModel` of the footprints on the grid.

    A footprint's roof is the highest ground under it plus its height: the highest
    node it covers, and on a DEM world also the source DEM at its vertices.
    """
    from .building_model import BuildingModel

    nx, ny = ground.shape
    roof = np.full((nx, ny), -np.inf)
    outside = off_grid = 0
    kept, tops = [], []
    dem = None if terrain is None else getattr(terrain, "ground", None)
    for g, h in zip(polys, heights):
        minx, miny, maxx, maxy = g.bounds
        i0 = max(int(np.floor((minx - org[0]) / cs[0])) - 1, 0)
        i1 = min(int(np.ceil((maxx - org[0]) / cs[0])) + 1, nx - 1)
        j0 = max(int(np.floor((miny - org[1]) / cs[1])) - 1, 0)
        j1 = min(int(np.ceil((maxy - org[1]) / cs[1])) + 1, ny - 1)
        if i0 > i1 or j0 > j1:
            outside += 1
            continue
        xs = org[0] + np.arange(i0, i1 + 1) * cs[0]
        ys = org[1] + np.arange(j0, j1 + 1) * cs[1]
        if all_touched:
            from affine import Affine
            from rasterio.features import geometry_mask

            t = Affine(cs[0], 0.0, xs[0] - 0.5 * cs[0], 0.0, cs[1], ys[0] - 0.5 * cs[1])
            inside = geometry_mask([g], out_shape=(len(ys), len(xs)), transform=t,
                                   all_touched=True, invert=True).T
        else:
            X, Y = np.meshgrid(xs, ys, indexing="ij")
            inside = shapely.intersects_xy(g, X, Y)  # inside or on the edge
        if not inside.any():
            off_grid += 1
            continue
        win = (slice(i0, i1 + 1), slice(j0, j1 + 1))
        base = float(ground[win][inside].max())
        if dem is not None:  # the DEM itself at the footprint's corners
            xy = shapely.get_coordinates(g)
            base = max(base, float(np.max(dem.height(xy[:, 0], xy[:, 1]))))
        top = base + float(h)
        roof[win] = np.where(inside, np.maximum(roof[win], top), roof[win])
        kept.append(g)
        tops.append(top)
    model = BuildingModel(tuple(kept), np.asarray(tops, dtype=float),
                          description=f"{len(kept)} building footprints with their roofs")
    return roof, outside, off_grid, model
