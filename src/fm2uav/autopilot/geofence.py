"""Geofences: the zones of a world as exclusion / inclusion polygons and circles in WGS84.

An *inclusion* fence is an area the vehicle must stay inside (an operating
area), an *exclusion* fence one it must not enter (a no-fly zone). PX4 and
ArduPilot take both from a QGroundControl plan (QGC uploads them as the fence
mission type); the plan's ``geoFence`` object is written and read by
:mod:`fm2uav.io.qgc`.

:func:`zone_fences` turns ``World.zones`` (:mod:`fm2uav.world.zones`) into
fences: each no-fly zone an *exclusion* polygon (or circle, when it is one),
the operating area an *inclusion* polygon. Fences are written as the zones are,
without the planning buffer (the buffer is the planner's margin, the fence the
boundary the autopilot enforces). QGC / PX4 / ArduPilot fences are
two-dimensional: a zone with a floor or a ceiling (airspace above or below which
the plan may fly) cannot be a fence without the autopilot breaching it when the
plan passes over or under it, so such zones are left out and named in the
returned warnings.

:func:`fences_from_world` turns shapely polygons or circles in world metres into
fences. QGC fences have no holes: an inclusion polygon's holes become exclusion
polygons; an exclusion polygon with holes is written without them (a larger
no-fly area, on the safe side) and listed in the returned warnings.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..errors import InputError
from ..world.geo import Anchor, to_lonlat

__all__ = [
    "FencePolygon",
    "FenceCircle",
    "Fence",
    "fences_from_world",
    "as_fences",
    "zone_fences",
]


def _latlon(lat: float, lon: float, what: str) -> tuple[float, float]:
    lat, lon = float(lat), float(lon)
    if not (math.isfinite(lat) and math.isfinite(lon) and -90 <= lat <= 90 and -180 <= lon <= 180):
        raise InputError(f"{what}: ({lat}, {lon}) is not a latitude, longitude in degrees")
    return lat, lon


@dataclass(frozen=True)
class FencePolygon:
    """A polygon fence in WGS84.

    Attributes
    ----------
    points : tuple of (lat, lon)
        Vertices [deg], clockwise, not closed (first != last), at least 3.
    inclusion : bool
        True: stay inside (operating area); False: stay out (no-fly zone).
    name : str
        For messages and reports.
    """

    points: tuple[tuple[float, float], ...]
    inclusion: bool = False
    name: str = ""

    def __post_init__(self) -> None:
        pts = [_latlon(a, b, f"fence {self.name!r} vertex") for a, b in self.points]
        if len(pts) > 1 and pts[0] == pts[-1]:
            pts = pts[:-1]
        if len(pts) < 3:
            raise InputError(f"fence polygon {self.name!r} needs at least 3 vertices, "
                             f"got {len(pts)}")
        # clockwise with north up: negative signed area in (lon, lat)
        x = np.array([p[1] for p in pts])
        y = np.array([p[0] for p in pts])
        area = 0.5 * float(np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y))
        if area > 0:
            pts = pts[::-1]
        object.__setattr__(self, "points", tuple(pts))


@dataclass(frozen=True)
class FenceCircle:
    """A circular fence in WGS84: ``center`` (lat, lon) [deg], ``radius`` [m]."""

    center: tuple[float, float]
    radius: float
    inclusion: bool = False
    name: str = ""

    def __post_init__(self) -> None:
        object.__setattr__(self, "center", _latlon(*self.center, f"fence {self.name!r} centre"))
        r = float(self.radius)
        if not (math.isfinite(r) and r > 0):
            raise InputError(f"fence circle {self.name!r} radius must be > 0 m, got {self.radius!r}")
        object.__setattr__(self, "radius", r)


Fence = FencePolygon | FenceCircle


def _ring_latlon(coords: Any, world: Any, anchor: Anchor | None) -> tuple[tuple[float, float], ...]:
    xy = np.asarray(coords, dtype=float)[:, :2]
    geo = to_lonlat(world, xy, anchor=anchor)
    return tuple((float(la), float(lo)) for lo, la in geo[:, :2])


def fences_from_world(geometry: Any, world: Any, *, anchor: Anchor | None = None,
                      inclusion: bool = False, name: str = "") -> tuple[list[Fence], list[str]]:
    """Fences in WGS84 from a geometry in world metres.

    Parameters
    ----------
    geometry : shapely Polygon / MultiPolygon, or ``("circle", (x, y), radius)``
        In the world's metres.
    world : World
        Gives the CRS (or use ``anchor``).
    inclusion : bool
        Operating area (True) or no-fly zone (False).

    Returns
    -------
    fences : list of FencePolygon / FenceCircle
    warnings : list of str
        Holes of exclusion polygons that could not be written.
    """
    warnings: list[str] = []
    if isinstance(geometry, tuple) and len(geometry) == 3 and geometry[0] == "circle":
        cx, cy = (float(v) for v in geometry[1])
        lo, la = to_lonlat(world, [[cx, cy]], anchor=anchor)[0, :2]
        return [FenceCircle((float(la), float(lo)), float(geometry[2]), inclusion, name)], warnings
    geoms = getattr(geometry, "geoms", None)
    polys = list(geoms) if geoms is not None else [geometry]
    out: list[Fence] = []
    for k, poly in enumerate(polys):
        if getattr(poly, "geom_type", "") != "Polygon":
            raise InputError(f"fence {name!r}: expected polygons, got {getattr(poly, 'geom_type', poly)!r}")
        label = name if len(polys) == 1 else f"{name} part {k + 1}"
        out.append(FencePolygon(_ring_latlon(poly.exterior.coords, world, anchor), inclusion, label))
        for h, ring in enumerate(poly.interiors):
            if inclusion:
                out.append(FencePolygon(_ring_latlon(ring.coords, world, anchor), False,
                                        f"{label} hole {h + 1}"))
            else:
                warnings.append(f"no-fly zone {label!r}: QGC fences have no holes; hole {h + 1} "
                                "is written as part of the no-fly area")
    return out, warnings


def as_fences(fences: Any) -> list[Fence]:
    """Fence objects from a sequence of them, or from a mapping in lat/lon::

        {"polygons": [{"inclusion": bool, "polygon": [[lat, lon], ...]}, ...],
         "circles":  [{"inclusion": bool, "center": [lat, lon], "radius": m}, ...]}

    (the closing vertex of a polygon may be repeated or not; ``name`` optional).
    """
    if fences is None:
        return []
    if isinstance(fences, dict):
        unknown = set(fences) - {"polygons", "circles"}
        if unknown:
            raise InputError(f"geofence mapping: unknown key(s) {sorted(unknown)}; allowed: "
                             "polygons, circles")
        out: list[Fence] = []
        for i, p in enumerate(fences.get("polygons", [])):
            out.append(FencePolygon(tuple((float(a), float(b)) for a, b in p["polygon"]),
                                    bool(p.get("inclusion", False)),
                                    str(p.get("name", f"polygon {i + 1}"))))
        for i, c in enumerate(fences.get("circles", [])):
            out.append(FenceCircle(tuple(c["center"]), c["radius"],
                                   bool(c.get("inclusion", False)),
                                   str(c.get("name", f"circle {i + 1}"))))
        return out
    out = list(fences)
    bad = [f for f in out if not isinstance(f, (FencePolygon, FenceCircle))]
    if bad:
        raise InputError(f"fences must be FencePolygon / FenceCircle objects or a mapping "
                         f"with polygons/circles, got {type(bad[0]).__name__}")
    return out


def zone_fences(zones: Any, world: Any, anchor: Anchor | None = None
                ) -> tuple[list[Any], list[str]]:
    """Geofences (WGS84) of the zones, and warnings for zones that cannot be fences.

    Parameters
    ----------
    zones : sequence of Zone
        Usually ``world.zones``.
    world : World
        Gives the CRS (or ``anchor`` for a world without one).
    anchor : Anchor, optional

    Returns
    -------
    fences : list of FencePolygon / FenceCircle
    warnings : list of str
    """
    fences: list[Any] = []
    warnings: list[str] = []
    for k, z in enumerate(zones or ()):
        name = z.name or f"{z.kind} {k + 1}"
        vertical = z.floor is not None or z.ceiling is not None
        if vertical and not z.inclusion:
            warnings.append(f"{z.kind} {name!r} has a floor/ceiling; QGC geofences are 2D, so it "
                            "is not written into the .plan geoFence (the plan keeps out of it)")
            continue
        geom = ("circle", z.circle[0], z.circle[1]) if z.circle is not None else z.geometry
        out, warn = fences_from_world(geom, world, anchor=anchor, inclusion=z.inclusion,
                                      name=name)
        fences.extend(out)
        warnings.extend(warn)
        if vertical:
            warnings.append(f"operating area {name!r}: its floor/ceiling are not part of the "
                            "geofence (QGC fences are 2D)")
    return fences, warnings
