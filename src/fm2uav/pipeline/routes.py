"""Many routes from one wave to their output set (``fm2uav routes``).

:func:`run_routes` plans the route from every start to one goal with
:func:`fm2uav.planning.many.plan_many` and writes:

* ``routes.geojson``: a FeatureCollection of one LineString per route, ``[lon, lat]``
  (``[lon, lat, alt]`` on a 3D map, alt in metres above the map's vertical datum),
  thinned by Douglas–Peucker to ``thin`` metres, with the properties ``id``,
  ``length_m``, ``planned_length_m``, ``time_s``, ``lowest_agl_m``,
  ``lowest_agl_filled_m``, ``planned_lowest_agl_m``, ``filled_ground_m``,
  ``clearance_m``, ``points`` (the written line's);
* ``routes.csv``: one row per start, in the file's order — ``id``, ``status`` (``ok`` or
  ``failed``), ``reason`` (:data:`fm2uav.planning.many.FAILURE_REASONS`), ``lon``,
  ``lat``, ``length_m``, ``planned_length_m``, ``time_s``, ``lowest_agl_m``,
  ``lowest_agl_filled_m``, ``planned_lowest_agl_m``, ``filled_ground_m``,
  ``clearance_m``, ``message``;
* ``summary.json``: the goal, the counts (per failure reason), the failed starts with
  their reason and message, lengths (min/median/max of ``length_m`` and of
  ``planned_length_m``), the routes over filled ground (``over_filled_ground``: how
  many, the first ids, the most metres, the lowest height above that invented ground; None
  on a 2D map), the settings and the timings.

The figures of a route are those of the line as written (what a vehicle given the file
flies, and what an independent check of the file measures): ``length_m`` the written
line's length — its rounded positions, segment by segment the WGS84 geodesic combined
with the altitude change (:func:`fm2uav.world.line_length.lonlat_line_lengths`);
``time_s`` = ``length_m / speed`` (a constant ground speed, no wind); ``lowest_agl_m``
the lowest height above the continuous *measured* ground along its straight legs (3D
maps; empty on a 2D map or where the whole line is over filled ground);
``filled_ground_m`` the metres of it over filled (unknown) ground — nodata the DEM did
not measure, classified as ``fm2uav plan`` classifies its path (0 where every metre is
measured; empty on a 2D map) — and ``lowest_agl_filled_m`` the lowest height above that
invented ground (empty where the line has none): a height above invented ground is not a
measured one, so it is never part of ``lowest_agl_m``. The planner's own figures, before thinning and in the map's metres, beside
them: ``planned_length_m`` (``Plan.length``, what ``fm2uav plan`` reports; the thinning
shortens a line by ~0.3 % at 1 m, and a projected map's metres differ from the
ellipsoid's by its scale factor), ``planned_lowest_agl_m`` (``fm2uav plan``'s
``height_above_ground.path.min_m``); ``clearance_m`` the plan's clearance to the
terrain/building surface. A start outside the map is refused with its lon/lat and the
map's lon/lat extent, then its position in map metres.
"""

from __future__ import annotations

import csv
import io
import json
from dataclasses import dataclass
from typing import Any

import numpy as np

from .. import progress
from .outputs import to_jsonable, write_json

__all__ = ["ROUTES_FILES", "RoutesRun", "RouteSettings", "run_routes", "routes_rows"]

#: The files of a ``fm2uav routes`` output set.
ROUTES_FILES = ("routes.geojson", "routes.csv", "summary.json")

_CSV_COLUMNS = ("id", "status", "reason", "lon", "lat", "length_m", "planned_length_m", "time_s",
                "lowest_agl_m", "lowest_agl_filled_m", "planned_lowest_agl_m", "filled_ground_m",
                "clearance_m", "message")


@dataclass(frozen=True)
class RouteSettings:
    """How :func:`run_routes` plans and writes.

    Attributes
    ----------
    speed : float
        Ground speed [m/s] for ``time_s`` (> 0).
    thin : float
        Douglas–Peucker tolerance [m] of the GeoJSON lines (0: every point).
    threads : int or None
        Threads of the descents (None: every core).
    anchor : optional
        lon/lat of x = y = 0 on a world without a CRS (default the exports' anchor).
    """

    speed: float = 10.0
    thin: float = 1.0
    threads: int | None = None
    anchor: Any = None


