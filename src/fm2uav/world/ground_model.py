"""The ground as the source DEM itself, beside the (coarser) planning grid.

A world built from a DEM resamples it to its cell size (``World.terrain``, one
height per column node), which is what FM² plans on. Between those nodes the
real ground can rise well above the bilinear surface of the nodes: on the
Jacksboro DEM (3″ pixels, ≈ 75 × 93 m) planned on 150 m nodes, a path flown at
exactly 150 m above ``World.terrain`` comes down to 135 m above the source
DEM on ridges. Every height-above-ground question (``World.ground_height``,
the final altitude profile, the safety figures, the exports' AMSL altitudes)
therefore reads the DEM itself.

:class:`GroundModel` keeps the source raster (elevations, affine transform,
CRS) and answers ``height(x, y)`` for world coordinates by transforming them
into the raster's CRS (pyproj, exact) and interpolating the raster bilinearly
between pixel centres — the DEM "interpolated bilinearly", with no second
resampling in between. Nodata pixels are filled with the nearest valid one
(as the world's terrain is) and ``sea_level`` clamps the ground as in the
world. It is kept whenever the raster holds at most :data:`MAX_SAMPLES`
pixels, also when the DEM is coarser than the planning grid: the nodes of a
reprojected grid are bilinear samples of the DEM, but the bilinear surface
between them is not the DEM's (a 0.01° DEM on its default 600 m UTM grid is
off by up to 7 m on rough relief). A larger raster is not kept; the world's
terrain answers then, and ``World.georef``'s sources still name the file.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
from scipy import ndimage

__all__ = ["GroundModel", "MAX_SAMPLES", "ground_model_from_dem", "sampling_step", "ground_bulge"]

#: Largest raster (pixels) kept as a ground model (about 200 MB of float64).
MAX_SAMPLES = 25_000_000


@dataclass(frozen=True, eq=False)
class GroundModel:
    """The source DEM, interpolated bilinearly at world coordinates.

    Attributes
    ----------
    z : ndarray, shape (rows, cols)
        Elevations [m, world z], nodata filled with the nearest valid pixel.
    transform : 6 floats
        Affine ``(a, b, c, d, e, f)`` from (col, row) pixel-corner coordinates
        to the raster's CRS.
    crs : str
        The raster's horizontal CRS (WKT or authority string).
    world_crs : str
        The world's CRS (the coordinates ``height`` is asked in).
    pixel_m : float
        Smaller side of a pixel in the world's metres.
    description : str
        One line for summaries.
    """

    z: np.ndarray = field(repr=False)
    transform: tuple[float, ...]
    crs: str = field(repr=False)
    world_crs: str = field(repr=False)
    pixel_m: float = 0.0
    description: str = ""
    _to_src: Any = field(default=None, init=False, repr=False, compare=False)
    _inv: tuple[float, ...] = field(default=(), init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        from .geo import parse_crs, transformer

        z = np.array(self.z, dtype=float, copy=True)
        if z.ndim != 2 or min(z.shape) < 2 or not np.all(np.isfinite(z)):
            raise ValueError(f"GroundModel z must be a finite (rows >= 2, cols >= 2) array, "
                             f"got shape {z.shape}")
        z.setflags(write=False)
        object.__setattr__(self, "z", z)
        a, b, c, d, e, f = (float(v) for v in self.transform)
        det = a * e - b * d
        if det == 0:
            raise ValueError("GroundModel transform is singular")
        # inverse affine: (x, y) -> (col, row)
        inv = (e / det, -b / det, (b * f - c * e) / det, -d / det, a / det, (c * d - a * f) / det)
        object.__setattr__(self, "_inv", inv)
        same = parse_crs(self.crs).equals(parse_crs(self.world_crs))
        object.__setattr__(self, "_to_src", None if same else
                           transformer(self.world_crs, self.crs))

    @property
    def shape(self) -> tuple[int, int]:
        """``(rows, cols)`` of the raster."""
        return tuple(int(v) for v in self.z.shape)  # type: ignore[return-value]

    def pixel_index(self, x: Any, y: Any) -> tuple[np.ndarray, np.ndarray]:
        """Continuous ``(row, col)`` of world ``(x, y)`` [m] in the raster, pixel centres at
        whole numbers: the bilinear surface is smooth between whole rows and columns."""
        xa, ya = np.broadcast_arrays(np.asarray(x, dtype=float), np.asarray(y, dtype=float))
        xs, ys = xa.ravel(), ya.ravel()
        if self._to_src is not None:
            xs, ys = self._to_src.transform(xs, ys)
            xs, ys = np.asarray(xs, dtype=float), np.asarray(ys, dtype=float)
        ia, ib, ic, id_, ie, if_ = self._inv
        col = ia * xs + ib * ys + ic - 0.5
        row = id_ * xs + ie * ys + if_ - 0.5
        return row.reshape(xa.shape), col.reshape(xa.shape)

    def height(self, x: Any, y: Any) -> np.ndarray:
        """Bilinear DEM height [m] at world ``(x, y)`` [m] (edge pixels outside)."""
        row, col = self.pixel_index(x, y)
        out = ndimage.map_coordinates(self.z, np.stack([row.ravel(), col.ravel()]), order=1,
                                      mode="nearest")
        return out.reshape(row.shape)


def sampling_step(world: Any) -> float:
    """Spacing [m] at which to sample a path against the ground: a quarter of the
    world's horizontal cell, and at most a quarter of the source DEM's pixel."""
    step = 0.25 * float(min(world.spacing[:2]))
    model = getattr(world, "ground", None)
    if model is not None and model.pixel_m > 0:
        step = min(step, 0.25 * float(model.pixel_m))
    return step


def _grid_index(world: Any, x: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Continuous index of world points in the grid the ground is bilinear on (the source
    DEM's pixel centres, or the world's terrain nodes): smooth between whole numbers."""
    model = getattr(world, "ground", None)
    if model is not None:
        return model.pixel_index(x, y)
    return ((np.asarray(x, dtype=float) - world.origin[0]) / world.spacing[0],
            (np.asarray(y, dtype=float) - world.origin[1]) / world.spacing[1])


