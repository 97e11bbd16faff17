"""Worlds from digital elevation models: any GDAL raster, tiles, or lon/lat grids.

``from_dem(source, cell_size, ceiling)``:

1. **Read** (:func:`read_dem`). A path is opened with rasterio, so any raster
   GDAL reads works (GeoTIFF, VRT, SRTM ``.hgt``, ...); several paths are
   tiles merged with ``rasterio.merge`` (they must share one CRS). Band 1 is
   read with ``masked=True``, so the nodata value, an internal mask band and
   an alpha band all mark missing pixels; the band's scale and offset are
   applied, and elevations in feet (band unit or vertical CRS) become metres.
   ``bbox`` (W, S, E, N in lon/lat degrees) reads only the window it needs.
   An array needs ``transform=`` (or ``bounds=``) and ``crs=``. Rows run
   north → south, as in every north-up raster; :func:`from_lonlat_grid` takes
   lon/lat vectors in any order instead.
2. **Sanity.** Elevations below :data:`MIN_ELEVATION` (-500 m) or above
   :data:`MAX_ELEVATION` (9000 m) that are not masked are refused: they are
   almost always an undeclared nodata value (-9999, -32768, 32767), and the
   message says how to declare it (``world.nodata_value`` / ``--nodata-value``).
3. **CRS** (:func:`fm2uav.world.geo.local_metric_crs`). The world is built in
   a metric CRS where lengths are true to 0.5 %: the DEM's own if projected
   and that accurate over the area, else the local UTM zone (geographic DEMs,
   Web Mercator, feet, other distorting projections), else a transverse
   Mercator centred on the area.
4. **Resample.** World nodes are laid every ``cell_size`` metres over the
   largest axis-aligned rectangle of that CRS inside the DEM's pixel-centre
   footprint (and inside ``bbox``); ``rasterio.warp.reproject`` with bilinear
   resampling gives each node the bilinear interpolation of the four
   surrounding pixel centres (``XSCALE=YSCALE=1``: the point value, no
   low-pass kernel when the cells are coarser than the pixels).
5. **Nodata.** A node is *missing* if any of its four pixels is masked (the
   validity mask is reprojected alongside the heights). ``nodata="error"``
   (default) refuses such a DEM with the count and the first missing node's
   lon/lat; ``nodata="fill"`` keeps GDAL's value from the valid pixels, or the
   nearest valid node's elevation where there is none, and marks every such
   node in ``World.filled`` (refused if more than half the nodes are missing).
6. **Sea.** With ``sea_level`` [m], the ground is ``max(DEM, sea_level)`` (a
   topo-bathymetric DEM is flown over the water, not the sea floor). Without
   it, a DEM with ground below 0 m gets a :class:`GeodataWarning` naming the
   option (polders and the Dead Sea are real, so nothing is clamped silently).
7. **Voxels.** The vertical axis spans from one cell under the lowest ground to
   ``ceiling`` (altitude of the top node in the DEM's datum). Default: the
   highest ground plus ``max(20 dz, agl + 10 dz)`` and at least ``top + 5 dz``,
   so a requested height above ground ``agl`` always has sky.

The world records :class:`~fm2uav.world.geo.Georef` (CRS, EPSG, vertical
reference, source files with SHA-256) in ``World.georef``.
"""

from __future__ import annotations

import dataclasses
import warnings
from collections.abc import Sequence
from os import PathLike
from pathlib import Path
from typing import Any

import numpy as np
from scipy import ndimage

from ..errors import InputError, WorldError
from .geo import (
    MAX_SCALE_ERROR,
    WGS84,
    SourceFile,
    check_fit,
    check_lonlat_bbox,
    check_size,
    crs_label,
    local_metric_crs,
    make_georef,
    parse_crs,
    sha256_file,
    transformer,
)

__all__ = [
    "from_dem",
    "from_lonlat_grid",
    "read_dem",
    "DemRaster",
    "GeodataWarning",
    "MIN_ELEVATION",
    "MAX_ELEVATION",
]

#: Elevations outside [MIN_ELEVATION, MAX_ELEVATION] m are taken for undeclared
#: nodata (the Dead Sea shore is at -430 m, Everest at 8849 m).
MIN_ELEVATION = -500.0
MAX_ELEVATION = 9000.0

