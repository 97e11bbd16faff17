"""Re-marching after a local change of the speed: keep what the change cannot reach.

In the Fast Marching Method a node's arrival time depends only on nodes frozen
before it (smaller times) and on its own speed and its upwind stencil's speeds.
When the speed changes on a set of nodes ``C``, the march over the new speed is
identical to the old one until the first node of ``C`` or of its face
neighbours ``N(C)`` is reached, so every node with an old time below

    t* = min over C ∪ N(C) of T_old

keeps its time exactly. :func:`remarch` freezes those nodes with their old
times and marches the rest again. The saving is the share of the map the wave
covers before it meets the change: large for a new obstacle far from the goal,
nothing for a change next to it.

Point sources get an initial ball (``fast_marching``'s source ball); a change
close to a source can alter the ball, so :func:`remarch` falls back to a full
march there.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from scipy import ndimage

from ..errors import InputError
from . import _kernels
from .fmm import SOURCE_INIT_CELLS, SOURCE_INIT_FRACTION, _as_speed, as_index_array, as_spacing
from .fmm import fast_marching, run_march

__all__ = ["remarch", "unaffected"]


def remarch(
    speed: Any,
    sources: Any,
    previous: np.ndarray,
    changed: np.ndarray,
    *,
    spacing: Any = 1.0,
    order: int = 2,
    stop_at: Any = None,
) -> np.ndarray:
    """Arrival times over a changed speed, re-using the times the change cannot affect.

    Parameters
    ----------
    speed : array_like, shape (nx, ny[, nz])
        The new speed [m/s].
    sources : sequence of int tuples
        The same sources as the previous march.
    previous : ndarray, same shape
        Arrival times [s] of a march from the same sources over the old speed,
        with the same ``spacing`` and ``order``: complete, or stopped early
        (``stop_at``; nodes not frozen are ``inf``), in which case the march is
        continued from its frozen nodes.
    changed : ndarray of bool, same shape
        Nodes whose speed differs from the old speed.
    spacing, order, stop_at
        As in :func:`fm2uav.eikonal.fast_marching`.

    Returns
    -------
    ndarray
        The arrival times :func:`fast_marching` gives on the new speed (same
        values up to round-off from the order of equal heap keys).

    Examples
    --------
    >>> import numpy as np
    >>> v = np.ones((30, 30)); T0 = fast_marching(v, [(0, 0)], order=1)
    >>> v2 = v.copy(); v2[20:25, 20:25] = 0.0
    >>> T1 = remarch(v2, [(0, 0)], T0, v2 != v, order=1)
    >>> bool(np.allclose(T1, fast_marching(v2, [(0, 0)], order=1)))
    True
    """
    v = _as_speed(speed)
    shape = v.shape
    prev = np.asarray(previous, dtype=float)
    chg = np.asarray(changed, dtype=bool)
    if prev.shape != shape or chg.shape != shape:
        raise InputError(
            f"previous times {prev.shape} and changed mask {chg.shape} must have the "
            f"speed's shape {shape}"
        )
    h = as_spacing(spacing, v.ndim)
    if chg.any():
        src = as_index_array(sources, shape, "sources")
        if _near_source(chg, src, shape, h):
            return fast_marching(v, sources, spacing=spacing, order=order, stop_at=stop_at)
    keep = unaffected(prev, chg) & np.isfinite(prev)
    if not chg.any() and stop_at is not None:
        stops = as_index_array(stop_at, shape, "stop_at")
        if keep[tuple(stops.T)].all():
            return prev.copy()  # nothing changed and the stop nodes are known already
    T = np.where(keep, prev, np.inf).reshape(-1)
    state = np.where(keep.reshape(-1), _kernels.FROZEN, 0).astype(np.uint8)
    h3 = h + (1.0,) * (3 - v.ndim)
    shape3 = shape + (1,) * (3 - v.ndim)
    return run_march(v.reshape(-1), _kernels.Start.whole(T, state, shape3), shape, h3, order,
                     stop_at)


def unaffected(previous: np.ndarray, changed: np.ndarray) -> np.ndarray:
    """Nodes whose arrival time a speed change on ``changed`` cannot alter.

    Parameters
    ----------
    previous : ndarray
        Arrival times of the complete march over the old speed [s].
    changed : ndarray of bool
        Nodes whose speed changed.

    Returns
    -------
    ndarray of bool
        ``previous < t*`` with ``t*`` the smallest old time on the changed nodes
        and their face neighbours (all False if nothing is below it).
    """
    chg = np.asarray(changed, dtype=bool)
    if not chg.any():
        return np.ones(chg.shape, dtype=bool)
    prev = np.asarray(previous)
    # dilate only the bounding box of the change (+1 node): C and its face neighbours
    idx = np.argwhere(chg)
    box = tuple(slice(max(a - 1, 0), b + 2) for a, b in zip(idx.min(0), idx.max(0)))
    reach = ndimage.binary_dilation(chg[box], structure=ndimage.generate_binary_structure(chg.ndim, 1))
    return prev < float(prev[box][reach].min())


def _near_source(chg: np.ndarray, src: np.ndarray, shape: tuple, h: tuple) -> bool:
    """True if a changed node lies within twice the source-ball radius of a source."""
    extent = max((n - 1) * hk for n, hk in zip(shape, h))
    radius = 2.0 * max(SOURCE_INIT_CELLS * max(h), SOURCE_INIT_FRACTION * extent)
    idx = np.argwhere(chg)
    for s in src:
        d2 = (((idx - s) * np.asarray(h)) ** 2).sum(axis=1)
        if (d2 <= radius * radius).any():
            return True
    return False
