"""Reading a DEM: one raster, the tiles of one DEM, or an array (:func:`read_dem`).

A path is opened with rasterio (any raster GDAL reads: GeoTIFF, VRT, SRTM
``.hgt``, ...); several paths are tiles of one DEM, merged with
``rasterio.merge`` on their own pixel grid. Band 1 is read with
``masked=True`` (nodata value, NaN, mask and alpha bands), then the numbers go
through the steps of :mod:`fm2uav.world.dem_values` in this order: crop (only
the window of ``bbox`` is read, rotated geotransforms included) → nodata
(declared, ``nodata``, undeclared sentinels found and said once) → scale,
offset and unit → ``sea_level`` clamp → plausibility by slope. Rasters that
are not elevation are refused before any pixel is read.
"""

from __future__ import annotations

import dataclasses
import warnings
from collections.abc import Sequence
from os import PathLike
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import InputError, WorldError
from .dem_values import (
    Sentinel,
    check_plausible,
    find_sentinels,
    length_unit_factor,
    pixel_sizes,
    raster_problem,
)
from .geo import (
    WGS84,
    SourceFile,
    check_fit,
    check_lonlat_bbox,
    crs_label,
    parse_crs,
    sha256_file,
    transformer,
)
from .quiet import GeodataWarning

__all__ = ["read_dem", "DemRaster"]

_CRS_HINT = "world.crs (CLI --crs)"


@dataclasses.dataclass(frozen=True)
class DemRaster:
    """A raster read by :func:`read_dem` (north-up or with a rotated geotransform).

    Attributes
    ----------
    z : ndarray (rows, cols)
        Elevations [m] (scale/offset and unit applied, nodata and undeclared
        sentinels NaN, ``sea_level`` applied).
    transform : 6 floats
        Affine ``(a, b, c, d, e, f)`` from (col, row) pixel-corner coordinates
        to CRS x/y.
    crs : str
        Horizontal CRS (WKT or authority string).
    vertical_crs : str or None
        Name of the declared vertical CRS (e.g. ``"EGM96 height"``).
    vertical_note : str
        What the elevations are when no vertical CRS is declared.
    sources : tuple of SourceFile
        The files read (empty for an array).
    undeclared : tuple of Sentinel
        Undeclared nodata values found (and taken as nodata).
    label : str
        What the raster is, for messages (``"the DEM dem.tif"``).
    """

    z: np.ndarray
    transform: tuple[float, float, float, float, float, float]
    crs: str
    vertical_crs: str | None = None
    vertical_note: str = ""
    sources: tuple[SourceFile, ...] = ()
    undeclared: tuple[Sentinel, ...] = ()
    label: str = "the DEM"


def _affine(transform: Any) -> tuple[float, ...]:
    t = tuple(float(v) for v in list(transform)[:6])
    if len(t) != 6 or not all(np.isfinite(t)):
        raise InputError(f"transform must be 6 finite numbers (a, b, c, d, e, f), got {transform!r}")
    if t[0] * t[4] - t[1] * t[3] == 0:
        raise InputError(f"transform {t} is singular (zero pixel size)")
    return t


def _split_crs(crs: Any) -> tuple[Any, str | None, float]:
    """(horizontal pyproj CRS, vertical CRS name or None, vertical unit in metres)."""
    c = parse_crs(crs)
    vname, factor = None, 1.0
    if c.is_compound:
        subs = c.sub_crs_list
        h = next((s for s in subs if s.is_geographic or s.is_projected), subs[0])
        v = next((s for s in subs if s.is_vertical), None)
        if v is not None:
            vname = v.name
            if v.axis_info:
                factor = float(v.axis_info[0].unit_conversion_factor)
        c = h
    return c, vname, factor


def _json_number(v: Any) -> Any:
    """A nodata value for JSON: NaN and infinities as text (``"nan"``), numbers as they are."""
    if v is None:
        return None
    f = float(v)
    return f if np.isfinite(f) else str(f)


def _bbox_in(crs: Any, bbox: tuple[float, float, float, float]) -> tuple[float, float, float, float]:
    """Outer bounds of a lon/lat box in ``crs`` (edges densified)."""
    x, y = _projected_edges(bbox, WGS84, crs)
    if not x.size:
        raise WorldError(f"bbox {bbox} cannot be projected to {crs_label(crs)}")
    return float(x.min()), float(y.min()), float(x.max()), float(y.max())


