"""Worlds from digital elevation models (GeoTIFF via rasterio, or arrays).

``from_dem(source, cell_size, ceiling)``:

1. **Read.** A path is opened with rasterio (band 1, its affine transform, CRS
   and nodata value); an array needs ``transform=`` (or ``bounds=``) and
   ``crs=``. Rows run north → south, as in every north-up raster.
2. **CRS.** The world is built in a metric CRS: the DEM's own if projected in
   metres, else (geographic, degrees) the UTM zone of the DEM's centre
   (:func:`fm2uav.world.geo.metric_crs`). It is stored as ``World.crs`` so that
   paths convert to lon/lat/alt (:func:`fm2uav.world.geo.to_lonlat`).
3. **Resample.** World nodes are laid every ``cell_size`` metres over the
   largest axis-aligned rectangle of the metric CRS that lies inside the DEM's
   pixel-centre footprint; each node's elevation is the bilinear interpolation
   of the four surrounding pixel centres (after pyproj maps the node back to
   the DEM's CRS).
4. **Nodata rule.** A node is *missing* if any of its four pixels is nodata or
   NaN. ``nodata="error"`` (default) refuses such a DEM with a message giving
   the count and the first missing node's lon/lat; ``nodata="fill"`` gives
   each missing node the elevation of the nearest valid node (refused if more
   than half the nodes are missing).
5. **Voxels.** The vertical axis spans from one cell under the lowest ground to
   ``ceiling`` (altitude of the top node in the DEM's datum, default the
   highest ground plus 20 cells) every ``dz`` metres; ``World.from_heightmap``
   fills the ground.
"""

from __future__ import annotations

import dataclasses
from os import PathLike
from typing import Any

import numpy as np
from scipy import ndimage

from ..errors import InputError, WorldError
from .geo import WGS84, metric_crs, parse_crs, transformer

__all__ = ["from_dem", "read_dem", "DemRaster"]


@dataclasses.dataclass(frozen=True)
class DemRaster:
    """A north-up raster: ``z[row, col]``, affine ``transform`` (a, b, c, d, e, f)
    mapping (col, row) pixel-corner coordinates to CRS x/y, and its CRS string."""

    z: np.ndarray
    transform: tuple[float, float, float, float, float, float]
    crs: str


def _affine(transform: Any) -> tuple[float, ...]:
    t = tuple(float(v) for v in list(transform)[:6])
    if len(t) != 6 or not all(np.isfinite(t)):
        raise InputError(f"transform must be 6 finite numbers (a, b, c, d, e, f), got {transform!r}")
    if t[0] * t[4] - t[1] * t[3] == 0:
        raise InputError(f"transform {t} is singular (zero pixel size)")
    return t


def read_dem(
    source: Any,
    *,
    crs: Any = None,
    transform: Any = None,
    bounds: Any = None,
    nodata: float | None = None,
) -> DemRaster:
    """Read a DEM into a :class:`DemRaster`, nodata → NaN.

    Parameters
    ----------
    source : str, PathLike or array_like (rows, cols)
        GeoTIFF path (rasterio) or elevations [m], rows north → south.
    crs : optional
        CRS of the raster; required for an array or a file without one.
    transform : 6 numbers, optional
        Affine pixel → CRS transform (rasterio/GDAL order a, b, c, d, e, f).
    bounds : (west, south, east, north), optional
        Raster edges in CRS units, instead of ``transform`` for an array.
    nodata : float, optional
        Value marking missing elevations (besides NaN); a file's own nodata is
        used if not given.
    """
    if isinstance(source, (str, PathLike)):
        import rasterio
        from rasterio.errors import RasterioIOError

        try:
            with rasterio.open(source) as ds:
                z = ds.read(1).astype(float)
                t = tuple(ds.transform)[:6]
                file_crs = ds.crs.to_string() if ds.crs else None
                file_nodata = ds.nodata
        except RasterioIOError as exc:
            raise InputError(f"cannot read the DEM {str(source)!r}: {exc}") from None
        if nodata is None:
            nodata = file_nodata
        crs_s = crs if crs is not None else file_crs
        if transform is not None:
            t = _affine(transform)
    else:
        try:
            z = np.array(source, dtype=float)
        except (TypeError, ValueError):
            raise InputError(
                f"DEM must be a GeoTIFF path or a 2D array of elevations, got {type(source).__name__}"
            ) from None
        if z.ndim != 2:
            raise InputError(f"DEM array must be 2D (rows, cols), got shape {z.shape}")
        if transform is not None:
            t = _affine(transform)
        elif bounds is not None:
            w, s, e, n = (float(v) for v in bounds)
            if not (e > w and n > s):
                raise InputError(f"bounds must be (west, south, east, north) with east > west "
                                 f"and north > south, got {bounds!r}")
            t = ((e - w) / z.shape[1], 0.0, w, 0.0, -(n - s) / z.shape[0], n)
        else:
            raise InputError("a DEM array needs transform= or bounds= to place it")
        crs_s = crs
    if z.size < 4 or min(z.shape) < 2:
        raise InputError(f"DEM must have at least 2 x 2 pixels, got {z.shape}")
    c = parse_crs(crs_s)
    z = z.copy()
    if nodata is not None and np.isfinite(nodata):
        z[z == nodata] = np.nan
    z[~np.isfinite(z)] = np.nan
    return DemRaster(z=z, transform=_affine(t), crs=c.to_string())


