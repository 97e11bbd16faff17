"""Coordinate reference systems for geo-referenced worlds (pyproj).

A world built from a DEM keeps its x/y in a *metric* projected CRS (the DEM's
own if it is projected in metres, else the UTM zone of the DEM's centre) and
stores it as :attr:`World.crs`; z is the DEM's elevation datum (normally
metres above mean sea level). These helpers pick that CRS and convert world
points to WGS84 longitude/latitude/altitude and back (:func:`to_lonlat`,
:func:`from_lonlat`, world first); a world without a CRS is placed at an
:class:`Anchor` on the Earth (the one conversion every export uses).

Choosing the world's CRS (:func:`local_metric_crs`): lengths in the world must
be true to :data:`MAX_SCALE_ERROR` (0.5 %). A projected CRS in metres is kept
when its point scale factor (``pyproj.Proj.get_factors``, Tissot's semi-axes)
stays within 1 ± 0.5 % over the area; otherwise (geographic degrees, Web
Mercator away from the equator, feet, any distorting projection) the world is
built in the UTM zone of the area's centre, or — when the area is too wide for
that zone's 0.5 % — in a transverse Mercator centred on the area (``k = 1``).

:class:`Georef` records where a world is: its horizontal CRS (EPSG code when
there is one), the vertical reference of its z, and the source files with
their SHA-256, so that every output can say where it is.
"""

from __future__ import annotations

import hashlib
from collections.abc import Mapping
from dataclasses import dataclass, field
from functools import lru_cache
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import InputError, WorldError

__all__ = [
    "Georef",
    "SourceFile",
    "MAX_SCALE_ERROR",
    "MAX_NODES",
    "check_size",
    "sha256_file",
    "scale_error",
    "local_metric_crs",
    "crs_label",
    "crs_token",
    "crs_epsg",
    "crs_string",
    "check_lonlat_bbox",
    "bounds_lonlat",
    "check_fit",
    "make_georef",
    "amsl_known",
    "parse_crs",
    "utm_crs",
    "metric_crs",
    "transformer",
    "Anchor",
    "DEFAULT_ANCHOR",
    "to_lonlat",
    "from_lonlat",
]

WGS84 = "EPSG:4326"


@lru_cache(maxsize=256)
def _crs_from_text(text: str) -> Any:
    from pyproj import CRS

    return CRS.from_user_input(text)


def parse_crs(crs: Any) -> Any:
    """A :class:`pyproj.CRS` from a string/EPSG code/CRS object, with a clear error
    (strings are parsed once: a custom WKT takes tens of milliseconds)."""
    from pyproj import CRS
    from pyproj.exceptions import CRSError

    if crs is None:
        raise WorldError(
            "the DEM has no coordinate reference system; pass crs= (e.g. crs='EPSG:4326' "
            "for longitude/latitude degrees or the EPSG code of its projection)"
        )
    try:
        if isinstance(crs, CRS):
            return crs
        if isinstance(crs, str):
            return _crs_from_text(crs)
        return CRS.from_user_input(crs)
    except CRSError as exc:
        raise WorldError(f"unknown coordinate reference system {crs!r}: {exc}") from None


@lru_cache(maxsize=256)
def _wkt_of_text(text: str) -> str:
    return _crs_from_text(text).to_wkt()


def _key(crs: Any) -> str:
    """One string per CRS, however it was written (EPSG code, PROJ string, WKT1 of a file,
    pyproj's WKT2): its WKT, so that caches keyed on it find it again."""
    return _wkt_of_text(crs) if isinstance(crs, str) else parse_crs(crs).to_wkt()


@lru_cache(maxsize=256)
def _identity_of(wkt: str) -> tuple[int | None, int | None, tuple[str, str] | None, str]:
    c = parse_crs(wkt)
    matches = c.list_authority(min_confidence=70)
    epsg70 = next((int(m.code) for m in matches if m.auth_name == "EPSG"), None)
    epsg90 = next((int(m.code) for m in matches if m.auth_name == "EPSG"
                   and m.confidence >= 90), None)
    auth90 = next(((m.auth_name, m.code) for m in matches if m.confidence >= 90), None)
    full = next((f"{m.auth_name}:{m.code}" for m in matches if m.confidence >= 100), None)
    return epsg70, epsg90, auth90, full or c.srs


