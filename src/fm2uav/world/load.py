"""One way in for real data: :class:`WorldSpec` → :func:`load_world` → a :class:`World`.

The mission file's ``world:`` section and the CLI's world options (``--dem``,
``--buildings``, ``--bbox``, ``--sea-level``, ... defined once in
:mod:`fm2uav.cli.options`) both become a :class:`WorldSpec`; :func:`load_world`
builds the world from it:

* ``dem`` only: :func:`fm2uav.world.dem.from_dem` (any GDAL raster or tiles);
* ``buildings`` only: :func:`fm2uav.world.buildings.from_buildings` on flat
  ground (footprints' cells *touched*, so small buildings still block);
* both: the buildings on the DEM (roof = highest ground under the footprint +
  height), in the DEM world's CRS and grid.

**A world sized for the request.** ``load_world(spec, agl=..., top=...)`` is
told the highest requested height above ground (the planner's ``agl`` and the
points' ``agl``) and the highest requested altitude:

* ``cell_size`` default: the DEM's pixel size on the ground, coarsened so that
  the map has at most :data:`AUTO_COLUMNS` columns and the grid at most
  :data:`AUTO_NODES` nodes (the relief read from a decimated copy of the DEM),
  rounded down to a round number (buildings-only: 2 m, columns rule);
* ``dz`` default: ``cell_size``, and with an ``agl`` at most ``agl / 6``
  (rounded down to a round number), so the flight level is >= 6 cells above
  the ground — unless ``height_cells`` fixes the node count (then ``cell_size``);
* ``ceiling`` default: the highest ground (or roof) + ``max(20 dz, agl + 10 dz)``
  (``agl`` given) and at least ``top + 5 dz``, so a 120 m request always has sky;
* ``margin`` default (buildings without a DEM or ``bbox``): :data:`DEFAULT_MARGIN`
  (50 m), at least :data:`MARGIN_CELLS` cells, of free ground around the footprints.

**Ground of buildings without a DEM.** ``ground_elevation`` (m above sea level)
puts the flat ground at that altitude, so z is an AMSL altitude; without it z is
the height above the ground and ``World.georef.amsl`` is False: missions are then
written relative to home and say so, never as altitudes above an implicit 0 m.

Every error names the mission-file key (``world.<key>``) and the CLI flag.

:func:`check_points` refuses a start, goal or take-off over a *filled* DEM
cell (``World.filled``, nodata filled with ``nodata: fill``): its ground height
was invented. ``allow_filled`` (CLI ``--allow-filled``) turns that into a warning.
"""

from __future__ import annotations

import math
import warnings
from pathlib import Path
from typing import TYPE_CHECKING, Any, Literal

from pydantic import BaseModel, ConfigDict, Field, ValidationInfo, field_validator

from ..errors import InputError, PointError, WorldError
from .quiet import GeodataWarning, library_warnings

if TYPE_CHECKING:  # numpy and the World load with the first world, not with the schema
    from .world import World

__all__ = [
    "WorldSpec",
    "load_world",
    "check_points",
    "world_summary",
    "round_down",
    "round_up",
    "AUTO_COLUMNS",
    "AUTO_NODES",
    "DEFAULT_MARGIN",
]

#: Default free border around buildings without a DEM [m] (at least :data:`MARGIN_CELLS`
#: cells): room to take off next to the outermost building and for FM² to go around it
#: (a start 13 m beside a building was outside a map cut at the footprints).
DEFAULT_MARGIN = 50.0
MARGIN_CELLS = 10
#: Largest number of map columns (nx * ny) of an automatic cell size.
AUTO_COLUMNS = 250_000
#: Largest number of grid nodes (columns x layers) of an automatic DEM cell size.
AUTO_NODES = 8_000_000
_ROUND = (1.0, 1.5, 2.0, 2.5, 3.0, 4.0, 5.0, 6.0, 8.0)


def round_down(v: float) -> float:
    """``v`` rounded down to 1, 1.5, 2, 2.5, 3, 4, 5, 6 or 8 times a power of ten."""
    if not (math.isfinite(v) and v > 0):
        raise InputError(f"cannot round {v!r}: give a positive number")
    e = math.floor(math.log10(v))
    m = v / 10.0**e
    best = max(r for r in _ROUND if r <= m + 1e-9)
    return float(f"{best:g}e{e}")


