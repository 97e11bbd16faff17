"""A planned mission as one GeoJSON bundle for a map (lon/lat, RFC 7946).

:func:`mission_map` turns a plan, its autopilot mission and its safety figures
into the document the map page draws (``viz/web/mission-map.js``): the web app
shows it after a planning job, and a self-contained report can inline the same
document with the same script. Everything is in WGS84 lon/lat degrees and
metres; numbers are rounded to what a map can show (1e-7 deg ≈ 1 cm, 0.1 m).

Features (``properties.kind``):

* ``route``: the flown path as a 3D LineString ``[lon, lat, alt AMSL]`` with
  per-point ``agl`` (height above the continuous ground), ``ground`` (AMSL) and
  ``distance`` (along the path) arrays — the profile chart reads them;
* ``item``: every mission item with a position (takeoff, waypoints, landing),
  numbered ``seq`` as QGroundControl numbers them (home is 0), with ``command``,
  ``frame``, ``alt`` (in the item's frame), ``alt_amsl`` and ``agl``;
* ``start``, ``goal``, ``via``: the points asked for;
* ``zone``: no-fly zones and the operating area (``inclusion``), with floor,
  ceiling, reference and buffer; circles keep ``center`` and ``radius``;
* ``fence``: the geofence written to the ``.plan`` (polygons and circles);
* coverage missions (:func:`coverage_features`): ``area`` (the surveyed polygon),
  ``band`` (the zigzag's bands as planned) and ``photo`` (the ground footprint of
  each photo the camera takes, numbered).

``summary`` holds the operator's figures (length, flight time, waypoints, lowest
height above ground, nearest zone) and ``rows`` the same summary rows the
command line prints.
"""

from __future__ import annotations

from typing import Any

import numpy as np

__all__ = ["mission_map", "zone_features", "coverage_features", "AGL_COLOURS"]

#: Colour scale of the route by height above ground, as a share of the requested
#: height (shared with the page's legend): below the floor red, at the level green.
AGL_COLOURS = (("#d7191c", 0.0), ("#fdae61", 0.5), ("#1a9641", 1.0), ("#2b83ba", 1.6))


def _r(v: Any, nd: int = 1) -> float | None:
    v = float(v)
    return round(v, nd) if np.isfinite(v) else None


def _lonlat(world: Any, pts: np.ndarray, anchor: Any) -> np.ndarray:
    from ..world.geo import to_lonlat

    return np.asarray(to_lonlat(world, pts, anchor=anchor), dtype=float)


def _ring(world: Any, xy: np.ndarray, anchor: Any) -> list[list[float]]:
    pts = np.column_stack([xy, np.zeros(len(xy))])
    ll = _lonlat(world, pts, anchor)
    return [[round(float(a), 7), round(float(b), 7)] for a, b in ll[:, :2]]


def _polygons(world: Any, geom: Any, anchor: Any) -> dict[str, Any]:
    polys = [geom] if geom.geom_type == "Polygon" else list(geom.geoms)
    coords = [[_ring(world, np.asarray(p.exterior.coords), anchor)]
              + [_ring(world, np.asarray(r.coords), anchor) for r in p.interiors]
              for p in polys]
    if len(coords) == 1:
        return {"type": "Polygon", "coordinates": coords[0]}
    return {"type": "MultiPolygon", "coordinates": coords}


def zone_features(world: Any, zones: Any, anchor: Any = None) -> list[dict[str, Any]]:
    """GeoJSON features of no-fly zones / operating areas (:class:`fm2uav.world.zones.Zone`)."""
    out = []
    for z in zones or ():
        props: dict[str, Any] = {"kind": "zone", "name": z.name, "floor": z.floor,
                                 "ceiling": z.ceiling, "reference": z.reference,
                                 "buffer": z.buffer, "inclusion": bool(z.inclusion),
                                 "source": z.source}
        if z.circle is not None:
            (cx, cy), radius = z.circle
            c = _lonlat(world, np.array([[cx, cy, 0.0]]), anchor)[0]
            props.update(center=[round(float(c[0]), 7), round(float(c[1]), 7)],
                         radius=float(radius))
        out.append({"type": "Feature", "properties": props,
                    "geometry": _polygons(world, z.geometry, anchor)})
    return out


