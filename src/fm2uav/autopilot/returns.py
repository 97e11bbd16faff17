"""The firmware's own return, made safe: the lowest return altitude that clears everything.

A firmware return (ArduPilot RTL, PX4 Return) flies a straight line to home or a
rally point at one altitude that no planner checks. This module writes the rules of
each firmware down as data (:class:`~fm2uav.autopilot.firmware.profile.ReturnModel`
in ``autopilot/firmware/``: how it climbs, what its altitude is measured from,
where it goes) and finds, for every airframe, the lowest return altitude for which
**every** straight return line — from every waypoint and from points every DEM
pixel along the mission's legs (:func:`route_samples`) to the destination the
firmware would choose — stays ``min_agl`` above the surface (the DEM, bilinear,
with roofs), under the ``max_agl`` ceiling where the altitude is the parameter's,
and out of every no-fly zone (:func:`firmware_returns`).

The surface along each line is read exactly (:func:`fm2uav.world.segments.surface_points`:
every pixel-row/column crossing and every parabola vertex of the bilinear DEM), so
the altitude found is the one an independent sampler of the source raster confirms;
it is rounded up to the whole metre.

The altitude must hold **on its own**: a vehicle above the return altitude keeps its
altitude (Copter, PX4) or glides down to it (ArduPlane), which only adds height, but
one below it — taking off, landing, pushed under the route — climbs over its position
(Copter, PX4; a PX4 fixed-wing in a loiter there) and then flies level at it. So every
line needs ``A >= max(surface + min_agl)`` along it; and a plane (ArduPlane, ``climb
= along``) climbs at its climb gradient ``g`` (climb rate / cruise speed) while it
flies home, ``z = min(A, z0 + g s)`` from the route's altitude ``z0``: every point
of the line must be reachable at that gradient, else no altitude works (the obstacle
is too close ahead). From a start below the floor (the take-off climb, the landing
approach: ``h0`` above the surface) a plane must keep ``min(min_agl, h0)`` above the
surface instead — it cannot be ``min_agl`` up at the runway, but its return must never
bring it closer to the surface than it starts. Above the ceiling: ``A - ground <= max_agl`` wherever the line
flies at ``A``.

When no altitude works (a ridge higher than the ceiling allows, an obstacle too
close for the climb, a zone on the line) :func:`firmware_returns` says so; the
mission then carries the planned safe return (:mod:`fm2uav.autopilot.safe_return`).

:func:`rtl_end_notes` is what a mission that ends with an RTL item says about it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..world.segments import ground_points, surface_points
from .firmware import PROFILES
from .firmware.profile import Param, ReturnModel
from .items import CMD_DO_CHANGE_SPEED, CMD_DO_LAND_START, CMD_NAV_WAYPOINT, MissionItem

__all__ = [
    "Destination",
    "RouteSamples",
    "ModelResult",
    "FirmwareReturns",
    "leg_speeds",
    "route_samples",
    "firmware_returns",
    "rtl_end_notes",
    "MAX_LINES",
    "RTL_WARNING",
]

#: Most straight return lines checked per model (the sampling step grows beyond it).
MAX_LINES = 20_000
#: How the warning about an unchecked RTL end starts (:func:`rtl_end_notes`).
RTL_WARNING = "RTL flies a straight line home"


# ---------------------------------------------------------------- the mission's route
def leg_speeds(items: Any, n_waypoints: int, default: float) -> tuple[np.ndarray, np.ndarray]:
    """Commanded speed of each leg and hold time at each waypoint, read from the items.

    MAVLink semantics: a ``DO_CHANGE_SPEED`` runs when the vehicle has reached the
    navigation item before it, so the speed in force on the leg towards a waypoint is
    the last one set before that waypoint's item; before any, the vehicle flies its
    default speed (``default``: the airframe's forward speed, as the mission's time
    estimate assumes). ``NAV_WAYPOINT`` param 1 is the hold time.

    Parameters
    ----------
    items : sequence of MissionItem
        The mission (takeoff first).
    n_waypoints : int
        Route waypoints (``len(mission.waypoints)``): the first ``NAV_WAYPOINT`` is the
        start when there is one more than ``n - 1`` of them.
    default : float
        Speed before the first ``DO_CHANGE_SPEED`` [m/s].

    Returns
    -------
    speeds : ndarray, shape (n - 1,)
    holds : ndarray, shape (n,)
    """
    nav = [it for it in items if it.command == CMD_NAV_WAYPOINT]
    offset = 0 if len(nav) >= n_waypoints else 1  # no item for the start (waypoint 0)
    speeds = np.full(max(n_waypoints - 1, 0), float(default))
    holds = np.zeros(n_waypoints)
    current, k = float(default), -1 + offset
    for it in items:
        if it.command == CMD_DO_CHANGE_SPEED and math.isfinite(it.params[1]) and it.params[1] > 0:
            current = float(it.params[1])
        elif it.command == CMD_NAV_WAYPOINT:
            k += 1
            if k >= n_waypoints:
                break
            holds[k] = max(float(it.params[0]), 0.0)
            if k >= 1:
                speeds[k - 1] = current
    return speeds, holds


@dataclass(frozen=True)
class RouteSamples:
    """Points along a mission's legs as flown, with the mission's clock.

    Attributes
    ----------
    points : ndarray, shape (m, 3)
        World metres at the flown altitude (terrain frame: the waypoints' height above
        the ground interpolated along the leg, on the ground under it).
    leg : ndarray of int, shape (m,)
        Leg of each point (leg k joins waypoints k and k + 1).
    fraction : ndarray, shape (m,)
        Position along its leg in [0, 1].
    distance : ndarray, shape (m,)
        3D distance flown along the route from the first waypoint [m].
    time : ndarray, shape (m,)
        Mission time at the point [s]: the take-off climb, the legs before at their
        commanded speeds (with holds), the leg's share (as the mission's estimate).
    waypoint : ndarray of int, shape (m,)
        Waypoint index of the point, -1 between waypoints.
    step : float
        Spacing between samples along the legs [m].
    """

    points: np.ndarray
    leg: np.ndarray
    fraction: np.ndarray
    distance: np.ndarray
    time: np.ndarray
    waypoint: np.ndarray
    step: float

    def __len__(self) -> int:
        return int(len(self.points))

    def at(self, leg: int, fraction: float, mission: Any) -> tuple[np.ndarray, float, float]:
        """(point, distance, time) at ``fraction`` of ``leg`` (one point, as the samples)."""
        s = route_samples(mission, legs=[(int(leg), float(fraction))])
        return s.points[0], float(s.distance[0]), float(s.time[0])


def _flown(world: Any, a: np.ndarray, b: np.ndarray, f: np.ndarray, terrain: bool,
           agl_a: float, agl_b: float) -> np.ndarray:
    pts = a[None, :] + f[:, None] * (b - a)[None, :]
    if terrain:  # the autopilot holds the AGL interpolated between the waypoints
        g = np.asarray(world.ground_height(pts[:, 0], pts[:, 1]), dtype=float)
        pts[:, 2] = g + agl_a + f * (agl_b - agl_a)
    return pts


def route_samples(mission: Any, step: float | None = None, *, max_points: int | None = None,
                  legs: Any = None) -> RouteSamples:
    """Points every ``step`` metres along the mission's legs, every waypoint included.

    Parameters
    ----------
    mission : MissionExport
    step : float, optional
        Horizontal spacing [m]; default the source DEM's pixel (the world's cell
        without a DEM).
    max_points : int, optional
        Cap: the step grows so that at most this many points are taken.
    legs : sequence of (leg, fraction), optional
        Only these points (for one point of the route, e.g. the point of no return).

    Returns
    -------
    RouteSamples
        Timed on the mission's own clock (:attr:`MissionExport.waypoint_times`).

    Raises
    ------
    ValueError
        A mission without its waypoint times (not made by ``build_mission``).
    """
    wps = mission.waypoints
    world = mission.world
    opt = mission.options
    p = np.asarray(wps.points_m, dtype=float)
    n = len(p)
    terrain = wps.frame == 10
    speeds, holds = leg_speeds(mission.items, n, opt.forward_speed)
    t_wp = getattr(mission, "waypoint_times", None)
    if t_wp is None or len(t_wp) != n:  # build_mission always sets it: one clock, no other
        raise ValueError("route_samples needs the mission's waypoint_times (one per waypoint, "
                         "as build_mission sets them)")
    t_wp = np.asarray(t_wp, dtype=float)
    seg3 = np.linalg.norm(np.diff(p, axis=0), axis=1)
    cum3 = np.concatenate([[0.0], np.cumsum(seg3)])
    # the mission's clock (MissionExport.waypoint_times, the summary's flight time); the hold
    # at a leg's end counts once it is reached
    travel = np.maximum(np.diff(t_wp) - holds[1:], 0.0)
    if legs is not None:
        rows = [(int(k), float(f)) for k, f in legs]
        leg_i = np.array([k for k, _ in rows], dtype=int)
        frac = np.array([f for _, f in rows], dtype=float)
        wp = np.full(len(rows), -1)
    else:
        if step is None:
            model = getattr(world, "ground", None)
            step = float(model.pixel_m) if model is not None and model.pixel_m > 0 else \
                float(min(world.spacing[:2]))
        horiz = np.hypot(*np.diff(p[:, :2], axis=0).T)
        total = float(horiz.sum())
        if max_points is not None and total / step > max_points:
            step = total / max_points
        leg_l, frac_l, wp_l = [], [], []
        for k in range(n - 1):
            m = max(int(np.ceil(horiz[k] / step)), 1)
            f = np.arange(m) / m
            leg_l.append(np.full(m, k))
            frac_l.append(f)
            wp_l.append(np.r_[k, np.full(m - 1, -1)])
        leg_l.append([max(n - 2, 0)])
        frac_l.append([1.0 if n > 1 else 0.0])
        wp_l.append([n - 1])
        leg_i = np.concatenate(leg_l).astype(int)
        frac = np.concatenate(frac_l).astype(float)
        wp = np.concatenate(wp_l).astype(int)
    pts = np.empty((len(leg_i), 3))
    dist = np.empty(len(leg_i))
    tim = np.empty(len(leg_i))
    for k in np.unique(leg_i):
        sel = leg_i == k
        if n == 1:
            pts[sel] = p[0]
            dist[sel] = 0.0
            tim[sel] = t_wp[0]
            continue
        f = frac[sel]
        pts[sel] = _flown(world, p[k], p[k + 1], f, terrain, float(wps.agl[k]),
                          float(wps.agl[k + 1]))
        dist[sel] = cum3[k] + f * seg3[k]
        tim[sel] = t_wp[k] + f * travel[k] + np.where(f >= 1.0, holds[k + 1], 0.0)
    return RouteSamples(points=pts, leg=leg_i, fraction=frac, distance=dist, time=tim,
                        waypoint=wp, step=float(step or 0.0))


def _rates(mission: Any) -> tuple[float, float]:
    """The mission's climb and descent rates [m/s]: those of its own time estimate."""
    f = mission.info["flight"]
    return float(f["climb_rate_mps"]), float(f["descent_rate_mps"])


