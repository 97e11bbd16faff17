"""Rally points: safe places to come down other than home, given or chosen by the planner.

A rally point is a place on the ground the vehicle may return to instead of home
(ArduPilot "Rally Points", PX4 "safe points"). fm2uav keeps, for each, the point on
the ground and the *approach point* above it, ``agl`` metres up: the end of its FM²
way back (:class:`~fm2uav.planning.returns.ReturnField`), where the vehicle descends
to land.

:func:`rally_points` checks points the operator gives (inside the map, over known
ground, out of obstacles and zones, reachable) and describes each site
(:func:`site_facts`: slope, distance to buildings and zones). :func:`choose_rally`
picks them for the operator: among *open* sites (:func:`candidate_sites`: over
measured ground, slope at most ``max_slope_deg``, ``building_clearance`` m from every
roof, ``zone_clearance`` m from every zone, reachable on the mission's map) it
bounds the worst return time along the route with the farthest-point greedy of the
k-centre problem (Gonzalez 1985): home is the first centre; then, repeatedly, the
route point whose way back is longest (in FM² time, the planner's own measure) gets
a wave of its own, the open site it reaches first becomes a rally point, and the
rally point's return field lowers every route point's time. With centres free to be
any route point this greedy is the 2-approximation of k-centre; restricted to open
sites (the k-supplier problem) it is a 3-approximation (Hochbaum & Shmoys 1986).
Two marches per rally point; it stops early when a new point no longer lowers the
worst time by 2 %.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..errors import InputError, PlanningError, PointError
from ..planning.returns import ReturnField

__all__ = ["RallyPoint", "rally_points", "site_facts", "candidate_sites", "choose_rally",
           "MAX_RALLY", "DEFAULT_AUTO_RALLY"]

#: Most rally points a mission carries (MAVProxy's rally loader keeps 10).
MAX_RALLY = 10
#: Rally points chosen by ``--rally auto`` without a count.
DEFAULT_AUTO_RALLY = 3
_FLAG = "--rally / --rally-file (mission file rally:)"


@dataclass(frozen=True)
class RallyPoint:
    """A rally point.

    Attributes
    ----------
    name : str
        ``"rally 1"``, ...
    point : ndarray, shape (ndim,)
        The approach point [m]: ``agl`` above the ground (2D worlds: x, y).
    ground : float
        Ground under it (world z) [m].
    agl : float
        Height of the approach point above the ground [m].
    chosen_by : {"user", "planner"}
    facts : dict
        :func:`site_facts` of the site.
    """

    name: str
    point: np.ndarray
    ground: float
    agl: float
    chosen_by: str = "user"
    facts: dict[str, Any] = field(default_factory=dict)

    def summary(self, world: Any, anchor: Any = None) -> dict[str, Any]:
        """JSON-friendly description with lon/lat and the ground's altitude."""
        from ..world.geo import to_lonlat

        lo, la, amsl = to_lonlat(world, [[self.point[0], self.point[1], self.ground]],
                                 anchor=anchor)[0]
        return {"name": self.name, "lon": round(float(lo), 9), "lat": round(float(la), 9),
                "ground_amsl_m": round(float(amsl), 2), "agl_m": self.agl,
                "x_m": round(float(self.point[0]), 2), "y_m": round(float(self.point[1]), 2),
                "chosen_by": self.chosen_by, **self.facts}


def _roof_distance(world: Any) -> np.ndarray | None:
    """Distance [m] from each column to the nearest roof column (None: no roofs); cached."""
    from scipy import ndimage

    from ..world.ground import roof_heights

    key = "rally_roof_distance"
    if key in world._cache:
        return world._cache[key]
    out = None
    if world.ndim == 3:
        roofs = np.isfinite(roof_heights(world))
        if roofs.any():
            out = ndimage.distance_transform_edt(~roofs, sampling=world.spacing[:2])
            out = np.maximum(out - 0.5 * float(min(world.spacing[:2])), 0.0)
    world._cache[key] = out
    return out


