"""The ground as the source DEM(s) themselves, beside the (coarser) planning grid.

A world built from a DEM resamples it to its cell size (``World.terrain``, one
height per column node), which is what FM² plans on. Between those nodes the
real ground can rise well above the bilinear surface of the nodes: on the
Jacksboro DEM (3″ pixels, ≈ 75 × 93 m) planned on 150 m nodes, a path flown at
exactly 150 m above ``World.terrain`` comes down to 135 m above the source
DEM on ridges. Every height-above-ground question (``World.ground_height``,
the final altitude profile, the safety figures, the exports' AMSL altitudes)
therefore reads the DEM itself.

:class:`GroundModel` keeps the source rasters (elevations, affine transform,
CRS; one :class:`GroundLayer` per DEM, in priority order: ``world.dem`` first,
then each ``world.dem_fill``) and answers ``height(x, y)`` for world
coordinates by transforming them into each raster's CRS (pyproj, exact) and
interpolating the raster bilinearly between pixel centres — the DEM
"interpolated bilinearly", with no second resampling in between.

**Known and unknown ground.** A point's height is *measured* by a layer when
the four pixels of its bilinear stencil (those with a non-zero weight) are all
valid in that layer; it takes the first such layer (:meth:`GroundModel.source`
says which). Where no layer measures it, the ground is *unknown* (filled): the
height is the first covering layer's value with its nodata filled by the
nearest valid pixel, and :meth:`GroundModel.filled` says so — every safety
figure over such points is reported apart (:mod:`fm2uav.analysis.known_ground`).
``sea_level`` is already applied to the rasters (:func:`fm2uav.world.dem.read_dem`).

The model is kept whenever its rasters hold at most :data:`MAX_SAMPLES` pixels
together, also when the DEM is coarser than the planning grid: the nodes of a
reprojected grid are bilinear samples of the DEM, but the bilinear surface
between them is not the DEM's (a 0.01° DEM on its default 600 m UTM grid is
off by up to 7 m on rough relief). Larger rasters are not kept; the world's
terrain (and ``World.filled``) answer then, and ``World.georef``'s sources still
name the files.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from scipy import ndimage

__all__ = ["GroundModel", "GroundLayer", "MAX_SAMPLES", "ground_model_from_dem",
           "sampling_step", "ground_bulge"]

#: Largest raster (pixels, all layers together) kept as a ground model (about 200 MB of
#: float64).
MAX_SAMPLES = 25_000_000
#: Points evaluated at a time by a model of several DEMs (bounds the temporaries).
_CHUNK = 1_000_000
#: How far inside each piece's ends :func:`ground_bulge` reads the ground [m].
_BULGE_INSET_M = 1e-3


@dataclass(frozen=True, eq=False)
class GroundLayer:
    """One source DEM of a :class:`GroundModel`.

    Attributes
    ----------
    z : ndarray, shape (rows, cols)
        Elevations [m, world z], nodata filled with the nearest valid pixel.
    valid : ndarray of bool, shape (rows, cols)
        Which pixels were measured (not nodata).
    transform : 6 floats
        Affine ``(a, b, c, d, e, f)`` from (col, row) pixel-corner coordinates
        to the raster's CRS.
    crs : str
        The raster's horizontal CRS (WKT or authority string).
    world_crs : str
        The world's CRS (the coordinates questions are asked in).
    pixel_m : float
        Smaller side of a pixel in the world's metres.
    name : str
        The file (or "array"), for summaries.
    spacing_m : float
        Larger side of a pixel in the world's metres (the distance over which relief
        between pixel centres goes unseen); default ``pixel_m``.
    """

    z: np.ndarray = field(repr=False)
    valid: np.ndarray = field(repr=False)
    transform: tuple[float, ...]
    crs: str = field(repr=False)
    world_crs: str = field(repr=False)
    pixel_m: float = 0.0
    name: str = ""
    spacing_m: float = 0.0
    _to_src: Any = field(default=None, init=False, repr=False, compare=False)
    _inv: tuple[float, ...] = field(default=(), init=False, repr=False, compare=False)
    _all_valid: bool = field(default=True, init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        from .geo import parse_crs, transformer

        z = np.array(self.z, dtype=float, copy=True)
        valid = np.array(self.valid, dtype=bool, copy=True)
        if z.ndim != 2 or min(z.shape) < 2 or not np.all(np.isfinite(z)) or \
                valid.shape != z.shape:
            raise ValueError(f"GroundLayer z must be a finite (rows >= 2, cols >= 2) array with "
                             f"a valid mask of its shape, got {z.shape} and {valid.shape}")
        z.setflags(write=False)
        valid.setflags(write=False)
        object.__setattr__(self, "z", z)
        object.__setattr__(self, "valid", valid)
        object.__setattr__(self, "_all_valid", bool(valid.all()))
        if not self.spacing_m:
            object.__setattr__(self, "spacing_m", float(self.pixel_m))
        a, b, c, d, e, f = (float(v) for v in self.transform)
        det = a * e - b * d
        if det == 0:
            raise ValueError("GroundLayer transform is singular")
        # inverse affine: (x, y) -> (col, row)
        inv = (e / det, -b / det, (b * f - c * e) / det, -d / det, a / det, (c * d - a * f) / det)
        object.__setattr__(self, "_inv", inv)
        same = parse_crs(self.crs).equals(parse_crs(self.world_crs))
        object.__setattr__(self, "_to_src", None if same else
                           transformer(self.world_crs, self.crs))

    def pixel_coords(self, x: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Continuous (row, col) of world points in this raster (pixel centres at integers)."""
        xs, ys = x, y
        if self._to_src is not None:
            xs, ys = self._to_src.transform(xs, ys)
            xs, ys = np.asarray(xs, dtype=float), np.asarray(ys, dtype=float)
        ia, ib, ic, id_, ie, if_ = self._inv
        col = ia * xs + ib * ys + ic - 0.5
        row = id_ * xs + ie * ys + if_ - 0.5
        return row, col

    def height_at(self, row: np.ndarray, col: np.ndarray) -> np.ndarray:
        """Bilinear height at continuous pixel coordinates (edge pixels outside)."""
        return ndimage.map_coordinates(self.z, np.stack([row, col]), order=1, mode="nearest")

    def measured_at(self, row: np.ndarray, col: np.ndarray) -> np.ndarray:
        """Whether every pixel with a non-zero bilinear weight is measured (and the point
        lies within the pixel-centre footprint)."""
        rows, cols = self.z.shape
        tol = 1e-6  # pixels: world edges sit on the footprint up to round-off
        ok = (row >= -tol) & (row <= rows - 1 + tol) & (col >= -tol) & (col <= cols - 1 + tol)
        ok &= np.isfinite(row) & np.isfinite(col)
        if self._all_valid:
            return ok
        r = np.clip(np.where(ok, row, 0.0), 0, rows - 1)
        c = np.clip(np.where(ok, col, 0.0), 0, cols - 1)
        r0 = np.minimum(np.floor(r).astype(np.int64), rows - 2)
        c0 = np.minimum(np.floor(c).astype(np.int64), cols - 2)
        fr, fc = r - r0, c - c0
        v = self.valid
        out = ok.copy()
        for dr, dc, w in ((0, 0, (1 - fr) * (1 - fc)), (0, 1, (1 - fr) * fc),
                          (1, 0, fr * (1 - fc)), (1, 1, fr * fc)):
            out &= (w <= 1e-12) | v[r0 + dr, c0 + dc]
        return out

    def covers(self, row: np.ndarray, col: np.ndarray) -> np.ndarray:
        """Whether points lie within the pixel-centre footprint."""
        rows, cols = self.z.shape
        return (row >= -0.5) & (row <= rows - 0.5) & (col >= -0.5) & (col <= cols - 0.5)


