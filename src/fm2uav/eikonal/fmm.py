"""Public Fast Marching Method: ``fast_marching(speed, sources, ...)``.

Every call goes prepare (validate, flatten) → kernel (compiled march) →
finalise (reshape), so input checks live in one place.
"""

from __future__ import annotations

import threading
from collections.abc import Sequence
from typing import Any

import numpy as np

from .._validate import grid
from ..errors import InputError
from . import _kernels, _parallel, _sources

__all__ = ["fast_marching", "as_spacing", "as_index_array"]

#: Radius of the exact point-source initialisation: the larger of this many
#: (largest) grid spacings ...
SOURCE_INIT_CELLS = 2.0
#: ... and this share of the grid's largest physical extent. A ball of fixed
#: physical size is what keeps the order-2 scheme second-order: a ball of a
#: fixed number of cells leaves an O(h) error from the source singularity
#: (measured rate ~1; with 5 % the rate is ~2, see tests/eikonal).
SOURCE_INIT_FRACTION = 0.05
#: Ball initialisation is for point sources: above this many sources (e.g. all
#: obstacle nodes of a map) sources are plain T = 0 nodes.
MAX_BALL_SOURCES = 64
#: A source gets its ball only where the speed in the ball's box varies by at
#: most this factor (max/min): the ball's times (straight ray for a constant
#: speed, the factored eikonal equation otherwise, see ``_sources``) assume a
#: smooth speed, so a slow wall or a jump (e.g. a flight-level layer) inside the
#: box is left to the march and its first-order fallback across jumps. Where the
#: nominal box fails, the radius is halved (down to ``SOURCE_INIT_CELLS`` cells)
#: until its box passes.
BALL_MAX_SPEED_RATIO = 1.5
#: Positive speeds below this are raised to it, so that ``1 / speed**2`` stays
#: finite (smaller speeds would otherwise act as walls).
MIN_SPEED = 1e-150


def as_spacing(spacing: float | Sequence[float], ndim: int) -> tuple[float, ...]:
    """Validate a grid spacing and return one positive float per axis [m]."""
    arr = np.atleast_1d(np.asarray(spacing, dtype=float))
    if arr.ndim != 1 or arr.size not in (1, ndim):
        raise InputError(
            f"spacing must be a number or {ndim} numbers (one per axis), got {spacing!r}"
        )
    if arr.size == 1:
        arr = np.repeat(arr, ndim)
    if not np.all(np.isfinite(arr)) or np.any(arr <= 0):
        raise InputError(
            f"spacing must be finite and > 0 on every axis, got {tuple(arr.tolist())}"
        )
    return tuple(float(a) for a in arr)


def as_index_array(points: Any, shape: tuple[int, ...], what: str) -> np.ndarray:
    """Validate integer grid indices; return an ``(m, ndim)`` int64 array.

    Accepts one index tuple, a sequence of tuples or an ``(m, ndim)`` array.
    """
    ndim = len(shape)
    try:
        arr = np.asarray(points)
    except (TypeError, ValueError) as exc:  # ragged input
        raise InputError(f"{what} must be integer index tuples of length {ndim}: {exc}") from None
    if arr.ndim == 1 and arr.size == ndim:
        arr = arr[None, :]
    if arr.ndim != 2 or arr.shape[1] != ndim or arr.shape[0] == 0:
        raise InputError(
            f"{what} must be a non-empty sequence of index tuples of length {ndim} "
            f"(the grid is {ndim}D), got array of shape {arr.shape}"
        )
    if arr.dtype.kind == "f":
        if not np.all(np.isfinite(arr)) or np.any(arr != np.round(arr)):
            raise InputError(
                f"{what} must be integer grid indices; got non-integer values "
                f"{arr[np.any(arr != np.round(arr), axis=1)][:3].tolist()} "
                "(convert world coordinates with World.to_cell)"
            )
    elif arr.dtype.kind not in "iu":
        raise InputError(f"{what} must be integer grid indices, got dtype {arr.dtype}")
    arr = arr.astype(np.int64)
    bad = np.any((arr < 0) | (arr >= np.asarray(shape)), axis=1)
    if np.any(bad):
        raise InputError(
            f"{what} {arr[bad][0].tolist()} lies outside the grid of shape {shape}; "
            f"indices must satisfy 0 <= i < n on every axis"
        )
    return arr


#: ``(is_calm(wind, shape), march(speed, sources, wind, **options) -> times)`` of the wind
#: march, registered by :mod:`fm2uav.eikonal.wind` (which the package imports): that module
#: uses this one's input checks, so the dependency goes one way and ``fast_marching``
#: finds the wind march here.
_WIND_MARCH: list = []