def site_facts(world: Any, xy: Any) -> dict[str, np.ndarray]:
    """Slope [deg], distance to the nearest roof and no-fly zone [m], and whether the
    ground is invented (filled DEM nodata) at sites ``xy`` (n, 2)."""
    import shapely

    p = np.atleast_2d(np.asarray(xy, dtype=float))[:, :2]
    model = getattr(world, "ground", None)
    h = max(float(model.pixel_m) if model is not None else float(min(world.spacing[:2])), 1.0)
    g = lambda dx, dy: np.asarray(world.ground_height(p[:, 0] + dx, p[:, 1] + dy), dtype=float)  # noqa: E731
    gx = (g(h, 0) - g(-h, 0)) / (2 * h)
    gy = (g(0, h) - g(0, -h)) / (2 * h)
    slope = np.degrees(np.arctan(np.hypot(gx, gy)))
    i = np.clip(np.floor((p[:, 0] - world.origin[0]) / world.spacing[0] + 0.5), 0,
                world.shape[0] - 1).astype(int)
    j = np.clip(np.floor((p[:, 1] - world.origin[1]) / world.spacing[1] + 0.5), 0,
                world.shape[1] - 1).astype(int)
    rd = _roof_distance(world)
    building = np.full(len(p), np.inf) if rd is None else rd[i, j]
    zone = np.full(len(p), np.inf)
    pts = shapely.points(p)
    for z in getattr(world, "zones", ()):
        geom = z.keep_out()  # an operating area: the allowed inside
        inside = shapely.contains(geom, pts)
        to_edge = shapely.distance(geom.boundary, pts)
        d = np.where(inside, to_edge, -to_edge) if z.inclusion else \
            np.where(inside, -to_edge, to_edge)
        zone = np.minimum(zone, d)
    filled = getattr(world, "filled", None)
    unknown = np.zeros(len(p), dtype=bool) if filled is None else np.asarray(filled)[i, j]
    return {"slope_deg": slope, "building_distance_m": building, "zone_distance_m": zone,
            "unknown_ground": unknown}


def _facts_row(facts: dict[str, np.ndarray], k: int) -> dict[str, Any]:
    def num(v: float) -> float | None:
        return None if not math.isfinite(float(v)) else round(float(v), 1)
    return {"slope_deg": num(facts["slope_deg"][k]),
            "building_distance_m": num(facts["building_distance_m"][k]),
            "zone_distance_m": num(facts["zone_distance_m"][k]),
            "unknown_ground": bool(facts["unknown_ground"][k])}


def _approach(world: Any, xy: np.ndarray, agl: float) -> tuple[np.ndarray, float]:
    g = float(world.ground_height(xy[0], xy[1]))
    if world.ndim == 2:
        return np.asarray(xy[:2], dtype=float), g
    return np.array([xy[0], xy[1], g + agl], dtype=float), g


