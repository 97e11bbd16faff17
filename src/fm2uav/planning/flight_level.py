"""Flight level over the ground: Algorithm 2 of the thesis (ch. 4) / the TFF paper.

For every column (i, j) the terrain top layer ``Surface(i, j)`` is found; the
cells of layer ``k = Surface(i, j) + Lf`` (``Lf = round(agl / dz)`` cells) are
clarified with the exponent ``p1`` and all other cells darkened with ``p2``.
With ``0 < p1 < p2`` the wave from the goal runs fastest along the flight level,
so the FM² path follows the terrain at ``agl`` metres.

Two readings of "the velocity map W" (``mode``):

``"capped"`` (default)
    Before the exponents, every cell of a column is capped at the value of W at
    that column's flight-level node: ``V = min(W, W_fl)``; then ``V ** p1`` on
    the level, ``V ** p2`` elsewhere. This makes the level the brightest cell of
    its column, which is what the seeds state and need ("the value of the cells
    where we want to force the planning must be close to 1"; "p2 darkens the
    upper layers") and what their figures show.

``"literal"``
    ``W ** p1`` on the level and ``W ** p2`` elsewhere with W the normalised
    distance map, word for word. Over an open field W grows with height up to
    ≈ 1 near the ceiling, and ``1 ** p2 = 1`` beats ``W_fl ** p1`` for any p2:
    the path climbs to the ceiling instead of following the terrain (0 % of the
    points within ±1 cell of the level on the open field, see docs/tff.md). It
    is kept for comparison.

Beyond the seeds (defaults keep the single layer): ``band`` widens the
clarified layer to all cells within ``band`` metres of the flight level, since
a one-cell layer is brittle on steep terrain; ``graded=True`` blends the
exponent from ``p1`` at the level to ``p2`` at the band edge.
"""

from __future__ import annotations

import numpy as np

from ..errors import InputError, PlanningError
from ..world import World
from .params import FLIGHT_LEVEL_MODES, FlightLevel

__all__ = [
    "flight_layer",
    "flight_level_speed",
    "exponents_from_k",
    "level_cells",
    "FLIGHT_LEVEL_MODES",
]


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


def level_cells(world: World, agl: float) -> int:
    """``Lf = round(agl / dz)``: the flight level in vertical cells (>= 1).

    Raises
    ------
    InputError
        2D world, ``agl`` not finite, <= 0, or less than half a vertical cell.
    """
    if world.ndim != 3:
        raise InputError("a flight level needs a 3D world (nx, ny, nz)")
    try:
        agl_f = float(agl)
    except (TypeError, ValueError):
        raise InputError(f"agl must be a height in metres, got {agl!r}") from None
    if not np.isfinite(agl_f) or agl_f <= 0:
        raise InputError(f"agl must be a positive height in metres, got {agl!r}")
    dz = world.spacing[2]
    lf = int(round(agl_f / dz))
    if lf < 1:
        raise InputError(
            f"agl = {agl_f:g} m is less than half a vertical cell ({dz:g} m); "
            f"use agl >= {dz / 2:g} m or a finer vertical spacing"
        )
    return lf


def flight_layer(world: World, agl: float) -> np.ndarray:
    """Index of the flight-level layer in every column [cells].

    ``Surface(i, j) + round(agl / dz)``, where ``Surface`` is the topmost
    obstacle node of the column (ground, or a roof; nodes of no-fly zones do
    not count). A column without any obstacle has ``Surface = -1`` (ground
    just below the map).

    Raises
    ------
    InputError
        2D world, ``agl`` not finite or < half a cell.
    PlanningError
        The flight level leaves the map (above the ceiling) in some column.
    """
    from ..world.zones import terrain_surface_index

    lf = level_cells(world, agl)
    dz = world.spacing[2]
    nz = world.shape[2]
    if lf >= nz:  # above the whole grid wherever the ground is (and no int64 overflow)
        raise PlanningError(
            f"the flight level agl = {float(agl):g} m leaves the map everywhere: it is higher "
            f"than the whole map ({nz} layers of {dz:g} m, {(nz - 1) * dz:g} m from bottom to "
            "top); lower agl or build a taller world (mission file planner.agl / "
            "world.ceiling; CLI --agl / --ceiling)")
    surface = terrain_surface_index(world)  # no-fly zone nodes are not ground
    layer = surface.astype(np.int64) + lf
    nz = world.shape[2]
    over = layer >= nz
    if over.any():
        worst = np.unravel_index(int(np.argmax(layer)), layer.shape)
        top_m = world.origin[2] + (nz - 1) * dz
        need = int(layer.max()) + 1
        raise PlanningError(
            f"the flight level agl = {float(agl):g} m leaves the map in {int(over.sum())} "
            f"column(s), e.g. column {[int(v) for v in worst]} needs layer {int(layer[worst])} "
            f"but the ceiling is layer {nz - 1} (z = {top_m:g} m); lower agl to at most "
            f"{(nz - 1 - int(surface.max())) * dz:g} m or build the world with "
            f"at least {need} height cells"
        )
    return layer


