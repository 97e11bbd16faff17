"""No-fly zones and the operating area: airspace the plan must keep out of (or inside).

A :class:`Zone` is a polygon or a circle in the world's metres with an
optional vertical extent and a buffer:

* ``floor`` / ``ceiling`` [m]: the zone spans ``floor <= z <= ceiling``;
  ``None`` = from the ground / without upper limit (a zone with neither is
  the whole column of air). ``reference`` says what they are measured from:
  ``"amsl"`` (the world's z datum) or ``"agl"`` (the ground under each point,
  :meth:`World.ground_height`).
* ``buffer`` [m]: the margin the plan keeps, horizontally (the footprint grown
  by ``buffer``) and vertically (floor lowered, ceiling raised by ``buffer``).
* ``inclusion=True`` makes it an *operating area*: the plan stays inside the
  footprint shrunk by ``buffer`` (and below its ceiling / above its floor).

:func:`with_zones` makes them obstacles of the world: every node within the
buffered zone grown by half a cell diagonal (so that no point of the true
buffered zone has a free nearest node; the descent never enters blocked
nodes) becomes occupied, and FM² keeps its clearance from them as from terrain.
The zones are kept on the world (``World.zones``) so that the ground and roof
questions, the flight level and the exports can tell airspace from terrain,
and :func:`zone_violations` checks a flown path or waypoint legs against the
true (not rasterised) geometry.

Files: :func:`read_zones` reads GeoJSON / KML / GeoPackage / Shapefile through
:func:`fm2uav.world.vectors.read_vectors` (lon/lat per RFC 7946 unless the file
says otherwise). Polygons are zones; points are circles and need a ``radius``
property [m]. Per-feature properties ``name``, ``floor``, ``ceiling``,
``reference``, ``buffer`` override the defaults given for the file.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING, Any

import numpy as np
import shapely
import shapely.validation
from shapely.geometry import Point, Polygon
from shapely.geometry.base import BaseGeometry

from ..errors import InputError, PointError, WorldError
from ..geometry import densify

if TYPE_CHECKING:
    from .world import World

__all__ = [
    "Zone",
    "ZONE_REFERENCES",
    "read_zones",
    "zone_from_mapping",
    "with_zones",
    "zone_voxels",
    "terrain_surface_index",
    "zone_bounds_along",
    "zone_violations",
    "zone_distances",
]

#: What a zone's floor/ceiling are measured from.
ZONE_REFERENCES = ("amsl", "agl")
#: Segments per quarter circle when a circle is rasterised or checked.
_QUAD_SEGS = 64
_NO_FLY = "no_fly_zones (CLI --no-fly)"


def _num(value: Any, what: str, where: str, *, minimum: float | None = None,
         positive: bool = False) -> float:
    if isinstance(value, bool):
        raise InputError(f"{where}: {what} must be a number in metres, got {value!r}")
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise InputError(f"{where}: {what} must be a number in metres, got {value!r}") from None
    if not math.isfinite(v) or (minimum is not None and v < minimum) or (positive and v <= 0):
        bound = "> 0" if positive else f">= {minimum:g}" if minimum is not None else "finite"
        raise InputError(f"{where}: {what} must be {bound} metres, got {value!r}")
    return v


class ZoneWarning(UserWarning):
    """A zone that changes nothing or not what it says: wholly off the map, or a polygon
    crossing itself that was repaired (shown by the CLI as one ``warning:`` line)."""


@dataclass(frozen=True, eq=False)
class Zone:
    """A no-fly zone (or, with ``inclusion=True``, the operating area).

    Attributes
    ----------
    geometry : shapely Polygon or MultiPolygon
        The zone itself in world metres (circles as 256-gon, see ``circle``).
    name : str
        For messages, reports and the geofence.
    floor, ceiling : float or None
        Vertical extent [m] (see the module docstring); None = unlimited.
    reference : {"amsl", "agl"}
        What floor/ceiling are measured from.
    buffer : float
        Margin the plan keeps from the zone [m], >= 0.
    inclusion : bool
        True: an operating area (stay inside), False: a no-fly zone.
    circle : ((x, y), radius) or None
        The exact circle [m] when the zone is one (exported as a fence circle).
    source : str
        Where it came from (file name or "mission file").
    """

    geometry: BaseGeometry
    name: str = ""
    floor: float | None = None
    ceiling: float | None = None
    reference: str = "amsl"
    buffer: float = 0.0
    inclusion: bool = False
    circle: tuple[tuple[float, float], float] | None = None
    source: str = ""

    def __post_init__(self) -> None:
        where = f"zone {self.name!r}" if self.name else "zone"
        g = self.geometry
        if not isinstance(g, BaseGeometry) or g.geom_type not in ("Polygon", "MultiPolygon"):
            raise InputError(f"{where}: geometry must be a polygon, got "
                             f"{getattr(g, 'geom_type', type(g).__name__)}")
        if g.is_empty:
            raise InputError(f"{where}: the polygon is empty")
        if not g.is_valid:
            import warnings

            why = shapely.validation.explain_validity(g)
            g = shapely.make_valid(g)
            polys = [p for p in getattr(g, "geoms", [g]) if p.geom_type == "Polygon"]
            if not polys:
                raise InputError(f"{where}: the polygon is invalid ({why}) and cannot be "
                                 "repaired; fix its outline")
            g = shapely.MultiPolygon(polys) if len(polys) > 1 else polys[0]
            warnings.warn(ZoneWarning(
                f"{where}: the polygon is invalid ({why}); it was repaired into "
                f"{len(polys)} part{'s' if len(polys) > 1 else ''} of {g.area:.0f} m² in all "
                "(the areas its outline encloses) — check that this is the zone meant"),
                stacklevel=2)
        if g.area <= 0:
            raise InputError(f"{where}: the polygon has no area")
        object.__setattr__(self, "geometry", g)
        if self.reference not in ZONE_REFERENCES:
            raise InputError(f"{where}: reference must be one of {', '.join(ZONE_REFERENCES)} "
                             f"(what floor/ceiling are measured from), got {self.reference!r}")
        for k in ("floor", "ceiling"):
            v = getattr(self, k)
            if v is not None:
                object.__setattr__(self, k, _num(v, k, where))
        object.__setattr__(self, "buffer", _num(self.buffer, "buffer", where, minimum=0.0))
        if self.floor is not None and self.ceiling is not None and self.floor >= self.ceiling:
            raise InputError(f"{where}: floor {self.floor:g} m must be below ceiling "
                             f"{self.ceiling:g} m")
        if (self.inclusion and self.floor is not None and self.ceiling is not None
                and self.floor + 2 * self.buffer >= self.ceiling):
            raise InputError(f"{where}: the operating area has no air left between its floor "
                             f"{self.floor:g} m and ceiling {self.ceiling:g} m inside a buffer "
                             f"of {self.buffer:g} m; lower operating_area buffer")
        if self.inclusion and self.buffer > 0:
            inner = g.buffer(-self.buffer)
            if inner.is_empty:
                raise InputError(f"{where}: the operating area has nothing left inside a "
                                 f"buffer of {self.buffer:g} m; lower operating_area buffer")

    # -------------------------------------------------------------- geometry
    @property
    def full_height(self) -> bool:
        """True when the zone is the whole column of air (no floor, no ceiling)."""
        return self.floor is None and self.ceiling is None

    @property
    def kind(self) -> str:
        """``"operating area"`` or ``"no-fly zone"``."""
        return "operating area" if self.inclusion else "no-fly zone"

    def label(self) -> str:
        """``no-fly zone 'name'`` for messages."""
        return f"{self.kind} {self.name!r}" if self.name else self.kind

    def keep_out(self, margin: float = 0.0) -> BaseGeometry:
        """Footprint the plan keeps out of [m]: the zone grown by ``buffer + margin``.

        For an operating area, the area *outside* it shrunk by ``buffer +
        margin`` (a large ring around it is not needed: callers test
        ``not inside``; see :meth:`inside_allowed`).
        """
        grow = self.buffer + margin
        if self.inclusion:
            return self.geometry.buffer(-grow, quad_segs=_QUAD_SEGS) if grow else self.geometry
        return self.geometry.buffer(grow, quad_segs=_QUAD_SEGS) if grow else self.geometry

    def vertical_range(self, ground: Any, margin: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
        """``(low, high)`` world z [m] of the zone's air over ground heights ``ground``.

        For a no-fly zone the *kept-out* air: floor lowered and ceiling raised by
        ``buffer + margin``. For an operating area the *allowed* air: floor raised and
        ceiling lowered by ``buffer + margin`` (the area shrunk, as horizontally).
        ``-inf`` / ``+inf`` where unlimited. The range is open: a point exactly at
        ``low`` or ``high`` is on the boundary, which the plan may fly along.
        """
        g = np.asarray(ground, dtype=float)
        base = g if self.reference == "agl" else np.zeros_like(g)
        grow = self.buffer + margin
        if self.inclusion:
            grow = -grow
        lo = np.full(g.shape, -np.inf) if self.floor is None else base + self.floor - grow
        hi = np.full(g.shape, np.inf) if self.ceiling is None else base + self.ceiling + grow
        return lo, hi

    def describe(self) -> dict[str, Any]:
        """JSON-friendly description (for summaries and reports)."""
        out: dict[str, Any] = {
            "name": self.name, "kind": self.kind, "reference": self.reference,
            "floor_m": self.floor, "ceiling_m": self.ceiling, "buffer_m": self.buffer,
            "area_m2": round(float(self.geometry.area), 1), "source": self.source,
        }
        if self.circle is not None:
            (cx, cy), r = self.circle
            out["circle"] = {"center_m": [round(cx, 3), round(cy, 3)], "radius_m": r}
        return out


def _circle(center: Sequence[float], radius: float) -> Polygon:
    return Point(float(center[0]), float(center[1])).buffer(float(radius), quad_segs=_QUAD_SEGS)


# ---------------------------------------------------------------------- building zones
_ZONE_KEYS = ("name", "floor", "ceiling", "reference", "buffer")


def _options(props: Mapping[str, Any], defaults: Mapping[str, Any], where: str) -> dict[str, Any]:
    out = {k: defaults[k] for k in _ZONE_KEYS if defaults.get(k) is not None}
    for k in _ZONE_KEYS:
        if props.get(k) is not None:
            out[k] = props[k]
    if "reference" in out:
        out["reference"] = str(out["reference"]).strip().lower()
    for k in ("floor", "ceiling", "buffer"):
        if k in out:
            out[k] = _num(out[k], k, where)
    if "name" in out:
        out["name"] = str(out["name"])
    return out


def zone_from_mapping(spec: Mapping[str, Any], *, inclusion: bool = False,
                      where: str = "no_fly_zones", source: str = "mission file") -> Zone:
    """One zone from an inline mapping in world metres.

    ``{polygon: [[x, y], ...]}`` or ``{circle: {center: [x, y], radius: r}}``,
    plus optional ``name``, ``floor``, ``ceiling``, ``reference``, ``buffer``.

    Raises
    ------
    InputError
        Missing/both shapes, too few vertices, bad numbers (``where`` names the entry).
    """
    if not isinstance(spec, Mapping):
        raise InputError(f"{where} must be a mapping with polygon: or circle:, got {spec!r}")
    has_p, has_c = spec.get("polygon") is not None, spec.get("circle") is not None
    if has_p == has_c:
        raise InputError(f"{where}: give exactly one of polygon: [[x, y], ...] (metres) or "
                         "circle: {center: [x, y], radius: r}")
    opts = _options(spec, {}, where)
    circle = None
    if has_p:
        try:
            pts = np.asarray(spec["polygon"], dtype=float)
        except (TypeError, ValueError):
            raise InputError(f"{where}.polygon must be a list of [x, y] points in metres") from None
        if pts.ndim != 2 or pts.shape[1] < 2 or len(pts) < 3 or not np.all(np.isfinite(pts)):
            raise InputError(f"{where}.polygon needs at least 3 [x, y] points in metres, got "
                             f"{np.shape(spec['polygon'])}")
        geom: BaseGeometry = Polygon(pts[:, :2])
    else:
        c = spec["circle"]
        if not isinstance(c, Mapping) or c.get("center") is None or c.get("radius") is None:
            raise InputError(f"{where}.circle must be {{center: [x, y], radius: r}} (metres)")
        try:
            center = [float(v) for v in c["center"]]
        except (TypeError, ValueError):
            center = []
        if len(center) != 2 or not all(map(math.isfinite, center)):
            raise InputError(f"{where}.circle.center must be [x, y] in metres, got {c['center']!r}")
        r = _num(c["radius"], "circle.radius", where, positive=True)
        geom, circle = _circle(center, r), ((center[0], center[1]), r)
    return Zone(geom, inclusion=inclusion, circle=circle, source=source, **opts)


def read_zones(source: Any, world: World, *, crs: Any = None, defaults: Mapping[str, Any] | None
               = None, inclusion: bool = False) -> list[Zone]:
    """Zones of a vector file (or in-memory GeoJSON) in the world's metres.

    Parameters
    ----------
    source : path or GeoJSON
        GeoJSON (lon/lat per RFC 7946), KML/KMZ, GeoPackage, Shapefile, ...
    world : World
        Gives the CRS the zones are reprojected into.
    crs : optional
        CRS of a file that declares none.
    defaults : mapping, optional
        ``name``, ``floor``, ``ceiling``, ``reference``, ``buffer`` for features
        without these properties.
    inclusion : bool
        Read them as operating areas.

    Raises
    ------
    WorldError
        Unreadable file, CRS problems (from :func:`~fm2uav.world.vectors.read_vectors`).
    InputError
        A point without ``radius``, a file without any polygon or circle.
    """
    from .vectors import read_vectors

    role = "area" if inclusion else "no-fly"
    data = read_vectors(source, target_crs=world.crs, crs=crs, role=role, kinds=None)
    label = data.source.path if getattr(data, "source", None) is not None else str(source)
    out: list[Zone] = []
    defaults = dict(defaults or {})
    for k, (g, props) in enumerate(zip(data.geometries, data.properties)):
        where = f"{label} feature {k}"
        if g is None or g.is_empty:
            continue
        opts = _options(props, defaults, where)
        opts.setdefault("name", f"{_file_name(label)} {k + 1}")
        kind = g.geom_type
        if kind in ("Polygon", "MultiPolygon"):
            out.append(Zone(g, inclusion=inclusion, source=label, **opts))
        elif kind in ("Point", "MultiPoint"):
            radius = props.get("radius", defaults.get("radius"))
            if radius is None:
                raise InputError(f"{where}: a point is a circular zone and needs a 'radius' "
                                 "property in metres")
            r = _num(radius, "radius", where, positive=True)
            for p in getattr(g, "geoms", [g]):
                out.append(Zone(_circle((p.x, p.y), r), inclusion=inclusion,
                                circle=((float(p.x), float(p.y)), r), source=label, **opts))
        elif kind == "GeometryCollection":
            polys = [p for p in g.geoms if p.geom_type in ("Polygon", "MultiPolygon")]
            if polys:
                out.append(Zone(shapely.union_all(polys), inclusion=inclusion, source=label,
                                **opts))
    if not out:
        raise InputError(f"{label}: no polygon or circle (point with a radius) to use as a "
                         f"{'operating area' if inclusion else 'no-fly zone'}")
    src = getattr(data.source, "crs", None)
    geographic = False
    if src is not None:
        from .geo import parse_crs

        try:
            geographic = bool(parse_crs(src).is_geographic)
        except Exception:  # noqa: BLE001 - a CRS read from the file; no swap test then
            geographic = False
    check_zones_on_map(out, world, label, lonlat_bounds=(
        getattr(data, "source_bounds", None) if geographic else None))
    return out


def _file_name(label: str) -> str:
    """The file name of a source label (for default zone names)."""
    return str(label).replace("\\", "/").rsplit("/", 1)[-1]


# ---------------------------------------------------------------------- on the world
def _margin_xy(world: World) -> float:
    h = np.asarray(world.spacing[:2], dtype=float)
    return 0.5 * float(np.hypot(*h)) + 1e-6


def _zone_mask(world: World, zone: Zone) -> np.ndarray:
    """Nodes blocked by one zone (bool, world shape)."""
    nx, ny = world.shape[:2]
    x = world.origin[0] + np.arange(nx) * world.spacing[0]
    y = world.origin[1] + np.arange(ny) * world.spacing[1]
    X, Y = np.meshgrid(x, y, indexing="ij")
    margin = _margin_xy(world)
    if zone.inclusion:
        inner = zone.keep_out(margin)
        cols = ~shapely.contains_xy(inner, X, Y) if not inner.is_empty else np.ones_like(X, bool)
    else:
        cols = shapely.contains_xy(zone.keep_out(margin), X, Y)
    if world.ndim == 2:
        return cols
    nz = world.shape[2]
    z = world.origin[2] + np.arange(nz) * world.spacing[2]
    ground = np.asarray(world.ground_height(X, Y), dtype=float)
    lo, hi = zone.vertical_range(ground, margin=0.5 * world.spacing[2] + 1e-6)
    if zone.inclusion:
        # outside the area: everything; inside: below the floor / above the ceiling
        inside_air = (z[None, None, :] >= np.where(np.isfinite(lo), lo, -np.inf)[:, :, None]) & \
            (z[None, None, :] <= np.where(np.isfinite(hi), hi, np.inf)[:, :, None])
        return cols[:, :, None] | ~inside_air
    band = (z[None, None, :] >= lo[:, :, None]) & (z[None, None, :] <= hi[:, :, None])
    return cols[:, :, None] & band


def zone_voxels(world: World) -> np.ndarray | None:
    """Bool mask of the nodes a world's zones block (cached), or None without zones."""
    zones = getattr(world, "zones", ())
    if not zones:
        return None
    key = "zone_voxels"
    if key not in world._cache:
        mask = np.zeros(world.shape, dtype=bool)
        for z in zones:
            mask |= _zone_mask(world, z)
        mask.setflags(write=False)
        world._cache[key] = mask
    return world._cache[key]


