"""Geodesic extraction: descend an arrival-time field from the start to the goal.

The second half of FM²: once ``T = fast_marching(W, goal)`` is known, the
fastest path from any start is the curve of steepest descent of ``T``, which
ends at the goal (where ``T = 0``). :func:`descend` follows it with sub-cell
steps along the Fast Marching upwind (characteristic) directions, smoothed
over about two cells, also inside one-cell bright channels such as a
terrain-following flight level, and falls back to discrete moves where the
gradient is unusable, so it always terminates.

Every call goes prepare (validate, pad 2D to 3D, mark blocked nodes as ``inf``)
→ kernel (compiled, :mod:`fm2uav.planning._geodesic_kernels`) → finalise
(trim to ``ndim`` columns, translate the kernel's status into errors).

The rules of :func:`descend`:

**Direction.** At every node a unit descent direction is taken from the
same stencil the Fast Marching Method solves: per axis, where ``T`` is
monotone through the node, the central difference; where it is not (the
node is a kink of ``T`` along that axis, or next to a blocked node or the
grid's edge), the FMM's upwind choice: the one-sided difference towards the
smaller neighbour, or 0 if no neighbour is smaller. So on a one-cell bright
layer (a terrain-following flight level) a layer node points along the
layer, not across it. These unit vectors are blended with cubic B-spline
weights over the 4 x 4 x 4 nodes around the point (free nodes only; on
axes coarser than the finest, partly linear weights so the smoothing is
isotropic in metres). The blend is a C2 field averaging over about two
cells, so the path rounds the staircase of a level over sloping ground
instead of tracing it.

**Step rule.** Each step has physical length ``step * min(spacing)`` [m]
(so at most ``step`` cells on every axis), integrated with the midpoint rule
(RK2). It is accepted if the *potential* at the new point is below the
largest potential of the last 8 accepted points by at least a tenth of the
step's nominal decrease (length times the local slowness ``|grad T|``), the
new point's nearest node is free (not blocked, finite ``T``) and the
straight segment to it enters no blocked node's cell. The potential is
``min(trilinear T, min_c T_c + s_c |p - c|)`` over the corners ``c`` of the
interpolation cell (``s_c`` the upwind slowness at ``c``): the second term
is the one-step eikonal (Hopf-Lax) estimate, which, unlike trilinear ``T``,
does not jump by the dark nodes' times when the point leaves the centre of a
thin bright channel. If a step enters a blocked cell it may slide along
that cell's face (one axis component dropped); otherwise the step is
halved (up to 3 tries), and the tries are repeated with the linear blend
of the node directions, which follows corners tightly. The 8-step window
(non-monotone acceptance, Grippo et al. 1986) with sufficient decrease
lets the path cross the small bumps of the potential in thin channels,
while its maximum strictly decreases every 8 steps, so the path cannot
cycle.

**Fallback and termination.** If no step is accepted (zero gradient,
plateau, noise, obstacle ahead), the path makes discrete steepest-descent
moves: to the free 8-neighbour (2D) / 26-neighbour (3D) of the current
nearest node with the smallest ``T``, strictly below the current node's,
without cutting between obstacles that touch at an edge or corner. It keeps
moving until the node's ``T`` is below the current potential (so the
descent potential keeps decreasing across fallbacks), then resumes
continuous steps. After ``max_steps`` continuous iterations only discrete
moves are made; each strictly lowers the node's ``T``, so the descent ends.
On a fast-marching field a lower axis neighbour exists at every reached node
but the source; where none exists away from the goal, PlanningError is
raised. As soon as the point is within one
cell of the goal on every axis and the straight segment to the goal is free,
the goal is appended exactly and the descent stops.
"""

from __future__ import annotations

from collections.abc import Sequence
import threading
from concurrent.futures import ThreadPoolExecutor
from typing import Any

import numpy as np

from .._validate import grid
from ..eikonal._kernels import _readonly
from ..eikonal.fmm import as_spacing
from ..errors import InputError, PlanningError, PointError, UnreachableError
from . import _geodesic_kernels as _k