def flight_level_speed(W: np.ndarray, world: World, level: FlightLevel) -> np.ndarray:
    """Impose a flight level on a velocity map (thesis Algorithm 2).

    Parameters
    ----------
    W : ndarray, shape (nx, ny, nz)
        Velocity map in [0, 1] (0 on obstacles).
    world : World
        3D world the map belongs to.
    level : FlightLevel
        ``agl`` [m] above the ground (or roofs); ``p1`` on the level cells and
        ``p2`` on all others; ``band`` [m] half-width of the clarified band
        (0: the seeds' single layer); ``graded``: blend the exponent from
        ``p1`` at the level to ``p2`` at the band edge; ``mode``: ``"capped"``
        caps every cell of a column at W of its flight-level node before the
        exponents, so the level is the brightest cell of its column;
        ``"literal"`` exponentiates W as is (does not follow the terrain on
        open maps; see the module docstring).

    Returns
    -------
    ndarray
        The shaped map (new array), still 0 where ``W`` is 0.

    Raises
    ------
    InputError
        ``level`` not a FlightLevel, shape mismatch, agl below half a cell.
    PlanningError
        The flight level leaves the map.

    Examples
    --------
    >>> import numpy as np
    >>> from fm2uav import FlightLevel, World
    >>> w = World.from_heightmap(np.zeros((3, 3)), 1.0, 6)   # ground at layer 0
    >>> W = np.linspace(0, 1, 6)[None, None, :].repeat(3, 0).repeat(3, 1)
    >>> V = flight_level_speed(W, w, FlightLevel(agl=2.0, p1=0.5, p2=2.0))
    >>> int(np.argmax(V[1, 1]))          # the level (layer 0 + 2) is the fastest
    2
    """
    if not isinstance(level, FlightLevel):
        raise InputError(
            f"level must be a fm2uav.FlightLevel, got {type(level).__name__}; "
            "e.g. FlightLevel(agl=150.0, p1=0.5, p2=1.3)"
        )
    W = np.asarray(W, dtype=float)
    if W.shape != world.shape:
        raise InputError(f"W has shape {W.shape} but the world is {world.shape}")
    p1, p2, band = level.p1, level.p2, level.band
    layer = flight_layer(world, level.agl)
    dz = world.spacing[2]
    k = np.arange(world.shape[2])[None, None, :]
    offset_m = np.abs(k - layer[:, :, None]) * dz  # distance to the level [m]

    if level.mode == "capped":
        w_fl = np.take_along_axis(W, layer[:, :, None], axis=2)  # (nx, ny, 1)
        # a level node with W = 0 (e.g. a wall at the ceiling) would zero the
        # whole column: leave such columns uncapped
        cap = np.where(w_fl > 0, w_fl, np.inf)
        V = np.minimum(W, cap)
    else:
        V = W

    inside = offset_m <= band + 1e-9 * dz
    if level.graded and band > 0:
        frac = np.clip(offset_m / band, 0.0, 1.0)
        exponent = np.where(inside, p1 + (p2 - p1) * frac, p2)
    else:
        exponent = np.where(inside, p1, p2)
    out = np.power(V, exponent)
    out[W <= 0] = 0.0
    return out
