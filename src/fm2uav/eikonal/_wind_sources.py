"""Point-source initialisation of the wind march (the source ball).

Private module of :func:`fm2uav.eikonal.wind.zermelo_march`; the isotropic
counterpart is :mod:`._sources` and the reasons are the same (docs/eikonal.md):
near a point source the arrival time is a cone whose gradient jumps at the
source, so the stencil's error there is O(h) and the march carries it
everywhere. Accurate times in a ball of fixed physical radius around each
source, frozen before the march, keep the order of the scheme.

What the ball holds
-------------------
* **Constant speed and wind** in the source's box: the exact time
  ``F(x - x_s)``, the ``t`` of ``|x - x_s - w t| = V t`` (bit for bit the
  closed form of :func:`fm2uav.eikonal.wind.zermelo_time`).
* **Varying speed or wind**: the *additively factored* equation marched on the
  box alone with the same stencil: ``T = T0 + tau`` with ``T0(x) = F_s(x -
  x_s)`` the source's constant-wind cone, so that in each full-face solve the
  vertex values are replaced by ``tau`` (smooth where ``T`` is not) plus
  ``T0(y)``, and the gradient by ``grad T0(y) + grad tau``. Vertex and edge
  candidates stay unfactored (they only win on a face side, where they equal
  the face's value).

Which sources, which radius (as the isotropic ball): the nominal radius is
``R = max(2 cells, 5 % of the grid's largest extent)``; a source's box is
*clean* when every node in it is passable (speed > 0, ``|w| < V``), its speeds
vary by at most ``BALL_MAX_SPEED_RATIO`` (max/min) and its winds differ from
the source's by at most ``BALL_MAX_WIND_CHANGE`` times the box's lowest speed.
Each source takes the largest of ``R, R/2, ...`` (last try: 2 cells) whose box
is clean, else no ball. Ball nodes (distance ``<= r``) keep the smallest time
over the sources; they are frozen when every source is clean, else they start
in the narrow band.
"""

from __future__ import annotations

import numpy as np

from . import _wind_march as wm

#: A ball's box is clean only if its speeds vary by at most this factor ...
BALL_MAX_SPEED_RATIO = 1.5
#: ... and its winds differ from the source's by at most this share of its
#: lowest speed.
BALL_MAX_WIND_CHANGE = 0.5


def _clean(speed: np.ndarray, wind: np.ndarray, ok: np.ndarray, ws: np.ndarray) -> bool:
    if not ok.all():
        return False
    vmin = float(speed.min())
    if float(speed.max()) > BALL_MAX_SPEED_RATIO * vmin:
        return False
    dw2 = np.einsum("...i,...i->...", wind - ws, wind - ws)
    return float(dw2.max()) <= (BALL_MAX_WIND_CHANGE * vmin) ** 2


def cone(dx: np.ndarray, dy: np.ndarray, dz: np.ndarray, V: float,
         w: np.ndarray) -> np.ndarray:
    """Constant-wind time [s] of the displacements ``(dx, dy, dz)`` [m] (vectorised).

    The same operations as :func:`fm2uav.eikonal._wind_kernels.zermelo_time`.
    """
    wd = w[0] * dx + w[1] * dy + w[2] * dz
    dd = dx * dx + dy * dy + dz * dz
    lam = V * V - (w[0] * w[0] + w[1] * w[1] + w[2] * w[2])
    root = np.sqrt(wd * wd + lam * dd)
    s = root + wd
    with np.errstate(divide="ignore", invalid="ignore"):
        down = np.where(s > 0, dd / np.where(s > 0, s, 1.0), 0.0)
        up = (root - wd) / lam
    return np.where(wd >= 0, down, up)


