"""Coordinate reference systems for geo-referenced worlds (pyproj).

A world built from a DEM keeps its x/y in a *metric* projected CRS (the DEM's
own if it is projected in metres, else the UTM zone of the DEM's centre) and
stores it as :attr:`World.crs`; z is the DEM's elevation datum (normally
metres above mean sea level). These helpers pick that CRS and convert world
points to WGS84 longitude/latitude/altitude and back.
"""

from __future__ import annotations

from functools import lru_cache
from typing import Any

import numpy as np

from ..errors import InputError, WorldError

__all__ = [
    "parse_crs",
    "utm_crs",
    "metric_crs",
    "transformer",
    "to_lonlat",
    "from_lonlat",
]

WGS84 = "EPSG:4326"


def parse_crs(crs: Any) -> Any:
    """A :class:`pyproj.CRS` from a string/EPSG code/CRS object, with a clear error."""
    from pyproj import CRS
    from pyproj.exceptions import CRSError

    if crs is None:
        raise WorldError(
            "the DEM has no coordinate reference system; pass crs= (e.g. crs='EPSG:4326' "
            "for longitude/latitude degrees or the EPSG code of its projection)"
        )
    try:
        return CRS.from_user_input(crs)
    except CRSError as exc:
        raise WorldError(f"unknown coordinate reference system {crs!r}: {exc}") from None


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
    return _transformer(parse_crs(src).to_string(), parse_crs(dst).to_string())


def _points(points: Any, what: str) -> np.ndarray:
    try:
        p = np.asarray(points, dtype=float)
    except (TypeError, ValueError):
        raise InputError(f"{what} must be numeric (N, 3), got {points!r}") from None
    one = p.ndim == 1
    p = np.atleast_2d(p)
    if p.ndim != 2 or p.shape[1] != 3 or not np.all(np.isfinite(p)):
        raise InputError(f"{what} must be finite points of shape (N, 3), got shape {p.shape}")
    return p[0] if one else p


def to_lonlat(world: Any, points_m: Any) -> np.ndarray:
    """World points [m] → WGS84 ``(lon [deg], lat [deg], alt [m])``, shape kept.

    ``alt`` is world z (the DEM's elevation datum).

    Raises
    ------
    InputError
        The world has no CRS (synthetic scenario).
    """
    if getattr(world, "crs", None) is None:
        raise InputError(
            f"world {getattr(world, 'name', '')!r} has no CRS, so its points have no "
            "longitude/latitude; build it from a DEM (World.from_dem) or place it with "
            "fm2uav.io.georef and an anchor"
        )
    p = _points(points_m, "points")
    q = np.atleast_2d(p)
    lon, lat = transformer(world.crs, WGS84).transform(q[:, 0], q[:, 1])
    out = np.stack([np.asarray(lon), np.asarray(lat), q[:, 2]], axis=1)
    return out[0] if p.ndim == 1 else out


def from_lonlat(world: Any, lonlatalt: Any) -> np.ndarray:
    """WGS84 ``(lon, lat, alt)`` → world points [m]; the inverse of :func:`to_lonlat`."""
    if getattr(world, "crs", None) is None:
        raise InputError("the world has no CRS; longitude/latitude cannot be placed in it")
    p = _points(lonlatalt, "lonlatalt")
    q = np.atleast_2d(p)
    if np.any(np.abs(q[:, 1]) > 90) or np.any(np.abs(q[:, 0]) > 180):
        raise InputError("longitude must be in [-180, 180] and latitude in [-90, 90] degrees")
    x, y = transformer(WGS84, world.crs).transform(q[:, 0], q[:, 1])
    out = np.stack([np.asarray(x), np.asarray(y), q[:, 2]], axis=1)
    return out[0] if p.ndim == 1 else out
