"""Arrival times in a wind: the Zermelo (Randers) eikonal equation.

A vehicle of airspeed ``V`` [m/s] in a wind ``w`` [m/s] moves over the ground
at ``V n + w`` for the unit heading ``n`` it chooses. The earliest arrival time
``T`` from a set of sources solves

    V |grad T| + w . grad T = 1        (|w| < V),

the eikonal equation of a Randers metric (Zermelo's navigation problem). In a
constant wind the time to fly a straight displacement ``d`` is the ``t > 0``
of ``|d - w t| = V t``:

    t = (sqrt((w.d)^2 + (V^2 - |w|^2) |d|^2) - w.d) / (V^2 - |w|^2).

:func:`zermelo_march` solves it on a grid (2D or 3D) with a semi-Lagrangian
Fast Marching on the 8- / 26-neighbour stencil (:mod:`._wind_kernels`,
docs/eikonal.md "Wind"); :func:`fm2uav.eikonal.fast_marching` calls it when
given a non-zero ``wind``. Nodes where the wind is at least the airspeed are
**refused**: impassable, reported in :attr:`ZermeloMarch.refused` and by
:func:`wind_refused`, never crossed.

Direction of travel. ``T(x)`` is the time to fly *from* the nearest source
*to* ``x``. Wind makes this asymmetric: the time to fly from ``x`` *to* the
sources (the FM² goal wave, descended from the start) is the arrival time in
the opposite wind, ``towards=True``.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..errors import InputError
from . import _wind_march as wm
from ._wind_sources import ball_start
from .fmm import (
    MAX_BALL_SOURCES,
    SOURCE_INIT_CELLS,
    SOURCE_INIT_FRACTION,
    _as_speed,
    as_index_array,
    as_spacing,
    register_wind_march,
)

__all__ = [
    "ZermeloMarch",
    "zermelo_march",
    "zermelo_time",
    "ground_speed",
    "heading",
    "as_wind",
    "wind_refused",
    "is_calm",
]


@dataclass(frozen=True)
class ZermeloMarch:
    """Result of :func:`zermelo_march`.

    Attributes
    ----------
    times : ndarray, shape grid
        Arrival time [s]; ``inf`` where unreachable, refused, or not final when
        an early stop ended the march. With ``towards=True``: the time to fly
        from each node to the nearest source.
    track : ndarray, shape (*grid, ndim), or None
        Unit direction of the vehicle's motion over the ground at each node on
        its time-optimal route (from the sources to the node; with
        ``towards=True`` from the node towards the sources): the characteristic
        of the equation, i.e. what a descent follows. Zero where ``times`` is
        not finite and at the sources. None unless asked (``track=True``).
    refused : ndarray of bool, shape grid
        Nodes with speed > 0 where ``|wind| >= speed``: treated as impassable.
    pops, reopened : int
        Nodes taken from the narrow band, and frozen nodes the label correction
        re-opened (0 where the stencil is causal: ``|w| / V`` at most
        ``acute_limit``).
    acute_limit : float
        The largest ``|w| / V`` at which the grid's stencil is causal.
    """

    times: np.ndarray
    track: np.ndarray | None
    refused: np.ndarray
    pops: int
    reopened: int
    acute_limit: float


def as_wind(wind: Any, shape: tuple[int, ...]) -> np.ndarray:
    """Validate a wind for a grid of ``shape``; return it as float64.

    A constant vector (``ndim`` components [m/s], x first) or one per node,
    shape ``(*shape, ndim)``. Raises :class:`~fm2uav.InputError` otherwise.
    """
    ndim = len(shape)
    try:
        arr = np.asarray(wind, dtype=float)
    except (TypeError, ValueError) as exc:
        raise InputError(f"wind must be numbers [m/s]: {exc}") from None
    if arr.shape not in ((ndim,), tuple(shape) + (ndim,)):
        hint = (" (a 3D grid needs a vertical component too: append 0 for a horizontal "
                "wind)" if ndim == 3 and arr.shape[-1:] == (2,) else "")
        raise InputError(
            f"wind must be one vector of {ndim} components or an array of shape "
            f"{tuple(shape) + (ndim,)} (one vector per node, x first), got shape "
            f"{arr.shape}{hint}"
        )
    if not np.all(np.isfinite(arr)):
        bad = np.argwhere(~np.isfinite(arr))[0].tolist()
        raise InputError(f"wind must be finite; found {arr[tuple(bad)]} at index {bad}")
    return arr


def is_calm(wind: Any, shape: tuple[int, ...]) -> bool:
    """True if ``wind`` (validated for ``shape``) is zero everywhere."""
    return not np.any(as_wind(wind, shape))


def _wind3(w: np.ndarray, n: int, ndim: int) -> tuple[np.ndarray, bool]:
    """The wind as the march reads it: (1, 3) if constant, else (n, 3)."""
    if w.ndim == 1:
        out = np.zeros((1, 3))
        out[0, :ndim] = w
        return out, True
    out = np.zeros((n, 3))
    out[:, :ndim] = w.reshape(n, ndim)
    return out, False


def wind_refused(speed: Any, wind: Any) -> np.ndarray:
    """Nodes refused because the wind is at least the airspeed (speed > 0 only).

    Parameters
    ----------
    speed : array_like, shape grid
        Airspeed [m/s].
    wind : array_like, shape (ndim,) or (*grid, ndim)
        Wind [m/s].

    Returns
    -------
    ndarray of bool, shape grid
    """
    v = _as_speed(speed)
    w = as_wind(wind, v.shape)
    w2 = np.sum(np.broadcast_to(w, v.shape + (v.ndim,)) ** 2, axis=-1)
    return (v > 0) & (w2 >= v * v)


def zermelo_time(displacement: Any, airspeed: Any, wind: Any) -> np.ndarray:
    """Time [s] to fly straight displacements at an airspeed in a constant wind.

    The ``t > 0`` of ``|d - w t| = V t`` (``|w| < V``; ``inf`` otherwise),
    broadcast over leading axes.

    Parameters
    ----------
    displacement : array_like, shape (..., ndim)
        Ground displacement [m].
    airspeed : array_like, shape (...)
        Airspeed [m/s].
    wind : array_like, shape (..., ndim)
        Wind [m/s].

    Examples
    --------
    >>> float(zermelo_time([100.0, 0.0], 10.0, [5.0, 0.0]))  # downwind: 15 m/s
    6.666666666666667
    >>> float(zermelo_time([0.0, 80.0], 10.0, [6.0, 0.0]))   # crosswind: 8 m/s
    10.0
    """
    d = np.asarray(displacement, dtype=float)
    V = np.asarray(airspeed, dtype=float)
    w = np.asarray(wind, dtype=float)
    ndim = d.shape[-1]
    d3 = [d[..., i] if i < ndim else 0.0 for i in range(3)]
    w0, w1, w2 = (w[..., i] if i < ndim else 0.0 for i in range(3))
    wd = w0 * d3[0] + w1 * d3[1] + w2 * d3[2]
    dd = d3[0] ** 2 + d3[1] ** 2 + d3[2] ** 2
    lam = V * V - (w0 * w0 + w1 * w1 + w2 * w2)
    with np.errstate(invalid="ignore", divide="ignore"):
        root = np.sqrt(wd * wd + lam * dd)
        s = root + wd
        t = np.where(wd >= 0, np.where(s > 0, dd / np.where(s > 0, s, 1.0), 0.0),
                     (root - wd) / lam)
    return np.where(lam > 0, t, np.where(dd == 0, 0.0, np.inf))


def ground_speed(track: Any, airspeed: Any, wind: Any) -> np.ndarray:
    """Ground speed [m/s] flying along unit ground tracks at an airspeed in a wind.

    ``g = w.t + sqrt((w.t)^2 + V^2 - |w|^2)`` for the unit track ``t`` (the
    ``g`` of ``|g t - w| = V``); NaN where ``|w| >= V`` or the track is zero.

    Examples
    --------
    >>> float(ground_speed([0.0, 1.0], 10.0, [6.0, 0.0]))
    8.0
    """
    t = np.asarray(track, dtype=float)
    V = np.asarray(airspeed, dtype=float)
    w = np.asarray(wind, dtype=float)
    norm = np.linalg.norm(t, axis=-1)
    with np.errstate(invalid="ignore", divide="ignore"):
        u = t / norm[..., None]
        wt = np.sum(w * u, axis=-1)
        lam = V * V - np.sum(w * w, axis=-1)
        g = wt + np.sqrt(wt * wt + lam)
    return np.where((lam > 0) & (norm > 0), g, np.nan)


def heading(track: Any, airspeed: Any, wind: Any) -> np.ndarray:
    """Unit air heading ``n`` that flies the ground tracks: ``V n = g t - w``.

    Examples
    --------
    >>> heading([0.0, 1.0], 10.0, [6.0, 0.0]).round(3).tolist()  # crab into the wind
    [-0.6, 0.8]
    """
    t = np.asarray(track, dtype=float)
    V = np.asarray(airspeed, dtype=float)
    w = np.asarray(wind, dtype=float)
    g = ground_speed(t, V, w)
    with np.errstate(invalid="ignore", divide="ignore"):
        u = t / np.linalg.norm(t, axis=-1)[..., None]
        return (g[..., None] * u - w) / V[..., None] if V.ndim else (g[..., None] * u - w) / V


def zermelo_march(
    speed: Any,
    sources: Any,
    wind: Any,
    *,
    spacing: float | Sequence[float] = 1.0,
    order: int = 2,
    stop_at: Any = None,
    source_ball: bool = True,
    towards: bool = False,
    track: bool = False,
) -> ZermeloMarch:
    """Earliest arrival times of a vehicle flying at ``speed`` in ``wind``.

    Solves ``V |grad T| + w . grad T = 1`` (docs/eikonal.md "Wind") with a
    semi-Lagrangian Fast Marching on the 8- (2D) or 26-neighbour (3D) stencil,
    first or second order, with label correction where ``|w| / V`` exceeds the
    stencil's causal limit (``1/sqrt(2)`` in 2D, ``1/sqrt(3)`` in 3D, square
    cells), so the result solves the discrete equations for any ``|w| < V``.

    Parameters
    ----------
    speed : array_like, shape (nx, ny) or (nx, ny, nz)
        Airspeed at each node [m/s], ``>= 0``; 0 marks impassable nodes (in
        FM², the velocity map W times the cruise airspeed).
    sources : sequence of int tuples or (m, ndim) int array
        Grid indices where ``T = 0`` (speed > 0 and ``|wind| < speed`` there).
        Around point sources (at most 64) nodes within ``max(2 cells, 5 % of
        the grid extent)`` get accurate times first: the exact constant-wind
        time where speed and wind are constant in the ball's box, the factored
        equation marched on the box otherwise (``_wind_sources``).
    wind : array_like, shape (ndim,) or (nx, ny[, nz], ndim)
        Wind [m/s] in the units of ``speed``, x component first, constant or
        per node. Where ``|wind| >= speed`` the node is refused (impassable).
    spacing : float or sequence of float, optional
        Node spacing [m], one value or one per axis. Default 1.
    order : {1, 2}, optional
        Order of the scheme; order 2 where the second node outward is frozen
        and not later, and speed and wind are smooth along it. Default 2.
    stop_at : sequence of int tuples, optional
        Stop as soon as these nodes are final; nodes not final then are
        ``inf``. Where the stencil is not causal at some passable node, the
        march runs to the end (the stop nodes' times are then still exact).
    source_ball : bool, optional
        Initialise the ball around point sources (default True).
    towards : bool, optional
        If True, ``times`` is the time to fly from each node *to* the nearest
        source (the march runs in the opposite wind), and ``track`` points
        towards the sources. Default False (from the sources).
    track : bool, optional
        Also return the unit ground-track direction of each node (for a
        descent). Default False.

    Returns
    -------
    ZermeloMarch

    Raises
    ------
    fm2uav.InputError
        Bad speed, wind, spacing, order, source or stop index; a source on a
        node with speed 0 or wind at least the airspeed.

    Examples
    --------
    >>> import numpy as np
    >>> res = zermelo_march(np.full((11, 11), 10.0), [(5, 5)], [5.0, 0.0], spacing=10.0,
    ...                     order=1)  # along a stencil direction order 1 is exact
    >>> round(float(res.times[10, 5]), 6), round(float(res.times[0, 5]), 6)  # down/upwind
    (3.333333, 10.0)
    """
    v = _as_speed(speed)
    shape = v.shape
    ndim = v.ndim
    h = as_spacing(spacing, ndim)
    if isinstance(order, bool) or not isinstance(order, (int, np.integer)) or order not in (1, 2):
        shown = order.item() if isinstance(order, np.generic) else order
        raise InputError(f"order must be 1 or 2, got {shown!r}")
    w = as_wind(wind, shape)
    if towards:
        w = -w
    src = as_index_array(sources, shape, "sources")
    n = v.size
    wind3, wconst = _wind3(w, n, ndim)
    flat_speed = np.ascontiguousarray(v, dtype=float).reshape(-1)
    ok = wm.passable(flat_speed, np.broadcast_to(wind3, (n, 3)) if wconst else wind3)
    refused = ((flat_speed > 0) & ~ok).reshape(shape)
    shape3 = shape + (1,) * (3 - ndim)
    h3 = h + (1.0,) * (3 - ndim)
    src3 = np.zeros((src.shape[0], 3), dtype=np.int64)
    src3[:, :ndim] = src
    src_flat = np.ravel_multi_index(tuple(src3.T), shape3)
    bad = ~ok[src_flat]
    if np.any(bad):
        where = src[bad][0].tolist()
        vs = float(flat_speed[src_flat[bad][0]])
        if vs <= 0:
            raise InputError(f"source {where} has speed 0 (impassable); "
                             "move the source to a node with speed > 0")
        ws = float(np.linalg.norm(wind3[0 if wconst else src_flat[bad][0]]))
        raise InputError(
            f"source {where} is refused: the wind there ({ws:g} m/s) is not below the "
            f"airspeed ({vs:g} m/s); move the source or lower the wind")
    grid = wm.WindGrid(flat_speed, wind3, wconst, ok, shape3, ndim, h3)
    extent = max((k - 1) * hk for k, hk in zip(shape, h))
    radius = max(SOURCE_INIT_CELLS * max(h), SOURCE_INIT_FRACTION * extent)
    if src.shape[0] > MAX_BALL_SOURCES or not source_ball:
        radius = 0.0
    idx, t0, fixed, trk0 = ball_start(grid, src3, radius, SOURCE_INIT_CELLS * max(h), order)
    stops = None
    if stop_at is not None:
        stop = as_index_array(stop_at, shape, "stop_at")
        stop3 = np.zeros((stop.shape[0], 3), dtype=np.int64)
        stop3[:, :ndim] = stop
        stops = np.ravel_multi_index(tuple(stop3.T), shape3)
    res = wm.run(grid, idx, t0, fixed, order, stops, want_track=track, start_track=trk0)
    tr = None
    if track:
        tr = res.track[:, :ndim]
        norm = np.linalg.norm(tr, axis=1)
        good = (norm > 0) & np.isfinite(res.times)
        tr = np.where(good[:, None], tr / np.where(good, norm, 1.0)[:, None], 0.0)
        if towards:
            tr = -tr
        tr = tr.reshape(shape + (ndim,))
    return ZermeloMarch(
        times=res.times.reshape(shape), track=tr, refused=refused, pops=res.pops,
        reopened=res.reopened, acute_limit=wm.get_stencil(ndim, h3).acute,
    )


def _times(speed: Any, sources: Any, wind: Any, **options: Any) -> np.ndarray:
    return zermelo_march(speed, sources, wind, **options).times


register_wind_march(is_calm, _times)  # fast_marching(wind=...) calls the march above