_CRS_HINT = "world.crs (CLI --crs)"
_FEET = {"ft", "foot", "feet", "us survey foot", "us-ft", "us_survey_foot", "foot_us"}


class GeodataWarning(UserWarning):
    """Something in the input data deserves the operator's attention (not an error)."""


@dataclasses.dataclass(frozen=True)
class DemRaster:
    """A north-up raster read by :func:`read_dem`.

    Attributes
    ----------
    z : ndarray (rows, cols)
        Elevations [m] (scale/offset and unit applied), NaN where masked.
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
    """

    z: np.ndarray
    transform: tuple[float, float, float, float, float, float]
    crs: str
    vertical_crs: str | None = None
    vertical_note: str = ""
    sources: tuple[SourceFile, ...] = ()


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


def _band_unit_factor(unit: str | None) -> float:
    u = (unit or "").strip().lower()
    if u in _FEET:
        return 0.3048006096 if "us" in u else 0.3048
    return 1.0


#: A pixel higher (or lower) than every one of its (at least 3 valid) neighbours by
#: more than this [m] is an isolated spike (a glitch or undeclared nodata), refused.
SPIKE_HEIGHT = 250.0


def _check_spikes(z: np.ndarray, where: str) -> None:
    """Refuse isolated one-pixel spikes/pits (issue 17: no silent wrong worlds)."""
    if z.size > 50_000_000 or min(z.shape) < 2:
        return
    pad = np.pad(z.astype(float), 1, constant_values=np.nan)
    rows, cols = z.shape
    nb = [pad[1 + di:1 + di + rows, 1 + dj:1 + dj + cols]
          for di in (-1, 0, 1) for dj in (-1, 0, 1) if (di, dj) != (0, 0)]
    with np.errstate(invalid="ignore"), warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        stack = np.stack(nb)
        hi = np.nanmax(stack, axis=0)
        lo = np.nanmin(stack, axis=0)
        count = np.isfinite(stack).sum(axis=0)
        spike = np.isfinite(z) & (count >= 3) & (
            (z - hi > SPIKE_HEIGHT) | (lo - z > SPIKE_HEIGHT))
    n = int(spike.sum())
    if n == 0:
        return
    r, c = (int(k[0]) for k in np.nonzero(spike))
    raise WorldError(
        f"{where} has {n} isolated spike(s)/pit(s): pixel (row {r}, col {c}) is "
        f"{float(z[r, c]):g} m while its neighbours lie between {float(lo[r, c]):g} and "
        f"{float(hi[r, c]):g} m (a single pixel more than {SPIKE_HEIGHT:g} m above/below all "
        "its neighbours is a data error, not terrain); fix or mask it in the file (gdal_calc), "
        "or declare its value as nodata with world.nodata_value (CLI --nodata-value) and "
        "world.nodata: fill (CLI --nodata fill)")


def _check_values(z: np.ndarray, where: str) -> None:
    """Refuse elevations that look like undeclared nodata or a wrong unit, and isolated
    spikes (:data:`SPIKE_HEIGHT`)."""
    finite = z[np.isfinite(z)]
    bad = finite[(finite < MIN_ELEVATION) | (finite > MAX_ELEVATION)]
    if bad.size == 0:
        _check_spikes(z, where)
        return
    vals, counts = np.unique(bad, return_counts=True)
    v = float(vals[np.argmax(counts)])
    n = int(counts.max())
    side = f"below {MIN_ELEVATION:g} m" if v < MIN_ELEVATION else f"above {MAX_ELEVATION:g} m"
    if n * 2 >= bad.size:
        raise WorldError(
            f"{where} has {bad.size} pixel(s) {side}, {n} of them exactly {v:g}, which looks like "
            f"an undeclared nodata value; declare it with world.nodata_value: {v:g} (CLI "
            f"--nodata-value {v:g}) or in the file (gdal_edit.py -a_nodata {v:g} FILE)")
    raise WorldError(
        f"{where} has {bad.size} pixel(s) {side} (from {float(bad.min()):g} to "
        f"{float(bad.max()):g} m), which is no terrain on Earth; are the elevations in another "
        "unit (feet, centimetres) or is nodata undeclared? Fix the file (gdal_edit.py -scale / "
        "-a_nodata) or declare the nodata value with world.nodata_value (CLI --nodata-value)")


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