@dataclass(frozen=True)
class RoutesRun:
    """What :func:`run_routes` planned and wrote."""

    many: Any
    rows: list[dict[str, Any]]
    summary: dict[str, Any]
    #: The starts [m], one row per start in the file's order (NaN where a row had none).
    starts: Any = None


def _lowest_line_agl(world: Any, lines: list[np.ndarray]) -> list[tuple[Any, Any]]:
    """The lowest height above the ground [m] along each written line's straight legs, over
    measured and over filled (unknown) ground apart.

    Each line (its points [m], as thinned) sampled as :func:`fm2uav.analysis.safety.
    leg_figures` samples waypoint legs (every quarter of ``sampling_step``, horizontally),
    against the continuous ground (:meth:`World.ground_height`), rounded to the mm; a sample
    is over filled ground as :func:`fm2uav.analysis.known_ground.filled_mask` says. Returns
    ``(measured, filled)`` per line, None where the line has no sample over that ground (a
    height above invented ground is never reported as a measured one).
    """
    from ..analysis.known_ground import filled_mask
    from ..analysis.safety import height_above_ground
    from ..geometry import densify
    from ..world.ground import has_unknown_ground
    from ..world.ground_model import sampling_step

    step = 0.25 * sampling_step(world)
    dense = [densify(p, step, horizontal=True)[0] for p in lines]
    counts = np.array([len(d) for d in dense])
    pts = np.concatenate(dense)
    h = height_above_ground(world, pts)
    filled = filled_mask(world, pts) if has_unknown_ground(world) else np.zeros(len(h), bool)
    out = []
    for seg_h, seg_f in zip(np.split(h, np.cumsum(counts)[:-1]),
                            np.split(filled, np.cumsum(counts)[:-1])):
        out.append(tuple(round(float(seg_h[sel].min()), 3) if sel.any() else None
                         for sel in (~seg_f, seg_f)))
    return out


def _filled_ground(world: Any, lines: list[np.ndarray]) -> list[float]:
    """Metres [m] of each written line (its points [m], as thinned) over filled (unknown)
    ground, classified as ``fm2uav plan`` classifies its path
    (:func:`fm2uav.analysis.known_ground.ground_split`); 0 on a map without unknown ground."""
    from ..analysis.known_ground import ground_split
    from ..world.ground import has_unknown_ground

    if not has_unknown_ground(world):
        return [0.0] * len(lines)
    out = []
    for p in lines:
        split = ground_split(world, p, np.zeros(len(p))) if len(p) >= 2 else None
        out.append(0.0 if split is None else float(split["filled"]["length_m"]))
    return out


def _lowest_agl(plan: Any) -> float | None:
    """The lowest height above the ground [m] along a plan, as ``fm2uav plan`` reports it."""
    from ..planning.altitude import height_figures

    h = plan.height_above_ground()
    return None if h is None else height_figures(h)["min_m"]


