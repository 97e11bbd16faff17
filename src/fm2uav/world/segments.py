"""The ground and the surface along straight segments, exactly: every kink and every top.

A straight line over a DEM interpolated bilinearly is a chain of quadratic pieces:
the height is linear in each raster direction between pixel centres, so along the
line it changes law exactly where the line crosses a row or a column of pixel
centres, and inside each piece it is a parabola. Sampling the line at a fixed step
misses the kinks (on a 45° slope a sample a sixteenth of a pixel off a ridge kink
reads ``pixel/16`` m low). :func:`ground_points` returns instead, for every
segment, the heights at its ends, at every crossing of a pixel-centre row or
column and at the vertex of every parabola between them: the maximum and the
minimum of these are the exact maximum and minimum of the DEM (bilinear) along the
line, the numbers an independent sampler converges to from below.

The DEM is the world's ground (:meth:`World.ground_height`): the source rasters
(:class:`~fm2uav.world.ground_model.GroundModel`, each in its own CRS; with several
DEMs in priority order the critical points of every one are taken, and both sides of
each crossing, where the ground may change from one DEM to the next) or the world's
terrain grid. A segment is cut into pieces of at most ``max_piece`` metres whose
ends are transformed into the raster exactly; a straight world line is straight in
the raster up to the curvature of the map projection over one piece (sub-millimetre
for 200 m pieces).

Roofs (:func:`surface_points`) are flat per world column (the nearest column's
roof, :func:`fm2uav.world.ground.surface_height`): the line meets a new column where
it crosses a half-integer node line, so the roofs are read once per column crossed.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from scipy import ndimage

__all__ = ["LinePoints", "ground_points", "surface_points", "MAX_PIECE_M"]

#: Longest piece of a segment transformed as a straight line into the raster [m].
MAX_PIECE_M = 200.0
#: Crossings handled per batch (memory: ~100 bytes each).
_BATCH = 2_000_000


@dataclass(frozen=True)
class LinePoints:
    """Points along many segments, flat: ``segment[k]``, ``t[k]`` in [0, 1], ``z[k]``.

    Sorted by segment, then ``t``. Every segment has at least its two ends.
    """

    segment: np.ndarray
    t: np.ndarray
    z: np.ndarray

    def reduce(self, fn: Any, n: int) -> np.ndarray:
        """``fn.reduceat`` of ``z`` per segment (e.g. ``np.maximum``), for ``n`` segments."""
        starts = np.searchsorted(self.segment, np.arange(n))
        return fn.reduceat(self.z, starts)


def _grids(world: Any) -> list[tuple[np.ndarray, Any]] | None:
    """The rasters the world's ground is made of, each as (heights, world xy → continuous
    (i, j) index of ``heights``): the source DEMs of its ground model (priority order), or
    its terrain grid; None when the ground is flat (no terrain)."""
    model = getattr(world, "ground", None)
    if model is not None:
        return [(layer.z, layer.pixel_coords) for layer in model.layers]
    if world.terrain is None:
        return None
    ox, oy = float(world.origin[0]), float(world.origin[1])
    dx, dy = float(world.spacing[0]), float(world.spacing[1])

    def index(x: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        return (np.asarray(x, dtype=float) - ox) / dx, (np.asarray(y, dtype=float) - oy) / dy

    return [(world.terrain, index)]


def _pieces(a: np.ndarray, b: np.ndarray, max_piece: float
            ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Cut segments a→b into pieces: (segment id, t0, t1, number of pieces) per piece."""
    length = np.hypot(*(b - a).T)
    n = np.maximum(np.ceil(length / max_piece).astype(np.int64), 1)
    seg = np.repeat(np.arange(len(a)), n)
    first = np.repeat(np.cumsum(n) - n, n)
    k = np.arange(len(seg)) - first
    nn = n[seg].astype(float)
    return seg, k / nn, (k + 1) / nn, n