def _read_files(paths: list[Path], crs: Any, nodata: float | None,
                bbox: tuple[float, float, float, float] | None, window_crs: Any = None
                ) -> tuple[np.ndarray, tuple[float, ...], Any, str | None, str, list[SourceFile]]:
    import rasterio
    from rasterio.errors import RasterioIOError

    datasets = []
    try:
        for p in paths:
            if not p.exists():
                raise InputError(f"cannot read the DEM {str(p)!r}: the file does not exist; "
                                 "check world.dem / --dem")
            from .. import _validate as v

            v.input_file(p, "the DEM", where=("world.dem", "--dem"))  # no folder / pipe
            try:
                datasets.append(rasterio.open(p))
            except RasterioIOError as exc:
                raise InputError(f"cannot read the DEM {str(p)!r}: {exc}") from None
        crss = _tile_crss(paths, datasets, crs)
        scales = {(float(ds.scales[0] or 1.0), float(ds.offsets[0] or 0.0)) for ds in datasets}
        if len(scales) > 1:
            raise WorldError(
                f"the DEM tiles have different scale/offset values {sorted(scales)}; unscale them "
                "first (gdal_translate -unscale) so that one merge applies to all")
        scale, offset = scales.pop()
        units = {_band_unit_factor(ds.units[0] if ds.units else None) for ds in datasets}
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
            res = max(abs(first.transform.a), abs(first.transform.e))
            window_bounds = (bx[0] - 2 * res, bx[1] - 2 * res, bx[2] + 2 * res, bx[3] + 2 * res)
        if len(datasets) == 1:
            z, t = _read_one(first, paths[0], window_bounds, bbox, h_crs)
        else:
            z, t = _merge_tiles(datasets, window_bounds, bbox, h_crs)
        if nodata is not None and np.isfinite(nodata):
            # an undeclared nodata value, given by the user, compared on the stored numbers
            raw = z
            z = np.where(raw == nodata, np.nan, raw)
        z = z * scale + offset
        factor = unit_factor if unit_factor != 1.0 else vfactor
        z = z * factor
        sources = []
        for p, ds in zip(paths, datasets):
            sources.append(SourceFile(
                path=str(p), role="dem", sha256=sha256_file(p), crs=crs_label(crss[0]),
                crs_rule="declared by the file" if ds.crs is not None else "given (world.crs / --crs)",
                details={"driver": ds.driver, "size_px": [ds.height, ds.width],
                         "pixel_size": [abs(ds.transform.a), abs(ds.transform.e)],
                         **({"scale": scale, "offset": offset}
                            if (scale, offset) != (1.0, 0.0) else {}),
                         **({"unit_factor": factor} if factor != 1.0 else {}),
                         **({"nodata": ds.nodata} if ds.nodata is not None else {})}))
        note = _vertical_note(first.driver)
        return z, tuple(t)[:6], h_crs, vname, note, sources
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
    from rasterio.windows import Window, from_bounds

    win = None
    if window_bounds is not None:
        full = Window(0, 0, first.width, first.height)
        w = from_bounds(*window_bounds, transform=first.transform)
        w = w.round_offsets(op="floor").round_lengths(op="ceil")
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

    kw = {"bounds": window_bounds} if window_bounds is not None else {}
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