# ---------------------------------------------------------------- destinations
@dataclass(frozen=True)
class Destination:
    """Where a firmware return may go.

    Attributes
    ----------
    name : str
        ``"home"``, ``"rally 1"``, ``"landing"`` (the start of the mission's landing).
    kind : {"home", "rally", "landing"}
    xy : ndarray, shape (2,)
        World metres.
    ground : float
        Ground under it (world z) [m].
    altitude : float
        Its own altitude (world z) [m] when the firmware measures the return
        altitude above it: home and landing at the ground (touchdown), a rally point
        at its written altitude.
    """

    name: str
    kind: str
    xy: np.ndarray
    ground: float
    altitude: float


def _landing_start(mission: Any) -> Destination | None:
    """The start of the mission's landing (first position item after DO_LAND_START), with
    the touchdown's ground as its altitude; None without a DO_LAND_START."""
    from ..world.geo import from_lonlat

    items = mission.items
    idx = [i for i, it in enumerate(items) if it.command == CMD_DO_LAND_START]
    if not idx:
        return None
    after = [it for it in items[idx[-1] + 1:] if it.has_position]
    if not after:
        return None
    first, last = after[0], after[-1]
    anchor = mission.options.anchor
    xy = from_lonlat(mission.world, [[first.lon, first.lat]], anchor=anchor)[0][:2]
    td = from_lonlat(mission.world, [[last.lon, last.lat]], anchor=anchor)[0][:2]
    g_td = float(mission.world.ground_height(td[0], td[1]))
    return Destination("landing", "landing", np.asarray(xy, dtype=float),
                       float(mission.world.ground_height(xy[0], xy[1])), g_td)


