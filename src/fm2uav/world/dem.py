"""Worlds from digital elevation models: any GDAL raster, tiles, or lon/lat grids.

``from_dem(source, cell_size, ceiling)``:

1. **Read** (:func:`read_dem`, :mod:`fm2uav.world.dem_read`). A path is opened with
   rasterio, so any raster
   GDAL reads works (GeoTIFF, VRT, SRTM ``.hgt``, ...); several paths are
   tiles merged with ``rasterio.merge`` (they must share one CRS). Band 1 is
   read with ``masked=True``, so the nodata value, an internal mask band and
   an alpha band all mark missing pixels; the band's scale and offset are
   applied, and elevations in feet (band unit or vertical CRS) become metres.
   ``bbox`` (W, S, E, N in lon/lat degrees) reads only the window it needs.
   An array needs ``transform=`` (or ``bounds=``) and ``crs=``. Rows run
   north → south, as in every north-up raster; :func:`from_lonlat_grid`
   (:mod:`fm2uav.world.lonlat_grid`) takes lon/lat vectors in any order instead.
2. **What the numbers mean** (:mod:`fm2uav.world.dem_values`), in this order:
   crop (the bbox window) → nodata (declared, ``nodata_value``, and undeclared
   sentinels such as -32768 found and announced) → ``sea_level`` clamp →
   plausibility judged by *slope* (a step no terrain on Earth can make is a data
   error; a real sea floor or a 500 m rise over a 2 km pixel is terrain).
   Rasters that are not elevation (RGB/palette images, complex bands, units
   that are not lengths) are refused before their pixels are read.
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
   validity mask is reprojected alongside the heights). ``fill`` lists more DEMs
   in priority order (a 30 m national model under a 1 m survey,
   :mod:`fm2uav.world.dem_stack`): a node missing in one is taken from the next
   that measures it. What no DEM measures is *unknown ground*:
   ``nodata="error"`` (default) refuses such a DEM with the count and the first
   missing node's lon/lat; ``nodata="fill"`` and ``nodata="error_on_route"``
   keep GDAL's value from the valid pixels, or the nearest valid node's
   elevation where there is none, and mark every such node in ``World.filled``
   (refused if more than half the nodes are missing); the safety figures then
   split every path into "over measured ground" and "over filled ground", and
   ``error_on_route`` refuses a plan that crosses filled ground
   (:mod:`fm2uav.analysis.known_ground`).
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
from .dem_read import DemRaster, _bbox_in, _split_crs, read_dem
from .geo import (
    MAX_SCALE_ERROR,
    WGS84,
    SourceFile,
    check_lonlat_bbox,
    check_size,
    crs_epsg,
    crs_label,
    local_metric_crs,
    make_georef,
    parse_crs,
    transformer,
)
from .lonlat_grid import lonlat_raster
from .quiet import GeodataWarning, library_warnings

__all__ = [
    "from_dem",
    "from_lonlat_grid",
    "read_dem",
    "DemRaster",
    "GeodataWarning",
    "NODATA_RULES",
    "SEA_LEVEL_RANGE",
]

#: The rules for DEM gaps under the map (``world.nodata`` / ``--nodata``).
NODATA_RULES = ("error", "fill", "error_on_route")
#: Accepted ``sea_level`` values [m] (the Dead Sea shore is at -430 m).
SEA_LEVEL_RANGE = (-500.0, 9000.0)


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
    fill: Sequence[Any] = (),
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
        Raster file(s) GDAL reads (several = tiles of one DEM, merged), or an
        elevation array [m] (rows north → south).
    cell_size : float or (dx, dy, dz)
        Node spacing of the world [m]; one number for all axes.
    ceiling : float, optional
        Altitude [m, DEM datum] of the top node; default: highest ground +
        ``max(20 dz, agl + 10 dz)``, and at least ``top + 5 dz``.
    fill : sequence, optional
        More DEMs in priority order (each a file, a list of tiles, or a
        :class:`DemRaster`), in any CRS and resolution: a node ``source`` does
        not measure takes its height from the first of them that does
        (:mod:`fm2uav.world.dem_stack`). Without ``bbox`` the map is ``source``'s
        footprint; with it, every DEM's footprint inside the box.
    crs, transform, bounds :
        Placement of an array, or the CRS of files that declare none; see
        :func:`read_dem`.
    nodata : {"error", "fill", "error_on_route"}
        Nodes no DEM measures: refused (default), or filled (nearest measured
        node) and marked in ``World.filled``; ``"error_on_route"`` also fills,
        and the commands refuse a plan that flies over them
        (:func:`fm2uav.analysis.known_ground.check_known_ground`).
    nodata_value : float, optional
        An undeclared elevation value meaning "missing" (e.g. -9999), in every DEM.
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
        filled), ``georef`` and ``ground`` (the DEMs at their own resolution).

    Raises
    ------
    WorldError
        No/unknown/wrong CRS, nodata under the map, ceiling not above the ground,
        elevations no terrain has.
    InputError
        Bad cell size or arguments, a raster that is not elevation.
    """
    dx, dy, dz = _check_dem_args(cell_size, nodata, sea_level)
    box = None if bbox is None else check_lonlat_bbox(bbox, "world.bbox (--bbox)")
    fills = list(fill or ())
    with library_warnings(_describe(source) + (f" and {len(fills)} fill DEM(s)" if fills
                                                else "")):
        return _build(source, fills, (dx, dy, dz), ceiling, crs=crs, transform=transform,
                      bounds=bounds, nodata=nodata, nodata_value=nodata_value, box=box,
                      sea_level=sea_level, agl=agl, top=top, name=name)