def rally_points(world: Any, given: Any, *, agl: float, reach: ReturnField | None = None,
                 names: Any = None) -> list[RallyPoint]:
    """Rally points the operator gives, checked.

    Parameters
    ----------
    world : World
    given : sequence of (x, y[, agl])
        Sites [m]; the third value, when given (not None), is the approach height
        above the ground [m] (default ``agl``).
    agl : float
        Default approach height above the ground [m].
    reach : ReturnField, optional
        Home's return field: each rally point must be reachable on the mission's map.
    names : sequence of str, optional
        Default ``"rally 1"``, ...

    Raises
    ------
    InputError
        More than :data:`MAX_RALLY` points, a site outside the map, over filled DEM
        nodata, in an obstacle or a no-fly zone, or cut off from home — naming the
        point and ``--rally``.
    """
    pts = [np.asarray([v for v in np.asarray(g, dtype=object).ravel() if v is not None],
                      dtype=float) for g in given]
    if len(pts) > MAX_RALLY:
        raise InputError(f"{len(pts)} rally points given; at most {MAX_RALLY} ({_FLAG}): "
                         "ArduPilot and MAVProxy keep 10")
    out: list[RallyPoint] = []
    for k, v in enumerate(pts):
        name = (list(names)[k] if names is not None else f"rally {k + 1}")
        if v.size not in (2, 3) or not np.all(np.isfinite(v)):
            raise InputError(f"{name}: a rally point is x, y[, agl] (finite), got {v.tolist()} "
                             f"({_FLAG})")
        h = float(v[2]) if v.size == 3 else float(agl)
        if not h > 0:
            raise InputError(f"{name}: the approach height above the ground must be > 0 m, got "
                             f"{h:g} ({_FLAG})")
        b = world.bounds
        if not (b[0, 0] <= v[0] <= b[0, 1] and b[1, 0] <= v[1] <= b[1, 1]):
            raise InputError(f"{name} at ({v[0]:.1f}, {v[1]:.1f}) m lies outside the map (x "
                             f"{b[0, 0]:.0f}..{b[0, 1]:.0f}, y {b[1, 0]:.0f}..{b[1, 1]:.0f} m); "
                             f"move it inside ({_FLAG})")
        point, ground = _approach(world, v[:2], h)
        if world.ndim == 3 and point[2] > b[2, 1]:
            raise InputError(f"{name}: its approach point {h:g} m above the ground is above the "
                             f"map's top ({b[2, 1]:.0f} m); lower its height ({_FLAG})")
        facts = site_facts(world, v[None, :2])
        if facts["unknown_ground"][0]:
            raise InputError(f"{name} at ({v[0]:.1f}, {v[1]:.1f}) m lies over filled DEM nodata: "
                             f"its ground is not measured; move it ({_FLAG})")
        if facts["zone_distance_m"][0] < 0:
            raise InputError(f"{name} at ({v[0]:.1f}, {v[1]:.1f}) m lies inside a no-fly zone "
                             f"(or outside the operating area); move it ({_FLAG})")
        cell = world.to_cell(point, what=name)
        if world.occupancy[cell]:
            raise InputError(f"{name}: its approach point {np.round(point, 1).tolist()} m is "
                             f"inside an obstacle (a building?); move the site or raise its "
                             f"height ({_FLAG})")
        if reach is not None and not np.isfinite(reach.cost(point)[0]):
            raise InputError(f"{name} at ({v[0]:.1f}, {v[1]:.1f}) m cannot be reached on the "
                             f"mission's map (walled off by obstacles or zones); move it "
                             f"({_FLAG})")
        out.append(RallyPoint(name, point, ground, h, "user", _facts_row(facts, 0)))
    return out


def candidate_sites(world: Any, home: ReturnField, *, agl: float, spacing: float | None = None,
                    max_slope_deg: float = 8.0, building_clearance: float = 25.0,
                    zone_clearance: float = 30.0) -> tuple[np.ndarray, dict[str, Any]]:
    """Open, reachable sites for rally points (module docstring): their approach points
    (m, ndim) [m] on a grid of ``spacing`` metres, and counts of what was left out."""
    b = world.bounds
    cell = float(min(world.spacing[:2]))
    if spacing is None:
        spacing = max(cell, float(max(b[0, 1] - b[0, 0], b[1, 1] - b[1, 0])) / 80.0)
    margin = 2 * cell
    xs = np.arange(b[0, 0] + margin, b[0, 1] - margin + 1e-9, spacing)
    ys = np.arange(b[1, 0] + margin, b[1, 1] - margin + 1e-9, spacing)
    X, Y = np.meshgrid(xs, ys, indexing="ij")
    xy = np.column_stack([X.ravel(), Y.ravel()])
    counts: dict[str, Any] = {"grid": int(len(xy)), "spacing_m": round(float(spacing), 1)}
    if not len(xy):
        return np.zeros((0, world.ndim)), counts
    f = site_facts(world, xy)
    keep = ~f["unknown_ground"]
    counts["unknown_ground"] = int((~keep).sum())
    steep = f["slope_deg"] > max_slope_deg
    counts["steep"] = int((keep & steep).sum())
    keep &= ~steep
    near_b = f["building_distance_m"] < building_clearance
    counts["near_buildings"] = int((keep & near_b).sum())
    keep &= ~near_b
    near_z = f["zone_distance_m"] < zone_clearance
    counts["near_zones"] = int((keep & near_z).sum())
    keep &= ~near_z
    g = np.asarray(world.ground_height(xy[:, 0], xy[:, 1]), dtype=float)
    pts = xy if world.ndim == 2 else np.column_stack([xy, g + agl])
    if world.ndim == 3:
        keep &= pts[:, 2] <= b[2, 1]
    cost = np.full(len(pts), np.inf)
    cost[keep] = home.cost(pts[keep])
    reach = np.isfinite(cost)
    counts["unreachable"] = int((keep & ~reach).sum())
    keep &= reach
    counts["open"] = int(keep.sum())
    counts["rules"] = {"max_slope_deg": max_slope_deg, "building_clearance_m": building_clearance,
                       "zone_clearance_m": zone_clearance, "measured_ground": True}
    return pts[keep], counts