def _read_array(source: Any, crs: Any, transform: Any, bounds: Any, nodata: float | None,
                ) -> tuple[np.ndarray, Any, Any, str | None, str]:
    """Elevations [m] of an in-memory DEM, its pixel transform, horizontal CRS, vertical CRS, note."""
    try:
        z = np.array(source, dtype=float)
    except (TypeError, ValueError):
        raise InputError(
            f"DEM must be a raster file path (or a list of tiles) or a 2D array of "
            f"elevations, got {type(source).__name__}") from None
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
    z = z.copy()
    if nodata is not None and np.isfinite(nodata):
        z[z == nodata] = np.nan
    z = z * vfactor
    return z, t, h_crs, vname, _vertical_note("")


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
) -> DemRaster:
    """Read a DEM into a :class:`DemRaster` (masked pixels → NaN).

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
        own nodata, mask and alpha bands, and NaN).
    bbox : (west, south, east, north), optional
        Lon/lat degrees: read only the window covering this box (files).
    window_crs : optional
        The CRS the box will be used in (the world's): the window then covers
        the box's outer rectangle in that CRS.

    Raises
    ------
    InputError
        Unreadable file, bad array or placement, bbox outside the DEM.
    WorldError
        Missing or conflicting CRS, tiles in different CRSs, coordinates that
        do not fit the CRS, implausible elevations (undeclared nodata).
    """
    box = None if bbox is None else check_lonlat_bbox(bbox, "world.bbox (--bbox)")
    paths: list[Path] | None = None
    if isinstance(source, (str, PathLike)):
        paths = [Path(source)]
    elif isinstance(source, (list, tuple)) and source and all(
            isinstance(s, (str, PathLike)) for s in source):
        paths = [Path(s) for s in source]
    vname: str | None = None
    note = ""
    sources: list[SourceFile] = []
    if paths is not None:
        z, t, h_crs, vname, note, sources = _read_files(paths, crs, nodata, box, window_crs)
        if transform is not None:
            t = _affine(transform)
        where = f"the DEM {paths[0]}" + (f" (+{len(paths) - 1} tiles)" if len(paths) > 1 else "")
    else:
        z, t, h_crs, vname, note = _read_array(source, crs, transform, bounds, nodata)
        where = "the DEM array"
    if z.size < 4 or min(z.shape) < 2:
        raise InputError(f"DEM must have at least 2 x 2 pixels, got {z.shape}")
    z[~np.isfinite(z)] = np.nan
    t = _affine(t)
    if not np.isfinite(z).any():
        raise WorldError(f"{where} has no valid elevation (every pixel is nodata) in the area read; "
                         "check the file, world.nodata_value and world.bbox")
    t, xs, ys = _corners(t, z.shape, h_crs)
    if h_crs.is_geographic and xs.min() < 180.0 < xs.max():
        raise WorldError(
            f"{where} crosses the antimeridian (longitudes {xs.min():g}..{xs.max():g}); crop it "
            "with world.bbox (CLI --bbox) to one side, or shift it (gdalwarp --config "
            "CENTER_LONG 180)")
    check_fit((xs.min(), ys.min(), xs.max(), ys.max()), h_crs,
              "declared by the file" if paths is not None else "given", where,
              f"{_CRS_HINT}, or fix the file (gdal_edit.py -a_srs)")
    _check_values(z, where)
    return DemRaster(z=z, transform=t, crs=h_crs.to_wkt(), vertical_crs=vname,
                     vertical_note=note, sources=tuple(sources))


def _footprint_lonlat(dem: DemRaster) -> tuple[float, float, float, float]:
    """Lon/lat box of the pixel-centre footprint of a raster."""
    rows, cols = dem.z.shape
    a, b, c, d, e, f = dem.transform
    edge = np.linspace(0, 1, 33)
    r = np.concatenate([np.zeros(33), edge * (rows - 1), np.full(33, rows - 1), edge * (rows - 1)])
    q = np.concatenate([edge * (cols - 1), np.full(33, cols - 1), edge * (cols - 1), np.zeros(33)])
    x = a * (q + 0.5) + b * (r + 0.5) + c
    y = d * (q + 0.5) + e * (r + 0.5) + f
    lon, lat = transformer(dem.crs, WGS84).transform(x, y)
    lon, lat = np.asarray(lon), np.asarray(lat)
    return float(lon.min()), float(lat.min()), float(lon.max()), float(lat.max())


def _source_crs(source: Any, crs: Any) -> Any:
    """Horizontal CRS of a DEM source before reading its pixels (None if unknown)."""
    first = source[0] if isinstance(source, (list, tuple)) and source and isinstance(
        source[0], (str, PathLike)) else source
    if isinstance(first, (str, PathLike)):
        import rasterio
        from rasterio.errors import RasterioIOError

        try:
            with rasterio.open(first) as ds:
                c = ds.crs.to_wkt() if ds.crs is not None else crs
        except RasterioIOError:
            return None  # read_dem reports it
    else:
        c = crs
    if c is None:
        return None
    return _split_crs(c)[0]