# ---------------------------------------------------------------- one model
@dataclass(frozen=True)
class ModelResult:
    """The safe return altitude of one firmware on one airframe.

    Attributes
    ----------
    model : ReturnModel
    altitude_m : float or None
        The return altitude parameter [m] (above home or the destination, as the
        model says); None when no altitude clears every line.
    clearing_m : float or None
        The lowest altitude clearing terrain, roofs and ``min_agl`` on every line,
        even where it breaks the ceiling [m] (None: none does — a climb too steep or
        a zone).
    feasible : bool
        ``altitude_m`` keeps every line safe and under the ceiling, out of the zones.
    reasons : list of str
        Why not, when not.
    rally_altitudes : dict of str to float
        A rally point's written altitude relative to home [m].
    params : list of Param
        What ``mission.param`` gets for this model.
    summary : dict
        JSON-friendly figures (lines, binding line, measured clearance, ...).
    """

    model: ReturnModel
    altitude_m: float | None
    clearing_m: float | None
    feasible: bool
    reasons: list[str]
    rally_altitudes: dict[str, float]
    params: list[Param]
    summary: dict[str, Any] = field(default_factory=dict)


@dataclass(frozen=True)
class _Lines:
    """Straight return lines a → b with their surface and ground points."""

    a: np.ndarray  # (n, 3) start at its flown altitude
    dest: list[Destination]  # one per line
    length: np.ndarray
    surf: Any  # LinePoints (surface)
    ground: Any  # LinePoints (ground)