def register_wind_march(is_calm: Any, march: Any) -> None:
    """Make ``fast_marching(wind=...)`` call ``march`` unless ``is_calm(wind, shape)``."""
    _WIND_MARCH[:] = [(is_calm, march)]


def _as_speed(speed: Any, threads: int = 1) -> np.ndarray:
    """The speed array of the march (read-only, float64, C order), checked: see
    :func:`_as_speed_span`."""
    return _as_speed_span(speed, threads)[0]


def _as_speed_span(speed: Any, threads: int = 1) -> tuple[np.ndarray, tuple[float, float]]:
    """The speed array of the march, checked in one compiled pass, and the smallest
    positive and the largest speed [m/s] found in the same pass (``(inf, 0)``: none
    positive), which the march's plateau test and the parallel march's first window
    would otherwise take a pass each to find.

    Raises :class:`~fm2uav.InputError` naming the first non-finite or negative speed;
    positive speeds below :data:`MIN_SPEED` are raised to it.
    """
    arr = np.ascontiguousarray(grid(speed, "speed"))
    # one compiled pass instead of three numpy passes (matters on 40 M-node maps), on the
    # march's threads for a big grid
    flat = _kernels._readonly(arr.reshape(-1))
    nth = _kernels.setup_threads(threads, flat.size)
    if nth > 1:
        bad, n_tiny, low, top = _kernels.scan_speed_parallel(nth, flat, MIN_SPEED)
    else:
        bad, n_tiny, low, top = _kernels.scan_speed(flat, MIN_SPEED)
    if bad >= 0:
        where = [int(w) for w in np.unravel_index(bad, arr.shape)]
        value = float(arr[tuple(where)])
        if not np.isfinite(value):
            raise InputError(f"speed must be finite; found {value} at index {where}")
        raise InputError(
            f"speed must be >= 0 (0 = impassable); found {value:g} at index {where}"
        )
    if n_tiny:
        arr = np.where((arr > 0) & (arr < MIN_SPEED), MIN_SPEED, arr)
        low, top = max(low, MIN_SPEED), max(top, MIN_SPEED)
    # one compiled flavour of the kernels (see _readonly)
    return _kernels._readonly(arr), (float(low), float(top))