def _projected_edges(rect: tuple[float, float, float, float], rect_crs: Any, crs: Any
                     ) -> tuple[np.ndarray, np.ndarray]:
    """The edges of a rectangle given in ``rect_crs``, 65 points each, projected to ``crs``
    (the finite points only)."""
    x0, y0, x1, y1 = rect
    t = np.linspace(0.0, 1.0, 65)
    x = np.concatenate([x0 + (x1 - x0) * t, np.full(65, x1), x1 - (x1 - x0) * t, np.full(65, x0)])
    y = np.concatenate([np.full(65, y0), y0 + (y1 - y0) * t, np.full(65, y1), y1 - (y1 - y0) * t])
    u, v = transformer(rect_crs, crs).transform(x, y)
    u, v = np.asarray(u), np.asarray(v)
    ok = np.isfinite(u) & np.isfinite(v)
    return u[ok], v[ok]


def _vertical_note(driver: str) -> str:
    if driver.upper() == "SRTMHGT":
        return ("assumed metres above the EGM96 geoid (mean sea level), the SRTM .hgt "
                "convention; the file declares no vertical CRS")
    return ("assumed metres above mean sea level (a geoid such as EGM96/EGM2008); the raster "
            "declares no vertical CRS")


def _rect_in(rect: tuple[float, float, float, float], rect_crs: Any, crs: Any
             ) -> tuple[float, float, float, float]:
    """Outer bounds in ``crs`` of a rectangle given in ``rect_crs`` (edges densified)."""
    u, v = _projected_edges(rect, rect_crs, crs)
    return float(u.min()), float(v.min()), float(u.max()), float(v.max())


@dataclasses.dataclass
class _Raw:
    """Stored numbers of a raster (NaN where masked) and how they become metres."""

    z: np.ndarray
    transform: tuple[float, ...]
    h_crs: Any
    vname: str | None
    note: str
    sources: list[SourceFile]
    scale: float = 1.0
    offset: float = 0.0
    factor: float = 1.0
    dtype: Any = None

    def metres(self, v: np.ndarray) -> np.ndarray:
        """Stored values → elevations [m]."""
        return (np.asarray(v, dtype=float) * self.scale + self.offset) * self.factor


def _open_dem(p: Path) -> Any:
    """An open rasterio dataset of a DEM file, refused when it is not one."""
    import rasterio
    from rasterio.errors import RasterioIOError

    from .. import _validate as v

    if not p.exists():
        raise InputError(f"cannot read the DEM {str(p)!r}: the file does not exist; "
                         "check world.dem / --dem")
    v.input_file(p, "the DEM", where=("world.dem", "--dem"))  # no folder / pipe
    try:
        ds = rasterio.open(p)
    except RasterioIOError as exc:
        raise InputError(f"cannot read the DEM {str(p)!r}: {exc}") from None
    problem = raster_problem(ds, p)
    if problem is not None:
        ds.close()
        raise InputError(problem)
    return ds


def _half_float(ds: Any) -> bool:
    """Whether a float32 band is stored as half-precision floats (float16, NBITS=16)."""
    try:
        nbits = ds.tags(1, ns="IMAGE_STRUCTURE").get("NBITS") or \
            ds.tags(ns="IMAGE_STRUCTURE").get("NBITS")
    except Exception:  # drivers without the namespace
        nbits = None
    return str(ds.dtypes[0]) == "float32" and str(nbits) == "16"