def _item_features(mission: Any) -> list[dict[str, Any]]:
    feats = []
    for k, it in enumerate(mission.items):
        lat, lon = it.params[4], it.params[5]
        if it.agl is None or not (np.isfinite(lat) and np.isfinite(lon)) or (lat == 0 and lon == 0):
            continue
        feats.append({"type": "Feature", "geometry": {
            "type": "Point", "coordinates": [round(float(lon), 7), round(float(lat), 7)]},
            "properties": {"kind": "item", "seq": k + 1, "command": it.name,
                           "label": it.label, "frame": int(it.frame),
                           "alt": _r(it.params[6]), "alt_amsl": _r(it.alt_amsl),
                           "agl": _r(it.agl)}})
    return feats


def _fence_features(mission: Any) -> list[dict[str, Any]]:
    from ..io.qgc import geofence_document

    doc = geofence_document(getattr(mission, "fences", ()) or ())
    feats = []
    for p in doc.get("polygons", ()):
        ring = [[round(float(lo), 7), round(float(la), 7)] for la, lo in p["polygon"]]
        ring.append(ring[0])
        feats.append({"type": "Feature", "properties": {"kind": "fence",
                                                        "inclusion": bool(p["inclusion"])},
                      "geometry": {"type": "Polygon", "coordinates": [ring]}})
    for c in doc.get("circles", ()):
        la, lo = c["circle"]["center"]
        feats.append({"type": "Feature", "properties": {
            "kind": "fence", "inclusion": bool(c["inclusion"]),
            "radius": float(c["circle"]["radius"])},
            "geometry": {"type": "Point", "coordinates": [round(float(lo), 7),
                                                          round(float(la), 7)]}})
    return feats


def mission_map(plan: Any, mission: Any, safety: dict[str, Any] | None = None, *,
                points: dict[str, Any] | None = None, anchor: Any = None,
                rows: dict[str, str] | None = None, junctions: Any = None) -> dict[str, Any]:
    """The map document of a plan and its autopilot mission (see the module docstring).

    Parameters
    ----------
    plan : fm2uav.Plan
        A 3D plan (the route joined over its legs).
    mission : fm2uav.io.MissionExport
        The built autopilot mission of that plan.
    safety : dict, optional
        :func:`fm2uav.analysis.safety.safety_summary` of the flight.
    points : dict, optional
        Named points asked for, ``{"start": xyz, "goal": xyz, "via 1": xyz}`` [m].
    anchor : fm2uav.world.geo.Anchor, optional
        Placement of a world without CRS.
    rows : dict, optional
        The summary rows the command line prints (shown as they are).
    junctions : sequence of int, optional
        Path indices where the route's legs meet (``Route.junctions``).

    Returns
    -------
    dict
        ``{"type": "FeatureCollection", "features": [...], "bbox": [W, S, E, N],
        "summary": {...}, "rows": {...}}``.
    """
    from ..geometry import arc_length

    world = plan.world
    path = np.asarray(plan.path, dtype=float)
    ll = _lonlat(world, path, anchor)
    ground = np.asarray(world.ground_height(path[:, 0], path[:, 1]), dtype=float)
    agl = path[:, 2] - ground
    amsl_offset = ll[:, 2] - path[:, 2]     # world z -> altitude AMSL (0 on a DEM world)
    dist = arc_length(path[:, :2])        # along the ground, as a profile is drawn
    level = getattr(plan, "level", None)
    requested = None if level is None else float(level.agl)
    feats: list[dict[str, Any]] = [{
        "type": "Feature",
        "geometry": {"type": "LineString", "coordinates": [
            [round(float(a), 7), round(float(b), 7), round(float(c), 1)] for a, b, c in ll]},
        "properties": {"kind": "route", "requested_agl": requested,
                       "agl": [round(float(v), 1) for v in agl],
                       "ground": [round(float(v), 1) for v in ground + amsl_offset],
                       "distance": [round(float(v), 1) for v in dist],
                       "junctions": [int(v) for v in np.atleast_1d(
                           [0, len(path) - 1] if junctions is None else junctions)]}}]
    for name, p in (points or {}).items():
        q = _lonlat(world, np.asarray(p, dtype=float)[None], anchor)[0]
        kind = name.split()[0] if name.split()[0] in ("start", "goal") else "via"
        feats.append({"type": "Feature", "geometry": {"type": "Point", "coordinates": [
            round(float(q[0]), 7), round(float(q[1]), 7), round(float(q[2]), 1)]},
            "properties": {"kind": kind, "name": name}})
    feats += _item_features(mission)
    feats += zone_features(world, getattr(world, "zones", ()), anchor)
    feats += _fence_features(mission)
    s = mission.summary()
    hag = (safety or {}).get("height_above_ground", {}).get("path", {})
    zones = (safety or {}).get("zones") or {}
    near = min(zones.get("distance_m", {}).values(), default=None)
    summary = {
        "length_m": _r(plan.length),
        "flight_time_s": _r(s["flight"]["flight_time_s"]),
        "flight_distance_m": _r(s["flight"]["flight_distance_m"]),
        "items": s["items"], "waypoints": s["waypoints"],
        "firmware": s["firmware"], "vehicle": s["vehicle"], "frame": s["frame"]["name"],
        "mav_frame": s["frame"]["mav_frame"], "end": s["end"],
        "home": s["home"], "requested_agl_m": requested,
        "min_agl_m": _r(hag["min_m"]) if "min_m" in hag else _r(np.min(agl)),
        "max_agl_m": _r(hag["max_m"]) if "max_m" in hag else _r(np.max(agl)),
        "nearest_zone_m": None if near is None else _r(near),
        "zone_entries": len(zones.get("path_entries", ())) if zones else 0,
        "warnings": list(s["warnings"]),
        "crs": s["crs"], "vertical_reference": s["vertical_reference"],
    }
    lon, lat = ll[:, 0], ll[:, 1]
    return {"type": "FeatureCollection", "features": feats,
            "bbox": [round(float(lon.min()), 7), round(float(lat.min()), 7),
                     round(float(lon.max()), 7), round(float(lat.max()), 7)],
            "summary": summary, "rows": dict(rows or {})}