def fast_marching(
    speed: Any,
    sources: Any,
    *,
    spacing: float | Sequence[float] = 1.0,
    order: int = 2,
    stop_at: Any = None,
    source_ball: bool = True,
    wind: Any = None,
    threads: int | None = None,
) -> np.ndarray:
    """Arrival times of a wave started at ``sources`` over a speed field.

    Solves the eikonal equation ``|grad T| * speed = 1`` on a node-centred grid
    with the Fast Marching Method (Sethian 1996), upwind first- or second-order.
    With a non-zero ``wind``, solves ``speed |grad T| + wind . grad T = 1``
    instead (a vehicle flying at airspeed ``speed`` in the wind; see
    :func:`fm2uav.eikonal.wind.zermelo_march`, which also gives the ground
    tracks and the times *to* the sources).

    Parameters
    ----------
    speed : array_like, shape (nx, ny) or (nx, ny, nz)
        Propagation speed at each node [m/s], ``>= 0``; 0 marks impassable nodes.
        Indexed x first.
    sources : sequence of int tuples or (m, ndim) int array
        Grid indices where ``T = 0``. Each must have speed > 0. Around point
        sources (at most 64), nodes within ``max(2 cells, 5 % of the grid
        extent)`` get accurate times before the march (the straight-ray time for
        a constant speed, the factored eikonal equation solved on the ball's box
        for a varying one), which keeps the order-2 scheme second-order. The
        ball needs a positive speed varying by at most 1.5x in its box; where
        that fails, it is halved down to 2 cells until it holds.
    spacing : float or sequence of float, optional
        Node spacing [m], one value or one per axis. Default 1.
    order : {1, 2}, optional
        Finite-difference order of the upwind stencil. Order 2 is used where two
        frozen upwind neighbours allow it, order 1 elsewhere. Default 2.
    stop_at : sequence of int tuples, optional
        Stop as soon as all these nodes are frozen. Nodes not frozen by then are
        returned as ``inf``.
    source_ball : bool, optional
        Initialise the ball around point sources (default True).
        The ball is skipped automatically where the speed near a source is not
        smooth (max/min > 1.5 in its box); False disables it everywhere.
    wind : array_like, shape (ndim,) or (nx, ny[, nz], ndim), optional
        Wind [m/s] (x component first), constant or per node, in the units of
        ``speed`` (then the airspeed). None or zero everywhere: the isotropic
        march above, bit for bit. Otherwise the wind march of
        :mod:`fm2uav.eikonal.wind`; nodes where ``|wind| >= speed`` are refused
        (impassable, ``inf``).
    threads : int, optional
        Threads the march may use (``>= 1``). None (default): the environment
        variable ``FM2UAV_THREADS`` if set, else every core this process may run
        on. With 2 or more, a grid of at least ``PARALLEL_MIN_NODES`` (1 M) nodes
        marches slabs of the grid in parallel, order 1 and 2 (order 2 from
        ``ORDER2_MIN_NODES_2D``, 4.2 M, and ``_3D``, 4 M), ``stop_at`` included
        (:mod:`fm2uav.eikonal._parallel`; order 1's times equal the serial march's
        to round-off, order 2's bit for bit on every case measured); the wind march
        and smaller grids march on one thread.

    Returns
    -------
    ndarray of float64, same shape as ``speed``
        Arrival time [s]; ``inf`` where unreachable (or not reached before stop).
        Results of 4 MiB to 256 MiB are written into pages that an earlier result,
        no longer referenced (nor any view of it), left behind: up to four such
        buffers stay with the process (``_kernels.result_array``; a fresh array's
        page faults cost up to a third of a 2048^2 march, docs/performance.md).

    Raises
    ------
    fm2uav.InputError
        Bad shape, dtype, negative/non-finite speed, spacing <= 0, order not
        1/2, source/stop index outside the grid, a source with speed 0, a wind
        of the wrong shape or not finite, a source where the wind is at
        least the airspeed, or ``threads`` (or ``FM2UAV_THREADS``) not an
        integer >= 1.

    Examples
    --------
    >>> import numpy as np
    >>> T = fast_marching(np.ones((5, 5)), [(0, 0)], order=1)
    >>> float(T[4, 0])
    4.0
    """
    nthreads = _parallel.resolve_threads(threads)
    v, span = _as_speed_span(speed, nthreads)
    shape = v.shape
    if wind is not None:
        is_calm, wind_march = _WIND_MARCH[0]
        if not is_calm(wind, shape):
            return wind_march(v, sources, wind, spacing=spacing, order=order, stop_at=stop_at,
                              source_ball=source_ball)
    h = as_spacing(spacing, v.ndim)
    if isinstance(order, bool) or not isinstance(order, (int, np.integer)) or order not in (1, 2):
        shown = order.item() if isinstance(order, np.generic) else order
        raise InputError(f"order must be 1 or 2, got {shown!r}")
    src = as_index_array(sources, shape, "sources")
    blocked = v[tuple(src.T)] <= 0
    if np.any(blocked):
        raise InputError(
            f"source {src[blocked][0].tolist()} has speed 0 (impassable); "
            "move the source to a node with speed > 0"
        )

    shape3 = shape + (1,) * (3 - v.ndim)
    h3 = h + (1.0,) * (3 - v.ndim)
    src3 = np.zeros((src.shape[0], 3), dtype=np.int64)
    src3[:, : v.ndim] = src

    flat_speed = v.reshape(-1)
    extent = max((n - 1) * hk for n, hk in zip(shape, h))
    radius = max(SOURCE_INIT_CELLS * max(h), SOURCE_INIT_FRACTION * extent)
    if src.shape[0] > MAX_BALL_SOURCES or not source_ball:
        radius = 0.0
    start, init = _source_box(v, src3, shape3, h3, radius, SOURCE_INIT_CELLS * max(h))
    if (radius > 0 and stop_at is None and nthreads > 1
            and _parallel.on_slabs(flat_speed.size, shape3[2] > 1, order)):
        # the slab march places its cuts from the sources while the balls are computed on
        # another core (on 2048^2 smooth speed the factored ball takes ~10 ms, the cuts ~4)
        ready = _in_background(init)
        return run_march(flat_speed, start, shape, h3, order, stop_at, threads=nthreads,
                         span=span, ready=ready, sources=src3)
    init()
    return run_march(flat_speed, start, shape, h3, order, stop_at, threads=nthreads, span=span)


def _in_background(fn) -> Any:
    """Run ``fn()`` on a new thread; returns the call that waits for it (and raises what it
    raised), whose ``running()`` says whether ``fn`` still runs. ``fn`` must release the GIL
    to run beside the caller (compiled, ``nogil``)."""
    failed: list[BaseException] = []

    def run() -> None:
        try:
            fn()
        except BaseException as exc:  # noqa: BLE001 - re-raised by ready()
            failed.append(exc)

    worker = threading.Thread(target=run, name="fm2uav-source-balls", daemon=True)
    worker.start()

    def ready() -> None:
        worker.join()
        if failed:
            raise failed[0]

    ready.running = worker.is_alive  # type: ignore[attr-defined]  # still computing?
    return ready