def _read_files(paths: list[Path], crs: Any, bbox: tuple[float, float, float, float] | None,
                window_crs: Any = None) -> _Raw:
    datasets = []
    try:
        for p in paths:
            datasets.append(_open_dem(p))
        crss = _tile_crss(paths, datasets, crs)
        scales = {(float(ds.scales[0] or 1.0), float(ds.offsets[0] or 0.0)) for ds in datasets}
        if len(scales) > 1:
            raise WorldError(
                f"the DEM tiles have different scale/offset values {sorted(scales)}; unscale them "
                "first (gdal_translate -unscale) so that one merge applies to all")
        scale, offset = scales.pop()
        units = {length_unit_factor(ds.units[0] if ds.units else None) for ds in datasets}
        unit_factor = units.pop() if len(units) == 1 else None
        if unit_factor is None:
            raise WorldError("the DEM tiles have different elevation units; convert them to "
                             "metres first")
        h_crs, vname, vfactor = _split_crs(crss[0])
        first = datasets[0]
        window_bounds = None
        if bbox is not None:
            # the world's rectangle is the bbox's outer box in the world's CRS: read the
            # source window that covers all of it (a rotated rectangle in the source CRS)
            bx = (_bbox_in(h_crs, bbox) if window_crs is None
                  else _rect_in(_bbox_in(window_crs, bbox), window_crs, h_crs))
            t0 = first.transform
            res = max(np.hypot(t0.a, t0.d), np.hypot(t0.b, t0.e))  # rotated: its own axes
            window_bounds = (bx[0] - 2 * res, bx[1] - 2 * res, bx[2] + 2 * res, bx[3] + 2 * res)
        if len(datasets) == 1:
            z, t = _read_one(first, paths[0], window_bounds, bbox, h_crs)
        else:
            z, t = _merge_tiles(datasets, window_bounds, bbox, h_crs)
        factor = unit_factor if unit_factor != 1.0 else vfactor
        half = _half_float(first)
        sources = []
        for p, ds in zip(paths, datasets):
            t1 = ds.transform
            sources.append(SourceFile(
                path=str(p), role="dem", sha256=sha256_file(p), crs=crs_label(crss[0]),
                crs_rule="declared by the file" if ds.crs is not None else "given (world.crs / --crs)",
                details={"driver": ds.driver, "size_px": [ds.height, ds.width],
                         "pixel_size": [float(np.hypot(t1.a, t1.d)), float(np.hypot(t1.b, t1.e))],
                         "dtype": "float16" if _half_float(ds) else str(ds.dtypes[0]),
                         **({"rotation_deg": round(float(np.degrees(np.arctan2(t1.d, t1.a))), 3)}
                            if t1.b or t1.d else {}),
                         **({"scale": scale, "offset": offset}
                            if (scale, offset) != (1.0, 0.0) else {}),
                         **({"unit_factor": factor} if factor != 1.0 else {}),
                         **({"nodata": _json_number(ds.nodata)} if ds.nodata is not None
                            else {})}))
        note = _vertical_note(first.driver)
        return _Raw(z, tuple(t)[:6], h_crs, vname, note, sources, scale, offset, factor,
                    "float16" if half else first.dtypes[0])
    finally:
        for ds in datasets:
            ds.close()


def _tile_crss(paths: list[Path], datasets: list[Any], crs: Any) -> list[Any]:
    """The horizontal CRS of each DEM tile (its own, else ``crs``); all must agree."""
    crss = []
    for p, ds in zip(paths, datasets):
        if ds.crs is None and crs is None:
            raise WorldError(
                f"the DEM {p} has no coordinate reference system; give it with {_CRS_HINT} "
                "(e.g. EPSG:4326 for lon/lat degrees) or assign one "
                "(gdal_edit.py -a_srs EPSG:32630 FILE)")
        if ds.crs is not None and crs is not None and not parse_crs(
                ds.crs.to_wkt()).equals(parse_crs(crs), ignore_axis_order=True):
            raise WorldError(
                f"the DEM {p} declares its CRS {crs_label(ds.crs.to_wkt())}, but {_CRS_HINT} "
                f"says {crs_label(crs)}; remove world.crs / --crs (it is only for files "
                "that declare none) or fix the file")
        crss.append(parse_crs(ds.crs.to_wkt()) if ds.crs is not None else parse_crs(crs))
    if any(not c.equals(crss[0], ignore_axis_order=True) for c in crss[1:]):
        raise WorldError(
            f"the DEM tiles are in different CRSs ({', '.join(sorted({crs_label(c) for c in crss}))}); "
            "reproject them to one CRS first (gdalwarp -t_srs EPSG:4326 ...) or build a VRT")
    return crss