def from_dem(
    source: Any,
    cell_size: float | tuple[float, float, float],
    ceiling: float | None = None,
    *,
    crs: Any = None,
    transform: Any = None,
    bounds: Any = None,
    nodata: str = "error",
    nodata_value: float | None = None,
    name: str = "",
) -> Any:
    """Build a 3D :class:`~fm2uav.World` from a DEM (see the module docstring).

    Parameters
    ----------
    source : str, PathLike or array_like (rows, cols)
        GeoTIFF path or elevation array [m] (rows north → south).
    cell_size : float or (dx, dy, dz)
        Node spacing of the world [m]; one number for all axes.
    ceiling : float, optional
        Altitude [m, DEM datum] of the top node; default highest ground + 20 dz.
    crs, transform, bounds :
        Placement of an array (or override a file's), see :func:`read_dem`.
    nodata : {"error", "fill"}
        What to do with nodes that touch nodata/NaN pixels. Default "error".
    nodata_value : float, optional
        Elevation value meaning "missing" (a file's own nodata by default).
    name : str
        World name.

    Returns
    -------
    World
        With ``terrain`` (resampled elevations), ``crs`` (metric CRS of x/y)
        and ``origin`` in that CRS [m].

    Raises
    ------
    WorldError
        No/unknown/wrong CRS, nodata under the map, ceiling not above the ground.
    InputError
        Bad cell size or arguments.
    """
    from .world import World

    cs = np.atleast_1d(np.asarray(cell_size, dtype=float))
    if cs.size not in (1, 3) or not np.all(np.isfinite(cs)) or np.any(cs <= 0):
        raise InputError(f"cell_size must be > 0 metres (one number or dx, dy, dz), got {cell_size!r}")
    dx, dy, dz = (float(v) for v in np.broadcast_to(cs, (3,)))
    if nodata not in ("error", "fill"):
        raise InputError(f"nodata must be 'error' or 'fill', got {nodata!r}")
    dem = read_dem(source, crs=crs, transform=transform, bounds=bounds, nodata=nodata_value)
    rows, cols = dem.z.shape
    a, b, c, d, e, f = dem.transform
    src = parse_crs(dem.crs)

    # pixel-centre coordinates in the DEM's CRS
    cc, rr = np.meshgrid(np.arange(cols) + 0.5, np.arange(rows) + 0.5)
    px = a * cc + b * rr + c
    py = d * cc + e * rr + f
    if src.is_geographic:
        if (np.nanmax(np.abs(px)) > 180.0) or (np.nanmax(np.abs(py)) > 90.0):
            raise WorldError(
                f"the DEM is declared in the geographic CRS {dem.crs!r} but its coordinates "
                f"reach x = {np.abs(px).max():.6g}, y = {np.abs(py).max():.6g}, outside "
                "longitude/latitude degrees; the CRS is wrong — give the right one with crs="
            )
        lon_c, lat_c = float(px.mean()), float(py.mean())
    else:
        lon_c, lat_c = transformer(src, WGS84).transform(float(px.mean()), float(py.mean()))
    dst = metric_crs(src, lon_c, lat_c)
    fwd = transformer(src, dst)
    # footprint of the pixel centres in the metric CRS, then an inner box
    edge = np.linspace(0, 1, 64)
    r_idx = np.concatenate([np.zeros(64), edge * (rows - 1), np.full(64, rows - 1), edge * (rows - 1)])
    c_idx = np.concatenate([edge * (cols - 1), np.full(64, cols - 1), edge * (cols - 1), np.zeros(64)])
    ex, ey = fwd.transform(a * (c_idx + 0.5) + b * (r_idx + 0.5) + c,
                           d * (c_idx + 0.5) + e * (r_idx + 0.5) + f)
    ex, ey = np.asarray(ex), np.asarray(ey)
    top, right, bottom, left = (slice(0, 64), slice(64, 128), slice(128, 192), slice(192, 256))
    west, east = ex[left].max(), ex[right].min()
    north, south = ey[top].min(), ey[bottom].max()
    if not (east > west and north > south):
        raise WorldError(f"the DEM footprint in {dst} is degenerate; is the transform/CRS right?")
    nx = int(np.floor((east - west) / dx + 1e-9)) + 1
    ny = int(np.floor((north - south) / dy + 1e-9)) + 1
    if nx < 2 or ny < 2:
        raise InputError(
            f"cell_size {dx:g} x {dy:g} m leaves fewer than 2 x 2 nodes on a DEM of "
            f"{east - west:.0f} x {north - south:.0f} m; use a smaller cell_size"
        )
    gx = west + np.arange(nx) * dx
    gy = south + np.arange(ny) * dy
    X, Y = np.meshgrid(gx, gy, indexing="ij")  # (nx, ny), x first
    sx, sy = transformer(dst, src).transform(X.ravel(), Y.ravel())
    sx, sy = np.asarray(sx), np.asarray(sy)
    det = a * e - b * d
    col = (e * (sx - c) - b * (sy - f)) / det - 0.5
    row = (-d * (sx - c) + a * (sy - f)) / det - 0.5
    heights = ndimage.map_coordinates(dem.z, [row, col], order=1, mode="nearest",
                                      prefilter=False).reshape(nx, ny)
    missing = ~np.isfinite(heights)
    if missing.any():
        n_miss = int(missing.sum())
        i, j = np.argwhere(missing)[0]
        lon, lat = transformer(dst, WGS84).transform(float(gx[i]), float(gy[j]))
        if nodata == "error":
            raise WorldError(
                f"the DEM has nodata/NaN under {n_miss} of {missing.size} world nodes, first at "
                f"node ({i}, {j}) = lon {lon:.5f}, lat {lat:.5f}; fill the gaps first, crop the "
                "DEM, or pass nodata='fill' to take the nearest valid elevation"
            )
        if n_miss * 2 > missing.size:
            raise WorldError(
                f"the DEM has nodata under {n_miss} of {missing.size} world nodes (more than "
                "half); nodata='fill' would invent most of the terrain — crop the DEM to its data"
            )
        _, (ii, jj) = ndimage.distance_transform_edt(missing, return_indices=True)
        heights = heights[ii, jj]
    hmin, hmax = float(heights.min()), float(heights.max())
    z0 = (np.floor(hmin / dz) - 1.0) * dz
    top_alt = hmax + 20.0 * dz if ceiling is None else float(ceiling)
    if not np.isfinite(top_alt) or top_alt < hmax + dz:
        raise WorldError(
            f"ceiling = {top_alt:g} m must be at least one cell ({dz:g} m) above the highest "
            f"ground {hmax:.1f} m of the DEM; raise it (e.g. ceiling={hmax + 20 * dz:.0f})"
        )
    nz = int(np.floor((top_alt - z0) / dz + 1e-9)) + 1
    w = World.from_heightmap(heights, (dx, dy, dz), nz, origin=(west, south, z0), name=name)
    return dataclasses.replace(w, crs=dst, name=name or "dem")