def _crossings(u0: np.ndarray, u1: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(piece index, t) where u(t) = u0 + t (u1 - u0) crosses an integer strictly inside."""
    lo = np.floor(np.minimum(u0, u1)) + 1.0
    hi = np.ceil(np.maximum(u0, u1)) - 1.0
    cnt = np.maximum(hi - lo + 1.0, 0.0).astype(np.int64)
    if cnt.sum() == 0:
        return np.zeros(0, dtype=np.int64), np.zeros(0)
    piece = np.repeat(np.arange(len(u0)), cnt)
    first = np.repeat(np.cumsum(cnt) - cnt, cnt)
    k = lo[piece] + (np.arange(len(piece)) - first)
    du = (u1 - u0)[piece]
    return piece, (k - u0[piece]) / du


def _piece_points(z: np.ndarray, i0: np.ndarray, j0: np.ndarray, i1: np.ndarray,
                  j1: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(piece, local t, is a crossing) of the ends, the crossings and the parabola vertices
    of the raster ``z`` along straight pieces."""
    pa, ta = _crossings(i0, i1)
    pb, tb = _crossings(j0, j1)
    n = len(i0)
    piece = np.concatenate([np.arange(n), np.arange(n), pa, pb])
    t = np.concatenate([np.zeros(n), np.ones(n), ta, tb])
    cross = np.concatenate([np.zeros(2 * n, bool), np.ones(len(pa) + len(pb), bool)])
    order = np.lexsort((t, piece))
    piece, t, cross = piece[order], t[order], cross[order]

    def at(pp: np.ndarray, tt: np.ndarray) -> np.ndarray:
        ii = i0[pp] + tt * (i1 - i0)[pp]
        jj = j0[pp] + tt * (j1 - j0)[pp]
        return ndimage.map_coordinates(z, np.stack([ii, jj]), order=1, mode="nearest")

    h = at(piece, t)
    # between consecutive points of a piece the height is a parabola in t: its vertex
    same = piece[1:] == piece[:-1]
    ta_, tb_ = t[:-1][same], t[1:][same]
    keep = tb_ - ta_ > 1e-12
    ta_, tb_ = ta_[keep], tb_[keep]
    pm = piece[:-1][same][keep]
    fa, fb = h[:-1][same][keep], h[1:][same][keep]
    fm = at(pm, 0.5 * (ta_ + tb_))
    B = -3.0 * fa + 4.0 * fm - fb
    C = 2.0 * fa - 4.0 * fm + 2.0 * fb
    with np.errstate(divide="ignore", invalid="ignore"):
        u = np.where(np.abs(C) > 1e-12, -B / (2.0 * C), -1.0)
    inside = (u > 0.0) & (u < 1.0)
    tv = ta_[inside] + u[inside] * (tb_ - ta_)[inside]
    return (np.concatenate([piece, pm[inside]]), np.concatenate([t, tv]),
            np.concatenate([cross, np.zeros(int(inside.sum()), bool)]))


def _critical(z: np.ndarray, coords: Any, a: np.ndarray, b: np.ndarray, max_piece: float
              ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(segment, t, is a crossing) of one raster's critical points along segments a → b."""
    seg, t0, t1, _ = _pieces(a, b, max_piece)
    pa = a[seg] + t0[:, None] * (b - a)[seg]
    pb = a[seg] + t1[:, None] * (b - a)[seg]
    i0, j0 = (np.asarray(v, dtype=float) for v in coords(pa[:, 0], pa[:, 1]))
    i1, j1 = (np.asarray(v, dtype=float) for v in coords(pb[:, 0], pb[:, 1]))
    # batches of pieces so that the crossings stay within memory
    est = np.abs(i1 - i0) + np.abs(j1 - j0) + 2.0
    bounds = np.searchsorted(np.cumsum(est), np.arange(1, int(est.sum() // _BATCH) + 2) * _BATCH)
    out_s, out_t, out_c = [], [], []
    start = 0
    for stop in list(bounds) + [len(seg)]:
        stop = int(min(max(stop, start), len(seg)))
        if stop <= start:
            continue
        sl = slice(start, stop)
        p, tl, cr = _piece_points(z, i0[sl], j0[sl], i1[sl], j1[sl])
        gp = p + start
        out_s.append(seg[gp])
        out_t.append(t0[gp] + tl * (t1 - t0)[gp])
        out_c.append(cr)
        start = stop
    return np.concatenate(out_s), np.concatenate(out_t), np.concatenate(out_c)


def ground_points(world: Any, a: Any, b: Any, *, max_piece: float = MAX_PIECE_M) -> LinePoints:
    """The ground's critical points along straight segments ``a[k] → b[k]`` (module docstring).

    Parameters
    ----------
    world : World
    a, b : array_like, shape (n, 2+)
        Segment ends in world metres (only x, y are used).
    max_piece : float
        Longest piece transformed into the raster as a straight line [m].

    Returns
    -------
    LinePoints
        ``z`` = ground height [m, world z]; the per-segment maximum and minimum of
        ``z`` are exact for the bilinear DEM.
    """
    a = np.asarray(a, dtype=float)[:, :2]
    b = np.asarray(b, dtype=float)[:, :2]
    grids = _grids(world)
    n = len(a)
    if grids is None or n == 0:
        floor = float(world.origin[2]) if world.ndim == 3 else 0.0
        seg = np.repeat(np.arange(n), 2)
        return LinePoints(seg, np.tile([0.0, 1.0], n), np.full(2 * n, floor))
    parts = [_critical(z, coords, a, b, max_piece) for z, coords in grids]
    s = np.concatenate([p[0] for p in parts])
    t = np.concatenate([p[1] for p in parts])
    if len(grids) > 1:  # the ground changes DEM at a crossing: read both sides of it
        cross = np.concatenate([p[2] for p in parts])
        eps = 1e-9
        s = np.concatenate([s, s[cross], s[cross]])
        t = np.clip(np.concatenate([t, t[cross] - eps, t[cross] + eps]), 0.0, 1.0)
    order = np.lexsort((t, s))
    s, t = s[order], t[order]
    pts = a[s] + t[:, None] * (b - a)[s]
    z = np.asarray(world.ground_height(pts[:, 0], pts[:, 1]), dtype=float)
    return LinePoints(s, t, z)


def surface_points(world: Any, a: Any, b: Any, *, max_piece: float = MAX_PIECE_M,
                   ground: LinePoints | None = None) -> LinePoints:
    """:func:`ground_points` with the roofs: the surface (ground or roof) along the segments.

    Adds one point per world column crossed (its middle), where the roof of that column
    is read (:meth:`World.surface_height`); at every point ``z`` is the surface.
    Without roofs it is :func:`ground_points` (``ground``, when already computed).
    """
    from .ground import roof_heights

    g = ground if ground is not None else ground_points(world, a, b, max_piece=max_piece)
    if world.ndim != 3 or not np.isfinite(roof_heights(world)).any():
        return g
    a2 = np.asarray(a, dtype=float)[:, :2]
    b2 = np.asarray(b, dtype=float)[:, :2]
    ox, oy = float(world.origin[0]), float(world.origin[1])
    dx, dy = float(world.spacing[0]), float(world.spacing[1])
    # column boundaries: half-integer node coordinates
    ia, ja = (a2[:, 0] - ox) / dx + 0.5, (a2[:, 1] - oy) / dy + 0.5
    ib, jb = (b2[:, 0] - ox) / dx + 0.5, (b2[:, 1] - oy) / dy + 0.5
    n = len(a2)
    p1, t1 = _crossings(ia, ib)
    p2, t2 = _crossings(ja, jb)
    seg = np.concatenate([np.arange(n), np.arange(n), p1, p2])
    t = np.concatenate([np.zeros(n), np.ones(n), t1, t2])
    order = np.lexsort((t, seg))
    seg, t = seg[order], t[order]
    same = seg[1:] == seg[:-1]
    mid_s = seg[:-1][same]
    mid_t = 0.5 * (t[:-1][same] + t[1:][same])
    pts = a2[mid_s] + mid_t[:, None] * (b2 - a2)[mid_s]
    roof = np.asarray(world.surface_height(pts[:, 0], pts[:, 1]), dtype=float)
    # the surface at the ground's points (roofs there too) and at the column middles
    gp = a2[g.segment] + g.t[:, None] * (b2 - a2)[g.segment]
    at_g = np.maximum(g.z, np.asarray(world.surface_height(gp[:, 0], gp[:, 1]), dtype=float))
    s_all = np.concatenate([g.segment, mid_s])
    t_all = np.concatenate([g.t, mid_t])
    z_all = np.concatenate([at_g, roof])
    order = np.lexsort((t_all, s_all))
    return LinePoints(s_all[order], t_all[order], z_all[order])