def round_up(v: float) -> float:
    """The smallest of 1, 1.5, 2, 2.5, 3, 4, 5, 6, 8 times a power of ten that is >= ``v``."""
    r = round_down(v)
    if r >= v * (1 - 1e-9):
        return r
    e = math.floor(math.log10(v))
    for m in (*_ROUND, 10.0):
        c = float(f"{m:g}e{e}")
        if c >= v * (1 - 1e-9):
            return c
    return float(f"1e{e + 1}")  # pragma: no cover - 10 x 10^e always matches


def _resolve(v: str, info: ValidationInfo | None) -> Path:
    base = (info.context or {}).get("base_dir") if info is not None and info.context else None
    p = Path(v).expanduser()
    if not p.is_absolute() and base is not None:
        p = Path(base) / p
    return p


_STRICT = ConfigDict(strict=True, extra="forbid", frozen=True, allow_inf_nan=False)


def _num(default: Any = None, *, unit: str = "", desc: str = "", **bounds: float) -> Any:
    return Field(default, description=desc, json_schema_extra={"unit": unit}, **bounds)


#: Largest ratio between the horizontal cell and the vertical cell of a data world.
MAX_ASPECT = 1000.0


def _not_there(path: Path, allowed: str) -> str:
    """The message of a missing data file (a dangling symbolic link named as such)."""
    import os

    from .._validate import cwd_gone, missing

    v = cwd_gone(path)
    if v:
        return v
    if os.path.islink(path):
        return f"{path} {missing(path)}; allowed: {allowed}"
    return f"file not found ({path}); allowed: {allowed}"


def _regular_file(path: Path, key: str) -> None:
    """A directory, named pipe or unreadable file as a ValueError (pydantic) — never a hang.

    The file is noted as an input of the command (``key`` names it), so that an output
    folder holding it is never replaced (:func:`fm2uav._validate.input_log`)."""
    from .. import _validate as v
    from ..errors import InputError

    v.note_input(path, key)
    try:
        v.input_file(path, "file")
    except InputError as exc:
        raise ValueError(str(exc).removeprefix("file ")) from None


def _raster_file(item: str, info: ValidationInfo | None) -> str:
    """A DEM path resolved against the mission file's folder, checked to be an elevation
    raster GDAL reads (as a ValueError for pydantic)."""
    path = _resolve(item, info)
    if not path.exists():
        raise ValueError(_not_there(path, "an existing raster file (GeoTIFF, VRT, .hgt, ...)"))
    _regular_file(path, "world.dem")
    import rasterio

    from .dem_values import raster_problem

    try:
        with library_warnings(f"the DEM {path.name}"), rasterio.open(path) as ds:
            problem = raster_problem(ds, path.name)
            crs = ds.crs
    except Exception as exc:  # rasterio raises its own error types
        raise ValueError(f"cannot be read as a raster ({type(exc).__name__}); "
                         "allowed: a raster file GDAL reads (GeoTIFF, VRT, .hgt)") from None
    if problem is not None:
        raise ValueError(problem.removeprefix(f"the DEM {path.name} "))
    if crs is None and (info is None or (info.data or {}).get("crs") is None):
        raise ValueError(
            f"{path.name} has no coordinate reference system (CRS); give it with world.crs "
            "(CLI --crs), e.g. EPSG:32630, or assign one in the file (gdal_edit.py -a_srs "
            "EPSG:32630 FILE)")
    return str(path)