def _read_one(first: Any, path: Path, window_bounds: tuple[float, ...] | None, bbox: Any,
              h_crs: Any) -> tuple[np.ndarray, Any]:
    """Pixels (masked → NaN) and transform of one open DEM, in ``window_bounds`` if given."""
    from rasterio.errors import RasterioIOError
    from rasterio.windows import Window

    win = None
    if window_bounds is not None:
        full = Window(0, 0, first.width, first.height)
        # the pixel box of the bounds' four corners: any affine, rotated ones included
        # (rasterio's from_bounds refuses a rotated geotransform)
        x0, y0, x1, y1 = window_bounds
        cols, rows = ~first.transform * (np.array([x0, x1, x0, x1]), np.array([y0, y0, y1, y1]))
        c0, r0 = np.floor(np.min(cols)), np.floor(np.min(rows))
        w = Window(c0, r0, np.ceil(np.max(cols)) - c0, np.ceil(np.max(rows)) - r0)
        try:
            win = w.intersection(full)
        except Exception:  # rasterio.errors.WindowError: no overlap
            win = None
        if win is None or win.width < 2 or win.height < 2:
            b = first.bounds
            raise InputError(_no_overlap(bbox, h_crs, (b.left, b.bottom, b.right, b.top)))
    try:  # a truncated or corrupt file opens (header) but fails here
        band = first.read(1, masked=True, window=win, out_dtype="float64")
        t = first.window_transform(win) if win is not None else first.transform
        z = np.ma.filled(band, np.nan)
        z = _apply_alpha(first, z, win)
    except RasterioIOError as exc:
        raise InputError(
            f"cannot read the pixels of the DEM {str(path)!r} (truncated or corrupt "
            f"file: {exc}); check world.dem / --dem, re-download or repair it "
            "(gdalinfo -checksum FILE shows the broken blocks)") from None
    return z, t


def _merge_tiles(datasets: list[Any], window_bounds: tuple[float, ...] | None, bbox: Any,
                 h_crs: Any) -> tuple[np.ndarray, Any]:
    """Pixels (masked → NaN) and transform of several open DEM tiles merged, in ``window_bounds``."""
    from rasterio.errors import RasterioIOError
    from rasterio.merge import merge

    kw = {}
    if window_bounds is not None:
        # on the tiles' own pixel grid: bounds off it make merge resample (nearest), which
        # moves the ground by up to half a pixel
        t0 = datasets[0].transform
        a, c, e, f = t0.a, t0.c, t0.e, t0.f
        left = c + np.floor((window_bounds[0] - c) / a) * a
        right = c + np.ceil((window_bounds[2] - c) / a) * a
        top = f + np.floor((window_bounds[3] - f) / e) * e
        bottom = f + np.ceil((window_bounds[1] - f) / e) * e
        kw = {"bounds": (left, min(bottom, top), right, max(bottom, top))}
    try:
        arr, t = merge(datasets, masked=True, dtype="float64", **kw)
    except ValueError as exc:
        raise InputError(f"cannot merge the DEM tiles: {exc}") from None
    except RasterioIOError as exc:
        raise InputError(
            f"cannot read the pixels of a DEM tile (truncated or corrupt file: {exc}); "
            "check world.dem / --dem, re-download or repair it (gdalinfo -checksum "
            "FILE shows the broken blocks)") from None
    z = np.ma.filled(arr[0], np.nan)
    if window_bounds is not None and not np.isfinite(z).any():
        lefts = [ds.bounds for ds in datasets]
        raise InputError(_no_overlap(bbox, h_crs, (
            min(b.left for b in lefts), min(b.bottom for b in lefts),
            max(b.right for b in lefts), max(b.top for b in lefts))))
    return z, t


def _apply_alpha(ds: Any, z: np.ndarray, win: Any) -> np.ndarray:
    """Mask pixels whose alpha band is 0 when GDAL does not (alpha of a float type)."""
    from rasterio.enums import ColorInterp, MaskFlags

    alpha = [i + 1 for i, c in enumerate(ds.colorinterp) if c == ColorInterp.alpha]
    if not alpha or MaskFlags.alpha in ds.mask_flag_enums[0]:
        return z
    a = ds.read(alpha[0], window=win)
    return np.where(a == 0, np.nan, z)


def _no_overlap(bbox: Any, crs: Any, bounds: tuple[float, float, float, float]) -> str:
    lon, lat = transformer(crs, WGS84).transform(
        [bounds[0], bounds[2], bounds[0], bounds[2]], [bounds[1], bounds[1], bounds[3], bounds[3]])
    lon, lat = np.asarray(lon), np.asarray(lat)
    return (f"bbox {','.join(f'{v:g}' for v in bbox)} does not overlap the DEM, which covers "
            f"lon {lon.min():.4f}..{lon.max():.4f}, lat {lat.min():.4f}..{lat.max():.4f}; fix "
            "world.bbox (CLI --bbox W,S,E,N, lon/lat)")