def _intersect(a: tuple[float, ...], b: tuple[float, ...]) -> tuple[float, float, float, float]:
    return (max(a[0], b[0]), max(a[1], b[1]), min(a[2], b[2]), min(a[3], b[3]))


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
    bbox: Sequence[float] | None = None,
    sea_level: float | None = None,
    agl: float | None = None,
    top: float | None = None,
    name: str = "",
) -> Any:
    """Build a 3D :class:`~fm2uav.World` from a DEM (see the module docstring).

    Parameters
    ----------
    source : str, PathLike, list of paths, or array_like (rows, cols)
        Raster file(s) GDAL reads, or an elevation array [m] (rows north → south).
    cell_size : float or (dx, dy, dz)
        Node spacing of the world [m]; one number for all axes.
    ceiling : float, optional
        Altitude [m, DEM datum] of the top node; default: highest ground +
        ``max(20 dz, agl + 10 dz)``, and at least ``top + 5 dz``.
    crs, transform, bounds :
        Placement of an array, or the CRS of a file that declares none; see
        :func:`read_dem`.
    nodata : {"error", "fill"}
        What to do with nodes that touch masked pixels. Default "error".
    nodata_value : float, optional
        An undeclared elevation value meaning "missing" (e.g. -9999).
    bbox : (west, south, east, north), optional
        Crop to this lon/lat box [deg].
    sea_level : float, optional
        Water surface altitude [m]: ground = max(DEM, sea_level).
    agl : float, optional
        Highest requested height above ground [m] (sizes the default ceiling).
    top : float, optional
        Highest requested altitude [m] (start/goal given as altitudes).
    name : str
        World name.

    Returns
    -------
    World
        With ``terrain`` (resampled elevations), ``crs`` (metric CRS of x/y),
        ``origin`` in that CRS [m], ``filled`` (nodes whose elevation was
        filled) and ``georef``.

    Raises
    ------
    WorldError
        No/unknown/wrong CRS, nodata under the map, ceiling not above the ground.
    InputError
        Bad cell size or arguments.
    """
    from .world import World

    dx, dy, dz = _check_dem_args(cell_size, nodata, sea_level)
    box = None if bbox is None else check_lonlat_bbox(bbox, "world.bbox (--bbox)")
    pre = _bbox_metric_crs(source, crs, box)
    dem = read_dem(source, crs=crs, transform=transform, bounds=bounds, nodata=nodata_value,
                   bbox=box, window_crs=None if pre is None else pre[0])
    src = parse_crs(dem.crs)

    area_ll = _footprint_lonlat(dem)
    if box is not None:
        area_ll = _overlap_with_bbox(area_ll, box)
    dst, err, reason = pre if pre is not None else local_metric_crs(src, area_ll)
    if err > MAX_SCALE_ERROR:
        warnings.warn(f"{reason}; crop the DEM with world.bbox (CLI --bbox) for true lengths",
                      GeodataWarning, stacklevel=2)
    fwd = transformer(src, dst)
    west, south, east, north = _inner_box(dem, fwd, dst, box)
    nx, ny = _node_counts(west, south, east, north, dx, dy)
    gx = west + np.arange(nx) * dx
    gy = south + np.arange(ny) * dy
    heights, valid = _resample(dem, src, dst, west, gy[-1], dx, dy, nx, ny)
    heights, filled = _fill_nodata(heights, valid, nodata, gx, gy, dst)
    vertical = (f"DEM heights, {dem.vertical_crs} (from the raster's vertical CRS)"
                if dem.vertical_crs else f"DEM heights, {dem.vertical_note}")
    heights, vertical, n_sea = _sea_level(heights, sea_level, vertical, gx, gy, dst)
    z0, nz = _vertical_nodes(heights, dz, ceiling, agl, top)
    check_size((nx, ny, nz), (dx, dy, dz), columns=True)
    w = World.from_heightmap(heights, (dx, dy, dz), nz, origin=(west, south, z0), name=name)
    details = {"world_nodes": [nx, ny, nz], "filled_nodes": int(filled.sum()),
               **({"sea_nodes": n_sea} if sea_level is not None else {}),
               **({"bbox": list(box)} if box is not None else {})}
    georef = _dem_georef(dem, details, src, dst, vertical, err, reason)
    # the DEM at its own resolution for every height-above-ground question (issue 13)
    from .ground_model import ground_model_from_dem

    ground = ground_model_from_dem(dem, src, dst, min(dx, dy), sea_level=sea_level)
    return w.with_fields(crs=crs_label(dst) if parse_crs(dst).to_epsg() else dst,
                         name=name or "dem", filled=filled, georef=georef, ground=ground)