class WorldSpec(BaseModel):
    """The real-data part of a world: DEM, buildings, crop, sea, grid (see the module docstring).

    Paths are resolved against ``context={"base_dir": ...}`` when validated
    (the mission file's folder).
    """

    model_config = _STRICT
    # first: the DEM and buildings validators below read it (fields validate in this order)
    crs: str | None = Field(None, description="CRS of input files that declare none")
    dem: str | list[str] | None = Field(
        None, description="DEM raster file(s) GDAL reads (GeoTIFF, VRT, .hgt); several = tiles "
        "of one DEM (merged, one CRS)")
    dem_fill: str | list[str | list[str]] | None = Field(
        None, description="more DEMs in priority order that fill the gaps of dem (any CRS and "
        "resolution; an entry may be a list of tiles)")
    buildings: str | None = Field(
        None, description="building footprints: GeoJSON (lon/lat), GeoPackage, Shapefile, KML/KMZ")
    bbox: list[float] | None = Field(
        None, min_length=4, max_length=4, description="crop: west, south, east, north [deg]")
    sea_level: float | None = _num(None, unit="m", ge=-500, le=9000,
                                   desc="water surface: ground = max(DEM, sea_level)")
    cell_size: float | None = _num(None, unit="m", gt=0, le=5000,
                                   desc="horizontal grid cell (default: from the data)")
    dz: float | None = _num(None, unit="m", gt=0, le=1000,
                            desc="vertical cell (default: cell_size, at most agl/6)")
    ceiling: float | None = _num(None, unit="m", ge=-500, le=12000,
                                 desc="altitude of the top node (default: follows agl)")
    nodata: Literal["error", "fill", "error_on_route"] = Field(
        "error", description="ground no DEM measures: refuse the DEM, fill it (reported as "
        "unknown ground), or fill it and refuse plans that fly over it")
    nodata_value: float | None = _num(None, unit="m", desc="an undeclared DEM nodata value")
    default_height: float | None = _num(None, unit="m", gt=0, le=1000,
                                        desc="height of buildings without one")
    metres_per_level: float = _num(3.0, unit="m", gt=0, le=20,
                                   desc="storey height for building:levels")
    height_cells: int | None = _num(None, ge=2, le=2000,
                                    desc="number of vertical nodes (buildings on flat ground)")
    margin: float | None = _num(None, unit="m", ge=0, le=100000,
                                desc="free border around the buildings (no DEM, no bbox); "
                                "default max(50 m, 10 cells)")
    ground_elevation: float | None = _num(
        None, unit="m", ge=-500, le=9000,
        desc="altitude of the flat ground of buildings without a DEM (m above sea level)")
    allow_filled: bool = Field(False, description="start/goal on filled nodata: warn only")

    @field_validator("dem")
    @classmethod
    def _dem_files(cls, v: Any, info: ValidationInfo) -> Any:
        if v is None:
            return v
        items = [v] if isinstance(v, str) else list(v)
        if not items:
            raise ValueError("is empty; allowed: a raster file or a list of tiles")
        out = [_raster_file(item, info) for item in items]
        return out[0] if isinstance(v, str) else out

    @field_validator("dem_fill")
    @classmethod
    def _fill_files(cls, v: Any, info: ValidationInfo) -> Any:
        if v is None:
            return v
        items = [v] if isinstance(v, str) else list(v)
        if not items:
            raise ValueError("is empty; allowed: a raster file or a list of them (priority "
                             "order)")
        out: list[Any] = []
        for item in items:
            if isinstance(item, list):
                if not item:
                    raise ValueError("has an empty list of tiles; allowed: raster files")
                out.append([_raster_file(t, info) for t in item])
            else:
                out.append(_raster_file(item, info))
        return out

    @field_validator("dem_fill")
    @classmethod
    def _fill_needs_dem(cls, v: Any, info: ValidationInfo) -> Any:
        if v is not None and (info.data or {}).get("dem") is None:
            raise ValueError("fills the gaps of world.dem (CLI --dem), which is not given; "
                             "give the DEM first, or make this DEM world.dem")
        return v

    def fill_sources(self) -> list[Any]:
        """``dem_fill`` as a list (each entry a file or a list of tiles), priority order."""
        if self.dem_fill is None:
            return []
        return [self.dem_fill] if isinstance(self.dem_fill, str) else list(self.dem_fill)

    def dem_files(self) -> list[str]:
        """Every DEM file of the spec (``dem`` tiles, then each ``dem_fill`` entry's files)."""
        out = [] if self.dem is None else ([self.dem] if isinstance(self.dem, str)
                                           else list(self.dem))
        for item in ([self.dem_fill] if isinstance(self.dem_fill, str) else
                     list(self.dem_fill or ())):
            out += item if isinstance(item, list) else [item]
        return out

    @field_validator("buildings")
    @classmethod
    def _buildings_file(cls, v: str | None, info: ValidationInfo) -> str | None:
        if v is None:
            return v
        path = _resolve(v, info)
        if not path.exists():
            raise ValueError(_not_there(path, "an existing vector file (GeoJSON, GeoPackage, "
                                        "Shapefile, KML/KMZ)"))
        _regular_file(path, "world.buildings")
        return str(path)

    @field_validator("bbox")
    @classmethod
    def _bbox(cls, v: list[float] | None) -> list[float] | None:
        if v is None:
            return v
        from .geo import check_lonlat_bbox

        try:
            return list(check_lonlat_bbox(v, "bbox"))
        except InputError as exc:
            raise ValueError(str(exc).removeprefix("bbox = ")) from None

    @field_validator("crs")
    @classmethod
    def _crs(cls, v: str | None) -> str | None:
        if v is None:
            return v
        from pyproj import CRS
        from pyproj.exceptions import CRSError

        try:
            CRS.from_user_input(v)
        except CRSError:
            raise ValueError("is not a CRS pyproj knows; allowed: e.g. EPSG:4326 (lon/lat) or "
                             "EPSG:32630") from None
        return v

    @property
    def has_data(self) -> bool:
        """Whether the spec names a DEM or a buildings file."""
        return self.dem is not None or self.buildings is not None

    def describe(self) -> str:
        """Short text of the sources, for titles (e.g. ``"dem.tif + town.geojson"``)."""
        parts = []
        if self.dem is not None:
            dems = [self.dem] if isinstance(self.dem, str) else self.dem
            parts.append(Path(dems[0]).name + (f" (+{len(dems) - 1} tiles)" if len(dems) > 1
                                               else ""))
            fills = self.fill_sources()
            if fills:
                names = [Path(f if isinstance(f, str) else f[0]).name for f in fills]
                parts[-1] += f" (gaps from {', '.join(names)})"
        if self.buildings is not None:
            parts.append(Path(self.buildings).name)
        return " + ".join(parts)


