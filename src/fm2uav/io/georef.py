"""Geo-referencing: world metres ⇄ WGS84 longitude/latitude/altitude.

Every export (GeoJSON, KML, QGroundControl ``.plan``, MAVLink WPL) needs
longitude/latitude. Two cases:

* ``world.crs`` is set (a DEM or building footprints in a projected CRS):
  world ``(x, y)`` are coordinates of that CRS [m]; pyproj converts them to
  WGS84 (EPSG:4326) with the transformers of :mod:`fm2uav.world.geo` (so the
  results equal :meth:`fm2uav.Plan.lonlat`). World ``z`` is taken as height above the datum of the
  source data (for a DEM: its elevations, normally metres above mean sea level).
* ``world.crs`` is ``None`` (synthetic scenarios): the world is placed on a
  local tangent plane at an :class:`Anchor`: world ``(x, y) = (0, 0)`` sits at
  the anchor's longitude/latitude, +x points east, +y north, and world
  ``z = 0`` is at the anchor's altitude. The plane is an azimuthal equidistant
  projection centred on the anchor (exact distances from the anchor; over a few
  km it is the tangent plane to within millimetres). The default anchor,
  :data:`DEFAULT_ANCHOR`, is the UC3M Leganés campus near Madrid, where the
  source thesis was written — give your own field with ``anchor=``.

All functions are pure; the transformers are cached per CRS.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from typing import Any

import numpy as np

from ..errors import InputError, WorldError

__all__ = [
    "Anchor",
    "DEFAULT_ANCHOR",
    "to_lonlat",
    "from_lonlat",
    "ground_height",
]


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


def _crs_transformers(src: str) -> tuple[Any, Any]:
    """Transformers world CRS → WGS84 and back (shared with :mod:`fm2uav.world.geo`)."""
    from ..world.geo import WGS84, parse_crs, transformer

    crs = parse_crs(src)
    if crs.is_geographic:
        raise WorldError(
            f"world CRS {src!r} is geographic (degrees), but world x/y are metres; "
            "build the world in a projected CRS (e.g. the UTM zone of the area)"
        )
    return transformer(crs, WGS84), transformer(WGS84, crs)


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
    """(forward, inverse, altitude offset [m]) for a world."""
    crs = getattr(world, "crs", None)
    if crs:
        fwd, inv = _crs_transformers(str(crs))
        return fwd, inv, 0.0
    a = DEFAULT_ANCHOR if anchor is None else anchor
    if not isinstance(a, Anchor):
        raise InputError(f"anchor must be a fm2uav.io.Anchor(lon, lat, alt), got {a!r}")
    fwd, inv = _anchor_transformers(_anchor_crs(a))
    return fwd, inv, float(a.alt)


def _points(points: Any, what: str) -> np.ndarray:
    try:
        p = np.asarray(points, dtype=float)
    except (TypeError, ValueError):
        raise InputError(f"{what} must be numeric, got {points!r}") from None
    if p.ndim == 1:
        p = p[None, :]
    if p.ndim != 2 or p.shape[1] not in (2, 3):
        raise InputError(f"{what} must have shape (N, 2) or (N, 3), got {p.shape}")
    if not np.all(np.isfinite(p)):
        raise InputError(f"{what} has non-finite values")
    return p


def to_lonlat(points_m: Any, world: Any, *, anchor: Anchor | None = None) -> np.ndarray:
    """World points [m] → ``(N, 3)`` array of longitude [deg], latitude [deg], altitude [m].

    Parameters
    ----------
    points_m : array_like, shape (N, 2) or (N, 3)
        World coordinates [m]. For 2D points the altitude is ``anchor.alt``
        (or 0 with a CRS).
    world : World
        Gives the CRS (``world.crs``); without one, ``anchor`` places it.
    anchor : Anchor, optional
        Placement of a world without CRS; default :data:`DEFAULT_ANCHOR`.
        Ignored when the world has a CRS.

    Returns
    -------
    ndarray, shape (N, 3)
        ``lon, lat`` in WGS84 degrees and altitude above the vertical datum [m]
        (``z + anchor.alt`` for anchored worlds, ``z`` with a CRS).
    """
    p = _points(points_m, "points_m")
    fwd, _, dz = _frame(world, anchor)
    lon, lat = fwd.transform(p[:, 0], p[:, 1])
    z = p[:, 2] if p.shape[1] == 3 else np.zeros(len(p))
    return np.column_stack([np.asarray(lon), np.asarray(lat), z + dz])


def from_lonlat(lonlatalt: Any, world: Any, *, anchor: Anchor | None = None) -> np.ndarray:
    """Inverse of :func:`to_lonlat`: ``(N, 3)`` lon [deg], lat [deg], alt [m] → world [m].

    ``(N, 2)`` input gives ``(N, 2)`` world x, y.
    """
    q = _points(lonlatalt, "lonlatalt")
    if np.any(np.abs(q[:, 1]) > 90) or np.any(np.abs(q[:, 0]) > 180):
        raise InputError("longitude must be in [-180, 180] and latitude in [-90, 90] degrees")
    _, inv, dz = _frame(world, anchor)
    x, y = inv.transform(q[:, 0], q[:, 1])
    xy = np.column_stack([np.asarray(x), np.asarray(y)])
    if q.shape[1] == 2:
        return xy
    return np.column_stack([xy, q[:, 2] - dz])


def ground_height(world: Any, points_m: Any) -> np.ndarray:
    """Ground height (world z [m]) under each point: the terrain, bilinearly interpolated.

    Worlds without a terrain map (e.g. buildings on flat ground) have their
    ground at the bottom of the grid, ``origin[2]``; 2D worlds at 0.
    """
    p = _points(points_m, "points_m")
    if getattr(world, "terrain", None) is not None:
        from ..world.ground import terrain_along

        full = np.zeros((len(p), world.ndim))
        full[:, :2] = p[:, :2]
        if world.ndim == 3:
            full[:, 2] = world.origin[2]
        return np.asarray(terrain_along(world, full), dtype=float)
    base = float(world.origin[2]) if world.ndim == 3 else 0.0
    return np.full(len(p), base)
