"""The open-field scenarios of the terrain-following paper and the thesis.

* ``"open-field"`` — terrain-following paper / thesis ch. 4: 120 x 90 x 40 cells
  of 15 m, start (20, 20, 20) and goal (100, 80, 30) in cells.
* ``"fissure"`` — thesis ch. 6 (leader–follower formation): same terrain, the
  formation crosses the fissure between the two lateral mountains from cell
  (x=30, y=40, z=25) to (x=112, y=40, z=30). The thesis prints these as
  ``ps(40, 30, 25)`` / ``pg(40, 112, 30)`` in Matlab (row, column) order, i.e.
  (y, x, z): x = 112 only fits the 120-cell x axis.

Start and goal are world coordinates in metres (node-centred grid, origin 0).
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np

from ..errors import WorldError
from ..world import World
from ..world.terrain import OPEN_FIELD_SHAPE, open_field_heights
from .scenario import Scenario

__all__ = ["open_field", "fissure", "OPEN_FIELD_CELL", "OPEN_FIELD_HEIGHT_CELLS"]

#: Cell size of the open-field map [m] (same on x, y, z).
OPEN_FIELD_CELL = 15.0
#: Number of vertical nodes of the open-field map.
OPEN_FIELD_HEIGHT_CELLS = 40


def _open_field_world_uncached(seed: int | np.random.Generator) -> World:
    heights_m = open_field_heights(seed, OPEN_FIELD_SHAPE) * OPEN_FIELD_CELL
    return World.from_heightmap(
        heights_m, OPEN_FIELD_CELL, OPEN_FIELD_HEIGHT_CELLS, name="open-field"
    )


@lru_cache(maxsize=4)
def _open_field_world_cached(seed: int) -> World:
    return _open_field_world_uncached(seed)


def _open_field_world(seed: int | np.random.Generator) -> World:
    # Worlds are immutable, so the same (int) seed shares one World — and with it
    # the derived arrays other modules keep in World._cache.
    if isinstance(seed, (int, np.integer)) and not isinstance(seed, bool):
        return _open_field_world_cached(int(seed))
    return _open_field_world_uncached(seed)


def _check_clear(world: World, point_m: np.ndarray, what: str, min_free_below: int = 3) -> None:
    """Raise WorldError unless ``point_m`` is free with free nodes below it."""
    cell = world.to_cell(point_m, what=what)
    i, j, k = cell
    ground = int(world.surface_index()[i, j])
    if k - ground - 1 < min_free_below:
        raise WorldError(
            f"scenario {what} {tuple(point_m.tolist())} m (cell {cell}) has only "
            f"{max(k - ground - 1, 0)} free node(s) above the ground (needs {min_free_below}); "
            "this seed makes the terrain too high there, try another seed"
        )


def _make(
    seed: int | np.random.Generator, start_cells: tuple, goal_cells: tuple, description: str
) -> Scenario:
    world = _open_field_world(seed)
    start = world.to_world(np.asarray(start_cells, dtype=float))
    goal = world.to_world(np.asarray(goal_cells, dtype=float))
    _check_clear(world, start, "start")
    _check_clear(world, goal, "goal")
    return Scenario(world=world, start=start, goal=goal, description=description)


def open_field(seed: int | np.random.Generator = 0) -> Scenario:
    """The terrain-following open field (paper 000 §2.1, thesis §4.1.1).

    120 x 90 x 40 nodes of 15 m; start (20, 20, 20) cells = (300, 300, 300) m,
    goal (100, 80, 30) cells = (1500, 1200, 450) m. ``seed`` drives the random
    relief (same seed → identical world).
    """
    return _make(
        seed,
        (20, 20, 20),
        (100, 80, 30),
        "Open field with mountainous terrain (120x90x40 cells of 15 m): central mountain, "
        "two lateral ridges forming a fissure along y = 40 cells; start (20,20,20) → goal "
        "(100,80,30) cells [terrain-following paper §2, thesis ch. 4]",
    )


def fissure(seed: int | np.random.Generator = 0) -> Scenario:
    """The formation mission through the fissure (thesis ch. 6).

    Same terrain as :func:`open_field`; start cell (x=30, y=40, z=25) =
    (450, 600, 375) m, goal cell (x=112, y=40, z=30) = (1680, 600, 450) m.
    """
    return _make(
        seed,
        (30, 40, 25),
        (112, 40, 30),
        "Formation mission across the fissure between the two lateral mountains of the "
        "open field: start (x=30,y=40,z=25) → goal (x=112,y=40,z=30) cells [thesis ch. 6]",
    )