def _choose(starts: np.ndarray, cands: list[Destination]) -> list[Destination]:
    """The closest candidate of each start (horizontal distance), as the firmware picks."""
    xy = np.array([c.xy for c in cands])
    d = np.hypot(starts[:, None, 0] - xy[None, :, 0], starts[:, None, 1] - xy[None, :, 1])
    return [cands[int(k)] for k in np.argmin(d, axis=1)]


def _lines(world: Any, starts: np.ndarray, dest: list[Destination]) -> _Lines:
    b = np.array([d.xy for d in dest])
    g = ground_points(world, starts[:, :2], b)
    s = surface_points(world, starts[:, :2], b, ground=g)
    return _Lines(a=starts, dest=dest, length=np.hypot(*(b - starts[:, :2]).T), surf=s, ground=g)


def _flown_z(model: ReturnModel, A: np.ndarray, z0: np.ndarray, t: np.ndarray,
             L: np.ndarray, grad: float) -> np.ndarray:
    """The lowest altitude the return flies at fraction ``t`` of its line (per point):
    the return altitude ``A`` itself — a vehicle above it keeps its altitude (or glides
    down to ``A``), which only adds height, and one below it may be anywhere below the
    route (taking off, landing, pushed down) — except where a plane still climbs to it
    at its gradient from the route's altitude ``z0``."""
    if model.climb == "vertical":
        return np.asarray(A, dtype=float) + np.zeros_like(t)
    return np.where(z0 >= A, A, np.minimum(A, z0 + grad * t * L))


def _floor(model: ReturnModel, lines: _Lines, min_agl: float, grad: float) -> np.ndarray:
    """The height above the surface each surface point of the lines must keep: ``min_agl``;
    for a plane climbing along its line (``climb = along``) from a start below the floor
    (the take-off climb, the landing approach, a goal asked lower), the start's own height
    above the surface: a plane taking off from home cannot be ``min_agl`` above the runway,
    but its return must never bring it closer to the surface than it starts."""
    s = lines.surf
    if model.climb == "vertical":
        return np.full(len(s.z), float(min_agl))
    seg = s.segment
    first = s.t == 0.0
    z_start = np.full(len(lines.a), np.nan)
    z_start[seg[first]] = s.z[first]
    agl0 = np.maximum(lines.a[:, 2] - z_start, 0.0)
    return np.minimum(float(min_agl), agl0[seg])