def ground_bulge(world: Any, a: Any, b: Any) -> tuple[np.ndarray, np.ndarray]:
    """How far the ground rises above, and drops below, the straight line between its
    heights at the ends of each chord ``a[i]`` → ``b[i]`` (x, y [m]): ``(rise, drop)`` [m],
    both >= 0.

    Exact for the bilinear ground (:meth:`World.ground_height`): along a straight chord it is a
    quadratic between the chord's crossings of the grid's whole rows and columns (the
    source DEM's pixel centres, or the terrain nodes), so the extremes lie at those
    crossings or at a piece's vertex; each piece is read at its ends and middle and its
    quadratic solved (a DEM in another CRS than the world bends the chord by far less
    than a millimetre over a pixel). Reading a few points per chord missed centimetres
    at pixel edges — enough to put a path exactly at a zone's ceiling inside it.
    """
    pa = np.atleast_2d(np.asarray(a, dtype=float))[:, :2]
    pb = np.atleast_2d(np.asarray(b, dtype=float))[:, :2]
    k = len(pa)
    if k == 0 or (getattr(world, "ground", None) is None and world.terrain is None):
        return np.zeros(k), np.zeros(k)
    r0, c0 = _grid_index(world, pa[:, 0], pa[:, 1])
    r1, c1 = _grid_index(world, pb[:, 0], pb[:, 1])
    # breakpoints: t where the row or the column index crosses a whole number
    ts = [np.zeros(k), np.ones(k)]
    for u0, u1 in ((r0, r1), (c0, c1)):
        lo, hi = np.minimum(u0, u1), np.maximum(u0, u1)
        first = np.floor(lo) + 1.0
        n = np.maximum(np.ceil(hi) - first, 0).astype(int)
        du = np.where(np.abs(u1 - u0) > 1e-12, u1 - u0, np.nan)
        for j in range(int(n.max()) if n.size else 0):
            v = first + j
            t = np.where(j < n, (v - u0) / du, np.nan)
            ts.append(np.where((t > 0) & (t < 1), t, np.nan))
    t = np.sort(np.column_stack(ts), axis=1)  # NaNs last
    ta, tb = t[:, :-1], t[:, 1:]
    ok = np.isfinite(ta) & np.isfinite(tb) & (tb > ta)
    tm = 0.5 * (ta + tb)
    fr = np.stack([ta, tm, tb], axis=-1)  # (k, pieces, 3)
    fr = np.where(ok[..., None], fr, 0.0)
    d = pb - pa
    q = pa[:, None, None, :] + fr[..., None] * d[:, None, None, :]
    g = np.asarray(world.ground_height(q[..., 0].ravel(), q[..., 1].ravel()),
                   dtype=float).reshape(fr.shape)
    g_end = np.asarray(world.ground_height(np.r_[pa[:, 0], pb[:, 0]],
                                           np.r_[pa[:, 1], pb[:, 1]]), dtype=float)
    lin = g_end[:k, None, None] + fr * (g_end[k:] - g_end[:k])[:, None, None]
    h = g - lin  # the ground above the chord's straight line, per piece at ends and middle
    # the quadratic through the three values: h(s) = h0 + B s + C s^2, s in [0, 1]
    h0, hm, h1 = h[..., 0], h[..., 1], h[..., 2]
    C = 2.0 * (h0 + h1) - 4.0 * hm
    B = h1 - h0 - C
    with np.errstate(divide="ignore", invalid="ignore"):
        s = np.where(np.abs(C) > 1e-12, -B / (2.0 * C), np.nan)
    inside = np.isfinite(s) & (s > 0) & (s < 1)
    hv = np.where(inside, h0 + B * s + C * s * s, np.nan)
    vals = np.concatenate([h0, h1, hv], axis=1)
    vals = np.where(np.concatenate([ok, ok, ok & inside], axis=1), vals, np.nan)
    rise = np.nanmax(np.concatenate([vals, np.zeros((k, 1))], axis=1), axis=1)
    drop = np.nanmax(np.concatenate([-vals, np.zeros((k, 1))], axis=1), axis=1)
    return np.maximum(rise, 0.0), np.maximum(drop, 0.0)


