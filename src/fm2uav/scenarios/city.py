"""The urban case study of thesis ch. 3 (and §4.1.1).

15 square buildings of 220–390 m height and 20–60 m width on a grid of 5 m
cells, placed at random (seeded), with two missions: low altitude (between
the buildings) and high altitude (over the lower buildings). Rasterised with
:func:`fm2uav.world.buildings.from_buildings`.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np

from ..errors import WorldError
from ..world import World
from ..world.buildings import from_buildings
from .scenario import Scenario

__all__ = [
    "CITY_CELL",
    "CITY_SHAPE",
    "CITY_MISSIONS",
    "city_buildings",
    "city_world",
    "city",
    "city_high",
]

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


#: The scenario description of each mission of :data:`CITY_MISSIONS`.
_CITY_DESCRIPTIONS = {
    "low": "low-altitude mission at 100 m between the buildings, corner to corner "
           "[thesis ch. 3, §3.3.1]",
    "high": "high-altitude mission at 350 m, over the lower roofs [thesis ch. 3, §3.3.2]",
}


def _city_scenario(seed: int | np.random.Generator, mission: str) -> Scenario:
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
    description = ("City of 15 square buildings 20-60 m wide, 220-390 m tall on 5 m cells; "
                   + _CITY_DESCRIPTIONS[mission])
    return Scenario(world=world, start=start, goal=goal, description=description)


def city(seed: int | np.random.Generator = 0) -> Scenario:
    """Thesis ch. 3 city, low-altitude mission (between the buildings).

    100 x 100 x 100 nodes of 5 m, 15 square buildings 20–60 m wide and
    220–390 m tall (seeded); start (8, 8, 20) cells = (40, 40, 100) m,
    goal (91, 91, 20) cells = (455, 455, 100) m.
    """
    return _city_scenario(seed, "low")


def city_high(seed: int | np.random.Generator = 0) -> Scenario:
    """Thesis ch. 3 city, high-altitude mission (over the lower buildings).

    Same world as :func:`city`; start (8, 8, 70) cells = (40, 40, 350) m,
    goal (91, 91, 70) cells = (455, 455, 350) m.
    """
    return _city_scenario(seed, "high")
