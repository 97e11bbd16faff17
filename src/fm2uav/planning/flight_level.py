"""Flight level over the ground: Algorithm 2 of the thesis (ch. 4) / the TFF paper.

For every column (i, j) the terrain top layer ``Surface(i, j)`` is found; the
cells of layer ``k = Surface(i, j) + Lf`` (``Lf = round(agl / dz)`` cells) are
clarified ``W ** p1`` and all other cells darkened ``W ** p2``. With
``0 < p1 < 1 < p2`` the wave from the goal runs fastest along the flight level,
so the FM² path follows the terrain at ``agl`` metres.

Beyond the seeds (defaults keep the seeds' behaviour): ``band`` widens the
clarified layer to all cells within ``band`` metres of the flight level, since
a one-cell layer is brittle on steep terrain; ``graded=True`` blends the
exponent from ``p1`` at the level to ``p2`` at the band edge.
"""

from __future__ import annotations

import numpy as np

from ..errors import InputError, PlanningError
from ..world import World

__all__ = ["flight_layer", "flight_level_speed", "exponents_from_k"]


def exponents_from_k(k: float) -> tuple[float, float]:
    """The seeds' one-parameter form: ``p1 = k``, ``p2 = 1 - k``.

    Raises
    ------
    InputError
        If either exponent would be <= 0 (``k`` must be in (0, 1)).
    """
    if not (0.0 < k < 1.0):
        raise InputError(f"k must be in (0, 1) so that p1 = k and p2 = 1 - k are > 0, got {k!r}")
    return float(k), float(1.0 - k)


def flight_layer(world: World, agl: float) -> np.ndarray:
    """Index of the flight-level layer in every column [cells].

    ``Surface(i, j) + round(agl / dz)``, where ``Surface`` is the topmost
    obstacle node of the column (ground, or a roof). A column without any
    obstacle has ``Surface = -1`` (ground just below the map).

    Raises
    ------
    InputError
        2D world, ``agl`` not finite or < one cell.
    PlanningError
        The flight level leaves the map (above the ceiling) in some column.
    """
    if world.ndim != 3:
        raise InputError("a flight level needs a 3D world (nx, ny, nz)")
    if not np.isfinite(agl) or agl <= 0:
        raise InputError(f"agl must be a positive height in metres, got {agl!r}")
    dz = world.spacing[2]
    lf = int(round(agl / dz))
    if lf < 1:
        raise InputError(
            f"agl = {agl:g} m is less than half a vertical cell ({dz:g} m); "
            f"use agl >= {dz / 2:g} m or a finer vertical spacing"
        )
    layer = world.surface_index().astype(np.int64) + lf
    nz = world.shape[2]
    over = layer >= nz
    if over.any():
        worst = np.unravel_index(int(np.argmax(layer)), layer.shape)
        top_m = world.origin[2] + (nz - 1) * dz
        raise PlanningError(
            f"the flight level agl = {agl:g} m leaves the map in {int(over.sum())} column(s), "
            f"e.g. column {[int(v) for v in worst]} needs layer {int(layer[worst])} but the "
            f"ceiling is layer {nz - 1} (z = {top_m:g} m); lower agl or build the world with "
            f"more height cells"
        )
    return layer


def flight_level_speed(
    W: np.ndarray,
    world: World,
    agl: float,
    p1: float,
    p2: float,
    *,
    band: float = 0.0,
    graded: bool = False,
) -> np.ndarray:
    """Impose a flight level on a velocity map (thesis Algorithm 2).

    Parameters
    ----------
    W : ndarray, shape (nx, ny, nz)
        Velocity map in [0, 1] (0 on obstacles).
    world : World
        3D world the map belongs to.
    agl : float
        Flight height above the ground (or roofs) [m].
    p1 : float
        Exponent on the flight-level cells, > 0 (< 1 clarifies).
    p2 : float
        Exponent on all other cells, > 0 (> 1 darkens).
    band : float, optional
        Half-width [m] of the clarified band around the level; 0 (default) is
        the seeds' single layer.
    graded : bool, optional
        Within the band, blend the exponent linearly from ``p1`` at the level
        to ``p2`` at the band edge. Default False (all band cells get ``p1``).

    Returns
    -------
    ndarray
        The shaped map (new array), still 0 on obstacles.
    """
    for name, p in (("p1", p1), ("p2", p2)):
        if not (np.isfinite(p) and p > 0):
            raise InputError(f"{name} must be a finite exponent > 0, got {p!r}")
    if not (np.isfinite(band) and band >= 0):
        raise InputError(f"band must be >= 0 metres, got {band!r}")
    W = np.asarray(W, dtype=float)
    if W.shape != world.shape:
        raise InputError(f"W has shape {W.shape} but the world is {world.shape}")
    layer = flight_layer(world, agl)
    dz = world.spacing[2]
    k = np.arange(world.shape[2])[None, None, :]
    offset_m = np.abs(k - layer[:, :, None]) * dz  # distance to the level [m]
    half = max(band, 0.0)
    exponent = np.full(W.shape, float(p2))
    inside = offset_m <= half + 1e-9 * dz
    if graded and half > 0:
        frac = np.clip(offset_m / half, 0.0, 1.0)
        exponent = np.where(inside, p1 + (p2 - p1) * frac, p2)
    else:
        exponent[inside] = p1
    out = np.power(W, exponent)
    out[W <= 0] = 0.0
    return out