def _read_array(source: Any, crs: Any, transform: Any, bounds: Any) -> _Raw:
    """The stored numbers of an in-memory DEM, its pixel transform and CRSs."""
    try:
        arr = np.asarray(source)
        z = np.array(arr, dtype=float)
    except (TypeError, ValueError):
        raise InputError(
            f"DEM must be a raster file path (or a list of tiles) or a 2D array of "
            f"elevations, got {type(source).__name__}") from None
    if np.iscomplexobj(arr):
        raise InputError("the DEM array is complex, not elevations; give real elevations [m]")
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
    if crs is None:
        raise WorldError(
            "the DEM has no coordinate reference system; pass crs= (e.g. crs='EPSG:4326' "
            "for longitude/latitude degrees or the EPSG code of its projection)")
    h_crs, vname, vfactor = _split_crs(crs)
    return _Raw(z.copy(), t, h_crs, vname, _vertical_note(""), [], factor=vfactor,
                dtype=arr.dtype)


def _lonlat_of(t: tuple[float, ...], h_crs: Any) -> Any:
    """``(row, col)`` → ``"lon ..., lat ..."`` of a pixel centre, for messages."""
    a, b, c, d, e, f = t

    def locate(r: int, col: int) -> str:
        x = a * (col + 0.5) + b * (r + 0.5) + c
        y = d * (col + 0.5) + e * (r + 0.5) + f
        lon, lat = transformer(h_crs, WGS84).transform(x, y)
        return f"lon {float(lon):.5f}, lat {float(lat):.5f}"
    return locate


def _undeclared(raw: _Raw, where: str) -> tuple[Sentinel, ...]:
    """Find undeclared nodata values in ``raw`` (set to NaN) and say so once."""
    dx, dy = pixel_sizes(raw.transform, raw.h_crs, raw.z.shape)
    mask, found = find_sentinels(raw.z, None if raw.dtype == "float16" else raw.dtype,
                                 raw.metres, dx, dy)
    if found:
        raw.z[mask] = np.nan
        v = found[0].value
        warnings.warn(
            f"{where} holds {', '.join(s.describe() for s in found)}: nodata the file does not "
            f"declare, taken as nodata (world.nodata decides what happens under the map); "
            f"declare it to say so (gdal_edit.py -a_nodata {v:g} FILE, or world.nodata_value: "
            f"{v:g}, CLI --nodata-value {v:g})", GeodataWarning, stacklevel=3)
    return tuple(found)


def _half_float_note(z: np.ndarray, where: str) -> None:
    """Warn when half-precision floats round the highest ground to more than a metre."""
    top = float(np.nanmax(np.abs(z)))
    step = float(np.spacing(np.float16(top))) if np.isfinite(top) else 0.0
    if step > 1.0:
        warnings.warn(
            f"{where} stores half-precision floats (float16): elevations near {top:.0f} m are "
            f"rounded to steps of {step:g} m; the heights above ground inherit that rounding",
            GeodataWarning, stacklevel=3)


def _corners(t: tuple[float, ...], shape: tuple[int, int], h_crs: Any,
             ) -> tuple[tuple[float, ...], np.ndarray, np.ndarray]:
    """The raster's corner x and y in its CRS; a lon/lat raster east of 180° shifted to -180..180.

    Returns the (possibly shifted) transform and the corners' x and y.
    """
    a, b, c, d, e, f = t
    rows, cols = shape
    xs = np.array([c, c + a * cols + b * rows, c + a * cols, c + b * rows])
    ys = np.array([f, f + d * cols + e * rows, f + d * cols, f + e * rows])
    if h_crs.is_geographic and xs.min() >= 180.0:
        # a raster in longitudes 0..360 lying east of the antimeridian: -180..180
        c -= 360.0
        xs -= 360.0
        t = (a, b, c, d, e, f)
    return t, xs, ys