def _pixel_ground_size(path: str) -> tuple[float, float]:
    """(pixel size on the ground [m], footprint area [m²]) of a raster from its metadata."""
    import rasterio

    from .dem_values import pixel_sizes
    from .geo import bounds_lonlat, parse_crs

    with library_warnings(f"the DEM {Path(path).name}"), rasterio.open(path) as ds:
        crs = parse_crs(ds.crs.to_wkt()) if ds.crs is not None else None
        t = ds.transform
        shape = (ds.height, ds.width)
        b = ds.bounds
    if crs is None:
        res = max(math.hypot(t.a, t.d), math.hypot(t.b, t.e))
        return res, (b.right - b.left) * (b.top - b.bottom)
    ll = bounds_lonlat((b.left, b.bottom, b.right, b.top), crs)
    from pyproj import Geod

    lat_c = 0.5 * (ll[1] + ll[3])
    geod = Geod(ellps="WGS84")
    width = geod.inv(ll[0], lat_c, ll[2], lat_c)[2]
    height = geod.inv(ll[0], ll[1], ll[0], ll[3])[2]
    if crs.is_geographic:
        # the larger step in degrees, as metres east-west at the centre (the pixel's short
        # side towards the poles: the finer of the two ground spacings of a square-degree grid)
        res = max(math.hypot(t.a, t.d), math.hypot(t.b, t.e))
        return float(res * 111320.0 * max(math.cos(math.radians(lat_c)), 0.05)), \
            float(width * height)
    ex, ey = pixel_sizes(tuple(t)[:6], crs, shape)
    return float(max(ex[0], ey[0])), float(width * height)


def _bbox_area(bbox: Any) -> float:
    from pyproj import Geod

    w, s, e, n = bbox
    return abs(Geod(ellps="WGS84").polygon_area_perimeter([w, e, e, w], [s, s, n, n])[0])