def choose_rally(home: ReturnField, clients: Any, k: int, *, agl: float, first: int = 1,
                 **rules: Any) -> tuple[list[RallyPoint], list[ReturnField], dict[str, Any]]:
    """Up to ``k`` rally points that bound the worst way back from ``clients`` (module docstring).

    Parameters
    ----------
    home : ReturnField
        Home's return field (the first centre; its map, level and settings are used).
    clients : array_like, shape (m, ndim)
        Route points [m] whose way back is bounded.
    k : int
        Most rally points to choose (1..:data:`MAX_RALLY`).
    agl : float
        Approach height of the chosen points above the ground [m].
    first : int
        Number of the first chosen point's name (``rally <first>``).
    **rules
        :func:`candidate_sites` rules (``max_slope_deg``, ``building_clearance``,
        ``zone_clearance``, ``spacing``).

    Returns
    -------
    rally : list of RallyPoint
    fields : list of ReturnField
        The return field of each (reused by the caller).
    report : dict
        Candidate counts, the worst FM² return cost before and after each pick.
    """
    if not 1 <= int(k) <= MAX_RALLY:
        raise InputError(f"--rally auto:K needs 1 <= K <= {MAX_RALLY}, got {k}")
    world = home.world
    sites, counts = candidate_sites(world, home, agl=agl, **rules)
    c = np.atleast_2d(np.asarray(clients, dtype=float))[:, :world.ndim]
    d = home.cost(c)
    worst = [float(np.max(d))]
    report: dict[str, Any] = {"candidates": counts, "worst_cost": worst, "stopped": ""}
    chosen: list[RallyPoint] = []
    fields: list[ReturnField] = []
    if not len(sites):
        report["stopped"] = "no open site on the map (see candidates)"
        return chosen, fields, report
    for r in range(int(k)):
        j = int(np.argmax(d))
        try:
            probe = ReturnField(world, home.W, c[j], name="probe", order=home.order,
                                step=home.step)
        except PlanningError:
            report["stopped"] = "the farthest route point has no free air around it"
            break
        sc = probe.cost(sites)
        if not np.isfinite(sc).any():
            report["stopped"] = "no open site reachable from the farthest route point"
            break
        site = sites[int(np.argmin(sc))]
        name = f"rally {first + r}"
        try:
            rf = ReturnField(world, home.W, site, name=name, level=home.level, order=home.order,
                             step=home.step)
        except (PlanningError, PointError):
            report["stopped"] = f"{name}: its site is not free air"
            break
        d_new = np.minimum(d, rf.cost(c))
        if float(np.max(d_new)) > 0.98 * float(np.max(d)):
            report["stopped"] = "a further rally point would lower the worst way back by < 2 %"
            break
        d = d_new
        worst.append(float(np.max(d)))
        g = float(world.ground_height(site[0], site[1]))
        facts = _facts_row(site_facts(world, site[None, :2]), 0)
        chosen.append(RallyPoint(name, site, g, float(agl), "planner", facts))
        fields.append(rf)
    report["worst_cost"] = [round(v, 3) for v in worst]
    return chosen, fields, report