def _node_counts(west: float, south: float, east: float, north: float, dx: float, dy: float
                 ) -> tuple[int, int]:
    """Horizontal node counts of the box [m] at spacing ``dx``, ``dy`` (at least 2 x 2, checked)."""
    nx = int(np.floor((east - west) / dx + 1e-9)) + 1
    ny = int(np.floor((north - south) / dy + 1e-9)) + 1
    if nx < 2 or ny < 2:
        raise InputError(
            f"world.cell_size (--cell-size) {dx:g} x {dy:g} m leaves fewer than 2 x 2 nodes on a "
            f"DEM area of {east - west:.0f} x {north - south:.0f} m; use a smaller cell size")
    check_size((nx, ny), (dx, dy))
    return nx, ny


def _dem_georef(dem: DemRaster, details: dict[str, Any], src: Any, dst: Any, vertical: str,
                err: float, reason: str) -> Any:
    """The georeference of a DEM world: its source files (or the array) with ``details``."""
    sources = tuple(dataclasses.replace(s, details={**s.details, **details})
                    for s in dem.sources) or (SourceFile(path="<array>", role="dem",
                                                         crs=crs_label(src), crs_rule="given",
                                                         details=details),)
    return make_georef(dst, vertical=vertical, vertical_crs=dem.vertical_crs,
                       vertical_assumed=dem.vertical_crs is None, reprojection=reason,
                       scale_error=err, sources=sources)


def _bbox_metric_crs(source: Any, crs: Any, box: Any) -> Any:
    """With a bbox, the world's metric CRS chosen from it first (so that the window read covers
    the bbox's rectangle in that CRS): :func:`local_metric_crs`'s answer; else None."""
    if box is None:
        return None
    src0 = _source_crs(source, crs)
    return None if src0 is None else local_metric_crs(src0, box)


def _check_dem_args(cell_size: Any, nodata: str, sea_level: float | None
                    ) -> tuple[float, float, float]:
    """Check the cell size [m], the nodata rule and the sea level of :func:`from_dem`; dx, dy, dz."""
    cs = np.atleast_1d(np.asarray(cell_size, dtype=float))
    if cs.size not in (1, 3) or not np.all(np.isfinite(cs)) or np.any(cs <= 0):
        raise InputError(f"world.cell_size (--cell-size) must be > 0 metres (one number or "
                         f"dx, dy, dz), got {cell_size!r}")
    dx, dy, dz = (float(v) for v in np.broadcast_to(cs, (3,)))
    if nodata not in ("error", "fill"):
        raise InputError(f"world.nodata (--nodata) must be 'error' or 'fill', got {nodata!r}")
    if sea_level is not None and not (np.isfinite(sea_level) and MIN_ELEVATION <= sea_level
                                      <= MAX_ELEVATION):
        raise InputError(f"world.sea_level (--sea-level) must be an altitude in metres, e.g. 0, "
                         f"got {sea_level!r}")
    return dx, dy, dz


def _overlap_with_bbox(area_ll: tuple[float, float, float, float], box: Any
                       ) -> tuple[float, float, float, float]:
    """The DEM's lon/lat footprint ``area_ll`` cut to ``box``; refused when they do not overlap."""
    full_ll = area_ll
    area_ll = _intersect(area_ll, box)
    if not (area_ll[2] > area_ll[0] and area_ll[3] > area_ll[1]):
        raise InputError(
            f"bbox {','.join(f'{v:g}' for v in box)} does not overlap the DEM, which covers "
            f"lon {full_ll[0]:.4f}..{full_ll[2]:.4f}, lat {full_ll[1]:.4f}..{full_ll[3]:.4f}; "
            "fix world.bbox (CLI --bbox W,S,E,N, lon/lat)")
    return area_ll


