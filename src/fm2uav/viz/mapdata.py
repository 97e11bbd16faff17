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
* the safe returns, when the mission has them (:func:`return_features`, the same
  features as ``returns.geojson``): ``return`` (the FM² way back from each waypoint,
  with ``to``, ``time_s``, ``length_m``), ``pnr`` (the point of no return) and
  ``pnr-return`` (its way back), ``rally`` (the rally points, on the ground);
* coverage missions (:func:`coverage_features`): ``area`` (the surveyed polygon),
  ``band`` (the zigzag's bands as planned) and ``photo`` (the ground footprint of
  each photo the camera takes, numbered).

``summary`` holds the operator's figures (length, flight time, waypoints, lowest
height above ground, nearest zone) and ``rows`` the same summary rows the
command line prints.

``summary.amsl`` (and the route's ``amsl``) is False when the world's altitude
above sea level is unknown (buildings without a DEM or ``world.ground_elevation``):
the "AMSL" altitudes and ``ground`` are then heights above the flat ground, as the
mission (relative to home) is, and the page labels them so.
"""

from __future__ import annotations

from typing import Any

import numpy as np

__all__ = ["mission_map", "zone_features", "coverage_features", "return_features",
           "route_feature", "point_features", "waypoint_features", "building_features", "extra_feature", "terrain_layer",
           "AGL_COLOURS"]

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


#: The features of ``returns.geojson`` the map draws.
RETURN_KINDS = ("return", "pnr", "pnr-return", "rally")


def return_features(mission: Any) -> list[dict[str, Any]]:
    """The safe returns of a built mission as map features (module docstring).

    The features of :func:`fm2uav.io.returns.returns_document` (home is left out: it is
    the mission's home) with coordinates rounded as the map shows them; none when the
    mission has no returns (``--no-returns``).
    """
    if getattr(mission, "returns", None) is None:
        return []
    from ..io.returns import returns_document

    def rnd(c: Any) -> Any:
        if c and isinstance(c[0], list):
            return [rnd(v) for v in c]
        return [round(float(c[0]), 7), round(float(c[1]), 7), round(float(c[2]), 1)]

    out = []
    for f in returns_document(mission)["features"]:
        if f["properties"].get("kind") in RETURN_KINDS:
            out.append({**f, "geometry": {"type": f["geometry"]["type"],
                                          "coordinates": rnd(f["geometry"]["coordinates"])}})
    return out


def route_feature(world: Any, path: Any, anchor: Any = None, *, name: str = "route",
                  requested: float | None = None, junctions: Any = None,
                  color: str | None = None, dash: str | None = None) -> dict[str, Any]:
    """The ``route`` feature of a path: a LineString ``[lon, lat, alt AMSL]`` with its
    height above the continuous ground, the ground (AMSL) and the distance along it.

    Parameters
    ----------
    world : World
        Gives the ground (3D paths) and the placement.
    path : array_like (N, 2|3)
        [m]; a 2D path has no heights (``agl`` and ``ground`` are null).
    anchor : Anchor, optional
        Placement of a world without CRS.
    name : str
        Shown on the map.
    requested : float, optional
        Requested height above ground [m]: the colour scale's green.
    junctions : sequence of int, optional
        Where the route's legs meet (default: its two ends).
    color, dash : str, optional
        A fixed line colour (and dash pattern, e.g. ``"6 4"``) instead of colouring
        by height above ground (several paths on one map).
    """
    from ..geometry import arc_length

    p = np.asarray(path, dtype=float)
    ll = _lonlat(world, p, anchor)
    dist = arc_length(p[:, :2])          # along the ground, as a profile is drawn
    props: dict[str, Any] = {"kind": "route", "name": name, "requested_agl": requested}
    if p.shape[1] == 3 and world is not None and world.ndim == 3:
        ground = np.asarray(world.ground_height(p[:, 0], p[:, 1]), dtype=float)
        agl = p[:, 2] - ground
        amsl_offset = ll[:, 2] - p[:, 2]    # world z -> altitude AMSL (0 on a DEM world)
        props["agl"] = [round(float(v), 1) for v in agl]
        props["ground"] = [round(float(v), 1) for v in ground + amsl_offset]
        top = float(np.max(agl)) if len(agl) else 0.0
        # the colour scale: green at the requested height (else at 1/1.6 of the highest)
        props["agl_scale"] = requested if requested else round(max(top, 1.0) / 1.6, 1)
        coords = [[round(float(a), 7), round(float(b), 7), round(float(c), 1)] for a, b, c in ll]
    else:
        props["agl"] = None
        props["ground"] = None
        coords = [[round(float(a), 7), round(float(b), 7)] for a, b in ll[:, :2]]
    props["distance"] = [round(float(v), 1) for v in dist]
    props["junctions"] = [int(v) for v in np.atleast_1d(
        [0, len(p) - 1] if junctions is None else junctions)]
    if color is not None:
        props["color"] = color
    if dash is not None:
        props["dash"] = dash
    return {"type": "Feature", "properties": props,
            "geometry": {"type": "LineString", "coordinates": coords}}


def point_features(world: Any, points: dict[str, Any], anchor: Any = None
                   ) -> list[dict[str, Any]]:
    """``start``, ``goal`` and ``via`` features of named points ``{"start": xyz, ...}`` [m]."""
    feats = []
    for name, p in (points or {}).items():
        q = _lonlat(world, np.asarray(p, dtype=float)[None], anchor)[0]
        kind = name.split()[0] if name.split()[0] in ("start", "goal") else "via"
        feats.append({"type": "Feature", "geometry": {"type": "Point", "coordinates": [
            round(float(q[0]), 7), round(float(q[1]), 7), round(float(q[2]), 1)]},
            "properties": {"kind": kind, "name": name}})
    return feats


def waypoint_features(world: Any, waypoints: Any, anchor: Any = None, *,
                      name: str = "waypoint") -> list[dict[str, Any]]:
    """Numbered ``item`` features (1, 2, ...) of waypoints [m] that are not a mission's items
    (e.g. the thinned waypoints of a path), with their height above the ground."""
    w = np.asarray(waypoints, dtype=float)
    if w.ndim != 2 or not len(w):
        return []
    ll = _lonlat(world, w, anchor)
    agl = (w[:, 2] - np.asarray(world.ground_height(w[:, 0], w[:, 1]), dtype=float)
           if w.shape[1] == 3 and world is not None and world.ndim == 3
           else np.full(len(w), np.nan))
    return [{"type": "Feature", "geometry": {"type": "Point", "coordinates": [
        round(float(q[0]), 7), round(float(q[1]), 7)]},
        "properties": {"kind": "item", "seq": k + 1, "command": name, "label": "",
                       "frame": None, "alt": _r(w[k, 2]) if w.shape[1] == 3 else None,
                       "alt_amsl": _r(q[2]) if w.shape[1] == 3 else None, "agl": _r(agl[k])}}
        for k, q in enumerate(ll)]


def building_features(world: Any, anchor: Any = None, *, max_count: int = 20_000
                      ) -> list[dict[str, Any]]:
    """``building`` features: what stands on the world's ground
    (:func:`fm2uav.viz.basemap.obstacle_footprints`), with its height above the ground."""
    from .basemap import footprints_lonlat, obstacle_footprints

    if world is None:
        return []
    fps = obstacle_footprints(world, max_count=max_count)
    feats = []
    for rings, h in footprints_lonlat(world, fps, anchor):
        coords = [[[round(float(a), 7), round(float(b), 7)] for a, b in r] for r in rings]
        feats.append({"type": "Feature", "properties": {"kind": "building", "height": h},
                      "geometry": {"type": "Polygon", "coordinates": coords}})
    return feats


def extra_feature(world: Any, layer: str, points: Any, anchor: Any = None, *,
                  style: dict[str, Any] | None = None, label: str = "",
                  geometry: str = "LineString") -> dict[str, Any]:
    """A feature of an extra map layer: a line (NaN rows split it), a polygon or points
    [m], drawn with a Leaflet ``style`` (``color``, ``weight``, ``dashArray``,
    ``fillColor``, ``fillOpacity``, ``radius`` for points) and listed as ``layer`` in the
    map's layer switcher — the hook for what other missions add (return paths, rally
    points, flown tracks).

    Parameters
    ----------
    geometry : {"LineString", "Polygon", "MultiPoint"}
    """
    p = np.asarray(points, dtype=float)
    ok = np.all(np.isfinite(p), axis=1)
    ll = np.full((len(p), 2), np.nan)
    if ok.any():
        ll[ok] = _lonlat(world, p[ok], anchor)[:, :2]
    parts, cur = [], []
    for k in range(len(p)):
        if ok[k]:
            cur.append([round(float(ll[k, 0]), 7), round(float(ll[k, 1]), 7)])
        elif cur:
            parts.append(cur)
            cur = []
    if cur:
        parts.append(cur)
    if geometry == "Polygon":
        geom = {"type": "Polygon", "coordinates": [r + [r[0]] for r in parts]}
    elif geometry == "MultiPoint":
        geom = {"type": "MultiPoint", "coordinates": [q for r in parts for q in r]}
    else:
        geom = ({"type": "LineString", "coordinates": parts[0]} if len(parts) == 1
                else {"type": "MultiLineString", "coordinates": parts})
    return {"type": "Feature", "properties": {"kind": "extra", "layer": layer,
                                              "style": dict(style or {}), "label": label},
            "geometry": geom}


def terrain_layer(world: Any, anchor: Any = None) -> dict[str, Any]:
    """The map's base layer: the world's ground as a shaded-relief PNG (data URI) placed by
    its lon/lat corners (:func:`fm2uav.viz.basemap.lonlat_image`, rows regular in
    Web-Mercator, as Leaflet places an image overlay)."""
    from .basemap import lonlat_image

    img = lonlat_image(world, anchor, rows="mercator")
    return {"url": img.data_uri(), "bounds": [round(float(v), 8) for v in img.bounds],
            "kind": img.kind, "filled": bool(img.filled), "pixel_m": round(img.pixel_m, 2)}


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
    world = plan.world
    path = np.asarray(plan.path, dtype=float)
    amsl = bool(getattr(mission.waypoints, "amsl", True))
    level = getattr(plan, "level", None)
    requested = None if level is None else float(level.agl)
    route = route_feature(world, path, anchor, requested=requested, junctions=junctions)
    ll = np.asarray(route["geometry"]["coordinates"], dtype=float)
    agl = np.asarray(route["properties"]["agl"], dtype=float)
    feats: list[dict[str, Any]] = [route]
    feats += point_features(world, points or {}, anchor)
    route["properties"]["amsl"] = amsl
    feats += _item_features(mission)
    feats += zone_features(world, getattr(world, "zones", ()), anchor)
    feats += _fence_features(mission)
    feats += return_features(mission)
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
        "home": s["home"], "amsl": amsl, "requested_agl_m": requested,
        "min_agl_m": _r(hag["min_m"]) if "min_m" in hag else _r(np.nanmin(agl)),
        "max_agl_m": _r(hag["max_m"]) if "max_m" in hag else _r(np.nanmax(agl)),
        "nearest_zone_m": None if near is None else _r(near),
        "zone_entries": len(zones.get("path_entries", ())) if zones else 0,
        "warnings": list(s["warnings"]),
        "crs": s["crs"], "vertical_reference": s["vertical_reference"],
        "point_of_no_return": _pnr_summary(mission),
    }
    lon, lat = ll[:, 0], ll[:, 1]
    return {"type": "FeatureCollection", "features": feats,
            "bbox": [round(float(lon.min()), 7), round(float(lat.min()), 7),
                     round(float(lon.max()), 7), round(float(lat.max()), 7)],
            "summary": summary, "rows": dict(rows or {})}


def _pnr_summary(mission: Any) -> dict[str, Any] | None:
    """The point of no return's figures for the page (None without returns)."""
    rep = getattr(mission, "returns", None)
    if rep is None:
        return None
    return {k: v for k, v in rep.pnr.items() if k not in ("point_m", "return")}


def coverage_features(coverage: Any, shots: Any, camera: Any = None, anchor: Any = None,
                      *, merge_above: int | None = None) -> list[dict[str, Any]]:
    """GeoJSON features of a coverage mission: the area, the bands and the photo footprints.

    Parameters
    ----------
    coverage : fm2uav.missions.coverage.CoveragePlan
    shots : fm2uav.missions.coverage.triggers.CameraPlan
    camera : fm2uav.missions.coverage.Camera, optional
        Gives the footprint size; without it each photo is a square of the trigger
        distance (the band spacing by default).
    merge_above : int, optional
        With more photos than this, their footprints are one ``photo`` feature: the
        ground they cover together (a (Multi)Polygon, ``properties.photos`` = the
        count) — thousands of rectangles drawn one by one are a solid block anyway.
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
    if not len(pts):
        return feats
    t = np.column_stack([np.cos(hdg), np.sin(hdg)])          # along the track
    n = np.column_stack([-t[:, 1], t[:, 0]])                  # across it
    corners = np.array([(-1, -1), (1, -1), (1, 1), (-1, 1), (-1, -1)], dtype=float)
    rings = (pts[:, None, :2] + corners[None, :, :1] * (along / 2) * t[:, None, :]
             + corners[None, :, 1:] * (across / 2) * n[:, None, :])      # (k, 5, 2) [m]
    if merge_above is not None and len(rings) > merge_above:
        from shapely import polygons, union_all

        covered = union_all(polygons(rings)).simplify(0.05 * min(along, across))
        feats.append({"type": "Feature", "properties": {"kind": "photo", "photos": len(rings)},
                      "geometry": _polygons(world, covered, anchor)})
        return feats
    flat = np.column_stack([rings.reshape(-1, 2), np.zeros(rings.shape[0] * 5)])
    ll = np.round(_lonlat(world, flat, anchor)[:, :2], 7).reshape(-1, 5, 2)
    for k, r in enumerate(ll):
        feats.append({"type": "Feature", "properties": {"kind": "photo", "photo": k + 1},
                      "geometry": {"type": "Polygon", "coordinates": [r.tolist()]}})
    return feats
