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
    "fence_statement",
    "statement_warning",
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
    """Geofences (WGS84) of the zones, and warnings about the fences (holes left out).

    Zones with a floor or a ceiling are not written as no-fly fences; what the fence
    cannot carry is stated by :func:`fence_statement` (the mission's summary, warnings
    and ``.plan`` metadata).

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
        if vertical and not z.inclusion:  # stated by fence_statement (the mission's warnings)
            continue
        geom = ("circle", z.circle[0], z.circle[1]) if z.circle is not None else z.geometry
        out, warn = fences_from_world(geom, world, anchor=anchor, inclusion=z.inclusion,
                                      name=name)
        fences.extend(out)
        warnings.extend(warn)
    return fences, warnings


#: What a QGroundControl geoFence (PX4's and ArduPilot's fence mission items) cannot hold.
FENCE_LIMITS = (
    "QGroundControl geofences (uploaded as PX4's and ArduPilot's fence items) are 2D polygons "
    "and circles: no floor, no ceiling, no height reference and no planning buffer. A no-fly "
    "zone with a floor or a ceiling is left out of geoFence (a 2D exclusion fence would trip "
    "where the plan flies over or under it) and the plan keeps out of its air by itself; an "
    "operating area's fence is its footprint only.")


def _zone_label(z: Any, k: int) -> str:
    return z.name or f"{z.kind} {k + 1}"


def _ardupilot_altitude(z: Any, *, home_amsl: float | None, flat_ground: bool
                        ) -> dict[str, Any] | None:
    """ArduPilot's FENCE_ALT_MAX / FENCE_ALT_MIN (metres above home, one value for the whole
    flight) for an operating area's ceiling / floor, where they truly represent it: an AMSL
    limit (known home altitude) or an AGL limit over flat ground (home on that ground).
    The limits are shrunk by the area's buffer, as the plan keeps them."""
    if not z.inclusion or (z.ceiling is None and z.floor is None):
        return None
    if z.reference == "amsl" and home_amsl is not None:
        base, how = float(home_amsl), "an AMSL limit minus home's altitude"
    elif z.reference == "agl" and flat_ground:
        base, how = 0.0, "an AGL limit over flat ground, home on that ground"
    else:
        return None
    out: dict[str, Any] = {"note": f"metres above home: {how}", "FENCE_TYPE_bits": 0}
    if z.ceiling is not None:
        out["FENCE_ALT_MAX"] = round(float(z.ceiling) - z.buffer - base, 1)
        out["FENCE_TYPE_bits"] |= 1
    if z.floor is not None:
        out["FENCE_ALT_MIN"] = round(float(z.floor) + z.buffer - base, 1)
        out["FENCE_TYPE_bits"] |= 8
    return out


def fence_statement(zones: Any, fences: Any, *, firmware: str = "generic",
                    home_amsl: float | None = None, flat_ground: bool = False
                    ) -> dict[str, Any] | None:
    """What the mission's geofence carries of the zones, and what it cannot (JSON-ready).

    For ``summary.json`` and the ``.plan``'s ``fm2uav`` object: each zone written as a fence
    (its kind), each zone or part of one that is not (a floor, a ceiling, the buffer) and
    why, :data:`FENCE_LIMITS`, and — on ArduPilot — the FENCE_ALT_MAX / FENCE_ALT_MIN
    parameters (metres above home, FENCE_TYPE bits 1 / 8) that represent an operating
    area's ceiling / floor exactly (an AMSL limit with a known home altitude, or an AGL
    limit over flat ground); no such parameter ever represents a no-fly zone's floor or
    ceiling, which is local while the parameters hold everywhere.

    Parameters
    ----------
    zones : sequence of Zone
        ``World.zones``.
    fences : sequence of FencePolygon / FenceCircle
        The fences written (their names are the zones').
    firmware : str
        ``ardupilot`` gives the altitude parameters.
    home_amsl : float, optional
        Home's altitude above sea level [m] (None when unknown).
    flat_ground : bool
        The world's ground is flat (buildings without a DEM).

    Returns
    -------
    dict or None
        None without zones.
    """
    zones = tuple(zones or ())
    if not zones:
        return None
    written: dict[str, list[str]] = {}
    for f in as_fences(fences):
        kind = ("inclusion " if f.inclusion else "exclusion ") + (
            "circle" if isinstance(f, FenceCircle) else "polygon")
        written.setdefault(f.name, []).append(kind)
    carried, not_carried, params = [], [], {}
    for k, z in enumerate(zones):
        name = _zone_label(z, k)
        vertical = {key: v for key, v in (("floor_m", z.floor), ("ceiling_m", z.ceiling))
                    if v is not None}
        if name in written:
            carried.append({"zone": name, "fence": written[name],
                            "carries": "the 2D footprint, without the planning buffer "
                                       f"({z.buffer:g} m)"})
        if vertical:
            why = ("a 2D fence cannot hold a floor or a ceiling: the zone is left out of "
                   "geoFence, the plan keeps out of its air" if not z.inclusion else
                   "a 2D fence cannot hold a floor or a ceiling: the fence is the area's "
                   "footprint only")
            entry = {"zone": name, "kind": z.kind, **vertical, "reference": z.reference,
                     "buffer_m": z.buffer, "why": why}
            if firmware == "ardupilot":
                alt = _ardupilot_altitude(z, home_amsl=home_amsl, flat_ground=flat_ground)
                if alt is not None:
                    params[name] = alt
                else:
                    entry["ardupilot"] = (
                        "FENCE_ALT_MAX / FENCE_ALT_MIN hold over the whole flight, above "
                        "home: they cannot represent "
                        + ("a no-fly zone's local floor/ceiling" if not z.inclusion else
                           "this limit (AGL over uneven ground, or home's altitude unknown)"))
            not_carried.append(entry)
    out: dict[str, Any] = {"fences": sum(len(v) for v in written.values()),
                           "carried": carried, "not_carried": not_carried,
                           "limits": FENCE_LIMITS}
    if params:
        out["ardupilot_parameters"] = params
    return out


def statement_warning(statement: dict[str, Any] | None) -> str | None:
    """One warning line of :func:`fence_statement`'s zones the fence cannot carry (None if
    every zone is carried whole)."""
    if not statement or not statement["not_carried"]:
        return None
    parts = []
    for e in statement["not_carried"]:
        lim = ", ".join(f"{k[:-2]} {e[k]:g} m" for k in ("floor_m", "ceiling_m") if k in e)
        parts.append(f"{e['kind']} {e['zone']!r} ({lim} {e['reference'].upper()}, buffer "
                     f"{e['buffer_m']:g} m)" + (": left out of geoFence" if e["kind"] ==
                                                "no-fly zone" else ": fence = footprint only"))
    extra = ""
    if statement.get("ardupilot_parameters"):
        extra = "; ArduPilot parameters that hold it: " + "; ".join(
            f"{n}: " + ", ".join(f"{k} {v:g}" for k, v in p.items() if k.startswith("FENCE_A"))
            for n, p in statement["ardupilot_parameters"].items())
    return ("geofence: QGC fences are 2D and cannot carry a floor or a ceiling — "
            + "; ".join(parts) + extra + " (the plan keeps out of the zones' air itself)")