def _inner_box(dem: DemRaster, fwd: Any, dst: Any, box: Any) -> tuple[float, float, float, float]:
    """Largest axis-aligned box [m] (in ``dst``) inside the DEM's pixel-centre footprint and ``box``."""
    rows, cols = dem.z.shape
    a, b, c, d, e, f = dem.transform
    # footprint of the pixel centres in the metric CRS, then an inner box
    edge = np.linspace(0, 1, 64)
    r_idx = np.concatenate([np.zeros(64), edge * (rows - 1), np.full(64, rows - 1), edge * (rows - 1)])
    c_idx = np.concatenate([edge * (cols - 1), np.full(64, cols - 1), edge * (cols - 1), np.zeros(64)])
    ex, ey = fwd.transform(a * (c_idx + 0.5) + b * (r_idx + 0.5) + c,
                           d * (c_idx + 0.5) + e * (r_idx + 0.5) + f)
    ex, ey = np.asarray(ex), np.asarray(ey)
    top_e, right, bottom, left = (slice(0, 64), slice(64, 128), slice(128, 192), slice(192, 256))
    # rows may run south -> north (e > 0): then "top" edge is the southern one
    ys_first, ys_last = ey[top_e].mean(), ey[bottom].mean()
    xs_first, xs_last = ex[left].mean(), ex[right].mean()
    lo_x, hi_x = (left, right) if xs_first <= xs_last else (right, left)
    lo_y, hi_y = (bottom, top_e) if ys_last <= ys_first else (top_e, bottom)
    west, east = ex[lo_x].max(), ex[hi_x].min()
    south, north = ey[lo_y].max(), ey[hi_y].min()
    if box is not None:
        bw, bs, be, bn = _bbox_in(dst, box)
        west, south, east, north = max(west, bw), max(south, bs), min(east, be), min(north, bn)
    if not (east > west and north > south):
        raise WorldError(f"the DEM footprint in {crs_label(dst)} is degenerate (or outside "
                         "world.bbox); is the transform/CRS right?")
    return west, south, east, north


def _fill_nodata(heights: np.ndarray, valid: np.ndarray, nodata: str, gx: np.ndarray,
                 gy: np.ndarray, dst: Any) -> tuple[np.ndarray, np.ndarray]:
    """Heights with nodata nodes refused (``nodata="error"``) or filled from the nearest valid
    node (at most half of them); and the mask of filled nodes."""
    missing = ~valid
    n_miss = int(missing.sum())
    filled = np.zeros(valid.shape, dtype=bool)
    if n_miss:
        i, j = np.argwhere(missing)[0]
        lon, lat = transformer(dst, WGS84).transform(float(gx[i]), float(gy[j]))
        if nodata == "error":
            raise WorldError(
                f"the DEM has nodata/NaN under {n_miss} of {missing.size} world nodes, first at "
                f"node ({i}, {j}) = lon {lon:.5f}, lat {lat:.5f}; crop it to its data with "
                "world.bbox (CLI --bbox W,S,E,N), fill the gaps first, or set world.nodata: fill "
                "(CLI --nodata fill) to take the nearest valid elevation")
        if n_miss * 2 > missing.size:
            raise WorldError(
                f"the DEM has nodata under {n_miss} of {missing.size} world nodes (more than "
                "half); world.nodata: fill would invent most of the terrain — crop the DEM to "
                "its data with world.bbox (CLI --bbox W,S,E,N)")
        none = ~np.isfinite(heights)
        if none.any():
            _, (ii, jj) = ndimage.distance_transform_edt(none, return_indices=True)
            heights = heights[ii, jj]
        filled = missing
    return heights, filled


def _sea_level(heights: np.ndarray, sea_level: float | None, vertical: str, gx: np.ndarray,
               gy: np.ndarray, dst: Any) -> tuple[np.ndarray, str, int]:
    """Ground raised to ``sea_level`` [m] (or a warning about ground below 0 m); the heights, the
    vertical description and the number of nodes below the sea level."""
    below = heights < (0.0 if sea_level is None else float(sea_level))
    n_sea = int(below.sum())
    if sea_level is not None:
        heights = np.maximum(heights, float(sea_level))
        vertical += f"; ground raised to world.sea_level = {float(sea_level):g} m over water"
    elif n_sea:
        i, j = np.unravel_index(int(np.argmin(heights)), heights.shape)
        lon, lat = transformer(dst, WGS84).transform(float(gx[i]), float(gy[j]))
        warnings.warn(
            f"the DEM has ground below 0 m under {n_sea} of {heights.size} nodes (lowest "
            f"{heights[i, j]:.1f} m at lon {lon:.5f}, lat {lat:.5f}); if that is sea or lake "
            "floor, set world.sea_level: 0 (CLI --sea-level 0) to fly over the water surface — "
            "it is kept as terrain otherwise", GeodataWarning, stacklevel=3)
    return heights, vertical, n_sea