def _describe(source: Any) -> str:
    """``"the DEM dem.tif"`` (or tiles / an array), for messages."""
    if isinstance(source, (str, PathLike)):
        return f"the DEM {Path(source).name}"
    if isinstance(source, DemRaster):
        return source.label
    if isinstance(source, (list, tuple)) and source and isinstance(source[0], (str, PathLike)):
        return f"the DEM {Path(source[0]).name} (+{len(source) - 1} tiles)"
    return "the DEM array"


def _read_fill(f: Any, k: int, crs: Any, nodata_value: float | None, box: Any, dst: Any,
               sea_level: float | None) -> DemRaster:
    """The ``k``-th fill DEM (a file, tiles or a DemRaster), read in the world's window."""
    if isinstance(f, DemRaster):
        return f
    try:
        d = read_dem(f, crs=crs, nodata=nodata_value, bbox=box, window_crs=dst,
                     sea_level=sea_level)
    except InputError as exc:
        if "does not overlap" not in str(exc):
            raise
        w, s_, e, n = box
        raise InputError(f"world.dem_fill (CLI --dem-fill) number {k + 1}, {_describe(f)}, "
                         f"does not overlap the map (lon {w:.4f}..{e:.4f}, lat {s_:.4f}.."
                         f"{n:.4f}), so it fills no gap; remove it or give a DEM of the mission "
                         "area") from None
    return dataclasses.replace(d, sources=tuple(
        dataclasses.replace(s_, role="dem_fill") for s_ in d.sources))