def with_zones(world: World, zones: Iterable[Zone]) -> World:
    """A new world whose occupancy also holds the zones (and ``World.zones`` lists them).

    Nodes within each zone's buffer grown by half a cell diagonal (and half a
    vertical cell) are blocked; an operating area blocks everything outside
    itself shrunk the same way. The zones already on ``world`` are kept.

    Raises
    ------
    InputError
        Not Zone objects.
    WorldError
        The zones block every node.
    """
    zs = tuple(zones)
    bad = [z for z in zs if not isinstance(z, Zone)]
    if bad:
        raise InputError(f"zones must be fm2uav.world.zones.Zone objects, got {type(bad[0]).__name__}")
    if not zs:
        return world
    all_zones = tuple(getattr(world, "zones", ())) + zs
    probe = replace(world, zones=all_zones)
    mask = zone_voxels(probe)
    occ = world.occupancy | mask
    if occ.all():
        raise WorldError(f"the {len(all_zones)} zone(s) block every node of the map; check "
                         f"{_NO_FLY} and operating_area (coordinates, buffer, CRS)")
    out = replace(world, occupancy=occ, zones=all_zones)
    out._cache["zone_voxels"] = mask
    if "base_occupancy" in world._cache:
        out._cache["base_occupancy"] = world._cache["base_occupancy"]
    else:
        base = world.occupancy if not getattr(world, "zones", ()) else None
        if base is not None:
            out._cache["base_occupancy"] = base
    return out