def _relief_of(path: str, spec: WorldSpec) -> tuple[float, float] | None:
    """(lowest, highest) elevation [m] of one DEM file over the area, from a decimated read
    (<= 256²) taken through the same nodata, sentinel and sea-level rules as the real read."""
    import numpy as np
    import rasterio
    from rasterio.windows import from_bounds

    from .dem_values import find_sentinels, length_unit_factor, pixel_sizes

    try:
        with library_warnings(f"the DEM {Path(path).name}"), rasterio.open(path) as ds:
            win = None
            if spec.bbox is not None and ds.crs is not None:
                from .dem_read import _bbox_in
                from .geo import parse_crs

                b = _bbox_in(parse_crs(ds.crs.to_wkt()), tuple(spec.bbox))
                win = from_bounds(*b, transform=ds.transform)
            full_h = ds.height if win is None else max(win.height, 1)
            full_w = ds.width if win is None else max(win.width, 1)
            h, w = int(min(256, full_h)), int(min(256, full_w))
            z = ds.read(1, masked=True, window=win, out_shape=(max(h, 1), max(w, 1)),
                        boundless=win is not None, out_dtype="float64")
            scale, offset = float(ds.scales[0] or 1.0), float(ds.offsets[0] or 0.0)
            unit = length_unit_factor(ds.units[0] if ds.units else None) or 1.0
            crs = ds.crs.to_wkt() if ds.crs is not None else spec.crs
            t = tuple(ds.transform)[:6]
            dtype = ds.dtypes[0]
    except Exception:  # any read problem is reported by the real read
        return None
    raw = np.ma.filled(z, np.nan)
    if spec.nodata_value is not None:
        raw[raw == spec.nodata_value] = np.nan
    if crs is not None and np.isfinite(raw).any():
        try:
            ex, ey = pixel_sizes(t, crs, raw.shape)
            k = max(full_h / raw.shape[0], full_w / raw.shape[1])  # the decimation
            mask, _ = find_sentinels(raw, dtype, lambda a: (a * scale + offset) * unit,
                                     ex[:1] * k, ey[:1] * k)
            raw[mask] = np.nan
        except Exception:  # the real read reports it
            pass
    v = (raw[np.isfinite(raw)] * scale + offset) * unit
    if v.size == 0:
        return None
    lo, hi = float(v.min()), float(v.max())
    if spec.sea_level is not None:
        lo = max(lo, float(spec.sea_level))
    return lo, max(hi, lo)


def _relief(spec: WorldSpec) -> tuple[float, float] | None:
    """(lowest, highest) elevation [m] of the DEMs' area (``dem`` and every ``dem_fill``)."""
    firsts = [spec.dem if isinstance(spec.dem, str) else spec.dem[0]]
    firsts += [f if isinstance(f, str) else f[0] for f in spec.fill_sources()]
    reliefs = [r for r in (_relief_of(f, spec) for f in firsts) if r is not None]
    if not reliefs:
        return None
    return min(r[0] for r in reliefs), max(r[1] for r in reliefs)


def _auto_cell(spec: WorldSpec, agl: float | None = None) -> tuple[float, str]:
    """Default horizontal cell [m] and how it was chosen (see the module docstring)."""
    if spec.dem is not None:
        first = spec.dem if isinstance(spec.dem, str) else spec.dem[0]
        pix, area = _pixel_ground_size(first)
        if spec.bbox is not None:
            area = _bbox_area(spec.bbox)
        elif isinstance(spec.dem, list):
            area *= len(spec.dem)  # tiles of about one size
        cap = math.sqrt(area / AUTO_COLUMNS)
        cell = max(pix, cap)
        capped = pix < cap
        why = (f"auto: DEM pixel {pix:.1f} m on the ground" if not capped else
               f"auto: at most {AUTO_COLUMNS} map columns over {area / 1e6:.1f} km²")
        relief = _relief(spec)
        if relief is not None and spec.dz is None:
            # keep the whole grid (columns x layers) under AUTO_NODES
            for _ in range(8):
                dz = min(cell, agl / 6.0) if agl is not None else cell
                top = max(20.0 * dz, (agl or 0.0) + 10.0 * dz)
                nz = (relief[1] - relief[0] + top) / dz + 2.0
                nodes = area / (cell * cell) * nz
                if nodes <= 0.85 * AUTO_NODES:  # the decimated relief and area run low
                    break
                cell *= math.sqrt(nodes / (0.85 * AUTO_NODES))
                capped = True
                why = (f"auto: at most {AUTO_NODES / 1e6:g} million nodes over "
                       f"{area / 1e6:.1f} km² and {relief[1] - relief[0]:.0f} m of relief")
        # the pixel size rounds down (no coarser than the data); a cap rounds up (stays a cap)
        return (round_up(cell) if capped else round_down(cell)), why
    from .vectors import read_vectors

    data = read_vectors(spec.buildings, target_crs="auto", crs=spec.crs, role="buildings")
    if spec.bbox is not None:
        area = _bbox_area(spec.bbox)
    elif data.geometries:
        import numpy as np
        import shapely

        x0, y0, x1, y1 = shapely.total_bounds(np.asarray(data.geometries, dtype=object))
        mg = DEFAULT_MARGIN if spec.margin is None else spec.margin
        area = (x1 - x0 + 2 * mg) * (y1 - y0 + 2 * mg)
    else:
        area = 0.0
    cap = math.sqrt(max(area, 1.0) / AUTO_COLUMNS)
    cell = round_up(cap) if cap > 2.0 else 2.0
    return cell, ("auto: 2 m for buildings" if cap <= 2.0 else
                  f"auto: at most {AUTO_COLUMNS} map columns over {area / 1e6:.2f} km²")


