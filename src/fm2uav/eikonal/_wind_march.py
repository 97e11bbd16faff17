"""Driver of the compiled wind march: padded state in, arrival times out.

Private module shared by :mod:`.wind` (the whole grid) and :mod:`._wind_sources`
(the factored march on a source's box). Arrays are flat and C-ordered; 2D grids
run as ``(nx, ny, 1)`` with the 8-neighbour stencil, 3D grids with the 26-one
(:func:`fm2uav.eikonal._wind_kernels.stencil`).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from . import _wind_kernels as wk

#: Ghost layers around the grid: the order-2 stencil reads ``y + 2 o``.
PAD = 2


class WindGrid(NamedTuple):
    """A grid ready to march: speeds and winds of every node (unpadded, flat).

    ``speed`` (n,) airspeed [m/s]; ``wind`` (n, 3) or (1, 3) [m/s] (``wconst``:
    the one vector of every node); ``passable`` (n,) bool: speed > 0 and
    ``|w| < V``; ``shape3`` ``(nx, ny, nz)``; ``ndim`` 2 or 3; ``h3`` spacing [m].
    """

    speed: np.ndarray
    wind: np.ndarray
    wconst: bool
    passable: np.ndarray
    shape3: tuple[int, int, int]
    ndim: int
    h3: tuple[float, float, float]


class MarchResult(NamedTuple):
    """Times (n,) [s] (``inf``: not reached, or not final at an early stop),
    the ground-track direction (n, 3) of each node (``None`` unless asked; not
    normalised, zero where unknown), and the march's counters."""

    times: np.ndarray
    track: np.ndarray | None
    pops: int
    reopened: int


def passable(speed: np.ndarray, wind: np.ndarray) -> np.ndarray:
    """Nodes a vehicle may use: airspeed > 0 and wind strictly below it."""
    w2 = np.einsum("ij,ij->i", wind, wind)
    return (speed > 0) & (w2 < speed * speed)


_STENCILS: dict[tuple[int, tuple[float, float, float]], wk.Stencil] = {}


def get_stencil(ndim: int, h3: tuple[float, float, float]) -> wk.Stencil:
    """The stencil of a grid (cached per dimension and spacing)."""
    key = (ndim, h3)
    if key not in _STENCILS:
        _STENCILS[key] = wk.stencil(ndim, h3)
    return _STENCILS[key]


def nonacute(grid: WindGrid) -> np.ndarray:
    """Passable nodes where the stencil is not acute (``|w| / V`` above its bound)."""
    c = get_stencil(grid.ndim, grid.h3).acute
    w2 = np.einsum("ij,ij->i", grid.wind, grid.wind)
    return grid.passable & (w2 > c * c * grid.speed * grid.speed)


