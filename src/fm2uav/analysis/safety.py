"""Safety figures of a flown path and its waypoint legs, on the continuous ground.

Every figure here is measured on what the vehicle flies, against the surface
model of the world (:meth:`World.ground_height` — the DEM interpolated
bilinearly — and :meth:`World.surface_height` with roofs), never on grid nodes:

* **height above ground** (AGL) at every path point: ``z - ground_height(x, y)``;
  min, p5, median, max and the share within ±5 m of the request, for the whole
  path and for the cruise (between the climb-out and the descent), and where
  the lowest point is;
* **height above the surface** (over roofs) when the world has buildings;
* **clearance**: distance to the terrain/building surface
  (:func:`fm2uav.world.clearance.surface_clearance`);
* **legs**: the straight legs between consecutive waypoints sampled every
  quarter of a horizontal cell (the autopilot flies those, not the dense
  path): lowest AGL along them and where, and the zones they enter;
* **zones**: horizontal distance to every no-fly zone / the operating area and
  any point inside (:mod:`fm2uav.world.zones`);
* **known and unknown ground** (:mod:`fm2uav.analysis.known_ground`): every
  figure above split into over measured ground and over filled (unknown)
  ground, length and share, the lowest AGL along the legs over each, which
  DEM measured how much; and whether the DEM's pixels resolve the relief for
  the requested flight level;
* **warnings**: a path that flies higher above the ground than
  :data:`ADVISORY_MAX_AGL` (120 m: the EU open category's limit, and about US
  Part 107's 400 ft) without a ``max_agl`` of its own is named, with where and how
  much of it — ``planner.max_agl`` (``--max-agl``) turns the advice into a limit the
  profile keeps (docs/safety.md).

:func:`safety_summary` gathers them in one JSON-friendly dict; the CLI puts it
into ``summary.json`` and the report, and the tests recompute the same numbers
from the written files with an independent bilinear sampler.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ..errors import InputError
from ..geometry import densify
from ..planning.altitude import height_figures
from ..world.clearance import surface_clearance
from ..world.ground import has_unknown_ground
from ..world.ground_model import sampling_step
from ..world.zones import zone_distances, zone_violations
from .known_ground import dem_resolution, filled_mask, ground_split

__all__ = ["ADVISORY_MAX_AGL", "height_above_ground", "leg_figures", "safety_summary",
           "ceiling_warning"]

#: Height above the ground [m] above which a plan without its own ``max_agl`` is warned
#: about: the EU open category's 120 m (Regulation (EU) 2019/947, UAS.OPEN.010) and about
#: the US Part 107 limit (400 ft = 121.9 m, 14 CFR 107.51).
ADVISORY_MAX_AGL = 120.0


def height_above_ground(world: Any, points: Any, *, surface: bool = False) -> np.ndarray:
    """``z - ground_height(x, y)`` [m] (``surface=True``: above roofs too)."""
    p = np.asarray(points, dtype=float)
    if p.ndim != 2 or p.shape[1] != 3:
        raise InputError(f"points must be (N, 3) metres, got shape {p.shape}")
    fn = world.surface_height if surface else world.ground_height
    return p[:, 2] - np.asarray(fn(p[:, 0], p[:, 1]), dtype=float)


def leg_figures(world: Any, waypoints: Any, *, requested: float | None = None,
                step: float | None = None, terrain_frame: bool = False,
                waypoint_agl: Any = None, cruise: Any = None) -> dict[str, Any]:
    """Height above ground along the straight legs between waypoints.

    Parameters
    ----------
    world : World
    waypoints : array_like, shape (n, 3)
        Waypoints [m] at their flown altitude (world z).
    requested : float, optional
        Requested AGL [m] (share within ±5 m).
    step : float, optional
        Sampling along the legs [m]; default a quarter of
        :func:`~fm2uav.world.ground_model.sampling_step` (at most 1/16 of a
        source-DEM pixel).
    terrain_frame : bool
        The autopilot follows the terrain between waypoints (MAVLink frame
        10): the AGL along a leg is the waypoints' AGL (``waypoint_agl``)
        interpolated, not a straight line in altitude.
    waypoint_agl : array_like, optional
        The AGL of each terrain-frame waypoint [m] (default: their own).
    cruise : array_like of bool, shape (n,), optional
        Which waypoints are cruise points: legs between two of them are the
        cruise legs (own figures).

    Returns
    -------
    dict
        ``legs``, ``step_m``, figures over every leg sample, the take-off and
        landing points included (``min_m`` ..., ``lowest_leg``,
        ``lowest_point_m``), ``min_off_takeoff_landing_m`` (the lowest sample
        outside the take-off and landing columns: what ``min_agl`` is checked
        on), ``cruise`` figures (legs between two cruise waypoints), zone
        entries of the legs.
    """
    p = np.asarray(waypoints, dtype=float)
    if p.ndim != 2 or p.shape[1] != 3 or len(p) < 2:
        raise InputError(f"waypoints must be (n >= 2, 3) metres, got shape {p.shape}")
    if step is None:
        step = 0.25 * sampling_step(world)
    dense, leg = densify(p, step, horizontal=True)  # every point's leg
    if terrain_frame:
        own = height_above_ground(world, p) if waypoint_agl is None else \
            np.asarray(waypoint_agl, dtype=float)
        seg = np.linalg.norm(np.diff(dense[:, :2], axis=0), axis=1)
        h = np.empty(len(dense))
        for k in range(len(p) - 1):
            m = np.flatnonzero(leg == k)
            d = np.concatenate([[0.0], np.cumsum(seg[m[:-1]])]) if len(m) > 1 else np.zeros(1)
            L = float(np.hypot(*(p[k + 1, :2] - p[k, :2])))
            t = d / L if L > 0 else np.zeros(len(m))
            h[m] = own[k] + t * (own[k + 1] - own[k])
        dense = dense.copy()
        dense[:, 2] = np.asarray(world.ground_height(dense[:, 0], dense[:, 1])) + h
    else:
        h = height_above_ground(world, dense)
    fig = height_figures(h, requested, points=dense)
    # off the take-off and landing columns (their vertical legs are exempt from min_agl)
    off = (np.hypot(*(dense[:, :2] - p[0, :2]).T) > 1e-6) & \
        (np.hypot(*(dense[:, :2] - p[-1, :2]).T) > 1e-6)
    inner = off if off.any() else np.ones(len(dense), dtype=bool)
    out: dict[str, Any] = {
        "legs": int(len(p) - 1), "step_m": round(float(step), 3),
        "frame": "terrain (AGL interpolated between waypoints)" if terrain_frame
        else "straight legs in altitude", **fig, "lowest_leg": int(leg[int(np.argmin(h))]),
        "min_off_takeoff_landing_m": round(float(h[inner].min()), 3)}
    if cruise is not None:
        c = np.asarray(cruise, dtype=bool)
        cl = c[:-1] & c[1:]
        sel = cl[leg] & inner
        if sel.any():
            out["cruise"] = height_figures(h[sel], requested, points=dense[sel])
    if has_unknown_ground(world):
        unknown = filled_mask(world, dense)
        out["ground"] = {
            "measured_min_m": round(float(h[~unknown].min()), 3) if (~unknown).any() else None,
            "filled_min_m": round(float(h[unknown].min()), 3) if unknown.any() else None,
            "filled_samples": int(unknown.sum()), "samples": int(len(h))}
    hits = zone_violations(world, dense if terrain_frame else p, step=step)
    out["zone_entries"] = [{"zone": v.zone, "leg": int(leg[min(v.segment, len(leg) - 1)])
                            if terrain_frame else v.segment,
                            "point_m": [round(c_, 2) for c_ in v.point],
                            "buffer_only": v.inside_buffer_only} for v in hits]
    return out


def safety_summary(world: Any, path: Any, *, requested: float | None = None,
                   phase: Any = None, waypoints: Any = None, waypoint_indices: Any = None,
                   terrain_frame: bool = False, waypoint_agl: Any = None,
                   level: Any = None) -> dict[str, Any]:
    """All safety figures of a flown path (see the module docstring).

    Parameters
    ----------
    world : World
    path : array_like, shape (N, 3)
        The flown path [m] (e.g. ``Plan.path``).
    requested : float, optional
        Requested AGL [m].
    phase : array_like of str, optional
        ``"climb-out"`` / ``"cruise"`` / ``"descent"`` per point (``Plan.phase``);
        without it the cruise figures are left out.
    waypoints : array_like, shape (n, 3), optional
        The thinned waypoints at their flown altitude (leg figures).
    waypoint_indices : array_like of int, optional
        Their indices in ``path`` (gives the cruise legs with ``phase``).
    terrain_frame, waypoint_agl :
        See :func:`leg_figures`.
    level : FlightLevel, optional
        Gives ``min_agl`` / ``max_agl`` / ``tolerance`` checks.

    Returns
    -------
    dict
        ``height_above_ground`` {``path``, ``cruise``}, ``cruise_points``
        (first and last index of the cruise in ``path``), ``clearance_m``,
        ``ground`` (:func:`~fm2uav.analysis.known_ground.ground_split`, DEM
        worlds), ``dem_resolution`` (with a flight level), ``legs``, ``zones``,
        ``checks`` (each limit with pass/fail).
    """
    p = np.asarray(path, dtype=float)
    if p.ndim != 2 or p.shape[1] != 3:
        return {"note": "2D path: no height above ground"}
    agl = height_above_ground(world, p)
    seg = np.linalg.norm(np.diff(p[:, :2], axis=0), axis=1)
    s = np.concatenate([[0.0], np.cumsum(seg)])
    out: dict[str, Any] = {
        "reference": "continuous ground: World.ground_height (bilinear on the DEM/terrain)",
        "height_above_ground": {"path": height_figures(agl, requested, points=p, s=s)},
    }
    roofs_differ = np.any(np.asarray(world.surface_height(p[:, 0], p[:, 1])) >
                          np.asarray(world.ground_height(p[:, 0], p[:, 1])) + 1e-9)
    if roofs_differ:
        out["height_above_surface"] = {"path": height_figures(
            height_above_ground(world, p, surface=True), requested, points=p, s=s)}
    cruise = None
    if phase is not None:
        ph = np.asarray(phase).astype(str)
        cruise = ph == "cruise"
        if cruise.any():
            idx = np.flatnonzero(cruise)
            out["cruise_points"] = [int(idx[0]), int(idx[-1])]
            out["height_above_ground"]["cruise"] = height_figures(
                agl[cruise], requested, points=p[cruise], s=s[cruise])
            if roofs_differ:
                out["height_above_surface"]["cruise"] = height_figures(
                    height_above_ground(world, p[cruise], surface=True), requested,
                    points=p[cruise], s=s[cruise])
        for name in ("climb-out", "descent"):
            m = ph == name
            out[f"{name.replace('-', '_')}_m"] = round(float(seg[m[1:]].sum()), 3)
    clr = surface_clearance(world, p)
    k = int(np.argmin(clr))
    out["clearance_m"] = round(float(clr[k]), 3)
    out["clearance_point_m"] = [round(float(v), 3) for v in p[k]]
    split = ground_split(world, p, agl, clr, requested=requested, s=s)
    if split is not None:
        out["ground"] = split
    res = dem_resolution(world, p, getattr(level, "agl", None) if level is not None
                         else requested, cruise=cruise)
    if res is not None:
        out["dem_resolution"] = res
    if getattr(world, "zones", ()):
        out["zones"] = {
            "count": len(world.zones),
            "distance_m": {n: round(d, 3) for n, d in zone_distances(world, p).items()},
            "path_entries": [{"zone": v.zone, "point_m": [round(c, 2) for c in v.point],
                              "buffer_only": v.inside_buffer_only}
                             for v in zone_violations(world, p)],
        }
    if waypoints is not None and len(waypoints) >= 2:
        wcruise = None
        if cruise is not None and waypoint_indices is not None:
            wcruise = cruise[np.asarray(waypoint_indices, dtype=int)]
        out["legs"] = leg_figures(world, waypoints, requested=requested,
                                  terrain_frame=terrain_frame, waypoint_agl=waypoint_agl,
                                  cruise=wcruise)
    if level is not None:
        out["checks"] = _checks(agl, cruise, level, out)
    warning = ceiling_warning(world, p, agl, level)
    out["warnings"] = [warning] if warning else []
    return out


def ceiling_warning(world: Any, path: Any, agl: Any, level: Any = None) -> str | None:
    """A warning when ``path`` flies higher than :data:`ADVISORY_MAX_AGL` above the ground
    and its ``level`` sets no ``max_agl`` (None otherwise): how high, where, over how much
    of the path, and the flag that makes it a limit."""
    if level is not None and getattr(level, "max_agl", None) is not None:
        return None
    h = np.asarray(agl, dtype=float)
    p = np.asarray(path, dtype=float)
    k = int(np.argmax(h))
    if not h[k] > ADVISORY_MAX_AGL + 1e-6:
        return None
    seg = np.linalg.norm(np.diff(p[:, :2], axis=0), axis=1)
    high = (h[1:] > ADVISORY_MAX_AGL) | (h[:-1] > ADVISORY_MAX_AGL)
    where = f"x {p[k, 0]:.0f}, y {p[k, 1]:.0f} m"
    if getattr(world, "crs", None):
        from ..world.geo import to_lonlat

        lon, lat, _ = to_lonlat(world, p[k])
        where = f"lon {lon:.5f}, lat {lat:.5f}"
    if level is None:
        fix = ("plan with a height above the ground and a ceiling: --agl H --max-agl 120 "
               "(planner.agl, planner.max_agl)")
    elif float(level.agl) > ADVISORY_MAX_AGL:
        fix = (f"lower --agl (planner.agl, now {float(level.agl):g} m) to 120 m or less and set "
               "--max-agl 120 (planner.max_agl); where a higher flight is allowed, give that "
               "ceiling as --max-agl")
    else:
        fix = "set the ceiling the profile keeps: --max-agl 120 (planner.max_agl)"
    return (f"the path flies up to {h[k]:.1f} m above the ground ({where}; {seg[high].sum():.0f} "
            f"m of it above {ADVISORY_MAX_AGL:g} m), higher than {ADVISORY_MAX_AGL:g} m — the "
            "limit of the EU open category and about that of US Part 107 (400 ft); if that is "
            f"not allowed where you fly, {fix}")


def _checks(agl: np.ndarray, cruise: np.ndarray | None, level: Any,
            figs: dict[str, Any]) -> dict[str, Any]:
    inner = agl[1:-1] if len(agl) > 2 else agl
    checks: dict[str, Any] = {}
    if getattr(level, "min_agl", None) is not None:
        lo = float(inner.min()) if len(inner) else float("inf")
        checks["min_agl"] = {"limit_m": level.min_agl, "lowest_m": round(lo, 3),
                             "ok": bool(lo >= level.min_agl - 1e-6)}
    if getattr(level, "max_agl", None) is not None:
        hi = float(agl.max())
        checks["max_agl"] = {"limit_m": level.max_agl, "highest_m": round(hi, 3),
                             "ok": bool(hi <= level.max_agl + 1e-6)}
    if cruise is not None and cruise.any():
        floor = level.agl - level.tolerance
        lo = float(agl[cruise].min())
        checks["cruise_floor"] = {"limit_m": round(floor, 3), "lowest_m": round(lo, 3),
                                  "ok": bool(lo >= floor - 1e-6)}
    legs = figs.get("legs")
    if legs is not None and "cruise" in legs:
        floor = level.agl - level.tolerance
        if level.min_agl is not None:
            floor = max(floor, level.min_agl)
        low = legs["cruise"]["min_m"]
        checks["cruise_legs_floor"] = {"limit_m": round(float(floor), 3), "lowest_m": low,
                                       "ok": bool(low >= floor - 1e-6)}
    if legs is not None and getattr(level, "min_agl", None) is not None:
        low = legs["min_off_takeoff_landing_m"]
        checks["legs_min_agl"] = {"limit_m": level.min_agl, "lowest_m": low,
                                  "ok": bool(low >= level.min_agl - 1e-6)}
    zones = figs.get("zones")
    if zones is not None:
        checks["zones"] = {"ok": not zones["path_entries"] and not (legs or {}).get(
            "zone_entries")}
    return checks
