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
   a few points per turn remain) and their vertices, in zigzag order, become
   the via points of :func:`fm2uav.missions.route.plan_route` at ``agl`` above
   the ground;
3. FM² plans leg by leg on the world's own velocity map, so a leg from the end
   of one piece to the start of the next goes around the zone, keeping the
   FM² clearance from it as from the terrain.

Limits: the bands are flown as FM² legs between their ends, not inside the
corridor, so the ground track may drift off a band where the terrain pulls
the geodesic (the coverage share reported is measured on the flown path); the
parts of the area inside the zones are not covered (they cannot be).
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
        The bands are closer than :data:`ROUTE_BAND_CELLS` cells (names the flags).
    PlanningError
        Nothing of the zigzag lies outside the zones.
    """
    cell = float(min(world.spacing[0], world.spacing[1]))
    if float(spacing) < ROUTE_BAND_CELLS * cell * (1 - 1e-9):
        raise InputError(
            f"the bands are {float(spacing):g} m apart (--spacing D), less than "
            f"{ROUTE_BAND_CELLS:g} cells of the map ({cell:g} m): the route around the no-fly "
            f"zones cannot fly them apart; use --cell-size {_round_cell(route_cell(spacing))} "
            f"(world.cell_size) or --spacing >= {ROUTE_BAND_CELLS * cell:g}")
    line = LineString(np.asarray(track, dtype=float)[:, :2])
    inside = line.intersection(allowed_region(world, margin))
    pieces = [g for g in getattr(inside, "geoms", [inside])
              if g.geom_type == "LineString" and not g.is_empty and g.length > 0]
    if not pieces:
        raise PlanningError("the whole zigzag lies in no-fly zones (or outside the operating "
                            "area); check --no-fly / no_fly_zones against --area")
    pieces.sort(key=lambda g: line.project(shapely.Point(g.coords[0])))
    pts: list[np.ndarray] = []
    for g in pieces:
        for p in np.asarray(g.simplify(0.25 * float(spacing)).coords)[:, :2]:
            if not pts or np.hypot(*(p - pts[-1])) > 2.0 * cell:
                pts.append(p)
    xy = np.asarray(pts)
    z = np.asarray(world.ground_height(xy[:, 0], xy[:, 1]), dtype=float) + float(agl)
    return np.column_stack([xy, z])


def plan_zone_route(world: Any, track: np.ndarray, spacing: float, level: FlightLevel, *,
                    shaping: Shaping | None = None, options: PlanOptions = PlanOptions(),
                    margin: float | None = None) -> Any:
    """FM² route along the zigzag ``track`` around the world's zones (module docstring).

    Returns
    -------
    fm2uav.missions.route.Route
        Its ``plan`` is the whole coverage flight.

    Raises
    ------
    PlanningError
        A leg cannot be planned (its message names the leg), or fewer than two
        points of the zigzag lie outside the zones.
    """
    from ..route import plan_route

    pts = zone_route_points(world, track, spacing, level.agl, margin)
    if len(pts) < 2:
        raise PlanningError("less than one band of the zigzag lies outside the no-fly zones; "
                            "nothing to cover (check --no-fly / no_fly_zones against --area)")
    return plan_route(world, pts[0], pts[-1], via=list(pts[1:-1]),
                      shaping=Shaping() if shaping is None else shaping, level=level,
                      options=options)