@dataclass(frozen=True, eq=False)
class GroundModel:
    """The source DEMs (priority order), interpolated bilinearly at world coordinates.

    Attributes
    ----------
    layers : tuple of GroundLayer
        ``world.dem`` first, then each ``world.dem_fill``.
    description : str
        One line for summaries.
    """

    layers: tuple[GroundLayer, ...]
    description: str = ""

    def __post_init__(self) -> None:
        if not self.layers:
            raise ValueError("GroundModel needs at least one layer")
        object.__setattr__(self, "layers", tuple(self.layers))

    @property
    def pixel_m(self) -> float:
        """The smallest pixel of the layers [m]."""
        return float(min(layer.pixel_m for layer in self.layers))

    def _evaluate(self, x: Any, y: Any) -> tuple[np.ndarray, np.ndarray, tuple[int, ...]]:
        """(heights, measuring layer or -1, shape) of world points, in chunks of
        :data:`_CHUNK` points (a clearance grid asks for millions)."""
        xa, ya = np.broadcast_arrays(np.asarray(x, dtype=float), np.asarray(y, dtype=float))
        xs, ys = xa.ravel(), ya.ravel()
        h = np.empty(xs.shape)
        src = np.empty(xs.shape, dtype=np.int8)
        for a in range(0, len(xs), _CHUNK):
            h[a:a + _CHUNK], src[a:a + _CHUNK] = self._evaluate_flat(xs[a:a + _CHUNK],
                                                                     ys[a:a + _CHUNK])
        return h, src, xa.shape

    def _evaluate_flat(self, xs: np.ndarray, ys: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        h = np.full(xs.shape, np.nan)
        src = np.full(xs.shape, -1, dtype=np.int8)
        fallback = np.full(xs.shape, np.nan)
        for k, layer in enumerate(self.layers):
            todo = src < 0
            if not todo.any():
                break
            row, col = layer.pixel_coords(xs[todo], ys[todo])
            m = layer.measured_at(row, col)
            hk = layer.height_at(row, col)
            idx = np.flatnonzero(todo)
            h[idx[m]] = hk[m]
            src[idx[m]] = k
            cover = ~m & layer.covers(row, col) & np.isnan(fallback[idx])
            fallback[idx[cover]] = hk[cover]
            if k == len(self.layers) - 1:  # beyond every footprint: the last layer's edge
                rest = ~m & np.isnan(fallback[idx])
                fallback[idx[rest]] = hk[rest]
        unknown = src < 0
        h[unknown] = fallback[unknown]
        return h, src

    def height(self, x: Any, y: Any) -> np.ndarray:
        """Bilinear DEM height [m] at world ``(x, y)`` [m] (see the module docstring)."""
        if len(self.layers) == 1:  # one DEM: its (nodata-filled) raster everywhere
            xa, ya = np.broadcast_arrays(np.asarray(x, dtype=float), np.asarray(y, dtype=float))
            layer = self.layers[0]
            row, col = layer.pixel_coords(xa.ravel(), ya.ravel())
            return layer.height_at(row, col).reshape(xa.shape)
        h, _, shape = self._evaluate(x, y)
        return h.reshape(shape)

    def source(self, x: Any, y: Any) -> np.ndarray:
        """Index of the layer measuring the ground at ``(x, y)``; -1 where none does."""
        _, src, shape = self._evaluate(x, y)
        return src.reshape(shape)

    def filled(self, x: Any, y: Any) -> np.ndarray:
        """Whether the ground at ``(x, y)`` is unknown (no layer measures it)."""
        return self.source(x, y) < 0


def sampling_step(world: Any) -> float:
    """Spacing [m] at which to sample a path against the ground: a quarter of the
    world's horizontal cell, and at most a quarter of the source DEM's pixel."""
    step = 0.25 * float(min(world.spacing[:2]))
    model = getattr(world, "ground", None)
    if model is not None and model.pixel_m > 0:
        step = min(step, 0.25 * float(model.pixel_m))
    return step


def _grid_indices(world: Any, x: np.ndarray, y: np.ndarray) -> list[tuple[np.ndarray, np.ndarray]]:
    """Continuous indices of world points in each grid the ground is bilinear on (every
    source DEM's pixel centres — a model of several DEMs switches layer only on the
    higher-priority layer's whole rows and columns — or the world's terrain nodes): the
    ground is smooth between whole numbers of all of them."""
    x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
    model = getattr(world, "ground", None)
    if model is not None:
        return [layer.pixel_coords(x, y) for layer in model.layers]
    return [((x - world.origin[0]) / world.spacing[0], (y - world.origin[1]) / world.spacing[1])]


def ground_bulge(world: Any, a: Any, b: Any) -> tuple[np.ndarray, np.ndarray]:
    """How far the ground rises above, and drops below, the straight line between its
    heights at the ends of each chord ``a[i]`` → ``b[i]`` (x, y [m]): ``(rise, drop)`` [m],
    both >= 0.

    Exact for the bilinear ground (:meth:`World.ground_height`): along a straight chord it is a
    quadratic between the chord's crossings of the grid's whole rows and columns (the
    source DEMs' pixel centres — of every layer: ``world.dem_fill`` takes over from
    ``world.dem`` only on its whole rows and columns, where the ground may step — or the
    terrain nodes), so the extremes lie at those crossings, on either side of a step, or
    at a piece's vertex; each piece is read 1 mm inside its ends and at its middle and its
    quadratic solved and extended to the ends (a DEM in another CRS than the world bends
    the chord by far less than a millimetre over a pixel). Reading a few points per chord
    missed centimetres at pixel edges — enough to put a path exactly at a zone's ceiling
    inside it.
    """
    pa = np.atleast_2d(np.asarray(a, dtype=float))[:, :2]
    pb = np.atleast_2d(np.asarray(b, dtype=float))[:, :2]
    k = len(pa)
    if k == 0 or (getattr(world, "ground", None) is None and world.terrain is None):
        return np.zeros(k), np.zeros(k)
    ends = zip(_grid_indices(world, pa[:, 0], pa[:, 1]), _grid_indices(world, pb[:, 0], pb[:, 1]))
    # breakpoints: t where a row or a column index crosses a whole number
    ts = [np.zeros(k), np.ones(k)]
    for u0, u1 in (pair for (r0, c0), (r1, c1) in ends for pair in ((r0, r1), (c0, c1))):
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
    # each piece is read 1 mm inside its ends (a quarter of it if shorter) and its quadratic
    # extended to them: where several DEMs meet, the ground switches layer (and may step)
    # on a grid line, and the chord's slight bend in another CRS must not put a read on the
    # far side of that line
    length = np.maximum(np.hypot(*(pb - pa).T), 1e-12)[:, None]
    eps = np.where(ok, np.minimum(_BULGE_INSET_M / length, 0.25 * (tb - ta)), 0.0)
    fr = np.stack([ta + eps, tm, tb - eps], axis=-1)  # (k, pieces, 3)
    fr = np.where(ok[..., None], fr, 0.0)
    d = pb - pa
    q = pa[:, None, None, :] + fr[..., None] * d[:, None, None, :]
    g = np.asarray(world.ground_height(q[..., 0].ravel(), q[..., 1].ravel()),
                   dtype=float).reshape(fr.shape)
    g_end = np.asarray(world.ground_height(np.r_[pa[:, 0], pb[:, 0]],
                                           np.r_[pa[:, 1], pb[:, 1]]), dtype=float)
    lin = g_end[:k, None, None] + fr * (g_end[k:] - g_end[:k])[:, None, None]
    h = g - lin  # the ground above the chord's straight line, per piece at ends and middle
    # the quadratic through the three values: h(u) = h0 + B u + C u^2, u in [0, 1] between
    # the reads; the piece's true ends are at u = -e and 1 + e
    h0, hm, h1 = h[..., 0], h[..., 1], h[..., 2]
    C = 2.0 * (h0 + h1) - 4.0 * hm
    B = h1 - h0 - C
    with np.errstate(divide="ignore", invalid="ignore"):
        e = np.where(ok, eps / np.maximum(tb - ta - 2.0 * eps, 1e-300), 0.0)
        s = np.where(np.abs(C) > 1e-12, -B / (2.0 * C), np.nan)
    inside = np.isfinite(s) & (s > -e) & (s < 1.0 + e)
    hv = np.where(inside, h0 + B * s + C * s * s, np.nan)
    h0, h1 = h0 - B * e + C * e * e, h0 + B * (1.0 + e) + C * (1.0 + e) ** 2
    vals = np.concatenate([h0, h1, hv], axis=1)
    vals = np.where(np.concatenate([ok, ok, ok & inside], axis=1), vals, np.nan)
    rise = np.nanmax(np.concatenate([vals, np.zeros((k, 1))], axis=1), axis=1)
    drop = np.nanmax(np.concatenate([-vals, np.zeros((k, 1))], axis=1), axis=1)
    return np.maximum(rise, 0.0), np.maximum(drop, 0.0)


def _pixel_metres(dem: Any, src: Any, dst: Any, larger: bool = False) -> float:
    """Smaller (``larger``: larger) side of the DEM's centre pixel, measured in the
    destination CRS [m]."""
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
    return max(side_c, side_r) if larger else min(side_c, side_r)


def ground_model_from_dem(dems: Any, srcs: Any, dst: Any, cell: float, *,
                          max_samples: int = MAX_SAMPLES) -> GroundModel | None:
    """The ground model of DEMs in priority order, or None if too large or without data.

    Parameters
    ----------
    dems : DemRaster or list of them
        The rasters as read (NaN where masked, ``sea_level`` applied), priority order.
    srcs : CRS or list of them
        Their CRSs; ``dst`` the world's.
    cell : float
        The world's smallest horizontal cell [m] (the model is kept at any cell
        size; the argument stays for callers).
    max_samples : int
        Largest number of pixels kept, all layers together.
    """
    from .geo import crs_label, parse_crs

    if not isinstance(dems, (list, tuple)):
        dems, srcs = [dems], [srcs]
    if sum(int(np.asarray(d.z).size) for d in dems) > max_samples:
        return None
    layers = []
    dst_s = parse_crs(dst).to_wkt()
    for dem, src in zip(dems, srcs):
        z = np.asarray(dem.z, dtype=float)
        if z.ndim != 2 or min(z.shape) < 2:
            return None
        pixel = _pixel_metres(dem, src, dst)
        bad = ~np.isfinite(z)
        if not (np.isfinite(pixel) and pixel > 0) or bad.all():
            return None
        if bad.any():
            _, (ii, jj) = ndimage.distance_transform_edt(bad, return_indices=True)
            z = z[ii, jj]
        name = Path(dem.sources[0].path).name if getattr(dem, "sources", ()) else "array"
        layers.append(GroundLayer(z, ~bad, tuple(float(v) for v in dem.transform),
                                  parse_crs(src).to_wkt(), dst_s, float(pixel), name,
                                  _pixel_metres(dem, src, dst, larger=True)))
    desc = "; ".join(f"{'fill: ' if k else ''}{layer.name} ({layer.z.shape[0]} x "
                     f"{layer.z.shape[1]} pixels of {layer.pixel_m:.1f} m, "
                     f"{crs_label(layer.crs)})" for k, layer in enumerate(layers))
    return GroundModel(tuple(layers), f"source DEM {desc}, bilinear between pixel centres")
