"""2D city map of the curvature study (Sensors 2022, seed 004, §3.1 and Fig. 7).

The seed plans 24 start/goal pairs "covering the main central area" of a city
map around the Centre Pompidou (Paris). The seed's raster is not published, so
this module draws a stand-in with the same features, from the real layout of
the quarter (approximate, axis-aligned to the seed's figures): the Centre
(166 m x 60 m, its long side north-south along Rue Beaubourg), the sloping
piazza (Place Georges Pompidou) west of it, the Stravinsky fountain square to
the south, and the irregular Marais blocks around them, cut by streets 8-20 m
wide, some of them oblique. Free space is the union of streets and squares;
everything else is building.

The geometry is fixed (no randomness); ``seed`` only draws the start/goal
pairs (:func:`city2d_pairs`).
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np
import shapely
from scipy import ndimage
from shapely.geometry import LineString, Polygon, box

from ..errors import WorldError
from ..world import World
from .scenario import Scenario

__all__ = [
    "CITY2D_SIZE",
    "CITY2D_CELL",
    "city2d_world",
    "city2d_pairs",
    "city2d",
]

#: Extent of the map (x, y) [m].
CITY2D_SIZE = (400.0, 300.0)
#: Node spacing [m].
CITY2D_CELL = 2.0

# Streets as (polyline [m], width [m]); x east, y north.
_STREETS: tuple[tuple[tuple[tuple[float, float], ...], float], ...] = (
    # north-south
    (((22.0, -5.0), (18.0, 120.0), (24.0, 305.0)), 12.0),  # Rue Saint-Martin
    (((70.0, -5.0), (66.0, 70.0)), 8.0),  # Rue Quincampoix (south part)
    (((62.0, 150.0), (58.0, 305.0)), 8.0),  # Rue Quincampoix (north part)
    (((236.0, -5.0), (234.0, 150.0), (238.0, 305.0)), 16.0),  # Rue Beaubourg
    (((300.0, -5.0), (306.0, 140.0), (296.0, 305.0)), 10.0),  # Rue du Temple
    (((362.0, -5.0), (358.0, 95.0), (372.0, 305.0)), 9.0),  # Rue Vieille-du-Temple
    # east-west
    (((-5.0, 30.0), (150.0, 34.0), (405.0, 26.0)), 10.0),  # Rue de la Verrerie / St-Merri
    (((-5.0, 262.0), (230.0, 258.0), (405.0, 266.0)), 14.0),  # Rue Rambuteau
    (((-5.0, 150.0), (95.0, 150.0)), 10.0),  # Rue Aubry-le-Boucher
    (((236.0, 110.0), (405.0, 104.0)), 9.0),  # Rue Simon-le-Franc / Michel-le-Comte
    (((236.0, 200.0), (405.0, 196.0)), 8.0),  # Rue des Haudriettes (stand-in)
    (((-5.0, 210.0), (62.0, 212.0)), 7.0),  # Rue de Venise (stand-in)
    # oblique
    (((66.0, 70.0), (95.0, 100.0)), 8.0),  # link Quincampoix -> piazza
    (((306.0, 140.0), (362.0, 60.0)), 8.0),  # Rue des Blancs-Manteaux (stand-in)
    (((18.0, 90.0), (66.0, 70.0)), 7.0),  # Rue de la Reynie (stand-in)
)

# Open squares as polygons [m].
_SQUARES: tuple[tuple[tuple[float, float], ...], ...] = (
    # Place Georges Pompidou (the piazza), west of the Centre
    ((95.0, 60.0), (166.0, 60.0), (166.0, 246.0), (95.0, 246.0)),
    # Place Igor Stravinsky (fountain square), south of the Centre
    ((150.0, 34.0), (228.0, 34.0), (228.0, 62.0), (150.0, 62.0)),
    # forecourt north of the Centre, on Rue Rambuteau
    ((166.0, 236.0), (236.0, 236.0), (236.0, 262.0), (166.0, 262.0)),
    # small square east (Square Sainte-Avoye stand-in)
    ((306.0, 150.0), (340.0, 150.0), (340.0, 178.0), (306.0, 178.0)),
)

# The Centre Pompidou itself (kept as a building even where squares touch it).
_CENTRE = box(166.0, 62.0, 226.0, 236.0)


def _free_space():
    parts = [LineString(line).buffer(width / 2.0, cap_style="flat", join_style="round")
             for line, width in _STREETS]
    parts += [Polygon(p) for p in _SQUARES]
    free = shapely.union_all(parts)
    return free.difference(_CENTRE)


@lru_cache(maxsize=2)
def _city2d_world_cached(cell: float) -> World:
    nx = int(round(CITY2D_SIZE[0] / cell)) + 1
    ny = int(round(CITY2D_SIZE[1] / cell)) + 1
    x = np.arange(nx) * cell
    y = np.arange(ny) * cell
    X, Y = np.meshgrid(x, y, indexing="ij")
    free = shapely.contains_xy(_free_space(), X, Y)
    # keep only the largest connected free region (enclosed courtyards are buildings)
    labels, n = ndimage.label(free)
    if n > 1:
        sizes = np.bincount(labels.ravel())
        sizes[0] = 0
        free = labels == int(np.argmax(sizes))
    return World(~free, spacing=cell, origin=(0.0, 0.0), name="city2d")


def city2d_world(cell: float = CITY2D_CELL) -> World:
    """The 2D city map (400 m x 300 m, nodes every ``cell`` metres).

    Parameters
    ----------
    cell : float, optional
        Node spacing [m]. Default :data:`CITY2D_CELL` (2 m: 201 x 151 nodes).

    Returns
    -------
    World
        2D world, occupancy True = building; the same object for the same
        ``cell`` (so derived arrays cached on it are shared).
    """
    cell = float(cell)
    if not (np.isfinite(cell) and 0.25 <= cell <= 20.0):
        raise WorldError(f"cell must be in [0.25, 20] metres, got {cell!r}")
    return _city2d_world_cached(cell)


def city2d_pairs(
    n: int = 24,
    seed: int | np.random.Generator = 0,
    *,
    world: World | None = None,
    min_clearance: float = 4.0,
    min_distance: float = 150.0,
    margin: float = 30.0,
) -> tuple[np.ndarray, np.ndarray]:
    """Start/goal pairs covering the central area of the city map.

    Points are drawn (seeded) among free nodes at least ``min_clearance``
    metres from any building and ``margin`` metres from the map border; the
    two points of a pair are at least ``min_distance`` metres apart. All
    free nodes are connected, so every pair is reachable.

    Parameters
    ----------
    n : int
        Number of pairs (the seed uses 24).
    seed : int or numpy.random.Generator
        Same seed → same pairs.
    world : World, optional
        Map to draw on; default :func:`city2d_world`.
    min_clearance, min_distance, margin : float
        [m], see above.

    Returns
    -------
    starts, goals : ndarray, shape (n, 2)
        World coordinates [m] (on nodes).
    """
    if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < 1:
        raise WorldError(f"n must be a positive integer number of pairs, got {n!r}")
    w = city2d_world() if world is None else world
    rng = seed if isinstance(seed, np.random.Generator) else np.random.default_rng(seed)
    dist = ndimage.distance_transform_edt(~w.occupancy, sampling=w.spacing)
    pts = w.to_world(np.argwhere(dist >= min_clearance))
    lo, hi = w.bounds[:, 0] + margin, w.bounds[:, 1] - margin
    pts = pts[np.all((pts >= lo) & (pts <= hi), axis=1)]
    if len(pts) < 2:
        raise WorldError("the map has too few free nodes for start/goal pairs; lower min_clearance")
    starts, goals = [], []
    tries = 0
    while len(starts) < n:
        tries += 1
        if tries > 1000 * n:
            raise WorldError(
                f"could not draw {n} pairs at least {min_distance} m apart; lower min_distance"
            )
        a, b = pts[rng.integers(len(pts), size=2)]
        if np.linalg.norm(a - b) >= min_distance:
            starts.append(a)
            goals.append(b)
    return np.array(starts), np.array(goals)


def city2d(seed: int | np.random.Generator = 0):
    """Scenario: the 2D city map with the first start/goal pair of ``seed``.

    The map is fixed; ``seed`` draws the pair (see :func:`city2d_pairs`).
    """
    world = city2d_world()
    starts, goals = city2d_pairs(1, seed, world=world)
    return Scenario(
        world=world,
        start=starts[0],
        goal=goals[0],
        description=(
            "2D city map around the Centre Pompidou, Paris (400 m x 300 m, 2 m nodes): the "
            "Centre, its piazza and the Marais streets; stand-in for the map of the "
            "curvature study [Sensors 2022 §3.1, Fig. 7]"
        ),
    )