def terrain_surface_index(world: World) -> np.ndarray:
    """Like :meth:`World.surface_index` but ignoring zone nodes: the terrain/roof top.

    ``(nx, ny)`` int, -1 where a column has no terrain or building node.
    """
    mask = zone_voxels(world)
    if mask is None:
        return world.surface_index()
    key = "terrain_surface_index"
    if key not in world._cache:
        occ = world.occupancy & ~mask
        nz = occ.shape[2]
        has = occ.any(axis=2)
        top = nz - 1 - np.argmax(occ[:, :, ::-1], axis=2)
        out = np.where(has, top, -1).astype(np.int64)
        out.setflags(write=False)
        world._cache[key] = out
    return world._cache[key]


# ---------------------------------------------------------------------- along a route
def _chord_ground(world: World, xy: np.ndarray, ground: np.ndarray, chords: np.ndarray
                  ) -> tuple[np.ndarray, np.ndarray]:
    """Highest and lowest ground [m] over each sample and the chosen chords next to it,
    relative to the chord's straight line (z is flown linearly between samples; the
    ground's exact rise and drop along a chord: :func:`fm2uav.world.ground_model.ground_bulge`)."""
    from .ground_model import ground_bulge

    g_hi, g_lo = ground.copy(), ground.copy()
    k = np.flatnonzero(chords)
    if not len(k):
        return g_hi, g_lo
    bump, dip = ground_bulge(world, xy[k], xy[k + 1])
    for side in (k, k + 1):
        np.maximum.at(g_hi, side, ground[side] + bump)
        np.minimum.at(g_lo, side, ground[side] - dip)
    return g_hi, g_lo