def run(grid: WindGrid, start_idx: np.ndarray, start_t: np.ndarray, start_fixed: np.ndarray,
        order: int, stop_idx: np.ndarray | None = None, *, want_track: bool = False,
        factor: tuple[np.ndarray, float, np.ndarray] | None = None,
        start_track: np.ndarray | None = None) -> MarchResult:
    """March ``grid`` from the start nodes.

    Parameters
    ----------
    start_idx, start_t, start_fixed : flat indices, times [s] and whether each
        start node is frozen for good (sources, a frozen ball) or only a band
        node the march may lower.
    order : 1 or 2.
    stop_idx : flat indices of the early-stop nodes, or None for a full march.
        The march stops when all are final; where the stencil is not acute at
        some node (label correction), it runs to the end instead (see
        docs/eikonal.md, "Wind").
    want_track : record each node's ground-track direction (``start_track``
        (m, 3) for the start nodes, zero if None).
    factor : ``(source point [m] (3,), airspeed [m/s], wind (3,) [m/s])`` to march
        the additively factored equation (the source box), or None.
    """
    nx, ny, nz = grid.shape3
    pz = PAD if grid.ndim == 3 else 0
    pshape = (nx + 2 * PAD, ny + 2 * PAD, nz + 2 * pz)
    sy = pshape[2]
    sx = pshape[1] * sy
    T = np.full(pshape, np.nan)
    T[PAD:PAD + nx, PAD:PAD + ny, pz:pz + nz] = np.where(
        grid.passable.reshape(grid.shape3), -np.inf, np.nan)
    T = T.reshape(-1)
    flag = np.zeros(T.size, dtype=np.uint8)

    def padded(idx: np.ndarray) -> np.ndarray:
        i, j, k = np.unravel_index(idx, grid.shape3)
        return (i + PAD) * sx + (j + PAD) * sy + (k + pz)

    st = get_stencil(grid.ndim, grid.h3)
    doff = st.off[:, 0] * sx + st.off[:, 1] * sy + st.off[:, 2]
    uoff = st.off[:, 0] * ny * nz + st.off[:, 1] * nz + st.off[:, 2]
    bdoff = st.boff[:, 0] * sx + st.boff[:, 1] * sy + st.boff[:, 2]
    # unsigned flat offsets (two's complement: index + offset wraps to the right
    # node): numba emits negative-index wraparound code for signed indices
    u64 = np.uint64
    tables = (doff.astype(u64), uoff.astype(u64), st.oph, st.fvert, st.fminv, st.fptr, st.fid,
              st.evert, st.eptr, st.eid, st.bptr, bdoff.astype(u64), st.fbig, st.ebig,
              grid.ndim)

    start_idx = np.asarray(start_idx, dtype=np.int64)
    pidx = padded(start_idx)
    start_t = np.asarray(start_t, dtype=float)
    T[pidx] = np.where(start_fixed, start_t, -start_t)
    flag[pidx[np.asarray(start_fixed, dtype=bool)]] |= wk.FIXED
    order_ = np.lexsort((pidx, start_t))  # a sorted array is a heap (key, padded index)
    cap = max(4096, 2 * start_idx.size)
    hk = np.empty(cap)
    hc = np.empty(cap, dtype=np.uint64)
    hu = np.empty(cap, dtype=np.uint64)
    hn = start_idx.size
    hk[:hn] = start_t[order_]
    hc[:hn] = pidx[order_]
    hu[:hn] = start_idx[order_]
    pos = np.full(T.size, -1, dtype=np.int64)
    pos[hc[:hn]] = np.arange(hn)

    any_na = bool(np.any(nonacute(grid)))
    nstop = 0
    can_stop = False
    if stop_idx is not None and len(stop_idx):
        sp = np.unique(padded(np.asarray(stop_idx, dtype=np.int64)))
        sp = sp[T[sp] == T[sp]]  # impassable stop nodes are never reached
        flag[sp] |= wk.STOP
        nstop = int(sp.size)
        can_stop = nstop > 0 and not any_na
    track = np.zeros((grid.speed.size if want_track else 0, 3))
    if want_track and start_track is not None:
        track[start_idx] = start_track
    if factor is None:
        fsrc, fV, fw, fac = np.zeros(3), 1.0, np.zeros(3), False
    else:
        (fsrc, fV, fw), fac = factor, True
    acute2 = st.acute ** 2
    cnt = np.array([hn, nstop, 0, 0], dtype=np.int64)
    scratch = np.zeros((8, st.off.shape[0]))
    fsrc = np.asarray(fsrc, dtype=float)
    fw = np.asarray(fw, dtype=float)
    shape3 = np.asarray(grid.shape3, dtype=np.uint64)
    h3 = np.asarray(grid.h3, dtype=float)
    while not wk.march(T, flag, grid.speed, grid.wind, grid.wconst, shape3, h3, tables, order,
                       hk, hc, hu, pos, cnt, can_stop, acute2, fac or not any_na, fac, fsrc, float(fV), fw, track,
                       scratch):
        n = int(cnt[0])  # the heap is full: double it and resume
        hk = np.concatenate([hk[:n], np.empty(hk.size)])
        hc = np.concatenate([hc[:n], np.empty(hc.size, dtype=np.uint64)])
        hu = np.concatenate([hu[:n], np.empty(hu.size, dtype=np.uint64)])
    pops, reopened = int(cnt[2]), int(cnt[3])
    inner = T.reshape(pshape)[PAD:PAD + nx, PAD:PAD + ny, pz:pz + nz]
    times = np.where(inner >= 0, inner, np.inf).reshape(-1)
    return MarchResult(times, track if want_track else None, int(pops), int(reopened))
