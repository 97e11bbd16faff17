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
  ``T0(y)``: in the semi-Lagrangian form the same minimum with the factored
  vertex values and the travel time shifted by the linear term, ``F(v) -
  grad T0(y) . v``, for vertex, edge and face candidates alike (on a constant
  box: ``T0`` to rounding). That shifted metric may be negative where the wind
  differs from the source's, so the box march corrects no labels (a plain
  march; the box is small and near the source).

Which sources, which radius (as the isotropic ball): the nominal radius is
``R = max(2 cells, 5 % of the grid's largest extent)``; a source's box is
*clean* when every node in it is passable (speed > 0, ``|w| < V``) and its
ground speeds, in each of 16 (2D) / 26 (3D) directions, are within
``BALL_MAX_SPEED_RATIO`` of the source's (with no wind: its speeds, as the
isotropic ball; near ``|w| = V`` a small change of the airspeed changes the
upwind ground speed many times over, and the source's cone is then no guide).
Each source takes the largest of ``R, R/2, ...`` (last try: 2 cells) whose box
is clean, else no ball. Ball nodes (distance ``<= r``) keep the smallest time
over the sources; they are frozen when every source is clean, else they start
in the narrow band.
"""

from __future__ import annotations

import numpy as np

from . import _wind_march as wm

#: A ball's box is clean only if, in every direction of :func:`directions`, the
#: ground speed at each of its nodes is within this factor of the source's.
BALL_MAX_SPEED_RATIO = 1.5


def directions(ndim: int) -> np.ndarray:
    """Unit directions (3 components) in which a box's ground speeds are compared:
    16 at 22.5 degrees in 2D, the 26 neighbour directions in 3D."""
    if ndim == 2:
        a = np.arange(16) * (np.pi / 8)
        return np.stack([np.cos(a), np.sin(a), np.zeros(16)], axis=-1)
    d = np.array([(i, j, k) for i in (-1, 0, 1) for j in (-1, 0, 1) for k in (-1, 0, 1)
                  if (i, j, k) != (0, 0, 0)], dtype=float)
    return d / np.linalg.norm(d, axis=1)[:, None]


def ground_speeds(speed: np.ndarray, wind: np.ndarray, dirs: np.ndarray) -> np.ndarray:
    """Ground speed [m/s] along each unit direction (last axis) at airspeed ``speed``
    in ``wind`` (3 components): the ``g`` of ``|g d - w| = V``."""
    wd = wind @ dirs.T
    lam = speed * speed - np.einsum("...i,...i->...", wind, wind)
    return wd + np.sqrt(wd * wd + lam[..., None])


def _clean(speed: np.ndarray, wind: np.ndarray, ok: np.ndarray, Vs: float,
           ws: np.ndarray, ndim: int) -> bool:
    # near |w| = V a small change of V changes the upwind ground speed manifold, so
    # the box is judged on ground speeds (with no wind: on speeds, as the isotropic ball)
    if not ok.all():
        return False
    dirs = directions(ndim)
    g = ground_speeds(speed, wind, dirs)
    gs = ground_speeds(np.asarray(Vs), np.asarray(ws, dtype=float), dirs)
    r = g / gs
    return float(r.max()) <= BALL_MAX_SPEED_RATIO and float(r.min()) >= 1 / BALL_MAX_SPEED_RATIO


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
        if _clean(speed[box], wbox, ok[box], Vs, ws, grid.ndim):
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