def _lowest(model: ReturnModel, lines: _Lines, min_agl: float, grad: float) -> np.ndarray:
    """The lowest absolute return altitude each line needs (inf: none works): the highest
    surface + floor (:func:`_floor`) on it, and for a plane climbing along the line, every
    point reachable at its climb gradient from the route's altitude."""
    s = lines.surf
    seg = s.segment
    n = len(lines.a)
    z0 = lines.a[:, 2]
    need = s.z + _floor(model, lines, min_agl, grad)
    starts = np.searchsorted(seg, np.arange(n))
    need_max = np.maximum.reduceat(need, starts)
    if model.climb == "vertical":
        return need_max
    reach = z0[seg] + grad * s.t * lines.length[seg] - need
    climb_ok = np.minimum.reduceat(np.where(need > z0[seg], reach, 0.0), starts) >= -1e-9
    return np.where(climb_ok, need_max, np.inf)


def _ceil_m(v: float) -> float:
    return float(math.ceil(v - 1e-6))


def _evaluate(model: ReturnModel, lines: _Lines, A: np.ndarray, grad: float,
              min_agl: float, max_agl: float | None, world: Any) -> dict[str, Any]:
    """Measured figures of lines flown at absolute return altitudes ``A`` (per line)."""
    s, g = lines.surf, lines.ground
    z0 = lines.a[:, 2]
    z = _flown_z(model, A[s.segment], z0[s.segment], s.t, lines.length[s.segment], grad)
    clear = z - s.z
    k = int(np.argmin(clear))
    out: dict[str, Any] = {"min_clearance_m": round(float(clear[k]), 2),
                           "lowest_line": int(s.segment[k])}
    zg = _flown_z(model, A[g.segment], z0[g.segment], g.t, lines.length[g.segment], grad)
    own = zg >= A[g.segment] - 1e-6  # where the altitude is the parameter's
    agl = zg - g.z
    out["max_agl_m"] = round(float(agl[own].max()), 2) if own.any() else None
    out["over_ceiling"] = int(np.unique(g.segment[own & (agl > max_agl + 1e-6)]).size) \
        if max_agl is not None else 0
    floor = _floor(model, lines, min_agl, grad)
    out["unsafe_lines"] = int(np.unique(s.segment[clear < floor - 1e-6]).size)
    zones: list[str] = []
    if getattr(world, "zones", ()):
        from ..world.zones import zone_violations

        for i in range(len(lines.a)):
            sel = s.segment == i
            pts = np.column_stack([lines.a[i, :2] + s.t[sel, None] * (lines.dest[i].xy -
                                                                     lines.a[i, :2]),
                                   z[sel]])
            pts = np.vstack([lines.a[i], pts])  # the climb over the start
            for v in zone_violations(world, pts):
                if v.zone not in zones:
                    zones.append(v.zone)
    out["zones_entered"] = zones
    out["obstacle_lines"] = _flat_obstacles(world, lines) if world.ndim == 2 else 0
    return out


def _flat_obstacles(world: Any, lines: _Lines) -> int:
    """Lines that cross an obstacle of a 2D map (its height is unknown), sampled every
    quarter cell at the nearest node."""
    step = 0.25 * float(min(world.spacing))
    bad = 0
    for i in range(len(lines.a)):
        a, b = lines.a[i, :2], lines.dest[i].xy
        n = max(int(np.ceil(np.hypot(*(b - a)) / step)), 1)
        pts = a + (np.arange(n + 1) / n)[:, None] * (b - a)
        idx = np.floor(world.to_index(pts) + 0.5).astype(int)
        idx = np.clip(idx, 0, np.asarray(world.shape) - 1)
        bad += bool(world.occupancy[idx[:, 0], idx[:, 1]].any())
    return bad