@progress.stage()
def run_routes(outdir: Any, world: Any, goal_m: Any, starts: Any, *, shaping: Any, level: Any,
               options: Any, settings: RouteSettings = RouteSettings(),
               summary: dict[str, Any] | None = None) -> RoutesRun:
    """Plan the route from every start to ``goal_m`` and write the output set.

    Parameters
    ----------
    outdir : fm2uav.io.outdir.OutputDir
    world : World
    goal_m : array_like
        The goal [m].
    starts : fm2uav.io.starts.Starts
        The starts (ids, points in metres, rows without a point).
    shaping, level, options
        As :func:`fm2uav.plan`.
    settings : RouteSettings
    summary : dict, optional
        Entries put first in ``summary.json`` (e.g. the world).

    Returns
    -------
    RoutesRun
    """
    from ..autopilot.thin import thin_indices
    from ..planning.many import RouteFailure, plan_many
    from ..world.geo import to_lonlat
    from ..world.line_length import lonlat_line_lengths

    progress.step("routes (one wave, every start)", 0.8)
    pts = np.asarray(starts.points, dtype=float)
    many = plan_many(world, goal_m, list(pts), shaping=shaping, level=level, options=options,
                     threads=settings.threads)
    progress.step("writing routes.geojson, routes.csv, summary.json", 0.2)
    routes = list(many.routes)
    for k, why in starts.problems.items():  # the row's own words, not "start must be finite"
        routes[k] = RouteFailure("invalid", why)
    start_ll = np.full((len(pts), 2), np.nan)
    known = np.isfinite(pts).all(axis=1)
    if known.any():
        start_ll[known] = to_lonlat(world, pts[known], anchor=settings.anchor)[:, :2]
    ok = [k for k, r in enumerate(routes) if not isinstance(r, RouteFailure)]
    lines: dict[int, np.ndarray] = {}  # each line as written: rounded lon, lat[, alt]
    lowest: dict[int, tuple[Any, Any]] = {k: (None, None) for k in ok}
    filled: dict[int, float | None] = {k: None for k in ok}
    if ok:
        keep = [routes[k].path[thin_indices(routes[k].path, settings.thin)] for k in ok]
        ends = np.cumsum([len(q) for q in keep])[:-1]
        geo = np.split(to_lonlat(world, np.concatenate(keep), anchor=settings.anchor), ends)
        lines = {k: _written(g, world.ndim) for k, g in zip(ok, geo)}
        if world.ndim == 3:
            lowest = dict(zip(ok, _lowest_line_agl(world, keep)))
            filled = dict(zip(ok, _filled_ground(world, keep)))
    written = dict(zip(ok, lonlat_line_lengths([lines[k] for k in ok])))
    extent = _extent_text(world, settings.anchor) if any(
        isinstance(r, RouteFailure) and r.reason == "outside" for r in routes) else ""
    rows: list[dict[str, Any]] = []
    features: list[dict[str, Any]] = []
    for k, r in enumerate(routes):
        row: dict[str, Any] = {"id": starts.ids[k], "lon": _deg(start_ll[k, 0]),
                               "lat": _deg(start_ll[k, 1])}
        if isinstance(r, RouteFailure):
            message = r.message
            if r.reason == "outside" and row["lon"] is not None:  # in the user's terms first
                message = (f"the start at lon {row['lon']}, lat {row['lat']} lies outside the "
                           f"map ({extent}); {message}")
            row.update(status="failed", reason=r.reason, length_m=None, planned_length_m=None,
                       time_s=None, lowest_agl_m=None, lowest_agl_filled_m=None,
                       planned_lowest_agl_m=None, filled_ground_m=None, clearance_m=None,
                       message=message)
        else:
            length = float(written[k])
            row.update(status="ok", reason="", length_m=round(length, 3),
                       planned_length_m=round(float(r.length), 3),
                       time_s=round(length / settings.speed, 3),
                       lowest_agl_m=lowest[k][0], lowest_agl_filled_m=lowest[k][1],
                       planned_lowest_agl_m=_lowest_agl(r),
                       filled_ground_m=filled[k],
                       clearance_m=(round(float(r.clearance), 3)
                                    if np.isfinite(r.clearance) else None), message="")
            props = {key: row[key] for key in ("id", "length_m", "planned_length_m", "time_s",
                                               "lowest_agl_m", "lowest_agl_filled_m",
                                               "planned_lowest_agl_m", "filled_ground_m",
                                               "clearance_m")}
            features.append({"type": "Feature", "properties": {**props,
                                                               "points": int(len(lines[k]))},
                             "geometry": {"type": "LineString",
                                          "coordinates": lines[k].tolist()}})
        rows.append(row)
    with outdir.open("routes.geojson") as fh:  # dumps: json's C encoder (dump's is Python's)
        fh.write(json.dumps({"type": "FeatureCollection", "features": features},
                            separators=(",", ":"), allow_nan=False))
    with outdir.open("routes.csv") as fh:
        fh.write(_csv_text(rows))
    many_summary = many.summary()
    doc = {**(summary or {}), **many_summary,
           "length_m": _stats([row["length_m"] for row in rows if row["status"] == "ok"]),
           "planned_length_m": many_summary["length_m"],
           "goal_lonlat": _goal_lonlat(world, many.goal, settings.anchor),
           "speed_m_s": settings.speed, "thin_m": settings.thin,
           "params": many.routes[ok[0]].params if ok else None,
           "failures": [{"id": row["id"], "reason": row["reason"], "message": row["message"]}
                        for row in rows if row["status"] == "failed"]}
    over = [row for row in rows if row.get("filled_ground_m")]
    low = [row["lowest_agl_filled_m"] for row in over if row["lowest_agl_filled_m"] is not None]
    doc["over_filled_ground"] = {  # unknown ground is said, never counted as known
        "routes": len(over), "ids": [row["id"] for row in over[:20]],
        "max_m": max((row["filled_ground_m"] for row in over), default=0.0),
        "lowest_agl_m": min(low, default=None)} if world.ndim == 3 else None
    failed = [row["reason"] for row in rows if row["status"] == "failed"]
    doc["failed"] = len(failed)
    doc["routes"] = len(rows) - len(failed)
    doc["failed_by_reason"] = {r: failed.count(r) for r in sorted(set(failed))}
    write_json(outdir, "summary.json", to_jsonable(doc))
    return RoutesRun(many=many, rows=rows, summary=doc, starts=pts)


