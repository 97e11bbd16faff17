"""Coverage flights around no-fly zones (issue 13 on ``fm2uav cover``).

The corridor FM² of :mod:`.fm2` follows the zigzag inside a corridor of
half-width ``h`` = corridor · D; a no-fly zone (an obstacle of the world, see
:func:`fm2uav.world.zones.with_zones`) that crosses the corridor cuts it, and
no path exists inside it. When the corridor meets a zone's kept-out footprint
(the zone grown by its buffer) or leaves the operating area, the coverage is
flown as a route instead:

1. the zigzag (bands and turns) is clipped to the allowed region — the map
   minus every zone's footprint grown by ``margin`` (two cells by default, so
   the points are clear of the rasterised zone nodes), intersected with the
   operating area shrunk the same way;
2. the clipped pieces are simplified (tolerance a quarter of D: band ends and
   a few points per turn remain) and their vertices, in zigzag order, are the
   route's points at ``agl`` above the ground;
3. consecutive points whose straight segment stays in the allowed region (the
   bands and turns themselves) are joined straight; a segment that would cross a
   zone's footprint is an FM² leg on the world's own velocity map, which goes
   around the zone (or over / under one with a ceiling / floor), keeping the FM²
   clearance from it as from the terrain. The final altitude profile then sets the
   heights of the whole flight over the ground and the roofs.

The route resolves bands at least :data:`ROUTE_BAND_CELLS` cells apart (its
points are kept more than two cells apart); ``fm2uav cover`` chooses such a cell
when the cell size is not given, and closer bands are refused naming
``--cell-size`` and ``--spacing``. The parts of the area inside the zones are not
covered (they cannot be); the coverage share reported is measured on the flown
path.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import shapely
from shapely.geometry import LineString, box

from ...errors import InputError, PlanningError
from ...planning import FlightLevel, PlanOptions, Shaping

__all__ = ["allowed_region", "meets_zones", "zone_route_points", "plan_zone_route",
           "ROUTE_BAND_CELLS", "route_cell"]

#: Fewest map cells between two bands the route around zones resolves: its points are kept
#: more than two cells apart (so that consecutive FM² legs are not shorter than the grid),
#: so band ends closer than that merge and the bands are not flown.
ROUTE_BAND_CELLS = 2.5


def route_cell(spacing: float) -> float:
    """Largest horizontal cell [m] on which the route around zones flies bands ``spacing``
    [m] apart (:data:`ROUTE_BAND_CELLS` cells between two bands)."""
    return float(spacing) / ROUTE_BAND_CELLS


def _margin(world: Any) -> float:
    return 2.0 * float(max(world.spacing[0], world.spacing[1]))


def allowed_region(world: Any, margin: float | None = None) -> Any:
    """Ground region [m] a flight may use: the map minus the zones' kept-out footprints
    grown by ``margin`` [m] (default two cells), inside the operating area shrunk by it.

    Zones with a floor/ceiling are kept out of at every height (a coverage flight at
    one height above ground may not go under or over them).
    """
    m = _margin(world) if margin is None else float(margin)
    b = world.bounds
    region = box(b[0, 0], b[1, 0], b[0, 1], b[1, 1])
    for z in getattr(world, "zones", ()) or ():
        if z.inclusion:
            region = region.intersection(z.keep_out(m))
        else:
            region = region.difference(z.keep_out(m))
    return region


def meets_zones(world: Any, track: np.ndarray, half_width: float,
                margin: float | None = None) -> bool:
    """True if the corridor of half-width ``half_width`` [m] about ``track`` (k, >=2) [m]
    reaches a zone's kept-out footprint (grown by ``margin``) or the operating area's edge."""
    if not getattr(world, "zones", ()):
        return False
    line = LineString(np.asarray(track, dtype=float)[:, :2])
    grown = line.buffer(float(half_width))
    return not allowed_region(world, margin).contains(grown)


def _round_cell(v: float) -> str:
    """A cell size [m] no larger than ``v``, as a short number for a message."""
    from ...world.load import round_down

    return f"{round_down(v):g}"


def zone_route_points(world: Any, track: np.ndarray, spacing: float, agl: float,
                      margin: float | None = None) -> np.ndarray:
    """Points (k, 3) [m] of the zigzag ``track`` outside the zones, in order, at ``agl``
    above the ground (see the module docstring, steps 1–2).

    Raises
    ------
    InputError
        The bands are closer than :data:`ROUTE_BAND_CELLS` cells (names the flags), or
        nothing of the zigzag lies outside the zones: the area and the zones
        contradict each other (bad input, exit code 2 on the command line).
    """
    cell = float(min(world.spacing[0], world.spacing[1]))
    if float(spacing) < ROUTE_BAND_CELLS * cell * (1 - 1e-9):
        raise InputError(
            f"the bands are {float(spacing):g} m apart (--spacing D), less than "
            f"{ROUTE_BAND_CELLS:g} cells of the map ({cell:g} m): the route around the no-fly "
            f"zones cannot fly them apart; use --cell-size {_round_cell(route_cell(spacing))} "
            f"(world.cell_size) or bands at least {ROUTE_BAND_CELLS * cell:g} m apart "
            "(--spacing)")
    line = LineString(np.asarray(track, dtype=float)[:, :2])
    inside = line.intersection(allowed_region(world, margin))
    pieces = [g for g in getattr(inside, "geoms", [inside])
              if g.geom_type == "LineString" and not g.is_empty and g.length > 0]
    if not pieces:
        raise InputError("the whole zigzag lies in no-fly zones (or outside the operating "
                         "area); check the no-fly zones (no_fly_zones / --no-fly) against the "
                         "survey area (--area)")
    pieces.sort(key=lambda g: line.project(shapely.Point(g.coords[0])))
    pts: list[np.ndarray] = []
    for g in pieces:
        for p in np.asarray(g.simplify(0.25 * float(spacing)).coords)[:, :2]:
            if not pts or np.hypot(*(p - pts[-1])) > 2.0 * cell:
                pts.append(p)
    xy = np.asarray(pts)
    z = np.asarray(world.ground_height(xy[:, 0], xy[:, 1]), dtype=float) + float(agl)
    return np.column_stack([xy, z])


#: Margin of a leg's window around its two ends [cells], at least.
WINDOW_CELLS = 20


def _window_leg(world: Any, W: np.ndarray, a: np.ndarray, b: np.ndarray, shaping: Shaping,
                level: FlightLevel, options: PlanOptions) -> Any:
    """The FM² leg ``a`` → ``b`` [m] on a window of the map around it (the map's own W cut
    to the window), or on the whole map when the window holds no way between them.

    The window is the two points' box grown by the leg's length and at least
    :data:`WINDOW_CELLS` cells, every layer: a march over the whole map for each of a
    survey's zone crossings took seconds per band (a flight level makes the air over a
    zone dark, so the front first fills the map's flight layer).
    """
    import dataclasses

    from ...errors import UnreachableError
    from ...planning import plan

    h = np.asarray(world.spacing[:2], dtype=float)
    grow = max(float(np.hypot(*(b - a)[:2])), WINDOW_CELLS * float(h.max()))
    lo = np.minimum(a[:2], b[:2]) - grow
    hi = np.maximum(a[:2], b[:2]) + grow
    i0 = np.maximum(np.floor((lo - np.asarray(world.origin[:2])) / h).astype(int), 0)
    i1 = np.minimum(np.ceil((hi - np.asarray(world.origin[:2])) / h).astype(int),
                    np.asarray(world.shape[:2]) - 1)
    cols = (slice(i0[0], i1[0] + 1), slice(i0[1], i1[1] + 1))
    whole = all(s.start == 0 and s.stop == n for s, n in zip(cols, world.shape[:2]))
    if not whole:
        origin = (world.origin[0] + i0[0] * h[0], world.origin[1] + i0[1] * h[1],
                  world.origin[2])
        sub = dataclasses.replace(
            world, occupancy=world.occupancy[cols], origin=origin,
            terrain=None if world.terrain is None else world.terrain[cols],
            filled=None if world.filled is None else world.filled[cols])
        try:
            return plan(sub, a, b, shaping=shaping, level=level,
                        options=dataclasses.replace(options, speed_map=np.ascontiguousarray(
                            W[cols])))
        except UnreachableError:
            pass  # no way inside the window: the whole map
    return plan(world, a, b, shaping=shaping, level=level,
                options=dataclasses.replace(options, speed_map=W))


def plan_zone_route(world: Any, track: np.ndarray, spacing: float, level: FlightLevel, *,
                    shaping: Shaping | None = None, options: PlanOptions = PlanOptions(),
                    margin: float | None = None) -> Any:
    """FM² route along the zigzag ``track`` around the world's zones (module docstring).

    Consecutive points whose straight segment stays in the allowed region (the bands and
    turns outside the zones) are joined straight: that is the zigzag itself, and the
    final altitude profile sets its heights over the ground and the roofs. Only the
    segments that would cross a zone's kept-out footprint (or leave the operating area)
    are FM² legs on the world's map, which go around the zone — or over / under one with
    a ceiling / floor. (Every leg an FM² march over the whole map made a survey of many
    narrow bands take minutes per band.)

    Returns
    -------
    fm2uav.missions.route.Route
        Its ``plan`` is the whole coverage flight (heights not yet profiled: ``profile``
        None, see :func:`~fm2uav.missions.coverage.fm2.with_flown_heights`); ``legs`` the
        FM² legs.

    Raises
    ------
    PlanningError
        A leg cannot be planned (its message names the leg).
    InputError
        Fewer than two points of the zigzag lie outside the zones.
    """
    import dataclasses
    import time

    from scipy import ndimage

    from ...geometry import path_length
    from ...planning import Plan
    from ...planning.planner import plan_params, plan_velocity
    from ...world.clearance import surface_clearance
    from ..route import Route

    t0 = time.perf_counter()
    pts = zone_route_points(world, track, spacing, level.agl, margin)
    if len(pts) < 2:
        raise InputError("less than one band of the zigzag lies outside the no-fly zones; "
                         "nothing to cover: check the no-fly zones (no_fly_zones / --no-fly) "
                         "against the survey area (--area)")
    shaping = Shaping() if shaping is None else shaping
    region = allowed_region(world, 0.0)
    step = 0.5 * float(min(world.spacing[0], world.spacing[1]))
    pieces, legs, W = [pts[:1]], [], None
    for k in range(len(pts) - 1):
        a, b = pts[k], pts[k + 1]
        if region.contains(LineString([a[:2], b[:2]])):  # the zigzag itself: straight
            n = max(int(np.ceil(np.hypot(*(b - a)[:2]) / step)), 1)
            q = a + (np.arange(1, n + 1)[:, None] / n) * (b - a)
            q[:-1, 2] = np.asarray(world.surface_height(q[:-1, 0], q[:-1, 1])) + level.agl
            pieces.append(q)
            continue
        if W is None:
            W = plan_velocity(world, shaping, level, options)
        try:
            leg = _window_leg(world, W, a, b, shaping, level, options)
        except PlanningError as exc:
            raise type(exc)(f"coverage leg {k + 1} of {len(pts) - 1} around the no-fly zones "
                            f"({np.round(a, 1).tolist()} → {np.round(b, 1).tolist()} m): "
                            f"{exc}") from None
        legs.append(leg)
        pieces.append(leg.path[1:])
    junctions = np.concatenate([[0], np.cumsum([len(q) for q in pieces[1:]])])
    path = np.concatenate(pieces)
    if W is None:
        W = plan_velocity(world, shaping, level, options)
    w = ndimage.map_coordinates(W, world.to_index(path).T, order=1, mode="nearest")
    joined = Plan(
        path=path, w=w, length=path_length(path),
        clearance=float(surface_clearance(world, path).min()),
        timings={"total": time.perf_counter() - t0}, W=W,
        T=legs[0].T if legs else np.zeros((1,) * world.ndim), world=world,
        params={**plan_params(shaping, level, options), "legs": len(legs),
                "straight_segments": len(pts) - 1 - len(legs)},
        shaping=shaping, level=level, profile=None)
    return Route(plan=joined, legs=tuple(legs), points=pts, junctions=junctions)