def _source_start(v: np.ndarray, src3: np.ndarray, shape3: tuple[int, ...],
                  h3: tuple[float, float, float], radius: float,
                  min_radius: float) -> _kernels.Start:
    """The march's start: the sources and their balls, on the box that holds them all.

    The source ball (exact straight-ray times for a constant speed, the factored
    eikonal equation on the ball's box otherwise, docs/eikonal.md) is computed on
    a copy of that box only, so a single source costs memory for its ball, not
    for the grid.
    """
    start, init = _source_box(v, src3, shape3, h3, radius, min_radius)
    init()
    return start


def _source_box(v: np.ndarray, src3: np.ndarray, shape3: tuple[int, ...],
                h3: tuple[float, float, float], radius: float,
                min_radius: float) -> tuple[_kernels.Start, Any]:
    """:func:`_source_start` in two steps: the start's box (its times ``inf``, its states
    0) and the call that writes the sources and their balls into it
    (:func:`fm2uav.eikonal._sources.init_sources`, which releases the GIL)."""
    reach = np.zeros(3, dtype=np.int64)
    if radius > 0:
        reach[:] = [int(np.floor(radius / hk)) for hk in h3]
        if shape3[2] == 1:
            reach[2] = 0
    dims = np.asarray(shape3)
    lo = np.maximum(src3.min(axis=0) - reach, 0)
    hi = np.minimum(src3.max(axis=0) + reach, dims - 1) + 1
    box = tuple(slice(a, b) for a, b in zip(lo, hi))
    bshape = tuple(int(n) for n in hi - lo)
    if bshape == tuple(shape3):  # sources all over the grid: no copy
        speed_box = v.reshape(-1)
    else:
        speed_box = np.ascontiguousarray(v.reshape(shape3)[box]).reshape(-1)
    T = np.full(speed_box.size, np.inf)
    state = np.zeros(speed_box.size, dtype=np.uint8)
    args = (_kernels._readonly(speed_box), T, state, *bshape, *h3, src3 - lo, radius,
            min_radius, BALL_MAX_SPEED_RATIO)

    def init() -> None:
        _sources.init_sources(*args)

    return _kernels.Start(tuple(int(a) for a in lo), bshape, T, state), init


def run_march(
    flat_speed: np.ndarray,
    start: _kernels.Start,
    shape: tuple[int, ...],
    h3: tuple[float, float, float],
    order: int,
    stop_at: Any,
    threads: int = 1,
    span: tuple[float, float] | None = None,
    ready: Any = None,
    sources: np.ndarray | None = None,
) -> np.ndarray:
    """March from the frozen/band nodes of ``start`` (a :class:`~fm2uav.eikonal._kernels.Start`).

    Shared by :func:`fast_marching` and :func:`fm2uav.eikonal.restart.remarch`:
    nodes frozen on entry (state 2) are expanded first, band nodes (state 1)
    carry tentative times. ``stop_at`` as in :func:`fast_marching`; ``threads``
    (resolved, ``>= 1``) as there: the parallel march on grids of at least
    :data:`~fm2uav.eikonal._tuning.PARALLEL_MIN_NODES` nodes when ``threads > 1`` (order 2
    while :data:`~fm2uav.eikonal._tuning.ORDER2` is set, the default; from
    :data:`~fm2uav.eikonal._tuning.ORDER2_MIN_NODES_2D` / ``_3D`` nodes:
    :func:`~fm2uav.eikonal._parallel.on_slabs`), else the serial one,
    which sets up on them (:func:`~fm2uav.eikonal._kernels.march`). ``span``: the
    smallest positive and the largest speed [m/s] if the caller knows them (the plateau
    test and the parallel march's first window then need no pass over the speeds).
    ``ready``, ``sources``: ``start``'s arrays still being written, and the source nodes
    (:func:`fm2uav.eikonal._parallel.march`); the slab march waits for them after placing
    its cuts, the others at once.

    Returns
    -------
    ndarray
        Arrival times, shape ``shape``.
    """
    shape3 = shape + (1,) * (3 - len(shape))
    slabs = threads > 1 and _parallel.on_slabs(flat_speed.size, shape3[2] > 1, order)
    if ready is not None and (stop_at is not None or not slabs):
        ready()
        ready = None
    stops = np.zeros((0, 3), dtype=np.int64)
    if stop_at is not None:
        idx = as_index_array(stop_at, shape, "stop_at")
        stops = np.zeros((idx.shape[0], 3), dtype=np.int64)
        stops[:, : len(shape)] = idx
        if start.frozen_at(stops).all():  # every stop node is a source or in its ball
            return start.frozen_times(shape3).reshape(shape)
    if slabs:
        T, _ = _parallel.march(flat_speed, start, shape3, h3, threads,
                               stops[~start.frozen_at(stops)], order=order, span=span,
                               ready=ready, sources=sources)
    else:
        T, _ = _kernels.march(flat_speed, start, shape3, h3, order, stops, threads=threads,
                              span=span)
    return T.reshape(shape)