def _chords_touching(foot: BaseGeometry, xy: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Which samples of the polyline ``xy`` meet ``foot`` (interior or boundary) themselves
    or through a chord to a neighbour, and which chords meet it."""
    m = len(xy)
    touched = shapely.intersects_xy(foot, xy[:, 0], xy[:, 1])
    hit = np.zeros(max(m - 1, 0), dtype=bool)
    if m < 2:
        return touched, hit
    x0, y0, x1, y1 = foot.bounds
    a, b = xy[:-1], xy[1:]
    near = ~((np.maximum(a[:, 0], b[:, 0]) < x0) | (np.minimum(a[:, 0], b[:, 0]) > x1)
             | (np.maximum(a[:, 1], b[:, 1]) < y0) | (np.minimum(a[:, 1], b[:, 1]) > y1))
    k = np.flatnonzero(near)
    if len(k):
        lines = shapely.linestrings(np.stack([a[k], b[k]], axis=1))
        hit[k] = shapely.intersects(foot, lines)
    touched[:-1] |= hit
    touched[1:] |= hit
    return touched, hit


def zone_bounds_along(world: World, xy: np.ndarray, z_route: np.ndarray
                      ) -> tuple[np.ndarray, np.ndarray]:
    """Lower/upper altitude bounds [m] the zones put on route samples.

    The flown height is linear between consecutive samples (a chord). For each zone
    with a floor or ceiling whose kept-out footprint meets a sample or one of its
    chords, the sample must pass over the zone (``z >= ceiling + buffer``) or under it
    (``z <= floor - buffer``) — on the side of the FM² route's own height ``z_route``
    there — so that the whole chord does: an AGL ceiling is raised by the ground's
    exact rise above the chord (:func:`fm2uav.world.ground_model.ground_bulge`), an AGL floor
    lowered by its drop. An operating area's floor/ceiling (shrunk by its buffer) bound every
    sample. Zones without vertical limits give no bound (the route must not enter them
    at all; see :func:`zone_violations`).

    Parameters
    ----------
    world : World
    xy : ndarray, shape (M, 2)
        Route samples [m].
    z_route : ndarray, shape (M,)
        The FM² route's height at each sample [m] (chooses over / under).

    Returns
    -------
    lower, upper : ndarray, shape (M,)
        ``-inf`` / ``+inf`` where unbounded.
    """
    xy = np.asarray(xy, dtype=float)
    m = len(xy)
    lower, upper = np.full(m, -np.inf), np.full(m, np.inf)
    zones = getattr(world, "zones", ())
    if not zones or world.ndim != 3:
        return lower, upper
    ground = np.asarray(world.ground_height(xy[:, 0], xy[:, 1]), dtype=float)
    for zone in zones:
        if zone.inclusion:
            chords = np.ones(max(m - 1, 0), dtype=bool)
            inside = np.ones(m, dtype=bool)
        elif zone.full_height:
            continue
        else:
            inside, chords = _chords_touching(zone.keep_out(), xy)
            if not inside.any():
                continue
        g_hi, g_lo = (_chord_ground(world, xy, ground, chords) if zone.reference == "agl"
                      else (ground, ground))
        if zone.inclusion:
            lower = np.maximum(lower, zone.vertical_range(g_hi)[0])
            upper = np.minimum(upper, zone.vertical_range(g_lo)[1])
            continue
        lo = zone.vertical_range(g_lo)[0]
        hi = zone.vertical_range(g_hi)[1]
        if zone.ceiling is None:
            over = np.zeros(m, dtype=bool)
        elif zone.floor is None:
            over = np.ones(m, dtype=bool)
        else:
            over = np.asarray(z_route, dtype=float) >= 0.5 * (lo + hi)
        lower = np.where(inside & over, np.maximum(lower, hi), lower)
        upper = np.where(inside & ~over, np.minimum(upper, lo), upper)
    return lower, upper


@dataclass(frozen=True)
class ZoneViolation:
    """A point of a path/leg inside a zone's kept-out air."""

    zone: str
    segment: int
    point: tuple[float, ...]
    inside_buffer_only: bool


def zone_violations(world: World, points: Any, *, step: float | None = None,
                    buffered: bool = True) -> list[ZoneViolation]:
    """Points of the polyline ``points`` (legs between them checked every ``step`` m)
    that lie in a zone's kept-out air, or outside the operating area.

    Parameters
    ----------
    world : World
        Its ``zones`` are checked (true geometry, not the rasterised nodes).
    points : array_like, shape (N, 2|3)
        Path or waypoints [m].
    step : float, optional
        Check spacing along each leg [m]; default a quarter of the horizontal cell.
    buffered : bool
        Include the buffer (default) or check the bare zone only.

    Returns
    -------
    list of ZoneViolation
        One per zone and leg (the first offending point of each).
    """
    zones = getattr(world, "zones", ())
    if not zones:
        return []
    p = np.asarray(points, dtype=float)
    if step is None:
        from .ground_model import sampling_step

        step = sampling_step(world)
    dense, seg = densify(p, step, horizontal=True)
    ground = (np.asarray(world.ground_height(dense[:, 0], dense[:, 1]), dtype=float)
              if dense.shape[1] == 3 else None)
    out: list[ZoneViolation] = []
    for zone in zones:
        bad = _inside(zone if buffered else replace(zone, buffer=0.0), dense, ground)
        if not bad.any():
            continue
        core = _inside(replace(zone, buffer=0.0), dense, ground) if zone.buffer else bad
        for k in np.unique(seg[bad]):
            first = int(np.flatnonzero(bad & (seg == k))[0])
            out.append(ZoneViolation(zone.name or zone.kind, int(k),
                                     tuple(float(v) for v in dense[first]),
                                     not bool(core[seg == k].any())))
    return out


#: Points within this distance [m] of a zone's (buffered) floor or ceiling are on its
#: boundary, which a plan may fly along: the profile puts the path exactly there.
BOUNDARY_TOL = 1e-3


def _inside(zone: Zone, dense: np.ndarray, ground: np.ndarray | None) -> np.ndarray:
    """Which points are in the zone's kept-out air (outside an operating area).

    The kept-out air is open: its boundary (the buffered footprint's edge, the buffered
    floor and ceiling, to :data:`BOUNDARY_TOL`) belongs to the air the plan may use.
    """
    if zone.inclusion:
        inside = ~shapely.intersects_xy(zone.keep_out(), dense[:, 0], dense[:, 1])
        if ground is not None:
            lo, hi = zone.vertical_range(ground)
            inside |= (dense[:, 2] < lo - BOUNDARY_TOL) | (dense[:, 2] > hi + BOUNDARY_TOL)
        return inside
    inside = shapely.contains_xy(zone.keep_out(), dense[:, 0], dense[:, 1])
    if ground is not None:
        lo, hi = zone.vertical_range(ground)
        inside &= (dense[:, 2] > lo + BOUNDARY_TOL) & (dense[:, 2] < hi - BOUNDARY_TOL)
    return inside


def zone_distances(world: World, points: Any) -> dict[str, float]:
    """Smallest horizontal distance [m] from the points to each no-fly zone's edge
    (negative: inside), and to the operating area's edge (negative: outside).

    Only points within a zone's vertical extent count for it (``inf`` if none).
    """
    zones = getattr(world, "zones", ())
    p = np.asarray(points, dtype=float)
    out: dict[str, float] = {}
    if not zones:
        return out
    pts = shapely.points(p[:, 0], p[:, 1])
    ground = (np.asarray(world.ground_height(p[:, 0], p[:, 1]), dtype=float)
              if p.shape[1] == 3 else None)
    for k, zone in enumerate(zones):
        name = zone.name or f"{zone.kind} {k + 1}"
        d = shapely.distance(zone.geometry.boundary, pts)
        inside = shapely.contains_xy(zone.geometry, p[:, 0], p[:, 1])
        signed = np.where(inside != zone.inclusion, -d, d)
        if ground is not None and not zone.inclusion:
            lo, hi = zone.vertical_range(ground)
            within = (p[:, 2] > lo + BOUNDARY_TOL) & (p[:, 2] < hi - BOUNDARY_TOL)
            signed = np.where(within, signed, np.inf)
        out[name] = float(np.min(signed)) if len(signed) else math.inf
    return out


def check_points_allowed(world: World, points: Mapping[str, Any]) -> None:
    """Refuse a start/goal inside a no-fly zone or outside the operating area, naming it.

    Raises
    ------
    PointError
        Bad input (exit code 2): the message names the point, the zone, what is wrong
        (inside the zone, its buffer, its vertical extent; outside the area) and how far
        it is from the allowed air.
    """

    for what, pt in points.items():
        p = np.asarray(pt, dtype=float)
        v = zone_violations(world, np.atleast_2d(p), buffered=True)
        if not v:
            continue
        zone = next((z for z in world.zones if (z.name or z.kind) == v[0].zone), None)
        at = np.round(p, 1).tolist()
        if zone is not None and zone.inclusion:
            d = float(zone.geometry.exterior.distance(Point(p[0], p[1]))) if hasattr(
                zone.geometry, "exterior") else float(zone.geometry.boundary.distance(
                    Point(p[0], p[1])))
            inside = bool(zone.geometry.contains(Point(p[0], p[1])))
            why = ((f"within its buffer of {zone.buffer:g} m from the edge ({d:.0f} m "
                    "from it)") if inside and zone.buffer > 0 and d < zone.buffer else
                   "above its ceiling or below its floor" if inside else
                   f"outside it, {d:.0f} m from its edge")
            raise PointError(
                f"the {what} {at} m is not inside the operating area {v[0].zone!r}: it lies "
                f"{why}; the whole flight must stay inside the area — move the {what} into "
                "it, or enlarge operating_area (or lower its buffer)")
        where = ("in its buffer" if v[0].inside_buffer_only else "inside it")
        raise PointError(
            f"the {what} {at} m lies in the no-fly zone {v[0].zone!r} ({where}); move the "
            f"{what} out of it, or change {_NO_FLY}")


def check_zones_on_map(zones: Sequence[Zone], world: World, label: str, *,
                       lonlat_bounds: Sequence[float] | None = None, anchor: Any = None,
                       inline: bool = False) -> None:
    """Say so when none of ``zones`` (one file or entry) touches the map.

    A zone file whose zones all lie off the map changes nothing in the plan; most
    often it is the wrong file or its coordinates are written ``[lat, lon]``. With
    ``lonlat_bounds`` (the zones' lon/lat bounds W, S, E, N as read), the swap is
    detected: when the bounds with longitude and latitude exchanged meet the map, the
    zones are refused (InputError, the fix named). ``label`` names the file (or, with
    ``inline``, the mission-file entry of one zone). Otherwise a
    :class:`ZoneWarning` names the file and how far its nearest zone is.

    Raises
    ------
    InputError
        The coordinates are ``[lat, lon]`` (swapped).
    """
    import warnings

    if not zones:
        return
    b = np.asarray(world.bounds, dtype=float)
    rect = shapely.box(b[0, 0], b[1, 0], b[0, 1], b[1, 1])
    shapes = []
    for z in zones:
        g = z.geometry.buffer(z.buffer) if z.buffer > 0 and not z.inclusion else z.geometry
        if np.all(np.isfinite(g.bounds)):
            shapes.append(g)
            if g.intersects(rect):
                return
    kind = "operating area" if zones[0].inclusion else "zone"
    n = len(zones)
    off = (f"{label} lies off the map" if inline else
           f"{label}: its {kind} lies off the map" if n == 1 else
           f"{label}: all of its {n} {kind}s lie off the map")
    covers = ""  # the map's lon/lat extent, when the zones were given in lon/lat
    if lonlat_bounds is not None and len(lonlat_bounds) == 4:
        w, s, e, nn = (float(v) for v in lonlat_bounds)
        corners = np.array([[b[0, 0], b[1, 0]], [b[0, 1], b[1, 0]], [b[0, 0], b[1, 1]],
                            [b[0, 1], b[1, 1]]])
        from .geo import to_lonlat

        ll = to_lonlat(world, corners, anchor=anchor)
        mw, me = float(ll[:, 0].min()), float(ll[:, 0].max())
        ms, mn = float(ll[:, 1].min()), float(ll[:, 1].max())
        covers = f"the map covers lon {mw:.5f}..{me:.5f}, lat {ms:.5f}..{mn:.5f}"
        # swapped: the file's "longitudes" are latitudes and the other way round
        if abs(w) <= 90 and abs(e) <= 90 and s <= me and nn >= mw and w <= mn and e >= ms:
            raise InputError(
                f"{off}, but with longitude and latitude swapped "
                f"{'it' if n == 1 else 'they'} would lie on it: the coordinates are written "
                f"[lat, lon] (x {w:.5f}..{e:.5f}, y {s:.5f}..{nn:.5f}; {covers}); GeoJSON "
                "(RFC 7946), KML and mission files write [lon, lat] — swap the two coordinates")
    near = min((float(rect.distance(g)) for g in shapes), default=float("inf"))
    dist = (f"the nearest is {near / 1000:.1f} km from its edge" if np.isfinite(near) else
            "its coordinates fall outside the map's coordinate system")
    if not inline:
        fix = ("check that it is the file meant for this area and that its coordinates are "
               "[lon, lat] (or give its CRS)")
    elif covers:
        fix = f"check its [lon, lat] coordinates: {covers}"
    else:  # an entry in world metres, like start and goal
        fix = (f"check its coordinates: they are world metres (lonlat: false) and the map covers "
               f"x {b[0, 0]:.0f}..{b[0, 1]:.0f} m, y {b[1, 0]:.0f}..{b[1, 1]:.0f} m")
    warnings.warn(ZoneWarning(
        f"{off} ({dist}), so {'it changes' if n == 1 else 'they change'} nothing in "
        f"this plan; {fix}"), stacklevel=2)


__all__ += ["ZoneViolation", "check_points_allowed", "check_zones_on_map", "ZoneWarning"]