def _one_source(grid: wm.WindGrid, src: np.ndarray, radius: float, min_radius: float,
                order: int) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
    """Ball of one source: (flat indices, times, ground tracks) of its nodes, or
    None if not clean."""
    shape = grid.shape3
    h = np.asarray(grid.h3)
    speed = grid.speed.reshape(shape)
    ok = grid.passable.reshape(shape)
    s_flat = int(np.ravel_multi_index(tuple(src), shape))
    ws = grid.wind[0 if grid.wconst else s_flat]
    Vs = float(grid.speed[s_flat])
    r = radius
    while True:
        reach = np.floor(r / h).astype(np.int64)
        if grid.ndim == 2:
            reach[2] = 0
        lo = np.maximum(src - reach, 0)
        hi = np.minimum(src + reach, np.asarray(shape) - 1) + 1
        box = tuple(slice(a, b) for a, b in zip(lo, hi))
        wbox = (np.broadcast_to(ws, tuple(hi - lo) + (3,)) if grid.wconst
                else grid.wind.reshape(shape + (3,))[box])
        if _clean(speed[box], wbox, ok[box], ws):
            break
        if r <= min_radius:
            return None
        r = max(r / 2, min_radius)
    bshape = tuple(int(n) for n in hi - lo)
    axes = [(np.arange(n) - (s - a)) * hk for n, s, a, hk in zip(bshape, src, lo, h)]
    dx, dy, dz = np.meshgrid(*axes, indexing="ij")  # [m] from the source
    xs = (src - lo) * h
    inside = np.sqrt(dx * dx + dy * dy + dz * dz) <= r
    vbox = speed[box]
    if np.all(vbox == Vs) and np.all(wbox == ws):
        times = cone(dx, dy, dz, Vs, ws)
        track = np.stack([dx, dy, dz], axis=-1)  # straight lines from the source
    else:
        sub = wm.WindGrid(
            np.ascontiguousarray(vbox).reshape(-1),
            np.ascontiguousarray(wbox).reshape(-1, 3), False,
            np.ones(vbox.size, dtype=bool), bshape, grid.ndim, grid.h3)
        src_local = int(np.ravel_multi_index(tuple(src - lo), bshape))
        res = wm.run(sub, np.array([src_local]), np.zeros(1), np.ones(1, dtype=bool), order,
                     want_track=True, factor=(xs, Vs, np.asarray(ws, dtype=float)))
        times = res.times.reshape(bshape)
        track = res.track.reshape(bshape + (3,))
        inside &= np.isfinite(times)
    local = np.argwhere(inside)
    flat = np.ravel_multi_index(tuple((local + lo).T), shape)
    return flat, times[inside], track[inside]


def ball_start(grid: wm.WindGrid, sources: np.ndarray, radius: float, min_radius: float,
               order: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Start nodes of the march: ``(flat indices, times [s], frozen for good,
    ground tracks (m, 3), zero at the sources)``.

    ``sources`` (m, 3) grid indices (z = 0 in 2D); ``radius`` 0 for none.
    """
    src_flat = np.unique(np.ravel_multi_index(tuple(sources.T), grid.shape3))
    idx = [src_flat]
    t = [np.zeros(src_flat.size)]
    trk = [np.zeros((src_flat.size, 3))]
    all_clean = True
    if radius > 0:
        for s in sources:
            ball = _one_source(grid, s, radius, min_radius, order)
            if ball is None:
                all_clean = False
                continue
            idx.append(ball[0])
            t.append(ball[1])
            trk.append(ball[2])
    idx_a = np.concatenate(idx).astype(np.int64)
    t_a = np.concatenate(t)
    trk_a = np.concatenate(trk)
    order_ = np.lexsort((t_a, idx_a))  # per node, the smallest time first
    idx_a, t_a, trk_a = idx_a[order_], t_a[order_], trk_a[order_]
    first = np.ones(idx_a.size, dtype=bool)
    first[1:] = idx_a[1:] != idx_a[:-1]
    idx_a, t_a, trk_a = idx_a[first], t_a[first], trk_a[first]
    fixed = np.full(idx_a.size, all_clean)
    fixed[np.isin(idx_a, src_flat)] = True
    trk_a[t_a == 0] = 0.0
    return idx_a, t_a, fixed, trk_a