def _model_result(model: ReturnModel, world: Any, starts: np.ndarray, home: Destination,
                  rally: list[Destination], landing: Destination | None, *, min_agl: float,
                  max_agl: float | None, grad: float,
                  rally_alt: dict[str, float] | None) -> ModelResult:
    """The lowest safe return altitude of one firmware model (module docstring)."""
    if model.destinations == "home_rally":
        cands = [home, *rally]
    else:
        cands = [*rally, *([landing] if landing is not None else [])] or [home]
    dest = _choose(starts, cands)
    lines = _lines(world, starts, dest)
    need = _lowest(model, lines, min_agl, grad)
    reasons: list[str] = []
    names = [d.name for d in dest]
    fixed_rally = rally_alt is not None and model.rally_altitude == "ground"

    def ref(d: Destination) -> float:  # what the parameter is measured from
        if model.reference == "home":
            return home.ground
        if d.kind == "rally" and rally_alt is not None:
            return home.ground + rally_alt[d.name]
        return d.altitude

    refs = np.array([ref(d) for d in dest])
    rel = need - refs  # the parameter each line needs
    transit = model.rally_altitude == "transit" and model.reference == "home"
    main = np.array([not (transit and d.kind == "rally") for d in dest])
    finite = np.isfinite(need)
    lo = model.min_m if model.min_m is not None else 0.0
    if not finite.all():
        bad = int(np.flatnonzero(~finite)[0])
        reasons.append(f"{int((~finite).sum())} line(s) cannot clear the surface at any return "
                       f"altitude: the climb at the airframe's gradient "
                       f"({math.degrees(math.atan(grad)):.1f} deg) meets the ground first "
                       f"(e.g. from {np.round(starts[bad, :2], 0).tolist()} m to {names[bad]})")
    T = _ceil_m(max(float(rel[main & finite].max()) if (main & finite).any() else lo, lo))
    r_alt: dict[str, float] = {}
    for d in rally:
        sel = np.array([x.name == d.name for x in dest]) & finite
        if transit:
            r_alt[d.name] = _ceil_m(max(float(rel[sel].max()) if sel.any() else T, T))
        elif fixed_rally:
            r_alt[d.name] = float(rally_alt[d.name])
        else:
            r_alt[d.name] = round(d.ground - home.ground, 2)
    A = np.array([home.ground + r_alt[d.name] if (transit and d.kind == "rally")
                  else ref(d) + T for d in dest])
    figs = _evaluate(model, lines, A, grad, min_agl, max_agl, world)
    clearing = None if not finite.all() else T
    if model.max_m is not None and T > model.max_m:
        reasons.append(f"the return altitude needed, {T:.0f} m, is above the firmware's "
                       f"maximum {model.max_m:g} m")
    if figs["over_ceiling"]:
        reasons.append(f"{figs['over_ceiling']} line(s) would fly above the max_agl ceiling of "
                       f"{max_agl:g} m (up to {figs['max_agl_m']:.0f} m above the ground): the "
                       "ground between the route and the destination is too uneven for one "
                       "altitude (a ridge)")
    if figs["obstacle_lines"]:
        reasons.append(f"{figs['obstacle_lines']} line(s) cross obstacles of the 2D map, whose "
                       "height is unknown: no altitude is known to clear them")
    if figs["zones_entered"]:
        reasons.append("straight return lines cross no-fly zones: "
                       + ", ".join(figs["zones_entered"]))
    if figs["unsafe_lines"] and finite.all():  # never expected: measured after rounding up
        reasons.append(f"{figs['unsafe_lines']} line(s) pass below {min_agl:g} m above the "
                       "surface")
    feasible = not reasons
    b = int(np.argmax(np.where(main & finite, rel, -np.inf))) if (main & finite).any() else 0
    bind_pt = _binding_point(lines, b, min_agl)
    summary = {
        "firmware": model.label,
        "lines": int(len(starts)),
        "destinations": {d.name: int(sum(1 for x in dest if x.name == d.name)) for d in cands},
        "return_altitude_m": T if feasible else None,
        "clearing_altitude_m": clearing,
        "altitude_reference": ("above home" if model.reference == "home" else
                               "above the destination (home, landing or rally point)"),
        "binding_line": {"from_m": np.round(starts[b], 1).tolist(), "to": names[b],
                         "surface_point_m": bind_pt},
        **figs,
        "feasible": feasible,
        "reasons": list(reasons),
    }
    params = _params(model, T if clearing is not None else None, feasible, bool(rally))
    return ModelResult(model=model, altitude_m=T if feasible else None, clearing_m=clearing,
                       feasible=feasible, reasons=reasons, rally_altitudes=r_alt,
                       params=params, summary=summary)


