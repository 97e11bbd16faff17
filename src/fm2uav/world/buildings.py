"""Worlds made of buildings: GeoJSON footprints with heights.

* :func:`from_buildings` (also ``World.from_buildings``) rasterises building
  footprints (GeoJSON ``Polygon`` / ``MultiPolygon`` features) with a height
  into an occupancy grid: node ``(i, j, k)`` is an obstacle iff its x-y point
  lies inside (or on the edge of) a footprint and ``z <= ground + height``,
  or iff it is at or below the ground.
* The urban case study of thesis ch. 3 built with it is
  :mod:`fm2uav.scenarios.city`.

Heights
-------
A feature's height is read from its properties, first match wins:

1. ``height`` — metres; a number or a string such as ``"25"``, ``"25 m"``,
   ``"25.5m"`` (OpenStreetMap ``height=*`` convention);
2. ``building:levels`` (or ``levels``) — number of storeys, multiplied by
   ``metres_per_level`` (default :data:`METRES_PER_LEVEL` = 3.0 m, the storey
   height the OpenStreetMap "Simple 3D buildings" guidance uses to derive a
   height from a level count);
3. otherwise ``default_height`` if given, else a :class:`WorldError`.
"""

from __future__ import annotations

import json
import re
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import Any

import numpy as np
import shapely
from shapely.geometry import shape as shapely_shape

from ..errors import WorldError
from .world import World

__all__ = [
    "METRES_PER_LEVEL",
    "from_buildings",
    "building_height",
]

#: Storey height used with ``building:levels`` [m] (OSM Simple 3D buildings).
METRES_PER_LEVEL = 3.0
_NUM = re.compile(r"^\s*([-+]?\d+(?:[.,]\d+)?)\s*(m|meters|metres)?\s*$", re.IGNORECASE)


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
    """Height [m] of one building from its GeoJSON properties (see module doc).

    Raises
    ------
    WorldError
        No usable ``height`` / ``building:levels`` and no ``default_height``.
    """
    props = dict(properties or {})
    if props.get("height") is not None:
        return _parse_number(props["height"], "height", index)
    for key in ("building:levels", "levels"):
        if props.get(key) is not None:
            return _parse_number(props[key], key, index) * float(metres_per_level)
    if default_height is not None:
        return _parse_number(default_height, "default_height", index)
    raise WorldError(
        f"building {index} has neither 'height' (m) nor 'building:levels' in its properties "
        f"{sorted(props)}; add one or pass default_height="
    )