def read_dem(
    source: Any,
    *,
    crs: Any = None,
    transform: Any = None,
    bounds: Any = None,
    nodata: float | None = None,
    bbox: Sequence[float] | None = None,
    window_crs: Any = None,
    sea_level: float | None = None,
) -> DemRaster:
    """Read a DEM into a :class:`DemRaster`: crop → nodata → sea level → plausibility.

    Parameters
    ----------
    source : str, PathLike, list of them, or array_like (rows, cols)
        A raster file GDAL reads, several tiles (merged), or elevations [m]
        with rows north → south.
    crs : optional
        CRS of an array, or of a file that declares none (mission file
        ``world.crs``); a file's own CRS must not be contradicted.
    transform : 6 numbers, optional
        Affine pixel → CRS transform (rasterio/GDAL order a, b, c, d, e, f) of
        an array.
    bounds : (west, south, east, north), optional
        Raster edges in CRS units, instead of ``transform`` for an array.
    nodata : float, optional
        A value meaning "missing" that the file does not declare (besides its
        own nodata, mask and alpha bands, NaN, and the sentinels found by
        :func:`fm2uav.world.dem_values.find_sentinels`).
    bbox : (west, south, east, north), optional
        Lon/lat degrees: read only the window covering this box (files).
    window_crs : optional
        The CRS the box will be used in (the world's): the window then covers
        the box's outer rectangle in that CRS.
    sea_level : float, optional
        Water surface [m]: measured pixels below it are raised to it.

    Raises
    ------
    InputError
        Unreadable file, not an elevation raster (RGB/palette image, complex
        band, a unit that is no length), bad array or placement, bbox outside
        the DEM.
    WorldError
        Missing or conflicting CRS, tiles in different CRSs, coordinates that
        do not fit the CRS, elevations no terrain on Earth has
        (:func:`fm2uav.world.dem_values.check_plausible`).
    """
    box = None if bbox is None else check_lonlat_bbox(bbox, "world.bbox (--bbox)")
    paths: list[Path] | None = None
    if isinstance(source, (str, PathLike)):
        paths = [Path(source)]
    elif isinstance(source, (list, tuple)) and source and all(
            isinstance(s, (str, PathLike)) for s in source):
        paths = [Path(s) for s in source]
    if paths is not None:
        raw = _read_files(paths, crs, box, window_crs)
        if transform is not None:
            raw.transform = _affine(transform)
        where = f"the DEM {paths[0]}" + (f" (+{len(paths) - 1} tiles)" if len(paths) > 1 else "")
    else:
        raw = _read_array(source, crs, transform, bounds)
        where = "the DEM array"
    z = raw.z
    if z.size < 4 or min(z.shape) < 2:
        raise InputError(f"DEM must have at least 2 x 2 pixels, got {z.shape}")
    z[~np.isfinite(z)] = np.nan
    t = _affine(raw.transform)
    t, xs, ys = _corners(t, z.shape, raw.h_crs)
    raw.transform = t
    if nodata is not None and np.isfinite(nodata):
        z[z == nodata] = np.nan  # the user's nodata value, on the stored numbers
    found = _undeclared(raw, where) if np.isfinite(z).any() else ()
    if not np.isfinite(z).any():
        raise WorldError(f"{where} has no valid elevation (every pixel is nodata) in the area read; "
                         "check the file, world.nodata_value and world.bbox")
    if raw.h_crs.is_geographic and xs.min() < 180.0 < xs.max():
        raise WorldError(
            f"{where} crosses the antimeridian (longitudes {xs.min():g}..{xs.max():g}); crop it "
            "with world.bbox (CLI --bbox) to one side, or shift it (gdalwarp --config "
            "CENTER_LONG 180)")
    check_fit((xs.min(), ys.min(), xs.max(), ys.max()), raw.h_crs,
              "declared by the file" if paths is not None else "given", where,
              f"{_CRS_HINT}, or fix the file (gdal_edit.py -a_srs)")
    z = raw.metres(z)
    if raw.dtype == "float16":
        _half_float_note(z, where)
    if sea_level is not None:
        z = np.where(np.isfinite(z), np.maximum(z, float(sea_level)), np.nan)
    dx, dy = pixel_sizes(t, raw.h_crs, z.shape)
    check_plausible(z, dx, dy, where, _lonlat_of(t, raw.h_crs))
    return DemRaster(z=z, transform=t, crs=raw.h_crs.to_wkt(), vertical_crs=raw.vname,
                     vertical_note=raw.note, sources=tuple(raw.sources), undeclared=found,
                     label=where)
