"""DEMs given as a plain elevation array with lon/lat coordinate vectors (the xarray layout).

:func:`lonlat_raster` turns ``z[i_lat, i_lon]`` with its ``lon`` (0..360 or
-180..180) and ``lat`` (either order) vectors into a north-up raster in
EPSG:4326; :func:`fm2uav.world.dem.from_lonlat_grid` builds the world from it.
Irregular rows or columns (e.g. rows regular in Mercator) are first
interpolated linearly onto a regular grid of their finest step.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ..errors import InputError

__all__ = ["lonlat_raster"]


def _regular(v: np.ndarray) -> bool:
    step = np.diff(v)
    return bool(np.all(np.abs(step - step.mean()) <= 1e-6 * max(abs(step.mean()), 1e-12)))


def _to_regular(z: np.ndarray, coord: np.ndarray, axis: int) -> tuple[np.ndarray, np.ndarray]:
    """Linear interpolation of ``z`` along ``axis`` onto a regular grid of the finest step."""
    step = float(np.min(np.diff(coord)))
    n = int(np.floor((coord[-1] - coord[0]) / step + 1e-9)) + 1
    reg = coord[0] + np.arange(n) * step
    pos = np.interp(reg, coord, np.arange(len(coord), dtype=float))
    i0 = np.clip(np.floor(pos).astype(int), 0, len(coord) - 2)
    fr = pos - i0
    zz = np.moveaxis(z, axis, 0)
    a, b = zz[i0], zz[i0 + 1]
    shape = (-1,) + (1,) * (zz.ndim - 1)
    w1 = fr.reshape(shape)
    # NaN only where a contributing sample is missing (0 * NaN stays NaN)
    out = np.where(w1 == 0, a, np.where(w1 == 1, b, a * (1 - w1) + b * w1))
    return np.moveaxis(out, 0, axis), reg


def lonlat_raster(z: Any, lon: Any, lat: Any) -> tuple[np.ndarray, tuple[float, ...]]:
    """A north-up EPSG:4326 raster ``(z, transform)`` from ``z[i_lat, i_lon]`` [m] and its
    pixel-centre ``lon`` (0..360 or -180..180) and ``lat`` (either order) vectors [deg].

    Irregular rows or columns (e.g. rows regular in Mercator) are first interpolated
    linearly onto a regular grid of their finest step.

    Raises
    ------
    InputError
        Shapes that do not match (a transposed array is named), coordinates not
        monotonic or out of range, a grid across the antimeridian.
    """
    try:
        zz = np.array(z, dtype=float)
        lo = np.array(lon, dtype=float).ravel()
        la = np.array(lat, dtype=float).ravel()
    except (TypeError, ValueError):
        raise InputError("z, lon and lat must be numeric arrays (z[i_lat, i_lon] in metres, "
                         "lon and lat in degrees)") from None
    if zz.ndim != 2:
        raise InputError(f"z must be 2D (n_lat, n_lon), got shape {zz.shape}")
    if zz.shape != (la.size, lo.size):
        if zz.shape == (lo.size, la.size):
            raise InputError(
                f"z has shape {zz.shape} = (n_lon, n_lat); give z[i_lat, i_lon] (pass z.T, or "
                "da.transpose('lat', 'lon') for an xarray DataArray)")
        raise InputError(f"z has shape {zz.shape} but lat has {la.size} and lon {lo.size} "
                         "values; z must be (n_lat, n_lon)")
    if lo.size < 2 or la.size < 2 or not (np.all(np.isfinite(lo)) and np.all(np.isfinite(la))):
        raise InputError("lon and lat need at least 2 finite values each")
    if np.any(np.abs(la) > 90) or lo.min() < -180 or lo.max() > 360:
        raise InputError(f"lon must be in -180..180 or 0..360 and lat in -90..90 degrees; got "
                         f"lon {lo.min():g}..{lo.max():g}, lat {la.min():g}..{la.max():g}")
    if lo.max() > 180:
        lo = np.where(lo > 180, lo - 360.0, lo)  # 0..360 -> -180..180
    o = np.argsort(lo, kind="stable")
    lo, zz = lo[o], zz[:, o]
    if np.any(np.diff(lo) <= 0):
        raise InputError("lon has repeated values (after mapping 0..360 to -180..180); give "
                         "strictly monotonic pixel-centre longitudes")
    if np.max(np.diff(lo)) > 10 * np.min(np.diff(lo)):
        raise InputError(
            f"the grid crosses the antimeridian or has a gap (lon steps from "
            f"{np.min(np.diff(lo)):g} to {np.max(np.diff(lo)):g} deg); crop it to one side first")
    if la[0] > la[-1]:
        la, zz = la[::-1], zz[::-1]
    if np.any(np.diff(la) <= 0):
        raise InputError("lat must be strictly monotonic (increasing or decreasing)")
    if not _regular(lo):
        zz, lo = _to_regular(zz, lo, axis=1)
    if not _regular(la):
        zz, la = _to_regular(zz, la, axis=0)
    rx = float(lo[1] - lo[0])
    ry = float(la[1] - la[0])
    # north-up raster: row 0 = northernmost latitude
    zz = zz[::-1]
    transform = (rx, 0.0, float(lo[0]) - 0.5 * rx, 0.0, -ry, float(la[-1]) + 0.5 * ry)
    return zz, transform