def _features(footprints: Any) -> list[tuple[Any, Mapping[str, Any]]]:
    """GeoJSON FeatureCollection / Feature list / file → [(geometry dict, properties)]."""
    if isinstance(footprints, (str, Path)):
        p = Path(footprints)
        if not p.exists():
            raise WorldError(f"building file {p} does not exist")
        try:
            footprints = json.loads(p.read_text())
        except json.JSONDecodeError as exc:
            raise WorldError(f"building file {p} is not valid GeoJSON: {exc}") from None
    if isinstance(footprints, Mapping):
        if footprints.get("type") == "FeatureCollection":
            feats: Iterable[Any] = footprints.get("features") or []
        elif footprints.get("type") == "Feature":
            feats = [footprints]
        else:
            raise WorldError(
                "buildings must be a GeoJSON FeatureCollection, a Feature or a list of "
                f"Features; got a mapping of type {footprints.get('type')!r}"
            )
    elif isinstance(footprints, Iterable):
        feats = list(footprints)
    else:
        raise WorldError(
            f"buildings must be GeoJSON (dict, list of features or file path), got "
            f"{type(footprints).__name__}"
        )
    out = []
    for i, f in enumerate(feats):
        if not isinstance(f, Mapping) or "geometry" not in f:
            raise WorldError(f"building {i} is not a GeoJSON Feature with a 'geometry'")
        out.append((f["geometry"], f.get("properties") or {}))
    return out


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
    crs: str | None = None,
) -> World:
    """Build a 3D world from building footprints with heights.

    Parameters
    ----------
    footprints : dict, list or path
        GeoJSON ``FeatureCollection`` (dict or ``.geojson`` file) or a list of
        ``Feature`` dicts with ``Polygon`` / ``MultiPolygon`` geometries in the
        world's x-y coordinates [m] (project lon/lat first).
    cell_size : float or (dx, dy, dz)
        Node spacing [m].
    shape : (nx, ny, nz), optional
        Grid size. Default: the footprints' bounding box plus ``margin``, and
        ``height_cells`` (or the tallest building + 2 nodes) vertically.
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
    name, crs : str, optional
        Stored on the world.

    Returns
    -------
    World
        ``terrain`` is the flat ground ``z0`` (bare earth, buildings excluded).

    Raises
    ------
    WorldError
        Bad geometry, missing height, a building taller than the grid, bad sizes.
    """
    cs = np.broadcast_to(np.asarray(cell_size, dtype=float), (3,)).copy() if np.ndim(
        cell_size
    ) <= 1 else None
    if cs is None or cs.shape != (3,) or not np.all(np.isfinite(cs)) or np.any(cs <= 0):
        raise WorldError(f"cell_size must be > 0 metres (one number or dx, dy, dz), got {cell_size!r}")
    if not (np.isfinite(metres_per_level) and metres_per_level > 0):
        raise WorldError(f"metres_per_level must be > 0, got {metres_per_level!r}")
    feats = _features(footprints)
    polys, heights = [], []
    for i, (geom, props) in enumerate(feats):
        try:
            g = shapely_shape(geom)
        except Exception as exc:  # shapely raises several types on bad GeoJSON
            raise WorldError(f"building {i}: invalid GeoJSON geometry ({exc})") from None
        if g.geom_type not in ("Polygon", "MultiPolygon") or g.is_empty:
            raise WorldError(
                f"building {i}: footprint must be a non-empty Polygon or MultiPolygon, got "
                f"{g.geom_type}"
            )
        if not g.is_valid:
            g = shapely.make_valid(g)
        polys.append(g)
        heights.append(
            building_height(
                props, metres_per_level=metres_per_level, default_height=default_height, index=i
            )
        )
    if shape is None:
        if not polys:
            raise WorldError("no buildings given and no shape=; give the grid size (nx, ny, nz)")
        minx, miny, maxx, maxy = shapely.total_bounds(np.array(polys, dtype=object))
        if origin is None:
            origin = (minx - margin, miny - margin, 0.0)
        nx = int(np.ceil((maxx + margin - origin[0]) / cs[0])) + 1
        ny = int(np.ceil((maxy + margin - origin[1]) / cs[1])) + 1
        nz = height_cells if height_cells is not None else int(np.ceil(max(heights) / cs[2])) + 3
        shape = (nx, ny, int(nz))
    if len(shape) != 3 or any(int(n) < 1 for n in shape):
        raise WorldError(f"shape must be three positive node counts (nx, ny, nz), got {shape!r}")
    nx, ny, nz = (int(n) for n in shape)
    org = np.zeros(3) if origin is None else np.asarray(origin, dtype=float)
    if org.shape != (3,) or not np.all(np.isfinite(org)):
        raise WorldError(f"origin must be three finite numbers (x0, y0, z0) in metres, got {origin!r}")
    xs = org[0] + np.arange(nx) * cs[0]
    ys = org[1] + np.arange(ny) * cs[1]
    zs = org[2] + np.arange(nz) * cs[2]
    X, Y = np.meshgrid(xs, ys, indexing="ij")
    roof = np.full((nx, ny), -np.inf)
    for i, (g, h) in enumerate(zip(polys, heights)):
        top = org[2] + h
        if top >= zs[-1]:
            need = int(np.ceil(h / cs[2])) + 2
            raise WorldError(
                f"building {i} is {h:.6g} m tall, reaching the top node z = {zs[-1]:.6g} m of "
                f"the grid; use at least {need} vertical nodes (shape / height_cells)"
            )
        inside = shapely.intersects_xy(g, X, Y)  # inside or on the edge
        roof = np.where(inside, np.maximum(roof, top), roof)
    ground = np.full((nx, ny), org[2])
    surface = np.maximum(roof, ground)
    occ = zs[None, None, :] <= surface[:, :, None]
    return World(
        occupancy=occ,
        spacing=tuple(float(c) for c in cs),
        origin=tuple(float(v) for v in org),
        terrain=ground,
        crs=crs,
        name=name,
    )
