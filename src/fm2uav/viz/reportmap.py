"""The map of a report: a lon/lat map document and the inline Leaflet page parts.

Every ``report.html`` opens on a 2D map (:func:`fm2uav.viz.report.report_html`): the
world's shaded relief as an image placed by its lon/lat corners
(:func:`fm2uav.viz.mapdata.terrain_layer`), the buildings, the zones with their
floor and ceiling, the survey area, bands and photo footprints, and the routes —
the main one coloured by height above ground with its colour bar, the others in
their own colours — with numbered waypoints. It is drawn by the app's own map
script (``viz/web/mission-map.js``) and the vendored Leaflet, inlined with the
document, so the file opens offline and fetches nothing.

Why Leaflet and not plotly's ``scattermap``: the same script and look as the app's
map (one renderer of a mission for both), canvas/SVG drawing that needs no WebGL
(``scattermap`` is MapLibre GL: a blank panel where WebGL is missing — remote
desktops, old field laptops, headless browsers), numbered waypoint labels, zone
labels and a layer switcher for free, and ~160 kB of script next to plotly's 4.7 MB.
"""

from __future__ import annotations

import base64
import functools
import html
import json
import re
from collections.abc import Mapping, Sequence
from importlib import resources
from typing import Any

import numpy as np

__all__ = ["report_map_document", "map_head", "map_body", "figures_table", "MAP_COLOURS"]

#: Colours of the routes drawn in a fixed colour (the 3D view's and the profiles').
MAP_COLOURS = ["#d62728", "#9467bd", "#e377c2", "#8c564b", "#17becf", "#7f7f7f", "#bcbd22",
               "#1f77b4", "#ff7f0e", "#2ca02c"]
#: Secondary routes longer than this are thinned for the map (every k-th point).
_MAX_SECONDARY = 5000


def _web(name: str) -> bytes:
    return resources.files("fm2uav.viz").joinpath("web", name).read_bytes()


def _text(name: str) -> str:
    """A text asset with ``\n`` line ends (a report reads back as it was written)."""
    return _web(name).decode("utf-8").replace("\r\n", "\n").replace("\r", "\n")


@functools.lru_cache(maxsize=1)
def _assets() -> tuple[str, str]:
    """(CSS, JS) of the map, inlined: Leaflet's images as data URIs."""
    css = _text("vendor/leaflet/leaflet.css")

    def inline(m: re.Match) -> str:
        data = base64.b64encode(_web(f"vendor/leaflet/{m.group(1)}")).decode("ascii")
        return f"url(data:image/png;base64,{data})"

    css = re.sub(r"url\((images/[\w.-]+\.png)\)", inline, css)
    css += "\n" + _text("mission-map.css")
    js = "\n;\n".join(_text(n) for n in (
        "vendor/leaflet/leaflet.js", "mission-map.js", "report-map.js"))
    return css, js


def _script_json(doc: Any) -> str:
    """JSON safe inside a ``<script>`` element."""
    return json.dumps(doc, separators=(",", ":"), allow_nan=False).replace("</", "<\\/")


def map_head() -> str:
    """The ``<style>`` of the map (Leaflet's CSS and the map's own)."""
    return f"<style>{_assets()[0]}</style>"


def map_body(doc: Mapping[str, Any], *, height: int = 600) -> str:
    """The map's ``<div id="fm2uav-map">``, its document and its scripts (Leaflet,
    mission-map.js, report-map.js), inline."""
    return (f'<div id="fm2uav-map" class="fm2uav-map" style="height:{int(height)}px" '
            f'role="img" aria-label="map of the mission in longitude and latitude"></div>\n'
            f'<script type="application/json" id="fm2uav-map-data">{_script_json(doc)}</script>\n'
            f"<script>{_assets()[1]}</script>")


def _bbox_of(features: Sequence[Mapping[str, Any]], kinds: set[str]) -> list[float] | None:
    pts: list[list[float]] = []

    def walk(c: Any) -> None:
        if isinstance(c, (list, tuple)) and c and isinstance(c[0], (int, float)):
            pts.append([float(c[0]), float(c[1])])
        elif isinstance(c, (list, tuple)):
            for x in c:
                walk(x)

    for f in features:
        if f["properties"].get("kind") in kinds:
            walk(f["geometry"]["coordinates"])
    if not pts:
        return None
    a = np.asarray(pts)
    return [float(a[:, 0].min()), float(a[:, 1].min()), float(a[:, 0].max()),
            float(a[:, 1].max())]