def _deg(v: float) -> float | None:
    return round(float(v), 7) if np.isfinite(v) else None


def _written(geo: np.ndarray, ndim: int) -> np.ndarray:
    """A line's GeoJSON positions: lon/lat to 1e-7 degrees (~1 cm), altitude to the mm."""
    if ndim == 2:
        return np.round(geo[:, :2], 7)
    return np.column_stack([np.round(geo[:, :2], 7), np.round(geo[:, 2], 3)])


def _stats(values: list[float]) -> dict[str, float] | None:
    """min / median / max [m] of the routes' lengths, None without a route."""
    if not values:
        return None
    return {"min": min(values), "median": round(float(np.median(values)), 3),
            "max": max(values)}


def _extent_text(world: Any, anchor: Any) -> str:
    """The map's lon/lat extent for a message: ``lon a..b, lat c..d`` (its corners)."""
    from ..world.geo import to_lonlat

    (x0, x1), (y0, y1) = np.asarray(world.bounds, dtype=float)[:2]  # (ndim, 2): min, max
    corners = np.array([[x0, y0], [x1, y0], [x1, y1], [x0, y1]])
    if world.ndim == 3:
        corners = np.column_stack([corners, np.zeros(4)])
    ll = to_lonlat(world, corners, anchor=anchor)
    return (f"lon {ll[:, 0].min():.5f}..{ll[:, 0].max():.5f}, "
            f"lat {ll[:, 1].min():.5f}..{ll[:, 1].max():.5f}")


def _goal_lonlat(world: Any, goal: np.ndarray, anchor: Any) -> list[float]:
    from ..world.geo import to_lonlat

    ll = to_lonlat(world, np.asarray(goal, dtype=float)[None], anchor=anchor)[0]
    return [round(float(v), 7) for v in ll[:2]]


def _csv_text(rows: list[dict[str, Any]]) -> str:
    buf = io.StringIO()
    w = csv.DictWriter(buf, fieldnames=list(_CSV_COLUMNS), lineterminator="\n")
    w.writeheader()
    for row in rows:
        w.writerow({k: ("" if row.get(k) is None else row.get(k)) for k in _CSV_COLUMNS})
    return buf.getvalue()


def routes_rows(run: RoutesRun) -> dict[str, str]:
    """The printed summary of ``fm2uav routes``."""
    s = run.summary
    out = {"starts": str(s["starts"]), "routes": str(s["routes"])}
    if s["failed"]:
        out["failed"] = ", ".join(f"{n} {r}" for r, n in s["failed_by_reason"].items())
    over = s.get("over_filled_ground") or {}
    if over.get("routes"):
        low = over.get("lowest_agl_m")
        out["over FILLED ground"] = (
            f"{over['routes']} route(s) fly over filled (unknown) ground, up to "
            f"{over['max_m']:.0f} m: filled_ground_m"
            + ("" if low is None else f"; lowest {low:.1f} m above that invented ground, "
               "not a measured height: lowest_agl_filled_m"))
    if s["length_m"]:
        L = s["length_m"]
        out["length [m]"] = f"{L['min']:.0f} / {L['median']:.0f} / {L['max']:.0f} (min/median/max)"
    t = s["timings_s"]
    out["time [s]"] = (f"{t['total']:.2f} wall, {t['cpu']:.2f} CPU ({s['threads']} threads; "
                       f"march {t['fast_marching']:.2f}, routes {t['routes']:.2f})")
    return out