def _build(source: Any, fills: list[Any], cell: tuple[float, float, float],
           ceiling: float | None, *, crs: Any, transform: Any, bounds: Any, nodata: str,
           nodata_value: float | None, box: Any, sea_level: float | None, agl: float | None,
           top: float | None, name: str) -> Any:
    """:func:`from_dem` once its arguments are checked (library warnings captured)."""
    from .dem_stack import DATUM_WARNING_M, composite
    from .geo import bounds_lonlat
    from .world import World

    dx, dy, dz = cell
    pre = _bbox_metric_crs(source, crs, box)
    dem = source if isinstance(source, DemRaster) else read_dem(
        source, crs=crs, transform=transform, bounds=bounds, nodata=nodata_value, bbox=box,
        window_crs=None if pre is None else pre[0], sea_level=sea_level)
    src = parse_crs(dem.crs)

    area_ll = _footprint_lonlat(dem)
    if box is not None:
        area_ll = _overlap_with_bbox(area_ll, box)
    dst, err, reason = pre if pre is not None else local_metric_crs(src, area_ll)
    if err > MAX_SCALE_ERROR:
        warnings.warn(f"{reason}; crop the DEM with world.bbox (CLI --bbox) for true lengths",
                      GeodataWarning, stacklevel=3)
    rect = _inner_box(dem, transformer(src, dst), dst, box)
    levels, srcs = [dem], [src]
    read_box = box if box is not None else bounds_lonlat(rect, dst)
    for k, f in enumerate(fills):
        d = _read_fill(f, k, crs, nodata_value, read_box, dst, sea_level)
        levels.append(d)
        srcs.append(parse_crs(d.crs))
        if box is not None:  # inside the box, the map spans every DEM's footprint
            try:
                r2 = _inner_box(d, transformer(srcs[-1], dst), dst, box)
            except WorldError:
                continue
            rect = (min(rect[0], r2[0]), min(rect[1], r2[1]), max(rect[2], r2[2]),
                    max(rect[3], r2[3]))
    west, south, east, north = rect
    nx, ny = _node_counts(west, south, east, north, dx, dy)
    gx = west + np.arange(nx) * dx
    gy = south + np.arange(ny) * dy
    comp = composite(levels, srcs, dst, west, gy[-1], dx, dy, nx, ny)
    # the DEMs at their own resolution for every height-above-ground question (issue 13)
    from .ground_model import ground_model_from_dem

    ground = ground_model_from_dem(levels, srcs, dst, min(dx, dy))
    hidden = _hidden_gaps(levels, srcs, dst, (west, south, gx[-1], gy[-1]), ground)
    heights, filled = _fill_nodata(comp.heights, comp.valid, nodata, gx, gy, dst, levels,
                                   hidden=hidden)
    for k, off in enumerate(comp.offsets):
        if off is not None and abs(off) > DATUM_WARNING_M:
            warnings.warn(
                f"where both measure the ground, {levels[k + 1].label} lies {off:+.1f} m "
                f"(median) from {dem.label}: different vertical datums (ellipsoidal heights "
                "against heights above the geoid)? The ground steps by that much where the "
                "fill takes over; convert one of them (gdalwarp -t_srs with a vertical CRS)",
                GeodataWarning, stacklevel=3)
    vertical = (f"DEM heights, {dem.vertical_crs} (from the raster's vertical CRS)"
                if dem.vertical_crs else f"DEM heights, {dem.vertical_note}")
    heights, vertical, n_sea = _sea_level(heights, sea_level, vertical, gx, gy, dst)
    z0, nz = _vertical_nodes(heights, dz, ceiling, agl, top)
    check_size((nx, ny, nz), (dx, dy, dz), columns=True)
    w = World.from_heightmap(heights, (dx, dy, dz), nz, origin=(west, south, z0), name=name)
    details = {"world_nodes": [nx, ny, nz], "filled_nodes": int(filled.sum()),
               "nodata_rule": nodata,
               **({"filled_pixels_between_nodes": hidden[0]} if hidden[0] else {}),
               **({"measured_nodes": comp.measured[0]} if fills else {}),
               **({"undeclared_nodata": [{"value": s_.value, "pixels": s_.pixels}
                                         for s_ in dem.undeclared]} if dem.undeclared else {}),
               **({"sea_nodes": n_sea} if sea_level is not None else {}),
               **({"bbox": list(box)} if box is not None else {})}
    georef = _dem_georef(dem, details, src, dst, vertical, err, reason)
    more = []
    for k, d in enumerate(levels[1:]):
        extra = {"priority": k + 2, "measured_nodes": comp.measured[k + 1],
                 **({"offset_to_dem_m": round(comp.offsets[k], 3)}
                    if comp.offsets[k] is not None else {}),
                 **({"undeclared_nodata": [{"value": s_.value, "pixels": s_.pixels}
                                           for s_ in d.undeclared]} if d.undeclared else {})}
        more += [dataclasses.replace(s_, details={**s_.details, **extra}) for s_ in d.sources] \
            or [SourceFile(path="<array>", role="dem_fill", crs=crs_label(srcs[k + 1]),
                           crs_rule="given", details=extra)]
    if more:
        georef = georef.with_sources(*more)
    return w.with_fields(crs=crs_label(dst) if crs_epsg(dst) else dst,
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
    if nodata not in NODATA_RULES:
        raise InputError(f"world.nodata (--nodata) must be one of {', '.join(NODATA_RULES)}, "
                         f"got {nodata!r}")
    if sea_level is not None and not (np.isfinite(sea_level) and SEA_LEVEL_RANGE[0] <= sea_level
                                      <= SEA_LEVEL_RANGE[1]):
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
    """An axis-aligned box [m] (in ``dst``) inside the DEM's pixel-centre footprint and ``box``.

    Each footprint edge is classified by where its middle lies (the westernmost is the west
    side, ...), so north-up, south-up and rotated geotransforms (up to 45°) give the box
    between the four sides; a footprint turned near 45° (a diamond) gets the largest box of
    its bounding box's shape, centred on it, that fits inside.
    """
    rows, cols = dem.z.shape
    a, b, c, d, e, f = dem.transform
    # footprint of the pixel centres in the metric CRS, then an inner box
    edge = np.linspace(0, 1, 64)
    r_idx = np.concatenate([np.zeros(64), edge * (rows - 1), np.full(64, rows - 1), edge * (rows - 1)])
    c_idx = np.concatenate([edge * (cols - 1), np.full(64, cols - 1), edge * (cols - 1), np.zeros(64)])
    ex, ey = fwd.transform(a * (c_idx + 0.5) + b * (r_idx + 0.5) + c,
                           d * (c_idx + 0.5) + e * (r_idx + 0.5) + f)
    ex, ey = np.asarray(ex), np.asarray(ey)
    sides = [slice(0, 64), slice(64, 128), slice(128, 192), slice(192, 256)]
    mx = [float(ex[s_].mean()) for s_ in sides]
    my = [float(ey[s_].mean()) for s_ in sides]
    w_, e_ = int(np.argmin(mx)), int(np.argmax(mx))
    s_, n_ = int(np.argmin(my)), int(np.argmax(my))
    rect = None
    if len({w_, e_, s_, n_}) == 4:
        rect = (ex[sides[w_]].max(), ey[sides[s_]].max(), ex[sides[e_]].min(),
                ey[sides[n_]].min())
    # the footprint as a ring: top, right, then bottom and left walked backwards
    ring_x = np.concatenate([ex[sides[0]], ex[sides[1]], ex[sides[2]][::-1], ex[sides[3]][::-1]])
    ring_y = np.concatenate([ey[sides[0]], ey[sides[1]], ey[sides[2]][::-1], ey[sides[3]][::-1]])
    if rect is None or not _inside(rect, ring_x, ring_y):
        rect = _centred_box(ring_x, ring_y)
    west, south, east, north = rect
    if box is not None:
        bw, bs, be, bn = _bbox_in(dst, box)
        west, south, east, north = max(west, bw), max(south, bs), min(east, be), min(north, bn)
    if not (east > west and north > south):
        raise WorldError(f"the DEM footprint in {crs_label(dst)} is degenerate (or outside "
                         "world.bbox); is the transform/CRS right?")
    return float(west), float(south), float(east), float(north)


def _inside(rect: tuple[float, ...], ex: np.ndarray, ey: np.ndarray) -> bool:
    """Whether the box ``rect`` is non-empty and inside the polygon of the footprint edges."""
    import shapely

    w, s, e, n = rect
    if not (e > w and n > s):
        return False
    poly = shapely.Polygon(np.column_stack([ex, ey])).buffer(1e-6 * max(e - w, n - s))
    return bool(poly.contains(shapely.box(w, s, e, n)))


def _centred_box(ex: np.ndarray, ey: np.ndarray) -> tuple[float, float, float, float]:
    """The largest box of the footprint's bounding-box shape, centred on its centroid, inside it."""
    import shapely

    poly = shapely.Polygon(np.column_stack([ex, ey]))
    if not poly.is_valid or poly.area <= 0:
        return (0.0, 0.0, 0.0, 0.0)
    cx, cy = poly.centroid.x, poly.centroid.y
    hw, hh = 0.5 * (ex.max() - ex.min()), 0.5 * (ey.max() - ey.min())
    lo, hi = 0.0, 1.0
    for _ in range(40):
        m = 0.5 * (lo + hi)
        if poly.contains(shapely.box(cx - m * hw, cy - m * hh, cx + m * hw, cy + m * hh)):
            lo = m
        else:
            hi = m
    return (cx - lo * hw, cy - lo * hh, cx + lo * hw, cy + lo * hh)


def _hidden_gaps(levels: Sequence[DemRaster], srcs: Sequence[Any], dst: Any,
                 rect: tuple[float, float, float, float], ground: Any
                 ) -> tuple[int, tuple[float, float] | None]:
    """Nodata pixels inside the map whose ground no DEM measures, counted at the DEMs' own
    resolution (holes smaller than a cell fall between the world's nodes): (count, lon/lat
    of the first). Without a ground model (rasters too large) the nodes alone count."""
    if ground is None:
        return 0, None
    west, south, east, north = rect
    count, first = 0, None
    for dem, src in zip(levels, srcs):
        bad = np.argwhere(~np.isfinite(dem.z))
        if not bad.size:
            continue
        a, b, c, d, e, f = dem.transform
        x = a * (bad[:, 1] + 0.5) + b * (bad[:, 0] + 0.5) + c
        y = d * (bad[:, 1] + 0.5) + e * (bad[:, 0] + 0.5) + f
        X, Y = (np.asarray(v) for v in transformer(src, dst).transform(x, y))
        inside = (X >= west) & (X <= east) & (Y >= south) & (Y <= north)
        if not inside.any():
            continue
        unknown = np.asarray(ground.source(X[inside], Y[inside])) < 0
        count += int(unknown.sum())
        if first is None and unknown.any():
            k = int(np.flatnonzero(unknown)[0])
            lon, lat = transformer(dst, WGS84).transform(float(X[inside][k]),
                                                         float(Y[inside][k]))
            first = (float(lon), float(lat))
    return count, first


def _fill_nodata(heights: np.ndarray, valid: np.ndarray, nodata: str, gx: np.ndarray,
                 gy: np.ndarray, dst: Any, levels: Sequence[DemRaster] = (), *,
                 hidden: tuple[int, Any] = (0, None)) -> tuple[np.ndarray, np.ndarray]:
    """Heights with the nodes no DEM measures refused (``nodata="error"``) or filled from the
    nearest measured node (at most half of them); and the mask of filled nodes. ``hidden``
    (:func:`_hidden_gaps`): nodata pixels between the nodes, refused under ``"error"`` too."""
    missing = ~valid
    n_miss = int(missing.sum())
    filled = np.zeros(valid.shape, dtype=bool)
    if not n_miss and hidden[0] and nodata == "error":
        found = [s_ for d in levels for s_ in d.undeclared]
        why = (f" (among them: {', '.join(s_.describe() for s_ in found)}, nodata the file "
               "does not declare)" if found else "")
        lon, lat = hidden[1]
        raise WorldError(
            f"the DEM has {hidden[0]} nodata/NaN pixel(s) inside the map{why}, between the "
            f"world's nodes, first at lon {lon:.5f}, lat {lat:.5f}: ground no DEM measures; "
            "crop it to its data with world.bbox (CLI --bbox W,S,E,N)"
            + ("" if len(levels) > 1 else ", fill them from another DEM with world.dem_fill "
               "(CLI --dem-fill FILE)")
            + ", or set world.nodata: fill (CLI --nodata fill) to take the nearest valid "
            "elevation, reported as unknown ground (error_on_route: the same, refusing plans "
            "that fly over it)")
    if n_miss:
        i, j = np.argwhere(missing)[0]
        lon, lat = transformer(dst, WGS84).transform(float(gx[i]), float(gy[j]))
        found = [s_ for d in levels for s_ in d.undeclared]
        why = (f" (among the gaps: {', '.join(s_.describe() for s_ in found)}, nodata the file "
               "does not declare)" if found else "")
        fill_hint = ("" if len(levels) > 1 else
                     ", fill them from another DEM with world.dem_fill (CLI --dem-fill FILE)")
        if nodata == "error":
            raise WorldError(
                f"the DEM has nodata/NaN under {n_miss} of {missing.size} world nodes{why}, first "
                f"at node ({i}, {j}) = lon {lon:.5f}, lat {lat:.5f}; crop it to its data with "
                f"world.bbox (CLI --bbox W,S,E,N){fill_hint}, or set world.nodata: fill (CLI "
                "--nodata fill) to take the nearest valid elevation, reported as unknown ground "
                "(error_on_route: the same, refusing plans that fly over it)")
        if n_miss * 2 > missing.size:
            raise WorldError(
                f"the DEM has nodata under {n_miss} of {missing.size} world nodes (more than "
                f"half){why}; world.nodata: {nodata} would invent most of the terrain — crop the "
                f"DEM to its data with world.bbox (CLI --bbox W,S,E,N){fill_hint}")
        none = ~np.isfinite(heights)
        if none.any():
            _, (ii, jj) = ndimage.distance_transform_edt(none, return_indices=True)
            heights = heights[ii, jj]
        filled = missing
    return heights, filled


#: Ground deeper than this [m] is no dry land (the Dead Sea shore is at -430 m): sea floor.
DRY_LAND_LOWEST = -500.0


def _sea_level(heights: np.ndarray, sea_level: float | None, vertical: str, gx: np.ndarray,
               gy: np.ndarray, dst: Any) -> tuple[np.ndarray, str, int]:
    """Ground raised to ``sea_level`` [m] (or a warning about ground below 0 m); the heights, the
    vertical description and the number of nodes over water (at or below the sea level)."""
    if sea_level is not None:
        n_sea = int((heights <= float(sea_level) + 1e-9).sum())
        heights = np.maximum(heights, float(sea_level))
        vertical += f"; ground raised to world.sea_level = {float(sea_level):g} m over water"
        return heights, vertical, n_sea
    n_sea = int((heights < 0.0).sum())
    if n_sea:
        i, j = np.unravel_index(int(np.argmin(heights)), heights.shape)
        lon, lat = transformer(dst, WGS84).transform(float(gx[i]), float(gy[j]))
        low = float(heights[i, j])
        what = ("that is deeper than any dry land (the Dead Sea shore is at -430 m): sea "
                "floor (or a data error), which the flight would follow under the water"
                if low < DRY_LAND_LOWEST else
                "if that is sea or lake floor, the flight would follow it under the water")
        warnings.warn(
            f"the DEM has ground below 0 m under {n_sea} of {heights.size} nodes (lowest "
            f"{low:.1f} m at lon {lon:.5f}, lat {lat:.5f}); {what}; set world.sea_level: 0 (CLI "
            "--sea-level 0) to fly over the water surface — without it the ground is kept as "
            "the DEM says (polders and the Dead Sea are real)", GeodataWarning, stacklevel=3)
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
    interpolated linearly onto a regular grid of their finest step
    (:func:`fm2uav.world.lonlat_grid.lonlat_raster`). Then the grid goes through
    :func:`from_dem` (EPSG:4326 → local UTM).

    Parameters
    ----------
    z : array_like (n_lat, n_lon)
        Elevations [m]; NaN = missing.
    lon, lat : array_like (n_lon,), (n_lat,)
        Pixel-centre coordinates [deg], each strictly monotonic.
    cell_size, ceiling, **kwargs :
        As :func:`from_dem` (``nodata``, ``nodata_value``, ``bbox``, ``sea_level``,
        ``agl``, ``top``, ``name``, ``fill``).

    Raises
    ------
    InputError
        Shapes that do not match (a transposed array is named), coordinates not
        monotonic or out of range, a grid across the antimeridian.
    """
    zz, transform = lonlat_raster(z, lon, lat)
    return from_dem(zz, cell_size, ceiling, crs="EPSG:4326", transform=transform, **kwargs)