def _vertical_nodes(heights: np.ndarray, dz: float, ceiling: float | None, agl: float | None,
                    top: float | None) -> tuple[float, int]:
    """Bottom node height z0 [m] (a cell under the lowest ground) and number of vertical nodes."""
    hmin, hmax = float(heights.min()), float(heights.max())
    z0 = (np.floor(hmin / dz) - 1.0) * dz
    top_alt = _ceiling(ceiling, hmax, dz, agl, top)
    if ceiling is None and (agl is not None or top is not None):
        # the default follows the request: the top node reaches it
        nz = int(np.ceil((top_alt - z0) / dz - 1e-9)) + 1
    else:  # a given ceiling (or the plain default) is a maximum: the top node stays under it
        nz = int(np.floor((top_alt - z0) / dz + 1e-9)) + 1
    return z0, nz


def _ceiling(ceiling: float | None, hmax: float, dz: float, agl: float | None,
             top: float | None) -> float:
    """Altitude of the top node [m] (see :func:`from_dem`)."""
    need = hmax + (0.0 if agl is None else float(agl)) + dz
    if ceiling is None:
        alt = hmax + max(20.0 * dz, (0.0 if agl is None else float(agl)) + 10.0 * dz)
        if top is not None and np.isfinite(top):
            alt = max(alt, float(top) + 5.0 * dz)
        return alt
    alt = float(ceiling)
    if not np.isfinite(alt) or alt < hmax + dz:
        raise WorldError(
            f"world.ceiling (--ceiling) = {alt:g} m must be at least one cell ({dz:g} m) above "
            f"the highest ground {hmax:.1f} m; raise it (e.g. {hmax + 20 * dz:.0f}) or leave it "
            "out")
    if agl is not None and alt < need:
        raise WorldError(
            f"world.ceiling (--ceiling) = {alt:g} m leaves no room to fly {float(agl):g} m above "
            f"the highest ground ({hmax:.1f} m); raise it to at least {np.ceil(need):.0f} m or "
            "leave it out (the default follows the requested height above ground)")
    if top is not None and np.isfinite(top) and alt < float(top):
        raise WorldError(
            f"world.ceiling (--ceiling) = {alt:g} m is below a requested altitude of "
            f"{float(top):g} m (start/goal); raise it or leave it out")
    return alt


def _resample(dem: DemRaster, src: Any, dst: Any, west: float, north: float, dx: float,
              dy: float, nx: int, ny: int) -> tuple[np.ndarray, np.ndarray]:
    """Bilinear heights and validity (all four pixels valid) at the world nodes, (nx, ny)."""
    from affine import Affine
    from rasterio.crs import CRS as RioCRS
    from rasterio.warp import Resampling, reproject

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


# ---------------------------------------------------------------------- lon/lat grids
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


def from_lonlat_grid(
    z: Any,
    lon: Any,
    lat: Any,
    cell_size: float | tuple[float, float, float],
    ceiling: float | None = None,
    **kwargs: Any,
) -> Any:
    """Build a world from a plain elevation array and its lon/lat coordinate vectors.

    The shape of an xarray ``DataArray`` of a DEM or bathymetry grid
    (``da.values, da.lon.values, da.lat.values``): ``z[i_lat, i_lon]`` [m],
    with ``lon`` in 0..360 or -180..180 degrees and ``lat`` in either order
    (south-up or north-up). Pixel centres sit at the given coordinates.
    Irregular rows or columns (e.g. rows regular in Mercator) are first
    interpolated linearly onto a regular grid of their finest step. Then the
    grid goes through :func:`from_dem` (EPSG:4326 → local UTM).

    Parameters
    ----------
    z : array_like (n_lat, n_lon)
        Elevations [m]; NaN = missing.
    lon, lat : array_like (n_lon,), (n_lat,)
        Pixel-centre coordinates [deg], each strictly monotonic.
    cell_size, ceiling, **kwargs :
        As :func:`from_dem` (``nodata``, ``nodata_value``, ``bbox``, ``sea_level``,
        ``agl``, ``top``, ``name``).

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
    return from_dem(zz, cell_size, ceiling, crs="EPSG:4326", transform=transform, **kwargs)