def coverage_features(coverage: Any, shots: Any, camera: Any = None, anchor: Any = None
                      ) -> list[dict[str, Any]]:
    """GeoJSON features of a coverage mission: the area, the bands and the photo footprints.

    Parameters
    ----------
    coverage : fm2uav.missions.coverage.CoveragePlan
    shots : fm2uav.missions.coverage.triggers.CameraPlan
    camera : fm2uav.missions.coverage.Camera, optional
        Gives the footprint size; without it each photo is a square of the trigger
        distance (the band spacing by default).
    """
    from ..missions.coverage.triggers import photo_positions

    world = coverage.plan.world
    area = coverage.zigzag.area
    feats: list[dict[str, Any]] = [{
        "type": "Feature", "properties": {"kind": "area", "area_m2": round(float(area.area), 1)},
        "geometry": _polygons(world, area, anchor)}]
    for k, band in enumerate(coverage.zigzag.bands()):
        xy = np.asarray(band.coords, dtype=float)
        feats.append({"type": "Feature", "properties": {"kind": "band", "band": k + 1},
                      "geometry": {"type": "LineString", "coordinates": _ring(world, xy, anchor)}})
    pts, hdg = photo_positions(coverage.path, shots)
    agl = float(coverage.level.agl)
    across, along = (camera.footprint(agl) if camera is not None
                     else (float(shots.trigger_distance), float(shots.trigger_distance)))
    for k, (p, h) in enumerate(zip(pts, hdg)):
        t = np.array([np.cos(h), np.sin(h)])          # along the track
        n = np.array([-t[1], t[0]])                   # across it
        c = p[:2]
        ring = np.array([c + a * along / 2 * t + b * across / 2 * n
                         for a, b in ((-1, -1), (1, -1), (1, 1), (-1, 1), (-1, -1))])
        feats.append({"type": "Feature", "properties": {"kind": "photo", "photo": k + 1},
                      "geometry": {"type": "Polygon", "coordinates": [_ring(world, ring, anchor)]}})
    return feats
