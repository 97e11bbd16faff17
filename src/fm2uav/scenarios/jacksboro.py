"""Real terrain: the Jacksboro fault DEM bundled with matplotlib.

``jacksboro_fault_dem.npz`` (matplotlib sample data): 344 x 403 elevations
[m] at 3 arc-seconds (0.000833°), 236-1076 m, around 84.08-84.41° W,
36.45-36.73° N (Tennessee, USA) — ridges of the Cumberland mountains cut by the
Jacksboro fault. The npz stores ``xmin``/``xmax`` (longitudes of the west and
east edges) and, despite their names, ``ymin`` = the *north* edge and ``ymax``
= the south edge (row 0 is the northern row; 344 x 0.000833° = ymin - ymax).

The scenario resamples it with :func:`fm2uav.world.dem.from_dem` to 150 m
horizontal and 30 m vertical cells in UTM zone 16N (EPSG:32616): 194 x 206 x
49 nodes over ~29 x 31 km; start and goal sit 300 m over the ground on either
side of the fault (south-west ridges → north-east valley).
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np

from ..world import World
from ..world.dem import from_dem
from .scenario import Scenario

__all__ = ["jacksboro", "jacksboro_world", "jacksboro_dem", "JACKSBORO_CELL", "JACKSBORO_DZ"]

#: Horizontal and vertical node spacing of the scenario [m].
JACKSBORO_CELL = 150.0
JACKSBORO_DZ = 30.0
#: Start/goal columns [cells of 150 m] and their height over the ground [m].
_START_COLUMN = (30, 60)
_GOAL_COLUMN = (170, 150)
_ABOVE_GROUND = 300.0


def jacksboro_dem() -> tuple[np.ndarray, tuple[float, float, float, float]]:
    """The raw DEM: ``(elevation[rows, cols] m, (west, south, east, north) deg)``."""
    from matplotlib import cbook

    d = cbook.get_sample_data("jacksboro_fault_dem.npz")
    z = np.asarray(d["elevation"], dtype=float)
    bounds = (float(d["xmin"]), float(d["ymax"]), float(d["xmax"]), float(d["ymin"]))
    return z, bounds


@lru_cache(maxsize=4)
def jacksboro_world(cell_size: float = JACKSBORO_CELL, dz: float = JACKSBORO_DZ) -> World:
    """The Jacksboro DEM as a World (cached: worlds are immutable)."""
    z, bounds = jacksboro_dem()
    return from_dem(z, (cell_size, cell_size, dz), crs="EPSG:4326", bounds=bounds,
                    name="jacksboro")


def jacksboro(seed: int | np.random.Generator = 0):
    """Scenario on the real Jacksboro fault DEM (geographic → UTM 16N).

    ``seed`` is accepted for the common scenario signature and unused (the
    terrain is real data).
    """
    w = jacksboro_world()
    pts = []
    for i, j in (_START_COLUMN, _GOAL_COLUMN):
        pts.append(np.array([w.origin[0] + i * w.spacing[0], w.origin[1] + j * w.spacing[1],
                             float(w.terrain[i, j]) + _ABOVE_GROUND]))
    return Scenario(
        world=w,
        start=pts[0],
        goal=pts[1],
        description="Real DEM: Jacksboro fault, Tennessee (matplotlib sample, 3 arc-s, "
        "236-1076 m) resampled to 150 m x 150 m x 30 m cells in UTM 16N; start and goal "
        "300 m over the ground across the fault",
    )
