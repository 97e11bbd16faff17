"""The coverage scenario of the seeds (paper 003 §II, thesis §5.1, §5.4).

"An open field map with mountainous terrain, where the surface is rather
uneven": a 118 x 87 x 40 grid of 10 m cells, with four irregular areas S1–S4
to cover (Fig. 5.8; the figures are lost, so the areas are redrawn). The
terrain is the open-field relief of :mod:`fm2uav.world.terrain` laid out on 118 x 87
columns. The areas were drawn so that their best zigzags resemble Table 5.1
with D = 80 m: costs 5105 / 6548 / 5334 / 6640 m at α ≈ 30.6° / 5.2° / 1.0° /
5.2° (seeds: 5446.5 / 6748.1 / 5908.6 / 7177.0 m at 37.1° / 2.5° / 1.0° / 1.3°).

Units of the seeds' D: they write "80 cells (800 m)", but an 800 m field of
view over areas inside a 1180 m x 870 m map would need only one or two bands,
while their costs (5.4–7.2 km) and the way they fall with D (Table 5.2:
9679 / 6909 / 5447 / 4616 m for D = 40 / 60 / 80 / 100) fit
``C ≈ A / D + const`` with an area A ≈ 0.34 km² only when D is in metres.
So the scenario uses D = 80 m.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np
from shapely.geometry import Polygon

from ..errors import WorldError
from ..missions.coverage.bands import zigzag
from ..missions.coverage.optimise import differential_evolution
from ..world import World
from ..world.terrain import open_field_heights
from .scenario import Scenario

__all__ = [
    "COVERAGE_SHAPE",
    "COVERAGE_CELL",
    "COVERAGE_HEIGHT_CELLS",
    "COVERAGE_SPACING",
    "COVERAGE_AGL",
    "COVERAGE_AREAS",
    "coverage_world",
    "coverage_area",
    "coverage",
]

#: (nx, ny) columns of the coverage map.
COVERAGE_SHAPE = (118, 87)
#: Cell size [m].
COVERAGE_CELL = 10.0
#: Vertical nodes.
COVERAGE_HEIGHT_CELLS = 40
#: The seeds' band spacing D [m] (see the module docstring on units).
COVERAGE_SPACING = 80.0
#: The seeds' flight level: 10 cells = 100 m above the ground.
COVERAGE_AGL = 100.0

#: Vertices [m] of the four areas S1–S4 (x, y in the map's metres).
COVERAGE_AREAS: dict[str, tuple[tuple[float, float], ...]] = {
    "S1": ((250, 60), (420, 90), (640, 240), (860, 400), (1010, 560), (990, 700), (860, 780),
           (700, 720), (520, 600), (360, 470), (210, 330), (150, 190)),
    "S2": ((80, 70), (330, 40), (600, 90), (860, 50), (1090, 100), (1100, 260), (1050, 400),
           (820, 420), (640, 480), (400, 450), (190, 470), (60, 350), (90, 210)),
    "S3": ((120, 420), (360, 400), (600, 430), (820, 395), (1070, 420), (1110, 560),
           (1060, 680), (830, 700), (640, 745), (430, 715), (240, 745), (110, 670), (140, 540)),
    "S4": ((60, 40), (300, 20), (560, 70), (820, 30), (1090, 80), (1110, 240), (1060, 380),
           (900, 430), (700, 400), (560, 455), (360, 420), (160, 450), (50, 340), (90, 200)),
}


def coverage_area(name: str) -> Polygon:
    """The area ``"S1"`` … ``"S4"`` as a shapely Polygon [m]."""
    key = str(name).strip().upper()
    if key not in COVERAGE_AREAS:
        raise WorldError(f"unknown coverage area {name!r}; valid: {', '.join(COVERAGE_AREAS)}")
    return Polygon(COVERAGE_AREAS[key])


def _build(seed) -> World:
    heights = open_field_heights(seed, COVERAGE_SHAPE) * COVERAGE_CELL
    return World.from_heightmap(heights, COVERAGE_CELL, COVERAGE_HEIGHT_CELLS, name="coverage")


@lru_cache(maxsize=4)
def _cached(seed: int) -> World:
    return _build(seed)


def coverage_world(seed: int | np.random.Generator = 0) -> World:
    """The 118 x 87 x 40 map of 10 m cells (same seed → same, shared World)."""
    if isinstance(seed, (int, np.integer)) and not isinstance(seed, bool):
        return _cached(int(seed))
    return _build(seed)


def coverage(seed: int | np.random.Generator = 0, area: str = "S1"):
    """Scenario: the coverage map; start/goal are the ends of the seeds' S-area zigzag.

    ``start``/``goal`` are the first and last points of the best (DE) zigzag of
    ``area`` with D = 80 m, 100 m above the ground.
    """
    world = coverage_world(seed)
    poly = coverage_area(area)
    best = differential_evolution(poly, COVERAGE_SPACING, seed=0)
    z = zigzag(poly, COVERAGE_SPACING, best.angle)
    ends = []
    for xy in (z.start, z.goal):
        i, j = (int(v) for v in np.clip(np.round(world.to_index(np.r_[xy, 0.0])[:2]), 0,
                                         np.asarray(world.shape[:2]) - 1))
        ends.append(np.r_[xy, world.terrain[i, j] + COVERAGE_AGL])
    return Scenario(
        world=world, start=ends[0], goal=ends[1],
        description=(f"Coverage map (118x87x40 cells of 10 m, mountainous open field) with "
                     f"areas S1-S4; start/goal = ends of the best zigzag over {area.upper()} "
                     "(D = 80 m) at 100 m AGL [coverage paper 003, thesis ch. 5]"),
    )