def _binding_point(lines: _Lines, i: int, min_agl: float) -> list[float] | None:
    s = lines.surf
    sel = np.flatnonzero(s.segment == i)
    if not len(sel):
        return None
    k = sel[int(np.argmax(s.z[sel]))]
    xy = lines.a[i, :2] + s.t[k] * (lines.dest[i].xy - lines.a[i, :2])
    return [round(float(xy[0]), 1), round(float(xy[1]), 1), round(float(s.z[k]), 1)]


def _params(model: ReturnModel, T: float | None, feasible: bool, rally: bool) -> list[Param]:
    """``mission.param`` lines of one model: the altitude in every version's spelling and
    unit, the behaviour it was checked for, rally settings, and — when no altitude is
    safe — the settings that make the return follow the mission (they win)."""
    out: dict[str, Param] = {}
    if T is not None:
        what = ("clears every straight return line" if feasible else
                "clears the terrain but not every limit: see the summary")
        for ap in model.altitude:
            out[ap.name] = Param(ap.name, round(T * ap.per_metre, 3),
                                 f"return altitude {T:g} m ({model.label}, {ap.versions}, "
                                 f"{ap.unit}): {what}")
    for p in model.settings + (model.rally_settings if rally else ()):
        out[p.name] = p
    if not feasible:
        for p in model.mission_return:
            out[p.name] = p
    return list(out.values())


# ---------------------------------------------------------------- every model of a firmware
@dataclass(frozen=True)
class FirmwareReturns:
    """The firmware's return made safe (or not) for a mission: one :class:`ModelResult` per
    firmware model of the airframe (two for ``generic``)."""

    results: list[ModelResult]
    min_agl: float
    min_agl_source: str
    max_agl: float | None
    rally_altitudes: dict[str, float]
    samples: RouteSamples

    @property
    def feasible(self) -> bool:
        """Every model has a safe return altitude."""
        return all(r.feasible for r in self.results)

    @property
    def params(self) -> list[Param]:
        """Every model's parameters, once each (first wins)."""
        seen: dict[str, Param] = {}
        for r in self.results:
            for p in r.params:
                seen.setdefault(p.name, p)
        return list(seen.values())

    def summary(self) -> dict[str, Any]:
        """JSON-friendly description (``returns.firmware`` in the summary)."""
        return {
            "feasible": self.feasible,
            "min_agl_m": self.min_agl,
            "min_agl_source": self.min_agl_source,
            "max_agl_m": self.max_agl,
            "start_points": {"count": len(self.samples),
                             "waypoints": int((self.samples.waypoint >= 0).sum()),
                             "spacing_m": round(self.samples.step, 3)},
            "rally_altitudes_m": dict(self.rally_altitudes),
            "models": [r.summary for r in self.results],
            "params": {p.name: p.value for p in self.params},
            "surface": "DEM interpolated bilinearly, read exactly along each line (every "
                       "pixel-row/column crossing and parabola vertex), roofs per column",
        }