def _pixel_metres(dem: Any, src: Any, dst: Any) -> float:
    """Smaller side of the DEM's centre pixel, measured in the destination CRS [m]."""
    from .geo import transformer

    rows, cols = dem.z.shape
    a, b, c, d, e, f = dem.transform
    r, q = rows / 2.0, cols / 2.0
    cx = np.array([q, q + 1, q])
    ry = np.array([r, r, r + 1])
    xs = a * cx + b * ry + c
    ys = d * cx + e * ry + f
    tx, ty = transformer(src, dst).transform(xs, ys)
    tx, ty = np.asarray(tx), np.asarray(ty)
    side_c = float(np.hypot(tx[1] - tx[0], ty[1] - ty[0]))
    side_r = float(np.hypot(tx[2] - tx[0], ty[2] - ty[0]))
    return min(side_c, side_r)


def ground_model_from_dem(dem: Any, src: Any, dst: Any, cell: float, *,
                          sea_level: float | None = None,
                          max_samples: int = MAX_SAMPLES) -> GroundModel | None:
    """The ground model of a DEM, or None if it is too large or has no valid pixel.

    Parameters
    ----------
    dem : fm2uav.world.dem.DemRaster
        The raster as read (north-up, NaN where masked).
    src, dst : CRS
        The DEM's CRS and the world's.
    cell : float
        The world's smallest horizontal cell [m] (the model is kept at any cell
        size; the argument stays for callers).
    sea_level : float, optional
        ``ground = max(DEM, sea_level)`` as in the world.
    max_samples : int
        Largest raster kept [pixels].
    """
    from .geo import crs_label, parse_crs

    z = np.asarray(dem.z, dtype=float)
    if z.ndim != 2 or min(z.shape) < 2 or z.size > max_samples:
        return None
    pixel = _pixel_metres(dem, src, dst)
    if not (np.isfinite(pixel) and pixel > 0):
        return None
    bad = ~np.isfinite(z)
    if bad.all():
        return None
    if bad.any():
        _, (ii, jj) = ndimage.distance_transform_edt(bad, return_indices=True)
        z = z[ii, jj]
    if sea_level is not None:
        z = np.maximum(z, float(sea_level))
    src_s = parse_crs(src).to_wkt()
    dst_s = parse_crs(dst).to_wkt()
    desc = (f"source DEM ({z.shape[0]} x {z.shape[1]} pixels of {pixel:.1f} m, "
            f"{crs_label(src)}), bilinear between pixel centres")
    return GroundModel(z, tuple(float(v) for v in dem.transform), src_s, dst_s, float(pixel),
                       desc)
