"""DEMs in priority order: the gaps of one filled from the next, at the world's nodes.

``world.dem`` may be one file or *tiles* of one DEM (same CRS, merged into one
raster). ``world.dem_fill`` (CLI ``--dem-fill FILE``, repeatable) lists more
DEMs in **priority order** — e.g. a 30 m national model under a 1 m survey, or
the neighbour country's DEM beside a country-shaped one — each in its own CRS
and at its own resolution. Each is resampled to the world's nodes
(:func:`resample`: the bilinear point value, and whether all four pixels
around the node are measured); a node takes its height from the first DEM that
measures it (:func:`composite`). What none measures is *unknown ground*: the
``world.nodata`` rule decides (refused, or filled and marked in
``World.filled``).

Where two DEMs both measure the ground, their median difference is recorded:
tens of metres usually mean different vertical datums (ellipsoidal heights
against heights above the geoid), which would put a step into the ground the
flight follows.
"""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np

__all__ = ["Composite", "resample", "composite", "DATUM_WARNING_M"]

#: A median difference [m] between two DEMs over their common ground above which the
#: summary warns of different vertical datums.
DATUM_WARNING_M = 10.0


def resample(dem: Any, src: Any, dst: Any, west: float, north: float, dx: float, dy: float,
             nx: int, ny: int) -> tuple[np.ndarray, np.ndarray]:
    """Bilinear heights and validity (all four pixels valid) at the world nodes, ``(nx, ny)``.

    ``rasterio.warp.reproject`` with ``XSCALE=YSCALE=1``: the point value of the
    bilinear surface through the four pixel centres around each node, with no
    low-pass kernel when the cells are coarser than the pixels. Outside the
    raster the height is NaN and the node not valid.
    """
    from affine import Affine
    from rasterio.crs import CRS as RioCRS
    from rasterio.warp import Resampling, reproject

    from .geo import parse_crs

    src_t = Affine(*dem.transform)
    dst_t = Affine(dx, 0.0, west - 0.5 * dx, 0.0, -dy, north + 0.5 * dy)
    src_rio = RioCRS.from_wkt(parse_crs(src).to_wkt())
    dst_rio = RioCRS.from_wkt(parse_crs(dst).to_wkt())
    out = np.full((ny, nx), np.nan)
    opts = {"XSCALE": 1, "YSCALE": 1}  # point bilinear: no low-pass kernel when downsampling
    reproject(dem.z, out, src_transform=src_t, src_crs=src_rio, dst_transform=dst_t,
              dst_crs=dst_rio, resampling=Resampling.bilinear, src_nodata=np.nan,
              dst_nodata=np.nan, **opts)
    ok = np.isfinite(dem.z).astype(np.float64)
    vout = np.zeros((ny, nx))
    reproject(ok, vout, src_transform=src_t, src_crs=src_rio, dst_transform=dst_t,
              dst_crs=dst_rio, resampling=Resampling.bilinear, src_nodata=None,
              dst_nodata=None, init_dest_nodata=False, **opts)
    heights = out[::-1].T.copy()
    valid = (vout[::-1].T >= 1.0 - 1e-6) & np.isfinite(heights)
    return heights, valid


@dataclasses.dataclass(frozen=True)
class Composite:
    """The ground at the world's nodes from DEMs in priority order.

    Attributes
    ----------
    heights : ndarray (nx, ny)
        The first measuring DEM's height; where none measures, the first DEM's
        value from its valid pixels (GDAL's renormalised bilinear), else NaN.
    valid : ndarray of bool (nx, ny)
        Whether some DEM measures the node.
    source : ndarray of int8 (nx, ny)
        Index of the DEM that measures the node, -1 for none.
    measured : tuple of int
        Nodes each DEM supplies.
    offsets : tuple of (float or None)
        Per DEM after the first: median of (its height - the first's) where
        both measure [m] (None without common ground).
    """

    heights: np.ndarray
    valid: np.ndarray
    source: np.ndarray
    measured: tuple[int, ...]
    offsets: tuple[float | None, ...]


def composite(levels: list[Any], srcs: list[Any], dst: Any, west: float, north: float,
              dx: float, dy: float, nx: int, ny: int) -> Composite:
    """:class:`Composite` of the DEMs ``levels`` (priority order) in CRSs ``srcs``."""
    heights = np.full((nx, ny), np.nan)
    partial = np.full((nx, ny), np.nan)
    valid = np.zeros((nx, ny), dtype=bool)
    source = np.full((nx, ny), -1, dtype=np.int8)
    measured: list[int] = []
    offsets: list[float | None] = []
    first: tuple[np.ndarray, np.ndarray] | None = None
    for k, (dem, src) in enumerate(zip(levels, srcs)):
        h, v = resample(dem, src, dst, west, north, dx, dy, nx, ny)
        take = v & ~valid
        heights[take] = h[take]
        source[take] = k
        valid |= v
        measured.append(int(take.sum()))
        gap = ~np.isfinite(partial) & np.isfinite(h)
        partial[gap] = h[gap]
        if first is None:
            first = (h, v)
        else:
            both = first[1] & v
            offsets.append(float(np.median(h[both] - first[0][both])) if both.sum() >= 10
                           else None)
    heights = np.where(valid, heights, partial)
    return Composite(heights, valid, source, tuple(measured), tuple(offsets))
