"""Worlds made of buildings: GeoJSON footprints with heights, and the thesis' city.

* :func:`from_buildings` (also ``World.from_buildings``) rasterises building
  footprints (GeoJSON ``Polygon`` / ``MultiPolygon`` features) with a height
  into an occupancy grid: node ``(i, j, k)`` is an obstacle iff its x-y point
  lies inside (or on the edge of) a footprint and ``z <= ground + height``,
  or iff it is at or below the ground.
* :func:`city` is the urban case study of thesis ch. 3 (and §4.1.1): 15 square
  buildings of 220–390 m height and 20–60 m width on a grid of 5 m cells,
  placed at random (seeded), with two missions: low altitude (between the
  buildings) and high altitude (over the lower buildings).

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
from functools import lru_cache
from pathlib import Path
from typing import Any

import numpy as np
import shapely
from shapely.geometry import shape as shapely_shape

from ..errors import WorldError
from .world import World

__all__ = [
    "METRES_PER_LEVEL",
    "CITY_CELL",
    "CITY_SHAPE",
    "from_buildings",
    "building_height",
    "city_buildings",
    "city_world",
    "CITY_MISSIONS",
    "city",
    "city_high",
]

#: Storey height used with ``building:levels`` [m] (OSM Simple 3D buildings).
METRES_PER_LEVEL = 3.0
#: Cell size of the city map [m] (thesis §3.2: "each cell ... is equivalent to 5 meters").
CITY_CELL = 5.0
#: Number of nodes (nx, ny, nz) of the city map. The thesis does not give the
#: extent; 100 x 100 x 100 nodes (495 m a side) holds 15 buildings of 20–60 m
#: with passages between them and leaves ~100 m of air over the tallest (390 m).
CITY_SHAPE = (100, 100, 90)
#: Thesis ch. 3 city: number of buildings, width and height ranges [m].
CITY_N_BUILDINGS = 15
CITY_WIDTH_M = (20.0, 60.0)
CITY_HEIGHT_M = (220.0, 390.0)

#: Missions of the city (thesis ch. 3 gives no coordinates; chosen here), in
#: cells of 5 m: ``name -> (start_cells, goal_cells)``. The low-altitude
#: mission flies at 100 m, under every roof (>= 220 m), corner to corner; the
#: high-altitude one at 350 m, over the lower roofs and around the taller ones.
CITY_MISSIONS: dict[str, tuple[tuple[int, int, int], tuple[int, int, int]]] = {
    "low": ((8, 8, 20), (91, 91, 20)),
    "high": ((8, 8, 83), (91, 91, 83)),
}

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


def _square(cx: float, cy: float, w: float) -> dict:
    h = w / 2.0
    ring = [[cx - h, cy - h], [cx + h, cy - h], [cx + h, cy + h], [cx - h, cy + h], [cx - h, cy - h]]
    return {"type": "Polygon", "coordinates": [ring]}


def city_buildings(seed: int | np.random.Generator = 0) -> dict:
    """The 15 square buildings of the thesis' city as a GeoJSON FeatureCollection.

    Widths uniform in 20–60 m and heights uniform in 220–390 m (both rounded to
    the 5 m cell), centres on the 5 m grid, placed by seeded rejection sampling so
    that buildings are >= 20 m apart, >= 25 m inside the 495 m map, and >= 40 m
    (horizontally) from the missions' start and goal columns.
    Properties: ``height`` [m], ``width`` [m], ``id``.
    """
    rng = seed if isinstance(seed, np.random.Generator) else np.random.default_rng(seed)
    c = CITY_CELL
    extent = (CITY_SHAPE[0] - 1) * c
    keep_out = [np.array(m[0][:2]) * c for m in CITY_MISSIONS.values()] + [
        np.array(m[1][:2]) * c for m in CITY_MISSIONS.values()
    ]
    placed: list[tuple[float, float, float]] = []
    feats = []
    for _ in range(20000):
        if len(placed) == CITY_N_BUILDINGS:
            break
        w = c * np.round(rng.uniform(*CITY_WIDTH_M) / c)
        h = c * np.round(rng.uniform(*CITY_HEIGHT_M) / c)
        lo, hi = 25.0 + w / 2, extent - 25.0 - w / 2
        cx = c * np.round(rng.uniform(lo, hi) / c)
        cy = c * np.round(rng.uniform(lo, hi) / c)
        ok = all(
            max(abs(cx - px) - (w + pw) / 2, abs(cy - py) - (w + pw) / 2) >= 20.0
            for px, py, pw in placed
        ) and all(
            np.hypot(max(abs(cx - k[0]) - w / 2, 0.0), max(abs(cy - k[1]) - w / 2, 0.0)) >= 40.0
            for k in keep_out
        )
        if not ok:
            continue
        placed.append((cx, cy, w))
        feats.append(
            {
                "type": "Feature",
                "geometry": _square(cx, cy, w),
                "properties": {"id": len(feats), "height": float(h), "width": float(w)},
            }
        )
    else:  # pragma: no cover - the loop always places 15 with these sizes
        raise WorldError("could not place the 15 city buildings; try another seed")
    if len(feats) < CITY_N_BUILDINGS:  # pragma: no cover
        raise WorldError(f"placed only {len(feats)} of 15 city buildings; try another seed")
    return {"type": "FeatureCollection", "features": feats}


def city_world(seed: int | np.random.Generator = 0) -> World:
    """The city of thesis ch. 3 as a :class:`World` (100³ nodes of 5 m)."""
    return from_buildings(
        city_buildings(seed), CITY_CELL, shape=CITY_SHAPE, origin=(0.0, 0.0, 0.0), name="city"
    )


@lru_cache(maxsize=4)
def _city_world_cached(seed: int) -> World:
    return city_world(seed)


def _city_scenario(seed: int | np.random.Generator, mission: str, description: str) -> Any:
    from .scenarios import Scenario  # scenarios imports this module

    if isinstance(seed, (int, np.integer)) and not isinstance(seed, bool):
        world = _city_world_cached(int(seed))  # immutable: share it (and its _cache)
    else:
        world = city_world(seed)
    s_cells, g_cells = CITY_MISSIONS[mission]
    start = world.to_world(np.asarray(s_cells, dtype=float))
    goal = world.to_world(np.asarray(g_cells, dtype=float))
    for what, p in (("start", start), ("goal", goal)):
        if world.occupancy[world.to_cell(p)]:
            raise WorldError(f"city {mission} {what} {p.tolist()} m is inside a building; try another seed")
    return Scenario(world=world, start=start, goal=goal, description=description)


def city(seed: int | np.random.Generator = 0) -> Any:
    """Thesis ch. 3 city, low-altitude mission (between the buildings).

    100 x 100 x 100 nodes of 5 m, 15 square buildings 20–60 m wide and
    220–390 m tall (seeded); start (8, 8, 20) cells = (40, 40, 100) m,
    goal (91, 91, 20) cells = (455, 455, 100) m.
    """
    return _city_scenario(
        seed,
        "low",
        "City of 15 square buildings 20-60 m wide, 220-390 m tall on 5 m cells; low-altitude "
        "mission at 100 m between the buildings, corner to corner [thesis ch. 3, §3.3.1]",
    )


def city_high(seed: int | np.random.Generator = 0) -> Any:
    """Thesis ch. 3 city, high-altitude mission (over the lower buildings).

    Same world as :func:`city`; start (8, 8, 70) cells = (40, 40, 350) m,
    goal (91, 91, 70) cells = (455, 455, 350) m.
    """
    return _city_scenario(
        seed,
        "high",
        "City of 15 square buildings 20-60 m wide, 220-390 m tall on 5 m cells; high-altitude "
        "mission at 350 m, over the lower roofs [thesis ch. 3, §3.3.2]",
    )