__all__ = ["descend", "descend_batch", "descend_stopped", "drop_ties", "reaches_any",
           "nearest_node", "default_max_steps"]


def nearest_node(points: Any) -> np.ndarray:
    """Nearest grid node of continuous index coordinates (ties round up).

    Parameters
    ----------
    points : array_like, shape (..., ndim)
        Continuous index coordinates [cells].

    Returns
    -------
    ndarray of int64, same shape
        ``floor(points + 0.5)``: the node whose cell ``[i - 0.5, i + 0.5)``
        holds each point. This is the rule :func:`descend` uses everywhere.
    """
    return np.floor(np.asarray(points, dtype=float) + 0.5).astype(np.int64)


def default_max_steps(shape: Sequence[int], spacing: Sequence[float], step: float) -> int:
    """Default bound on the number of continuous descent iterations.

    Enough steps of ``step * min(spacing)`` metres to walk a path that visits
    every node once along cell diagonals, i.e. ``n_nodes * |h| / (step * min h)``
    (plus a small constant). A real geodesic is far shorter; the bound only
    matters for pathological fields, after which :func:`descend` switches to
    pure discrete descent.
    """
    h = np.asarray(spacing, dtype=float)
    n_nodes = int(np.prod(shape))
    return int(np.ceil(n_nodes * float(np.linalg.norm(h)) / (step * float(h.min())))) + 100


def _as_field(T: Any) -> np.ndarray:
    arr = grid(T, "T", holding=" of arrival times")
    bad = _k.first_invalid_time(_readonly(np.ascontiguousarray(arr).reshape(-1)))
    if bad >= 0:
        where = [int(w) for w in np.unravel_index(bad, arr.shape)]
        raise InputError(
            f"T must hold arrival times (finite, or +inf where unreached); "
            f"found {arr[tuple(where)]} at index {where}"
        )
    return arr


def _as_point(p: Any, shape: tuple[int, ...], what: str) -> np.ndarray:
    ndim = len(shape)
    try:
        arr = np.asarray(p, dtype=float).reshape(-1)
    except (TypeError, ValueError):
        raise InputError(f"{what} must be {ndim} numbers (index coordinates), got {p!r}") from None
    if arr.size != ndim:
        raise InputError(
            f"{what} must have {ndim} coordinates (the field is {ndim}D), got {arr.size}: {p!r}"
        )
    if not np.all(np.isfinite(arr)):
        raise InputError(f"{what} must be finite, got {arr.tolist()}")
    upper = np.asarray(shape, dtype=float) - 1.0
    tol = 1e-9
    if np.any(arr < -tol) or np.any(arr > upper + tol):
        raise PointError(
            f"{what} {arr.tolist()} (index coordinates) lies outside the grid, whose "
            f"coordinates run from 0 to {upper.tolist()} on each axis; move it inside the map"
        )
    return np.clip(arr, 0.0, upper)


def _check_step(step: float, max_steps: int | None, shape: tuple[int, ...], h: Any
                ) -> tuple[float, int]:
    """``step`` [cells] in (0, 1] and ``max_steps`` (default :func:`default_max_steps`) checked."""
    step = float(step)
    if not (np.isfinite(step) and 0.0 < step <= 1.0):
        raise InputError(f"step must be in (0, 1] cells, got {step!r}")
    if max_steps is None:
        max_steps = default_max_steps(shape, h, step)
    elif (
        isinstance(max_steps, bool)
        or not isinstance(max_steps, (int, np.integer))
        or max_steps < 0
    ):
        raise InputError(f"max_steps must be a non-negative integer or None, got {max_steps!r}")
    return step, max_steps


def _with_blocked(field: np.ndarray, blocked: Any) -> tuple[np.ndarray, np.ndarray | None]:
    """``field`` with ``inf`` on the blocked nodes (a copy if any), and the checked bool mask."""
    if blocked is None:
        return field, None
    shape = field.shape
    mask = np.asarray(blocked)
    if mask.dtype != bool and mask.dtype.kind not in "iu":
        raise InputError(f"blocked must be a boolean array, got dtype {mask.dtype}")
    if mask.shape != shape:
        raise InputError(
            f"blocked has shape {mask.shape} but T has shape {shape}; they must match"
        )
    mask = mask.astype(bool, copy=False)
    if mask.any():
        field = field.copy()
        field[mask] = np.inf
    return field, mask