def firmware_returns(mission: Any, *, rally: Any = (), min_agl: float, min_agl_source: str = "",
                     max_agl: float | None = None, samples: RouteSamples | None = None
                     ) -> FirmwareReturns:
    """The lowest safe firmware return altitude of a mission (module docstring).

    Parameters
    ----------
    mission : MissionExport
        Its firmware and airframe choose the models, its legs the start points.
    rally : sequence of RallyPoint
        The mission's rally points (:mod:`fm2uav.autopilot.rally`).
    min_agl : float
        Lowest height above the surface along every line [m].
    max_agl : float, optional
        Ceiling above the ground where the altitude is the parameter's [m].
    samples : RouteSamples, optional
        Start points (default :func:`route_samples` every DEM pixel, at most
        :data:`MAX_LINES`).

    Returns
    -------
    FirmwareReturns
    """
    world = mission.world
    opt = mission.options
    models = PROFILES[opt.firmware].returns.get(opt.vehicle, ())
    if samples is None:
        samples = route_samples(mission, max_points=MAX_LINES)
    starts = samples.points
    if world.ndim == 2:
        starts = starts.copy()
    hx, hy = mission.waypoints.points_m[0, :2]
    home_g = float(world.ground_height(hx, hy))
    home = Destination("home", "home", np.array([hx, hy]), home_g, home_g)
    dests = [Destination(r.name, "rally", np.asarray(r.point[:2], dtype=float), r.ground,
                         r.ground) for r in rally]
    landing = _landing_start(mission)
    climb, _ = _rates(mission)
    grad = climb / max(opt.forward_speed, 1e-6)
    results: list[ModelResult] = []
    rally_alt: dict[str, float] | None = None
    # transit-altitude models first: their rally altitudes are the ones written
    for m in sorted(models, key=lambda m: m.rally_altitude != "transit"):
        r = _model_result(m, world, starts, home, dests, landing, min_agl=min_agl,
                          max_agl=max_agl, grad=grad, rally_alt=rally_alt)
        if rally_alt is None:
            rally_alt = r.rally_altitudes
        results.append(r)
    order = {m.label: k for k, m in enumerate(models)}
    results.sort(key=lambda r: order[r.model.label])
    return FirmwareReturns(results=results, min_agl=float(min_agl),
                           min_agl_source=min_agl_source, max_agl=max_agl,
                           rally_altitudes=dict(rally_alt or {}), samples=samples)


# ---------------------------------------------------------------- an RTL end
def rtl_end_notes(world: Any, start_xy: np.ndarray, end_xy: np.ndarray, firmware: str,
                  tolerance: float, end_items: list[MissionItem]) -> tuple[dict[str, Any],
                                                                           list[str]]:
    """What a mission ending with ``NAV_RETURN_TO_LAUNCH`` says about its return.

    The landing added after the RTL item where the firmware requires one (PX4's
    ``MIS_TKO_LAND_REQ``), and the straight line home the RTL flies: its length, how
    high the ground under it rises above home, and — when the route did not come back
    home itself — that this line is checked only by the firmware return settings
    (:func:`firmware_returns`, ``mission.param``).

    Returns
    -------
    landing : dict
        ``note``, ``rtl_straight_line_m``, ``rtl_max_ground_above_home_m``.
    warnings : list of str
    """
    landing: dict[str, Any] = {}
    warnings: list[str] = []
    if len(end_items) > 1:
        landing["note"] = ("PX4 needs a landing in fixed-wing and "
                           "VTOL missions (MIS_TKO_LAND_REQ = 2): the RTL item is followed by a "
                           "landing at home, which the return mode uses through DO_LAND_START")
    line = start_xy[None, :] + np.linspace(0, 1, 50)[:, None] * (end_xy - start_xy)[None, :]
    b = world.bounds
    inside = ((line[:, 0] >= b[0, 0]) & (line[:, 0] <= b[0, 1]) & (line[:, 1] >= b[1, 0])
              & (line[:, 1] <= b[1, 1]))
    g = lambda xy: np.asarray(world.ground_height(xy[:, 0], xy[:, 1]), dtype=float)  # noqa: E731
    rise = (float((g(line[inside]) - g(start_xy[None, :])[0]).max()) if inside.any()
            else float("nan"))
    back = float(np.hypot(*(end_xy - start_xy)))
    landing["rtl_straight_line_m"] = round(back, 1)
    landing["rtl_max_ground_above_home_m"] = None if not np.isfinite(rise) else round(rise, 1)
    if back > max(10.0, tolerance):  # the route did not come back home itself
        rises = (f" — the ground under it rises {rise:.0f} m above home"
                 if np.isfinite(rise) and rise > 0 else "")
        warnings.append(f"{RTL_WARNING} at the firmware's return altitude "
                        "(PX4 RTL_RETURN_ALT, ArduPilot RTL_ALT / RTL_ALTITUDE)"
                        f"{rises}: fly it only with the return altitude fm2uav checked "
                        "(mission.param, returns.firmware in the summary), or use return: true "
                        "(--return) for a planned way back")
    return landing, warnings