def _requested(v: float | None, what: str) -> float | None:
    if v is None:
        return None
    f = float(v)
    if not math.isfinite(f) or f <= 0:
        raise InputError(f"{what} must be a positive height in metres, got {v!r}")
    return f


def load_world(spec: WorldSpec, *, agl: float | None = None, top: float | None = None,
               name: str = "", max_cell: tuple[float, str] | None = None) -> World:
    """Build the world a :class:`WorldSpec` describes, sized for the request.

    Parameters
    ----------
    spec : WorldSpec
        With ``dem`` and/or ``buildings``.
    agl : float, optional
        Highest requested height above the ground [m] (planner ``agl``, points'
        ``agl``): sets the default ``dz`` (<= agl / 6) and ceiling.
    top : float, optional
        Highest requested altitude [m] (points given with ``alt`` / ``z``).
    name : str
        World name (default: the source file's stem).
    max_cell : (float, str), optional
        Largest automatic cell size [m] and why (e.g. a survey whose bands must be
        resolved): the default ``cell_size`` is rounded down to it. Ignored when
        ``spec.cell_size`` is given.

    Returns
    -------
    World
        With ``crs``, ``georef`` (sources with SHA-256, the cell choices in the
        DEM source's ``details``) and, for DEMs, ``filled``.

    Raises
    ------
    InputError, WorldError
        One line naming the mission-file key and the CLI flag.
    """
    from .buildings import from_buildings
    from .dem import from_dem

    if not spec.has_data:
        raise InputError("the world needs world.dem (CLI --dem) and/or world.buildings "
                         "(CLI --buildings)")
    if spec.ground_elevation is not None and spec.dem is not None:
        raise InputError("world.ground_elevation (--ground-elevation) is for buildings without "
                         "a DEM; with world.dem (--dem) the ground is the DEM's: leave it out")
    if spec.margin is not None and spec.dem is not None:
        raise InputError("world.margin (--margin) is for buildings without a DEM; with "
                         "world.dem (--dem) the map is the DEM's (crop it with world.bbox / "
                         "--bbox): leave it out")
    agl = _requested(agl, "planner.agl (--agl)")
    if spec.cell_size is not None:
        dx, why_dx = float(spec.cell_size), "given (world.cell_size)"
    else:
        dx, why_dx = _auto_cell(spec, agl)
        if max_cell is not None and float(max_cell[0]) < dx:
            dx, why_dx = round_down(float(max_cell[0])), f"auto: {max_cell[1]}"
    if spec.dz is not None:
        dz, why_dz = float(spec.dz), "given (world.dz)"
    elif spec.height_cells is not None:
        dz, why_dz = dx, "= cell_size (world.height_cells fixes the node count)"
    elif agl is not None and agl / 6.0 < dx:
        dz, why_dz = round_down(agl / 6.0), f"auto: at most agl / 6 = {agl / 6.0:.3g} m"
    else:
        dz, why_dz = dx, "auto: = cell_size"
    if agl is not None and agl < dz / 2.0:
        raise InputError(
            f"world.dz (--dz) = {dz:g} m is more than twice the requested height above ground "
            f"{agl:g} m: the flight level would round to the ground; use world.dz <= {agl / 6:g}")
    if max(dx, dz) / min(dx, dz) > MAX_ASPECT:
        # e.g. dz 1 mm under 30 m cells: 9e4 layers, a 3e8-node march running for hours
        raise InputError(
            f"world.cell_size (--cell-size) = {dx:g} m and world.dz (--dz) = {dz:g} m differ by "
            f"a factor {max(dx, dz) / min(dx, dz):.3g} (limit {MAX_ASPECT:g}): the grid would "
            "need absurdly many nodes for its accuracy; give a dz between "
            f"{dx / MAX_ASPECT:g} and {dx * MAX_ASPECT:g} m")
    stem = name
    if not stem:
        first = spec.dem if isinstance(spec.dem, str) else (spec.dem or [spec.buildings])[0]
        stem = Path(str(first)).stem
    grid = {"cell_size": dx, "cell_size_rule": why_dx, "dz": dz, "dz_rule": why_dz}
    world = None
    if spec.dem is not None:
        world = from_dem(spec.dem, (dx, dx, dz), spec.ceiling, fill=spec.fill_sources(),
                         crs=spec.crs, nodata=spec.nodata,
                         nodata_value=spec.nodata_value, bbox=spec.bbox,
                         sea_level=spec.sea_level, agl=agl, top=top, name=stem)
    if spec.buildings is not None:
        margin = (max(DEFAULT_MARGIN, MARGIN_CELLS * dx) if spec.margin is None
                  else float(spec.margin))
        world = from_buildings(
            spec.buildings, (dx, dx, dz), height_cells=spec.height_cells,
            metres_per_level=spec.metres_per_level, default_height=spec.default_height,
            margin=margin, name=stem, crs=spec.crs, terrain=world, all_touched=True,
            bbox=spec.bbox if world is None else None, agl=agl, top=top,
            ground_elevation=spec.ground_elevation)
        if spec.ceiling is not None and world.bounds[2, 1] > spec.ceiling + 1e-6 and \
                spec.dem is not None:
            raise WorldError(
                f"world.ceiling (--ceiling) = {spec.ceiling:g} m is below the roofs plus the "
                f"requested height; raise it to at least {world.bounds[2, 1]:.0f} m or leave "
                "it out")
    if world.georef is not None:
        import dataclasses

        srcs = list(world.georef.sources)
        srcs[0] = dataclasses.replace(srcs[0], details={**srcs[0].details, **grid})
        world = dataclasses.replace(world, georef=dataclasses.replace(world.georef,
                                                                      sources=tuple(srcs)))
    return world