def report_map_document(
    world: Any,
    paths: Mapping[str, Any],
    *,
    anchor: Any = None,
    base: Mapping[str, Any] | None = None,
    main: str | None = None,
    waypoints: Mapping[str, Any] | None = None,
    ideal_agl: Mapping[str, float | None] | None = None,
    agl: float | None = None,
    styles: Mapping[str, Mapping[str, Any]] | None = None,
    overlays: Mapping[str, Mapping[str, Any]] | None = None,
    extra: Sequence[Mapping[str, Any]] = (),
) -> dict[str, Any] | None:
    """The map document of a report (None without a world: nothing places the paths).

    Parameters
    ----------
    world : World or None
    paths : mapping of str to array (N, 2|3)
        Named paths [m]. The main one (``main``, default the first) is coloured by
        height above ground; the others get the 3D view's colours.
    anchor : Anchor, optional
        Placement of a world without CRS (default: the exports' default anchor).
    base : dict, optional
        A document of :func:`fm2uav.viz.mapdata.mission_map` (its route is the main
        path, with the mission's numbered items, zones and fences) — the paths it
        already has are not added again.
    waypoints : mapping, optional
        Waypoints [m] per path; the main path's are numbered on the map (when
        ``base`` has no mission items).
    ideal_agl : mapping, optional
        Requested height above ground [m] per path (the main route's colour scale);
        ``agl`` is the default for every path.
    styles : mapping, optional
        Per-path plotly styles of the report (``color``, ``dash``): kept on the map.
    overlays : mapping, optional
        The report's scene overlays ``{"points", "color", "dash", "width"}``; drawn as
        extra layers unless ``"map": False`` (what the map draws itself: zones, filled
        ground).
    extra : sequence of dict
        More features (:func:`fm2uav.viz.mapdata.extra_feature`): the hook for layers
        other missions add (return paths, rally points).
    """
    from .mapdata import (
        building_features,
        extra_feature,
        point_features,
        route_feature,
        terrain_layer,
        waypoint_features,
        zone_features,
    )

    if world is None:
        return None
    doc: dict[str, Any] = dict(base) if base is not None else {"type": "FeatureCollection"}
    feats: list[dict[str, Any]] = list(doc.get("features", []))
    kinds = {f["properties"].get("kind") for f in feats}
    names = list(paths)
    main = main if main is not None else (names[0] if names else None)
    ideal = dict(ideal_agl or {})
    styles = styles or {}
    routes: list[dict[str, Any]] = []
    for i, name in enumerate(names):
        p = np.asarray(paths[name], dtype=float)
        level = ideal.get(name, agl)
        if name == main:
            if "route" in kinds:
                for f in feats:   # the mission's route: named as the report names it
                    if f["properties"].get("kind") == "route":
                        f["properties"]["name"] = name
                continue
            routes.append(route_feature(world, p, anchor, name=name, requested=level))
            if "start" not in kinds and len(p) >= 2:
                feats += point_features(world, {"start": p[0], "goal": p[-1]}, anchor)
            if "item" not in kinds and waypoints and waypoints.get(name) is not None:
                feats += waypoint_features(world, waypoints[name], anchor)
        else:
            idx = np.arange(0, len(p), max(1, int(np.ceil(len(p) / _MAX_SECONDARY))))
            q = p[np.unique(np.r_[idx, len(p) - 1])]
            st = styles.get(name, {})
            dash = {"dash": "8 5", "dot": "2 5", "dashdot": "8 4 2 4"}.get(st.get("dash"))
            routes.append(route_feature(world, q, anchor, name=name, requested=level,
                                        color=st.get("color", MAP_COLOURS[i % len(MAP_COLOURS)]),
                                        dash=dash))
    feats = routes + feats
    if "zone" not in kinds:
        feats += zone_features(world, getattr(world, "zones", ()), anchor)
    feats += building_features(world, anchor)
    for name, ov in (overlays or {}).items():
        if ov.get("map", True) is False:
            continue
        style = {"color": ov.get("color", "#555555"),
                 "weight": max(1.0, float(ov.get("width", 2)) / 2)}
        if ov.get("dash"):
            style["dashArray"] = "6 5"
        pts = np.asarray(ov["points"], dtype=float)
        if np.isfinite(pts).all(axis=1).sum() >= 2:
            feats.append(extra_feature(world, name, pts[:, :2], anchor, style=style, label=name))
    feats += [dict(f) for f in extra]
    doc["features"] = feats
    doc["terrain"] = terrain_layer(world, anchor)
    doc["buildings_name"] = "buildings" if world.ndim == 3 else "obstacles"
    view = _bbox_of(feats, {"route", "zone", "area", "start", "goal", "via", "extra"})
    w, s, e, n = doc["terrain"]["bounds"]
    if view is None:
        view = [w, s, e, n]
    doc.setdefault("bbox", view)
    doc["view"] = [round(v, 7) for v in view]
    return doc


def figures_table(figures: Mapping[str, Any]) -> str:
    """The operator's figures as a two-column table (label, value)."""
    body = "".join(f"<tr><th>{html.escape(str(k))}</th><td>{html.escape(str(v))}</td></tr>"
                   for k, v in figures.items())
    return f'<table id="fm2uav-figures" class="figures">{body}</table>'