def _refuse_blocked(mask: np.ndarray | None, node: tuple[int, ...], p: np.ndarray, what: str
                    ) -> None:
    """PointError when the ``what`` point ``p`` [m] has its nearest ``node`` blocked."""
    if mask is not None and mask[node]:
        raise PointError(
            f"{what} {p.tolist()} lies in blocked node {list(node)}; move the {what} to free space"
        )


def _check_goal(field: np.ndarray, mask: np.ndarray | None, g: np.ndarray) -> tuple[int, ...]:
    """Refuse a goal that is blocked or not the source of ``field``; its nearest node."""
    shape = field.shape
    gn = tuple(nearest_node(g).tolist())
    _refuse_blocked(mask, gn, g, "goal")
    if not np.isfinite(field[gn]):
        raise PlanningError(
            f"goal {g.tolist()}: its nearest node {list(gn)} has T = inf, so T was not computed "
            "from this goal; compute T with the goal's nearest node as the source"
        )
    t_min = float(field.min())
    if field[gn] > t_min:
        where = np.unravel_index(int(np.argmin(field)), shape)
        raise PlanningError(
            f"goal {g.tolist()}: T at its nearest node {list(gn)} is {field[gn]:g}, but T is "
            f"lower ({t_min:g}) at node {[int(i) for i in where]}, so T was not computed from "
            "this goal; compute T with the goal's nearest node as the source"
        )
    return gn


def _check_start(field: np.ndarray, mask: np.ndarray | None, s: np.ndarray, g: np.ndarray
                 ) -> None:
    """Refuse a blocked or unreached start."""
    sn = tuple(nearest_node(s).tolist())
    _refuse_blocked(mask, sn, s, "start")
    if not np.isfinite(field[sn]):
        raise UnreachableError(
            f"start {s.tolist()} cannot reach the goal {g.tolist()}: its nearest node {list(sn)} "
            "was never reached by the wave from the goal (T = inf), so no free connection "
            "joins them; move the start or the goal into the same free region, or clear "
            "(lower the obstacles / raise the speed of) the cells that separate them"
        )


def _check_endpoints(field: np.ndarray, mask: np.ndarray | None, s: np.ndarray, g: np.ndarray
                     ) -> tuple[int, ...]:
    """Refuse a goal that is blocked or not the source of ``field``, or a blocked / unreached
    start; the goal's nearest node."""
    gn = _check_goal(field, mask, g)
    _check_start(field, mask, s, g)
    return gn


def _run(field: np.ndarray, field3: np.ndarray, h3: tuple[float, ...], s: np.ndarray,
         g: np.ndarray, gn: tuple[int, ...], step: float, max_steps: int) -> np.ndarray:
    """The kernel's descent from ``s`` to ``g`` on the prepared (3D-padded) field; the path in
    index coordinates of ``field``'s dimension, ends exact."""
    ndim = field.ndim
    pad = 3 - ndim
    s3 = np.concatenate([s, np.zeros(pad)])
    g3 = np.concatenate([g, np.zeros(pad)])
    path, status, info, _ = _k.descend_kernel(field3, s3, g3, *h3, step, int(max_steps))
    if status != _k.OK:
        raise _stuck_error(field, s, g, gn, info)
    path = np.ascontiguousarray(path[:, :ndim])
    path[0] = s
    path[-1] = g
    return path


def _stuck_error(field: np.ndarray, s: np.ndarray, g: np.ndarray, gn: tuple[int, ...],
                 info: np.ndarray) -> PlanningError:
    """The error of a descent from ``s`` stuck at node ``info`` (the kernel's ``STUCK``)."""
    node = info[:field.ndim].tolist()
    return PlanningError(
        f"descent from start {s.tolist()} stuck at node {node} (T = {field[tuple(node)]:g}), "
        f"which has no free neighbour with smaller T and is not next to the goal "
        f"{g.tolist()}; T must be the arrival times of a wave started at the goal's "
        f"nearest node {list(gn)} (e.g. fast_marching(speed, [goal_node]))"
    )