def _identity(key: str) -> tuple[int | None, int | None, tuple[str, str] | None, str]:
    """(EPSG code at 70 % confidence, at 90 %, authority at 90 %, ``to_string()``) of a CRS.

    pyproj searches its whole database for a CRS without an authority code (about half a
    second for a custom WKT), so each CRS is identified once, in one search.
    """
    ident = _identity_of(_key(key))
    return ident[:3] + ((key if isinstance(key, str) and ident[3] == _key(key) else ident[3]),)


def crs_epsg(crs: Any, min_confidence: int = 70) -> int | None:
    """EPSG code of a CRS (None without one), identified once per CRS."""
    ident = _identity(crs if isinstance(crs, str) else _key(crs))
    return ident[1] if min_confidence >= 90 else ident[0]


def crs_string(crs: Any) -> str:
    """``pyproj.CRS.to_string()`` of a CRS (authority string, else its definition), cached."""
    return _identity(crs if isinstance(crs, str) else _key(crs))[3]


def utm_crs(lon: float, lat: float) -> str:
    """EPSG code (``"EPSG:326zz"`` north / ``"EPSG:327zz"`` south) of the UTM zone at a point [deg]."""
    if not (np.isfinite(lon) and np.isfinite(lat) and -180 <= lon <= 180 and -80 <= lat <= 84):
        raise WorldError(
            f"longitude/latitude ({lon}, {lat}) deg is outside the UTM range "
            "(lon -180..180, lat -80..84); is the DEM's CRS right?"
        )
    zone = min(int((lon + 180.0) // 6.0) + 1, 60)
    return f"EPSG:{(32600 if lat >= 0 else 32700) + zone}"


def _is_metre(crs: Any) -> bool:
    units = [a.unit_name for a in crs.axis_info[:2]]
    return bool(units) and all(u in ("metre", "meter", "m") for u in units)


def metric_crs(crs: Any, lon: float, lat: float) -> str:
    """The metric CRS a world uses for a DEM in ``crs`` centred at (lon, lat) [deg].

    Geographic → UTM zone of the centre; projected in metres → itself.

    Raises
    ------
    WorldError
        Projected CRS whose units are not metres (reproject the DEM first).
    """
    c = parse_crs(crs)
    if c.is_geographic:
        return utm_crs(lon, lat)
    if c.is_projected and _is_metre(c):
        return c.to_string()
    raise WorldError(
        f"the DEM's CRS {c.to_string()!r} is neither geographic nor projected in metres "
        f"(axis units {[a.unit_name for a in c.axis_info]}); reproject it (e.g. gdalwarp "
        "-t_srs EPSG:4326) first"
    )


@lru_cache(maxsize=32)
def _transformer(src: str, dst: str) -> Any:
    from pyproj import Transformer

    return Transformer.from_crs(src, dst, always_xy=True)


def transformer(src: Any, dst: Any) -> Any:
    """Cached ``pyproj.Transformer`` (x/lon first) from ``src`` to ``dst``."""
    return _transformer(_key(src), _key(dst))


@dataclass(frozen=True)
class Anchor:
    """Where a world without a CRS is placed on the Earth.

    Attributes
    ----------
    lon, lat : float
        WGS84 longitude and latitude of world ``(x, y) = (0, 0)`` [deg].
    alt : float
        Altitude of world ``z = 0`` above mean sea level [m].
    """

    lon: float
    lat: float
    alt: float = 0.0

    def __post_init__(self) -> None:
        for name, lo, hi in (("lon", -180.0, 180.0), ("lat", -89.0, 89.0)):
            v = getattr(self, name)
            if not isinstance(v, (int, float, np.number)) or not np.isfinite(v) or not lo <= v <= hi:
                raise InputError(f"anchor {name} must be a number in [{lo:g}, {hi:g}] deg, got {v!r}")
        if not np.isfinite(self.alt):
            raise InputError(f"anchor alt must be a finite height in metres, got {self.alt!r}")


#: Default anchor of synthetic worlds: UC3M, Leganés (Madrid), 0 m.
DEFAULT_ANCHOR = Anchor(lon=-3.7649, lat=40.3326, alt=0.0)


@lru_cache(maxsize=32)
def _anchor_transformers(proj: str) -> tuple[Any, Any]:
    from pyproj import Transformer

    return (Transformer.from_crs(proj, "EPSG:4326", always_xy=True),
            Transformer.from_crs("EPSG:4326", proj, always_xy=True))


def _anchor_crs(anchor: Anchor) -> str:
    return (
        f"+proj=aeqd +lat_0={anchor.lat!r} +lon_0={anchor.lon!r} +x_0=0 +y_0=0 "
        "+datum=WGS84 +units=m +no_defs"
    )


def _frame(world: Any, anchor: Anchor | None) -> tuple[Any, Any, float]:
    """(world → WGS84, WGS84 → world, altitude offset [m]) of a world."""
    crs = getattr(world, "crs", None)
    if crs:
        c = parse_crs(str(crs))
        if c.is_geographic:
            raise WorldError(
                f"world CRS {crs!r} is geographic (degrees), but world x/y are metres; "
                "build the world in a projected CRS (e.g. the UTM zone of the area)"
            )
        return transformer(c, WGS84), transformer(WGS84, c), 0.0
    a = DEFAULT_ANCHOR if anchor is None else anchor
    if not isinstance(a, Anchor):
        raise InputError(f"anchor must be a fm2uav.io.Anchor(lon, lat, alt), got {a!r}")
    fwd, inv = _anchor_transformers(_anchor_crs(a))
    return fwd, inv, float(a.alt)


def _points(points: Any, what: str) -> tuple[np.ndarray, bool]:
    """``(N, 2|3)`` finite float points, and whether one point ``(2|3,)`` was given."""
    try:
        p = np.asarray(points, dtype=float)
    except (TypeError, ValueError):
        raise InputError(f"{what} must be numeric, got {points!r}") from None
    one = p.ndim == 1
    q = p[None, :] if one else p
    if q.ndim != 2 or q.shape[1] not in (2, 3):
        raise InputError(f"{what} must have shape (N, 2) or (N, 3), got {p.shape}")
    if not np.all(np.isfinite(q)):
        raise InputError(f"{what} has non-finite values")
    return q, one


def to_lonlat(world: Any, points_m: Any, *, anchor: Anchor | None = None) -> np.ndarray:
    """World points [m] → WGS84 ``(lon [deg], lat [deg], alt [m])``.

    Parameters
    ----------
    world : World or None
        With ``world.crs`` (a DEM or footprints in a projected CRS): world x, y
        are coordinates of that CRS and ``alt`` is world z (the data's
        vertical datum, normally metres above mean sea level). Without a CRS
        (synthetic scenarios, or None) the world sits on the local tangent
        plane of ``anchor`` (azimuthal equidistant, +x east, +y north) and
        ``alt = z + anchor.alt``.
    points_m : array_like, shape (N, 2|3) or (2|3,)
        World coordinates [m]; 2D points get ``z = 0``.
    anchor : Anchor, optional
        Placement of a world without CRS; default :data:`DEFAULT_ANCHOR`
        (the UC3M Leganés campus, where the source thesis was written).
        Ignored when the world has a CRS.

    Returns
    -------
    ndarray, shape (N, 3) (or (3,) for one point)
    """
    q, one = _points(points_m, "points_m")
    fwd, _, dz = _frame(world, anchor)
    lon, lat = fwd.transform(q[:, 0], q[:, 1])
    z = q[:, 2] if q.shape[1] == 3 else np.zeros(len(q))
    out = np.column_stack([np.asarray(lon), np.asarray(lat), z + dz])
    return out[0] if one else out


def from_lonlat(world: Any, lonlatalt: Any, *, anchor: Anchor | None = None) -> np.ndarray:
    """WGS84 ``(lon [deg], lat [deg][, alt [m]])`` → world [m]; the inverse of :func:`to_lonlat`.

    ``(N, 2)`` lon/lat give ``(N, 2)`` world x, y; ``(N, 3)`` give x, y, z.
    """
    q, one = _points(lonlatalt, "lonlatalt")
    if np.any(np.abs(q[:, 1]) > 90) or np.any(np.abs(q[:, 0]) > 180):
        raise InputError("longitude must be in [-180, 180] and latitude in [-90, 90] degrees")
    _, inv, dz = _frame(world, anchor)
    x, y = inv.transform(q[:, 0], q[:, 1])
    out = np.column_stack([np.asarray(x), np.asarray(y)])
    if q.shape[1] == 3:
        out = np.column_stack([out, q[:, 2] - dz])
    return out[0] if one else out


# ---------------------------------------------------------------------- CRS choice
#: Largest number of grid nodes a world built from data may have (a bool
#: occupancy of this size takes 400 MB; the FM² arrays take ~20x more).
MAX_NODES = 400_000_000


#: Memory FM² planning takes per grid node [bytes] (occupancy, distance, W, T, the
#: marcher's state), used to say how much a refused grid would need.
BYTES_PER_NODE = 40


def _memory_bytes() -> float:
    """Physical memory of this machine [bytes] (inf if unknown)."""
    import os

    try:
        return float(os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES"))
    except (ValueError, OSError, AttributeError):  # pragma: no cover - non-POSIX
        return float("inf")


#: A terrain (column) world planned regionally (coarse-to-fine windows,
#: :mod:`fm2uav.planning.regional`) holds only its bool grid at full size: bytes per
#: node, with the building's transient and the windows.
COLUMN_BYTES_PER_NODE = 3
#: Largest number of nodes of a terrain (column) world.
MAX_COLUMN_NODES = 4_000_000_000


def check_size(shape: Any, cell: Any, *, columns: bool = False) -> None:
    """Refuse, before anything is allocated, a grid larger than :data:`MAX_NODES` or
    than this machine's memory, saying how much it would need and what shrinks it.

    ``columns=True``: a terrain world (DEM), which a terrain-following plan may plan
    regionally, at :data:`COLUMN_BYTES_PER_NODE` (limit :data:`MAX_COLUMN_NODES`)."""
    n = float(np.prod([float(int(v)) for v in shape]))
    per_node = COLUMN_BYTES_PER_NODE if columns else BYTES_PER_NODE
    need = n * per_node
    limit = min(float(MAX_COLUMN_NODES if columns else MAX_NODES), _memory_bytes() / per_node)
    if n > limit:
        raise WorldError(
            f"the world would have {' x '.join(str(int(v)) for v in shape)} = {n:.3g} nodes "
            f"(about {need / 2**30:.3g} GiB to plan on; limit {limit:.2g} nodes on this "
            f"machine) at cells of {' x '.join(f'{float(c):g}' for c in cell)} m; "
            "use a larger world.cell_size / world.dz (CLI --cell-size / --dz) or crop the "
            "area with world.bbox (CLI --bbox W,S,E,N)")


#: Largest length distortion accepted in a world's CRS (0.5 %): beyond it the
#: data are reprojected (see :func:`local_metric_crs`).
MAX_SCALE_ERROR = 0.005


def crs_label(crs: Any) -> str:
    """Short name of a CRS: ``"EPSG:32630"`` when it has an authority code, a PROJ string
    when it was given as one (the world's own transverse Mercator), else its name and
    projection, e.g. ``'"Custom TM South" (Transverse Mercator; WKT without an EPSG code)'``
    — never a whole WKT, and never through ``to_proj4`` (which warns and loses datum
    shifts)."""
    _, code, auth, text = _identity(crs if isinstance(crs, str) else _key(crs))
    if code is not None:
        return f"EPSG:{code}"
    if auth is not None:
        return f"{auth[0]}:{auth[1]}"
    if text.startswith("+proj"):
        return text
    c = parse_crs(crs)
    base = c.source_crs if c.is_bound and c.source_crs is not None else c
    name = base.name if base.name and base.name.lower() not in ("unknown", "unnamed") else ""
    op = getattr(base, "coordinate_operation", None)
    method = getattr(op, "method_name", "") if op is not None else ""
    kind = method or ("geographic" if base.is_geographic else base.type_name)
    shown = f'"{name}"' if name else "unnamed CRS"
    return f"{shown} ({kind}; WKT without an EPSG code)"


def crs_token(crs: Any) -> str:
    """One word naming a CRS exactly, for file headers (``# crs=...``): its authority code
    (``"EPSG:32630"``), else ``"wkt-sha256:"`` and 16 hex digits of its WKT.

    Two files on the same world carry the same token, so ``fm2uav export`` can tell a
    path planned on another world even when the CRS has no EPSG code.
    """
    _, code, auth, _ = _identity(crs if isinstance(crs, str) else _key(crs))
    if code is not None:
        return f"EPSG:{code}"
    if auth is not None:
        return f"{auth[0]}:{auth[1]}"
    return "wkt-sha256:" + hashlib.sha256(parse_crs(crs).to_wkt().encode()).hexdigest()[:16]


def _lonlat_samples(bbox: tuple[float, float, float, float], n: int = 7) -> tuple[np.ndarray, np.ndarray]:
    w, s, e, nn = bbox
    lon, lat = np.meshgrid(np.linspace(w, e, n), np.linspace(s, nn, n))
    return lon.ravel(), np.clip(lat.ravel(), -89.9, 89.9)


def scale_error(crs: Any, bbox_lonlat: tuple[float, float, float, float]) -> float:
    """Largest length distortion ``max |k - 1|`` of a projected CRS over a lon/lat box.

    ``k`` runs over Tissot's semi-axes (``pyproj.Proj.get_factors``) at 7 x 7
    points of the box, times the CRS's unit in metres (a CRS in feet has
    ``k ~ 3.28`` per metre). Geographic CRSs give ``inf`` (degrees are not lengths).
    """
    from pyproj import Proj

    c = parse_crs(crs)
    if not c.is_projected:
        return float("inf")
    unit = c.axis_info[0].unit_conversion_factor if c.axis_info else 1.0
    lon, lat = _lonlat_samples(bbox_lonlat)
    try:
        f = Proj(c).get_factors(lon, lat)
    except Exception:  # pyproj raises ProjError for projections without factors
        return float("inf")
    a = np.asarray(f.tissot_semimajor, dtype=float)
    b = np.asarray(f.tissot_semiminor, dtype=float)
    if not (np.all(np.isfinite(a)) and np.all(np.isfinite(b))):
        return float("inf")
    # k is dimensionless (ground length -> projected metres); a CRS in feet
    # stores k / unit units per ground metre, which is what lengths in the
    # world would be off by if its numbers were read as metres
    k = np.concatenate([a, b]) / unit
    return float(np.max(np.abs(k - 1.0)))


def _tmerc(lon0: float, lat0: float) -> str:
    return (f"+proj=tmerc +lat_0={lat0:.6f} +lon_0={lon0:.6f} +k=1 +x_0=0 +y_0=0 "
            "+datum=WGS84 +units=m +no_defs +type=crs")


def local_metric_crs(crs: Any, bbox_lonlat: tuple[float, float, float, float]
                     ) -> tuple[str, float, str]:
    """The CRS a world uses for data in ``crs`` covering ``bbox_lonlat`` (W, S, E, N deg).

    Returns
    -------
    crs : str
        The data's own CRS when it is projected and its length distortion over
        the box is <= :data:`MAX_SCALE_ERROR`; else the UTM zone of the box
        centre if that keeps <= 0.5 %; else a transverse Mercator centred on
        the box (PROJ string).
    error : float
        Largest length distortion ``|k - 1|`` of the returned CRS over the box.
    reason : str
        Why this CRS (for the summary), e.g. ``"EPSG:3857 distorts lengths by
        30.5 % here; reprojected to the local UTM zone EPSG:32630"``.
    """
    c = parse_crs(crs)
    own = scale_error(c, bbox_lonlat)
    name = crs_label(c)
    if own <= MAX_SCALE_ERROR:
        return crs_string(c), own, f"{name} kept (length distortion {100 * own:.2f} % here)"
    units = {a.unit_name for a in c.axis_info[:2]}
    if c.is_geographic:
        why = f"{name} is geographic (degrees)"
    elif c.is_projected and not units <= {"metre", "meter", "m"}:
        why = f"{name} is in {', '.join(sorted(units))}, not metres"
    elif np.isfinite(own):
        why = f"{name} distorts lengths by {100 * own:.2f} % here"
    else:
        why = f"{name} has no usable scale factor"
    w, s, e, n = bbox_lonlat
    lon_c, lat_c = 0.5 * (w + e), 0.5 * (s + n)
    if -80.0 <= lat_c <= 84.0:
        utm = utm_crs(float(np.clip(lon_c, -180.0, 180.0)), lat_c)
        err = scale_error(utm, bbox_lonlat)
        if err <= MAX_SCALE_ERROR:
            return utm, err, f"{why}; reprojected to the local UTM zone {utm}"
    tm = _tmerc(lon_c, 0.0)
    err = scale_error(tm, bbox_lonlat)
    if not err <= 10 * MAX_SCALE_ERROR:
        raise WorldError(
            f"the area lon {w:.3f}..{e:.3f}, lat {s:.3f}..{n:.3f} is too wide for one metric "
            f"grid (lengths would be off by {100 * err:.1f} % at its edges); crop it to the "
            "mission area with world.bbox (CLI --bbox W,S,E,N)")
    return tm, err, (f"{why}; the area is too wide for one UTM zone, so reprojected to a "
                     f"transverse Mercator centred on lon {lon_c:.4f} (length distortion "
                     f"{100 * err:.2f} % at the edges)")


def bounds_lonlat(bounds: Any, crs: Any) -> tuple[float, float, float, float]:
    """Lon/lat box (W, S, E, N) [deg] of a box ``(minx, miny, maxx, maxy)`` in ``crs``.

    The box edges are densified (65 points each), so curved images of straight
    edges are covered.
    """
    minx, miny, maxx, maxy = (float(v) for v in bounds)
    t = np.linspace(0.0, 1.0, 65)
    x = np.concatenate([minx + (maxx - minx) * t, np.full(65, maxx), maxx - (maxx - minx) * t,
                        np.full(65, minx)])
    y = np.concatenate([np.full(65, miny), miny + (maxy - miny) * t, np.full(65, maxy),
                        maxy - (maxy - miny) * t])
    lon, lat = transformer(crs, WGS84).transform(x, y)
    lon, lat = np.asarray(lon), np.asarray(lat)
    ok = np.isfinite(lon) & np.isfinite(lat)
    if not ok.any():
        raise WorldError(f"the box {bounds} cannot be converted from {crs_label(crs)} to lon/lat")
    return (float(lon[ok].min()), float(lat[ok].min()), float(lon[ok].max()),
            float(lat[ok].max()))


def check_lonlat_bbox(bbox: Any, what: str = "bbox") -> tuple[float, float, float, float]:
    """Validate a ``(west, south, east, north)`` box in lon/lat degrees.

    Raises
    ------
    InputError
        Not four finite numbers, out of range, or west >= east / south >= north.
    """
    try:
        v = tuple(float(x) for x in bbox)
    except (TypeError, ValueError):
        raise InputError(f"{what} must be 4 numbers W,S,E,N in lon/lat degrees, got {bbox!r}") from None
    if len(v) != 4 or not all(np.isfinite(v)):
        raise InputError(f"{what} must be 4 finite numbers W,S,E,N in lon/lat degrees, got {bbox!r}")
    w, s, e, n = v
    if not (-180 <= w <= 180 and -180 <= e <= 180 and -90 <= s <= 90 and -90 <= n <= 90):
        raise InputError(
            f"{what} = {w:g},{s:g},{e:g},{n:g} is not lon/lat: longitudes must be in [-180, 180] "
            "and latitudes in [-90, 90] degrees (order W,S,E,N)")
    if not (e > w and n > s):
        raise InputError(
            f"{what} = {w:g},{s:g},{e:g},{n:g} needs west < east and south < north (order W,S,E,N); "
            "boxes across the antimeridian are not supported")
    return v


def check_fit(bounds: Any, crs: Any, rule: str, where: str, hint: str) -> None:
    """Refuse coordinates that cannot be in ``crs``.

    Parameters
    ----------
    bounds : (minx, miny, maxx, maxy)
        Extent of the data in ``crs`` units.
    crs :
        The declared or assumed CRS.
    rule : str
        How that CRS was known (for the message).
    where : str
        What the data are (for the message), e.g. "the buildings file b.geojson".
    hint : str
        The option that sets the CRS, e.g. "world.crs (CLI --crs)".

    Raises
    ------
    WorldError
        Geographic CRS with coordinates outside [-180, 180] x [-90, 90]; a
        projected CRS whose coordinates look like degrees (all within lon/lat
        range and less than 2 units wide) or fall outside its area of use
        (with a 5 degree margin).
    """
    minx, miny, maxx, maxy = (float(v) for v in bounds)
    c = parse_crs(crs)
    if not all(np.isfinite([minx, miny, maxx, maxy])):
        raise WorldError(f"{where} has non-finite coordinates; fix the file")
    lonlat_like = (-180 <= minx and maxx <= 180 and -90 <= miny and maxy <= 90)
    if c.is_geographic:
        if not lonlat_like:
            raise WorldError(
                f"{where} is read as lon/lat degrees ({rule}: {crs_label(c)}) but its coordinates "
                f"reach x {minx:.6g}..{maxx:.6g}, y {miny:.6g}..{maxy:.6g}, which are not degrees; "
                f"if they are metres of a projected CRS, give it with {hint}, e.g. "
                "EPSG:32630")
        return
    extent = max(maxx - minx, maxy - miny)
    if lonlat_like and extent < 2.0:
        raise WorldError(
            f"{where} is read in {crs_label(c)} ({rule}), in metres, but its coordinates "
            f"(x {minx:.6g}..{maxx:.6g}, y {miny:.6g}..{maxy:.6g}) look like lon/lat degrees; "
            f"give the right CRS with {hint} (EPSG:4326 for lon/lat) or fix the file")
    aou = c.area_of_use
    if aou is None:
        return
    xs = np.array([minx, maxx, minx, maxx, 0.5 * (minx + maxx)])
    ys = np.array([miny, miny, maxy, maxy, 0.5 * (miny + maxy)])
    lon, lat = transformer(c, WGS84).transform(xs, ys)
    lon, lat = np.asarray(lon), np.asarray(lat)
    margin = 5.0  # degrees: data often spill a little beyond a zone's official area
    ok = (np.all(np.isfinite(lon)) and np.all(np.isfinite(lat))
          and np.all(lon >= aou.west - margin) and np.all(lon <= aou.east + margin)
          and np.all(lat >= aou.south - margin) and np.all(lat <= aou.north + margin))
    if not ok:
        raise WorldError(
            f"{where} is read in {crs_label(c)} ({rule}) but its coordinates "
            f"(x {minx:.6g}..{maxx:.6g}, y {miny:.6g}..{maxy:.6g}) fall outside that CRS's area "
            f"of use ({aou.name}); give the right CRS with {hint} or fix the file")



# ---------------------------------------------------------------------- provenance
def sha256_file(path: str | Path) -> str:
    """Hex SHA-256 of a file's bytes."""
    h = hashlib.sha256()
    with open(path, "rb") as fh:
        for chunk in iter(lambda: fh.read(1 << 20), b""):
            h.update(chunk)
    return h.hexdigest()


@dataclass(frozen=True)
class SourceFile:
    """One input file of a world.

    Attributes
    ----------
    path : str
        As given (absolute when resolved from a mission file).
    role : str
        ``"dem"``, ``"buildings"``, ``"area"``, ``"no-fly"``, ...
    sha256 : str or None
        Checksum of the file's bytes (``None`` for in-memory data).
    crs : str or None
        CRS the data were read in (declared by the file, given, or assumed).
    crs_rule : str
        How that CRS was known, e.g. ``"declared by the file"``,
        ``"RFC 7946 (GeoJSON without a crs member: lon/lat WGS84)"``.
    details : mapping
        Per-role facts for summaries, e.g. buildings per height rule, filled
        DEM cells, the reprojection.
    """

    path: str
    role: str
    sha256: str | None = None
    crs: str | None = None
    crs_rule: str = ""
    details: Mapping[str, Any] = field(default_factory=dict)

    def as_dict(self) -> dict[str, Any]:
        """JSON-ready dict."""
        return {"path": self.path, "role": self.role, "sha256": self.sha256, "crs": self.crs,
                "crs_rule": self.crs_rule, **({"details": dict(self.details)}
                                              if self.details else {})}


@dataclass(frozen=True)
class Georef:
    """Where a world is: CRS of x/y, vertical reference of z, and its sources.

    Attributes
    ----------
    crs : str
        Horizontal CRS of world x/y (the same string as ``World.crs``).
    epsg : int or None
        Its EPSG code (``None`` for a custom transverse Mercator).
    vertical : str
        What world z is, e.g. ``"DEM heights, EGM96 height (from the raster's
        vertical CRS)"`` or ``"DEM heights, assumed metres above mean sea level
        (the raster declares no vertical CRS)"``.
    vertical_crs : str or None
        Name of the declared vertical CRS (e.g. ``"EGM96 height"``), if any.
    vertical_assumed : bool
        ``True`` when :attr:`vertical` is an assumption, not read from the data.
    reprojection : str
        Why the world has this CRS (kept / reprojected and from what).
    scale_error : float
        Largest length distortion of :attr:`crs` over the world (``|k - 1|``).
    sources : tuple of SourceFile
    amsl : bool
        World z is an altitude above mean sea level (a DEM's heights, or the flat
        ground of a buildings world at a given ``world.ground_elevation``). False: z
        is the height above a flat ground whose altitude is unknown (buildings
        without a DEM or a ground elevation): missions are then written relative to
        home, never as AMSL altitudes.
    """

    crs: str
    epsg: int | None = None
    vertical: str = ""
    vertical_crs: str | None = None
    vertical_assumed: bool = True
    reprojection: str = ""
    scale_error: float = 0.0
    sources: tuple[SourceFile, ...] = ()
    amsl: bool = True

    @property
    def name(self) -> str:
        """Short name of :attr:`crs` (:func:`crs_label`), for summaries."""
        return crs_label(self.crs)

    def as_dict(self) -> dict[str, Any]:
        """JSON-ready dict (``summary.json`` ``"georef"``; exports' metadata)."""
        return {"crs": self.crs, "crs_name": self.name, "crs_token": crs_token(self.crs),
                "epsg": self.epsg, "vertical": self.vertical,
                "vertical_crs": self.vertical_crs, "vertical_assumed": self.vertical_assumed,
                "amsl": self.amsl,
                "reprojection": self.reprojection,
                "scale_error_pct": round(100.0 * float(self.scale_error), 4),
                "sources": [s.as_dict() for s in self.sources]}

    def comment(self) -> str:
        """One line for file headers, e.g. ``"crs=EPSG:32630; z=DEM heights, ..."``."""
        srcs = ", ".join(f"{s.role} {Path(s.path).name} sha256={s.sha256[:12] if s.sha256 else '-'}"
                         for s in self.sources)
        token = crs_token(self.crs)
        name = self.name
        return (f"crs={token}" + (f" ({name})" if name != token else "")
                + f"; z={self.vertical}" + (f"; sources: {srcs}" if srcs else ""))

    def with_sources(self, *more: SourceFile) -> Georef:
        """A copy with more sources appended."""
        import dataclasses

        return dataclasses.replace(self, sources=tuple(self.sources) + tuple(more))


def make_georef(crs: Any, *, vertical: str, vertical_crs: str | None = None,
                vertical_assumed: bool = True, reprojection: str = "",
                scale_error: float = 0.0, sources: tuple[SourceFile, ...] = (),
                amsl: bool = True) -> Georef:
    """A :class:`Georef` for a world in ``crs`` (EPSG code looked up)."""
    epsg = crs_epsg(crs)
    return Georef(crs=crs_string(crs) if epsg else str(crs), epsg=epsg,
                  vertical=vertical, vertical_crs=vertical_crs,
                  vertical_assumed=vertical_assumed, reprojection=reprojection,
                  scale_error=float(scale_error), sources=tuple(sources), amsl=bool(amsl))


def amsl_known(world: Any) -> bool:
    """Whether world z is an altitude above mean sea level (:attr:`Georef.amsl`).

    True for DEM worlds, buildings on a given ground elevation and worlds without a
    CRS (placed at their anchor's altitude); False for buildings without a DEM or a
    ground elevation (z = height above their flat ground).
    """
    g = getattr(world, "georef", None)
    return True if g is None else bool(getattr(g, "amsl", True))