def check_points(world: World, points: dict[str, Any], *, allow_filled: bool = False) -> None:
    """Refuse named points (``{"start": p, "goal": q}``) over filled DEM nodata (ground no DEM
    measures, :func:`fm2uav.world.ground.ground_source`).

    Parameters
    ----------
    world : World
    points : dict
        Name → world point [m] (x, y[, z]).
    allow_filled : bool
        Warn (:class:`~fm2uav.world.dem.GeodataWarning`) instead of raising.

    Raises
    ------
    PointError
        A point whose ground height is filled (invented); the message names
        ``--allow-filled`` / ``world.allow_filled``.
    """
    import numpy as np

    from .ground import has_unknown_ground

    if not has_unknown_ground(world):
        return
    for what, p in points.items():
        q = np.asarray(p, dtype=float)
        world.to_cell(q, what=what)  # outside the map: named as such
        # the rule of every safety figure: the ground under the point is measured by no DEM
        if bool(np.asarray(world.ground_filled(q[0], q[1]))):
            lonlat = ""
            if world.crs is not None:
                from .geo import to_lonlat

                ll = to_lonlat(world, [q[0], q[1], 0.0])
                lonlat = f" (lon {ll[0]:.5f}, lat {ll[1]:.5f})"
            msg = (f"the {what}{lonlat} lies over a DEM gap whose ground height was filled "
                   "(world.nodata: fill), so its altitude above ground is invented; move the "
                   f"{what} onto real data, or accept it with --allow-filled "
                   "(mission file: world.allow_filled: true)")
            if not allow_filled:
                raise PointError(msg)
            warnings.warn(msg.split("; move")[0] + " (allowed by --allow-filled)",
                          GeodataWarning, stacklevel=2)


def world_summary(world: World) -> dict[str, Any]:
    """What a summary says about a world: CRS, vertical reference, sources, counts.

    JSON-ready; ``{"crs": None, ...}`` for worlds without a CRS.
    """
    g = getattr(world, "georef", None)
    out: dict[str, Any] = {"name": world.name, "shape": list(world.shape),
                           "spacing_m": list(world.spacing), "crs": world.crs}
    if g is not None:
        out["georef"] = g.as_dict()
        for s in g.sources:
            d = dict(s.details)
            if s.role == "buildings":
                out["buildings"] = {"count": d.get("buildings"),
                                    "height_rule": d.get("height_rule"),
                                    "skipped": d.get("skipped", {}),
                                    "outside_map": d.get("outside_map", 0)}
    if getattr(world, "filled", None) is not None:
        out["filled_nodes"] = int(world.filled.sum())
    return out