def _plain_starts(starts: Sequence[Any], shape: tuple[int, ...]) -> tuple[np.ndarray, np.ndarray]:
    """``starts`` as an ``(n, ndim)`` array, clipped into the grid as :func:`_as_point`
    clips one, and a bool per start: True where :func:`_as_point` would accept it (the
    others, False, are left to it, for its error)."""
    n, ndim = len(starts), len(shape)
    try:
        arr = np.asarray(starts, dtype=float)
    except (TypeError, ValueError):
        arr = None
    if arr is None or arr.shape != (n, ndim):
        return np.zeros((n, ndim)), np.zeros(n, dtype=bool)
    upper = np.asarray(shape, dtype=float) - 1.0
    ok = np.all(np.isfinite(arr) & (arr >= -1e-9) & (arr <= upper + 1e-9), axis=1)
    return np.clip(arr, 0.0, upper), ok


def _starts_free(field: np.ndarray, mask: np.ndarray | None, pts: np.ndarray) -> np.ndarray:
    """Per start (index coordinates inside the grid): its nearest node is not blocked and
    was reached (what :func:`_check_start` checks)."""
    at = tuple(np.clip(nearest_node(pts), 0, np.asarray(field.shape) - 1).T)
    free = np.isfinite(field[at])
    if mask is not None:
        free &= ~mask[at]
    return free


def _padded(field: np.ndarray, h: Sequence[float]) -> tuple[np.ndarray, tuple[float, ...]]:
    pad = 3 - field.ndim
    field3 = np.ascontiguousarray(field.reshape(field.shape + (1,) * pad))
    return field3, tuple(h) + (min(h),) * pad  # keeps min(spacing) of the real axes


def descend(
    T: Any,
    start: Any,
    goal: Any,
    *,
    spacing: float | Sequence[float] = 1.0,
    blocked: Any = None,
    step: float = 0.5,
    max_steps: int | None = None,
) -> np.ndarray:
    """Path of steepest descent of an arrival-time field, from ``start`` to ``goal``.

    The path follows ``-grad T`` (the physical gradient, ``dT/dx_k = dT/di_k / h_k``)
    with sub-cell steps, and ends exactly at ``goal``.

    The direction, step and fallback rules are in the module docstring
    (sections *Direction*, *Step rule*, *Fallback and termination*).

    Parameters
    ----------
    T : array_like, shape (nx, ny) or (nx, ny, nz)
        Arrival times [s] of a wave started at the nearest node of ``goal``
        (``T = 0`` there); ``inf`` where unreached or impassable. Indexed x first.
    start, goal : sequence of float, length ndim
        Continuous index coordinates [cells] (node ``i`` sits at ``i``); may be
        off-grid, e.g. ``(3.2, 7.9, 4.0)``. Must lie inside the grid
        (``0 <= p_k <= n_k - 1``; up to 1e-9 cell outside is clipped in).
    spacing : float or sequence of float, optional
        Node spacing [m], one value or one per axis. Default 1.
    blocked : array_like of bool, same shape as ``T``, optional
        True marks obstacle nodes. No path point, and no segment between two
        path points, enters the cell of a blocked node or of a node with
        ``T = inf``.
    step : float, optional
        Step length in cells of the finest axis, ``0 < step <= 1``; each step is
        ``step * min(spacing)`` metres. Default 0.5.
    max_steps : int, optional
        Bound on the continuous iterations (accepted steps and fallbacks) before
        switching to pure discrete descent; 0 gives a purely discrete path.
        Default :func:`default_max_steps` (grid-size based, generous).

    Returns
    -------
    ndarray of float64, shape (N, ndim)
        Path points in continuous index coordinates [cells]. ``path[0]`` equals
        ``start`` and ``path[-1]`` equals ``goal`` exactly; consecutive points
        are distinct, so ``start == goal`` gives a single point (``N == 1``).
        Convert to metres with ``origin + path * spacing``.

    Raises
    ------
    fm2uav.InputError
        Bad shapes or dtypes, NaN in ``T``, ``step`` outside (0, 1], negative
        ``max_steps``, wrong number of coordinates.
    fm2uav.PlanningError
        ``start`` or ``goal`` outside the grid or inside a blocked node; ``T``
        not minimal (or ``inf``) at the goal's nearest node; the descent hit a
        local minimum of ``T`` away from the goal (``T`` has a second source).
    fm2uav.UnreachableError
        The start's nearest node has ``T = inf``: the wave from the goal never
        reached it, so no path connects them.

    Examples
    --------
    >>> import numpy as np
    >>> from fm2uav.eikonal import fast_marching
    >>> T = fast_marching(np.ones((11, 11)), [(10, 5)])
    >>> path = descend(T, (0.0, 5.0), (10.0, 5.0))
    >>> path[0].tolist(), path[-1].tolist()
    ([0.0, 5.0], [10.0, 5.0])
    """
    field = _as_field(T)
    shape = field.shape
    ndim = field.ndim
    h = as_spacing(spacing, ndim)
    step, max_steps = _check_step(step, max_steps, shape, h)
    s = _as_point(start, shape, "start")
    g = _as_point(goal, shape, "goal")
    field, mask = _with_blocked(field, blocked)
    gn = _check_endpoints(field, mask, s, g)
    field3, h3 = _padded(field, h)
    return _run(field, field3, h3, s, g, gn, step, max_steps)


def descend_batch(
    T: Any,
    starts: Sequence[Any],
    goal: Any,
    *,
    spacing: float | Sequence[float] = 1.0,
    blocked: Any = None,
    step: float = 0.5,
    max_steps: int | None = None,
) -> list[np.ndarray]:
    """:func:`descend` from each of ``starts`` to one ``goal``, the field checked once.

    The same paths as one :func:`descend` per start; ``T`` and ``blocked`` are checked
    and prepared once (a per-call check scans the whole field), each start on its own.

    Returns
    -------
    list of ndarray
        One path (N, ndim) per start, in index coordinates.

    Raises
    ------
    As :func:`descend`, for the first start that fails.
    """
    field = _as_field(T)
    shape = field.shape
    h = as_spacing(spacing, field.ndim)
    step, max_steps = _check_step(step, max_steps, shape, h)
    g = _as_point(goal, shape, "goal")
    field, mask = _with_blocked(field, blocked)
    gn = _check_goal(field, mask, g)
    field3, h3 = _padded(field, h)
    out = []
    for start in starts:
        s = _as_point(start, shape, "start")
        _check_start(field, mask, s, g)
        out.append(_run(field, field3, h3, s, g, gn, step, max_steps))
    return out


def drop_ties(T: np.ndarray, node: tuple[int, ...]) -> np.ndarray:
    """``inf``, in place, on every node whose time equals ``T[node]``, except ``node``.

    A march stopped as soon as ``node`` froze (``fast_marching(..., stop_at=[node])``)
    has frozen the nodes of a smaller time, and, of the nodes of exactly the same time,
    whichever its queue popped first (ties in any order). Dropping those ties makes the
    field the start ``node`` descends a function of the times alone, so that
    :func:`descend_stopped` can rebuild it from a whole march (what :func:`fm2uav.plan`
    and :func:`fm2uav.planning.many.plan_many` share).

    Parameters
    ----------
    T : ndarray
        Arrival times [s] of a march stopped at ``node`` (written in place).
    node : tuple of int
        The stop node.

    Returns
    -------
    ndarray
        ``T`` itself.
    """
    t = T[node]
    if np.isfinite(t):
        if T.flags.c_contiguous:  # one compiled pass, no map-sized mask
            _k.drop_equal(T.reshape(-1), np.ravel_multi_index(node, T.shape),
                                         float(t))
        else:
            ties = T == t
            if np.count_nonzero(ties) > 1:
                T[ties] = np.inf
                T[node] = t
    return T


def reaches_any(T: np.ndarray, mask: np.ndarray) -> bool:
    """Whether a node where ``mask`` is True has a finite time in ``T`` (same shapes).

    ``np.isfinite(T[mask]).any()`` without the copy of the masked times.
    """
    if T.flags.c_contiguous and mask.flags.c_contiguous and T.dtype == np.float64:
        return bool(_k.any_finite_on(_readonly(T.reshape(-1)), _readonly(mask.reshape(-1))))
    return bool(np.isfinite(T[mask]).any())


def _sorted_nodes(values: np.ndarray, where: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Flat indices of the nodes ``where`` is True, sorted by ``values``, and their values."""
    idx = np.flatnonzero(where)
    v = values[idx]
    order = np.argsort(v, kind="stable")
    return idx[order], v[order]


#: Starts per call of ``descend_stopped``'s ``on_done``.
_BATCH = 256


def descend_stopped(
    T: Any,
    starts: Sequence[Any],
    goal: Any,
    *,
    frozen: Any,
    spacing: float | Sequence[float] = 1.0,
    blocked: Any = None,
    step: float = 0.5,
    max_steps: int | None = None,
    threads: int = 1,
    on_done: Any = None,
) -> list[np.ndarray | Exception]:
    """Descents of one whole march from many starts, each as a march stopped there sees it.

    :func:`fm2uav.plan` marches from the goal only until the start freezes
    (``stop_at``) and descends that field: nodes later than the start are ``inf``
    there, which the descent reads (the smoothing blends free nodes only). This gives
    every start exactly that field, rebuilt from one march to the end: the nodes frozen
    before the march (``frozen``, the source ball), and of the others those earlier than
    the start; the start's ties dropped on both sides (:func:`drop_ties`). So each path
    equals :func:`descend` of ``drop_ties(fast_marching(..., stop_at=[start]))``, element
    for element, at the cost of one march and one descent per start.

    Starts are taken from the latest to the earliest, each thread on its own copy of the
    field, which it makes ``inf`` from the top as the starts get earlier (one sort of the
    nodes, no copy per start).

    Parameters
    ----------
    T : array_like, shape (nx, ny) or (nx, ny, nz)
        Arrival times [s] of a march from ``goal``'s nearest node, to the end (no stop).
    starts : sequence of array_like
        Start points in index coordinates [cells].
    goal : array_like
        The source in index coordinates [cells].
    frozen : array_like, same shape as ``T``
        The times frozen before the march (``fast_marching(speed, [goal_node],
        stop_at=[goal_node])``: the source and its ball), ``inf`` elsewhere.
    spacing, blocked, step, max_steps
        As :func:`descend`.
    threads : int, optional
        Threads running the descents (the compiled kernel releases the GIL). Default 1.
    on_done : callable, optional
        Called as ``on_done(positions, results)`` in the descending thread after every
        few hundred starts (positions in ``starts``, their entries of the returned list):
        the caller's work on finished paths overlaps the other threads' descents.

    Returns
    -------
    list
        Per start, its path (N, ndim) in index coordinates, or the error :func:`descend`
        would raise for it (:class:`~fm2uav.errors.PointError` outside the grid or in a
        blocked node, :class:`~fm2uav.errors.UnreachableError` never reached,
        :class:`~fm2uav.errors.PlanningError` stuck), as an exception object.

    Raises
    ------
    fm2uav.InputError
        Bad ``T``, ``frozen``, spacing, step or goal; ``threads`` < 1.
    fm2uav.PlanningError
        ``T`` not a march from the goal (:func:`descend`).
    """
    field = _as_field(T)
    shape = field.shape
    h = as_spacing(spacing, field.ndim)
    step, max_steps = _check_step(step, max_steps, shape, h)
    if isinstance(threads, bool) or not isinstance(threads, (int, np.integer)) or threads < 1:
        raise InputError(f"threads must be a positive integer, got {threads!r}")
    ball = np.asarray(frozen, dtype=float)
    if ball.shape != shape:
        raise InputError(f"frozen has shape {ball.shape} but T has shape {shape}; they must match")
    g = _as_point(goal, shape, "goal")
    field, mask = _with_blocked(field, blocked)
    gn = _check_goal(field, mask, g)
    in_ball = np.isfinite(ball)
    if mask is not None:
        in_ball &= ~mask
    flat = field.reshape(-1)
    ball_field = np.where(in_ball, field, np.inf).reshape(-1)
    out: list[Any] = [None] * len(starts)
    pts, ok = _plain_starts(starts, shape)
    ok[ok] = _starts_free(field, mask, pts[ok])
    for k in np.flatnonzero(~ok).tolist():  # one by one, for the error descend raises
        try:
            pts[k] = _as_point(starts[k], shape, "start")
            _check_start(field, mask, pts[k], g)
        except (PlanningError, InputError) as exc:
            out[k] = exc
            continue
        ok[k] = True
    idx = np.flatnonzero(ok)
    nodes = np.ravel_multi_index(tuple(nearest_node(pts[idx]).T), shape)
    times = flat[nodes]
    inside = in_ball.reshape(-1)[nodes]
    starts3 = np.zeros((len(pts), 3))
    starts3[:, :field.ndim] = pts
    g3 = np.zeros(3)
    g3[:field.ndim] = g
    h3 = _padded(field, h)[1]
    shape3 = shape + (1,) * (3 - field.ndim)
    near = idx[inside], nodes[inside], times[inside]
    later = np.argsort(-times[~inside], kind="stable")  # the latest first
    late = idx[~inside][later], nodes[~inside][later], times[~inside][later]
    ball_idx, ball_vals = _sorted_nodes(flat, in_ball.reshape(-1))
    # the nodes outside the ball a march stopped at the earliest start has not frozen
    order, vals = _sorted_nodes(flat, np.isfinite(flat) & ~in_ball.reshape(-1)
                                & (flat >= (late[2][-1] if len(late[2]) else np.inf)))

    stop = threading.Event()

    def run(items: tuple[np.ndarray, np.ndarray, np.ndarray], base: np.ndarray,
            sweep: bool) -> None:
        work = base.copy()
        hi = len(vals)  # vals[hi:] are inf in work
        ks, nds, ts = items
        for a in range(0, len(ks), _BATCH):  # a compiled sweep per batch of starts
            if stop.is_set():  # the caller was interrupted: leave at once
                return
            b = min(a + _BATCH, len(ks))
            path_pts, offsets, status, info, hi = _k.descend_sweep(
                work, shape3, flat, order, vals, hi, ball_idx, ball_vals, ts[a:b], nds[a:b],
                starts3[ks[a:b]], g3, *h3, step, int(max_steps), sweep)
            path_pts = np.ascontiguousarray(path_pts[:, :field.ndim])
            for r, k in enumerate(ks[a:b].tolist()):
                if status[r] == _k.OK:
                    out[k] = path_pts[offsets[r]:offsets[r + 1]]
                else:
                    out[k] = _stuck_error(field, pts[k], g, gn, info[r])
            if on_done is not None:
                done = ks[a:b].tolist()
                on_done(done, [out[k] for k in done])

    if on_done is not None:
        bad = [k for k, r in enumerate(out) if r is not None]  # refused before descending
        if bad:
            on_done(bad, [out[b] for b in bad])
    tasks: list[tuple[tuple[np.ndarray, np.ndarray, np.ndarray], np.ndarray, bool]] = []
    if len(near[0]):
        tasks.append((near, ball_field, False))
    # several chunks per thread, taken as threads free up: the latest starts have the
    # longest paths, so equal shares of the starts are not equal work
    n_late = len(late[0])
    n_chunks = max(1, min(int(threads) * (4 if threads > 1 else 1), n_late))
    for c in range(n_chunks):
        part = slice(c * n_late // n_chunks, (c + 1) * n_late // n_chunks)
        if part.stop > part.start:
            tasks.append((tuple(x[part] for x in late), flat, True))
    if threads == 1 or len(tasks) == 1:
        for task in tasks:
            run(*task)
    else:
        with ThreadPoolExecutor(max_workers=int(threads)) as pool:
            futures = [pool.submit(run, *task) for task in tasks]
            try:
                for f in futures:
                    f.result()
            except BaseException:  # Ctrl-C or a failing on_done: stop the other threads
                stop.set()
                raise
    return out
