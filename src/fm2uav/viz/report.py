"""Interactive HTML reports: one self-contained file per run, map first.

A report shows, in this order,

* the map (:mod:`fm2uav.viz.reportmap`): the world's shaded relief in lon/lat,
  buildings, zones with their floor and ceiling, survey area and footprints, the
  main route coloured by height above ground (with its colour bar) and numbered
  waypoints, the other paths in their colours, a lon/lat graticule and a scale
  bar — beside it the operator's figures (length, flight time, photos, lowest
  height above ground and where, nearest zone, ...) and the warnings;
* profiles along each path: altitude and ground, height above ground, and the
  velocity map W (the admissible speed share);
* a 3D view: the terrain surface (or, without terrain, the height of the
  obstacles of each column, e.g. buildings), every path, its thinned
  waypoints, start and goal — rotate/zoom with the mouse; long paths (hundreds
  of coverage bands) thinned and coloured by the distance flown;
* result tables, and the planner's research parameters and metrics (W, α/β,
  p1/p2, cells, ...) folded away in a ``<details>`` section;
* optionally, per-path line styles (e.g. planned solid, flown dashed), the
  ideal flight level of each path (ground + agl) on the altitude profile, and
  overlays (area outlines, bands, flown tracks) in the 3D view and on the map.

A report without a world (e.g. ``fm2uav check`` of a bare path file) has no
map (nothing places the paths) and draws the paths alone.

The file is self-contained: plotly.js (about 4.7 MB), Leaflet and the map's
script are inlined, the relief is a data URI; nothing is fetched from the
network, so it opens offline and can be mailed as one file.
Drawing only: every number comes from the caller, or is measured against the
world's continuous ground as the safety figures are.
"""

from __future__ import annotations

import html
import json
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from ..geometry import arc_length

__all__ = ["report_html", "plan_report", "write_report", "join_polylines", "path_figures",
           "latlon_text"]

#: Path colours: the first (the main route, coloured by height above ground on the map)
#: red; the others avoid the map's height-above-ground scale (red-orange-green-blue), so a
#: second path never reads as a height.
_COLOURS = ["#d62728", "#9467bd", "#e377c2", "#8c564b", "#17becf", "#7f7f7f", "#bcbd22",
            "#1f77b4", "#ff7f0e", "#2ca02c"]
_CONFIG = {"displaylogo": False, "responsive": True}


def _ground(world: Any, path: np.ndarray) -> np.ndarray | None:
    """Ground under a 3D path for the profile (None: no terrain to draw)."""
    if world is None or getattr(world, "terrain", None) is None or path.shape[1] != 3:
        return None
    return np.asarray(world.ground_height(path[:, 0], path[:, 1]), dtype=float)


def _stride(n: int, limit: int) -> int:
    return max(1, int(np.ceil(n / limit)))


#: Paths with more points are thinned in the 3D view and coloured by the distance flown.
_LONG_PATH = 4000


def _profile_points(world: Any, p: np.ndarray, limit: int) -> np.ndarray:
    """Indices of a path's points drawn on its profile: all of them, or every k-th plus the
    lowest and the highest point above the ground (a thinned profile keeps its extremes)."""
    if len(p) <= limit:
        return np.arange(len(p))
    idx = np.arange(0, len(p), _stride(len(p), limit))
    extra = [len(p) - 1]
    if world is not None and world.ndim == 3 and p.shape[1] == 3:
        agl = p[:, 2] - np.asarray(world.ground_height(p[:, 0], p[:, 1]), dtype=float)
        extra += [int(np.argmin(agl)), int(np.argmax(agl))]
    return np.unique(np.r_[idx, extra])


def _thin(p: np.ndarray, limit: int) -> np.ndarray:
    """Every k-th point of a path (its last point kept) so that at most ~``limit`` remain."""
    if len(p) <= limit:
        return p
    idx = np.arange(0, len(p), _stride(len(p), limit))
    return p[np.unique(np.r_[idx, len(p) - 1])]


def _surface(world: Any, limit: int) -> list[tuple[np.ndarray, np.ndarray, np.ndarray, str]]:
    """``[(x, y, z(ny, nx), label), ...]`` of the ground, subsampled to <= limit nodes/axis:
    the terrain, and what stands on it (buildings, blocks, zones closed to flight) as
    ``"obstacles"`` with NaN where nothing does — or, without terrain, the height of the
    obstacles of each column alone. Empty for a 2D world."""
    if world.ndim != 3:
        return []
    nx, ny = world.shape[:2]
    s = max(_stride(nx, limit), _stride(ny, limit))
    x = world.origin[0] + np.arange(0, nx, s) * world.spacing[0]
    y = world.origin[1] + np.arange(0, ny, s) * world.spacing[1]
    top = world.surface_index().astype(float)
    h = np.where(top >= 0, world.origin[2] + top * world.spacing[2], world.origin[2])
    # obstacles standing on the terrain (buildings) rise more than a cell above it
    raised = world.terrain is not None and bool(np.any(h > world.terrain + world.spacing[2]))
    if world.terrain is not None and not raised:
        return [(x, y, np.asarray(world.terrain[::s, ::s]).T, "terrain")]
    if world.terrain is not None:
        h = np.maximum(h, world.terrain)
    # block maximum, so thin obstacles (walls, small buildings) stay visible
    px, py = (-nx) % s, (-ny) % s
    hp = np.pad(h, ((0, px), (0, py)), mode="edge")
    z = hp.reshape(hp.shape[0] // s, s, hp.shape[1] // s, s).max(axis=(1, 3))
    if world.terrain is None:
        return [(x, y, np.asarray(z).T, "obstacles")]
    ground = np.asarray(world.terrain[::s, ::s], dtype=float)
    z = z[:ground.shape[0], :ground.shape[1]]
    from scipy.ndimage import binary_dilation

    up = z > ground + world.spacing[2]
    # a ring of ground nodes around each block, so its walls are drawn down to the ground
    blocks = np.where(up, z, np.where(binary_dilation(up, np.ones((3, 3), bool)), ground,
                                                   np.nan))
    return [(x, y, ground.T, "terrain"), (x, y, blocks.T, "obstacles")]


def _table(rows: Mapping[str, Any]) -> str:
    if not rows:
        return ""
    body = "".join(
        f"<tr><th>{html.escape(str(k))}</th><td>{html.escape(_fmt(v))}</td></tr>"
        for k, v in rows.items()
    )
    return f"<table>{body}</table>"


def _results_table(title: str, rows: Sequence[Mapping[str, Any]]) -> str:
    """A titled table with one column per key (the union of the rows' keys, in order)."""
    if not rows:
        return ""
    cols = list(dict.fromkeys(k for r in rows for k in r))
    head = "".join(f"<th>{html.escape(str(c))}</th>" for c in cols)
    body = "".join(
        "<tr>" + "".join(f"<td>{html.escape(_fmt(r.get(c, '')))}</td>" for c in cols) + "</tr>"
        for r in rows
    )
    return (f'<section><h2>{html.escape(title)}</h2><div style="overflow-x:auto">'
            f'<table class="results"><tr>{head}</tr>{body}</table></div></section>')


def join_polylines(lines: Sequence[Any]) -> np.ndarray:
    """Several polylines as one array with a NaN row between them (drawn with gaps).

    Parameters
    ----------
    lines : sequence of array_like (n_i, d)
        Polylines [m] (e.g. coverage bands, the rings of an area).

    Returns
    -------
    ndarray, shape (sum n_i + len(lines) - 1, d)
    """
    arrs = [np.asarray(a, dtype=float) for a in lines if len(a)]
    if not arrs:
        raise ValueError("join_polylines needs at least one non-empty polyline")
    gap = np.full((1, arrs[0].shape[1]), np.nan)
    out = [arrs[0]]
    for a in arrs[1:]:
        out += [gap, a]
    return np.concatenate(out)


def _overlay(value: Any) -> dict[str, Any]:
    if isinstance(value, Mapping):
        ov = dict(value)
        ov["points"] = np.asarray(ov["points"], dtype=float)
        return ov
    return {"points": np.asarray(value, dtype=float)}


def _fmt(v: Any) -> str:
    if isinstance(v, float):
        return f"{v:.6g}"
    if isinstance(v, (list, tuple, np.ndarray)):
        return "[" + ", ".join(_fmt(x) for x in np.asarray(v).ravel().tolist()) + "]"
    if isinstance(v, dict):
        return ", ".join(f"{k}={_fmt(x)}" for k, x in v.items())
    return str(v)


def _is_3d(world: Any, paths: Mapping[str, np.ndarray]) -> bool:
    if world is not None:
        return world.ndim == 3
    return next(iter(paths.values())).shape[1] == 3


def _densify(pts: np.ndarray, step: float) -> np.ndarray:
    """Insert points so no segment is longer than ``step``; NaN gap rows are kept."""
    out = [pts[:1]]
    for a, b in zip(pts[:-1], pts[1:]):
        n = 1
        if np.all(np.isfinite(a)) and np.all(np.isfinite(b)):
            n = max(1, int(np.ceil(np.linalg.norm(b - a) / step)))
        t = np.arange(1, n + 1)[:, None] / n
        out.append(a + t * (b - a) if n > 1 else b[None])
    return np.concatenate(out)


def _overlay_points(world: Any, pts: np.ndarray, three_d: bool) -> np.ndarray:
    """Drape 2-column polylines over the ground of a 3D world; NaN rows kept as gaps.

    The polyline is densified to the grid spacing and lifted half a vertical
    cell (at least 2 m) so it stays above the drawn surface.
    """
    if not three_d or pts.shape[1] == 3:
        return pts
    if world is not None and world.terrain is not None:
        pts = _densify(pts, float(min(world.spacing[:2])))
    z = np.full(len(pts), np.nan)
    ok = np.all(np.isfinite(pts), axis=1)
    if world is not None and ok.any():
        flat = np.column_stack([pts[ok], np.zeros(int(ok.sum()))])
        g = _ground(world, flat)
        lift = max(2.0, 0.5 * float(world.spacing[2]))
        z[ok] = (g + lift) if g is not None else world.bounds[2, 0]
    elif ok.any():
        z[ok] = 0.0
    return np.column_stack([pts[:, :2], z])


def _scene_figure(world: Any, paths: Mapping[str, np.ndarray],
                  waypoints: Mapping[str, np.ndarray], limit: int,
                  styles: Mapping[str, Mapping[str, Any]] | None = None,
                  overlays: Mapping[str, Mapping[str, Any]] | None = None) -> Any:
    import plotly.graph_objects as go

    fig = go.Figure()
    styles = styles or {}
    three_d = _is_3d(world, paths)
    if world is None:
        pass
    elif three_d:
        for x, y, z, label in _surface(world, limit):
            fig.add_trace(go.Surface(
                x=x, y=y, z=z, name=label,
                colorscale="Earth" if label == "terrain" else [[0, "#8a8a92"], [1, "#4a4a52"]],
                opacity=0.9 if label == "terrain" else 0.75, showscale=False,
                hovertemplate="x %{x:.0f} m<br>y %{y:.0f} m<br>z %{z:.1f} m<extra>" + label
                + "</extra>"))
    else:
        b = world.bounds
        fig.add_trace(go.Heatmap(
            z=world.occupancy.T.astype(np.uint8),
            x0=b[0, 0], dx=world.spacing[0], y0=b[1, 0], dy=world.spacing[1],
            colorscale=[[0, "#ffffff"], [1, "#444444"]], showscale=False, name="obstacles",
            hoverinfo="skip"))
    scatter = go.Scatter3d if three_d else go.Scatter
    for j, (name, ov) in enumerate((overlays or {}).items()):
        if ov.get("scene", True) is False:
            continue
        pts = _overlay_points(world, ov["points"], three_d)
        kw = {"z": pts[:, 2]} if three_d else {}
        line = {"color": ov.get("color", "#555555"), "width": ov.get("width", 3 if three_d else 2)}
        if ov.get("dash"):
            line["dash"] = ov["dash"]
        fig.add_trace(scatter(x=pts[:, 0], y=pts[:, 1], mode="lines", name=name, line=line,
                              connectgaps=False, hoverinfo="skip", **kw))
    for i, (name, p) in enumerate(paths.items()):
        c = _COLOURS[i % len(_COLOURS)]
        st = dict(styles.get(name, {}))
        by_distance = st.pop("colorby", None) == "distance" or len(p) > _LONG_PATH
        q = _thin(p, _LONG_PATH)
        kw = {"z": q[:, 2]} if three_d else {}
        line = {"color": c, "width": (3 if by_distance else 6) if three_d else
                (1.5 if by_distance else 3), **st}
        c = line["color"]
        if by_distance and three_d:   # hundreds of bands: the order of flight reads from the colour
            line["color"] = arc_length(q) / 1000.0
            line["colorscale"] = "Turbo"
            if three_d:
                line["colorbar"] = {"title": {"text": "flown [km]"}, "len": 0.6, "x": 1.0}
                line["showscale"] = True
        fig.add_trace(scatter(x=q[:, 0], y=q[:, 1], mode="lines", name=name, line=line,
                              **kw))
        if name in waypoints:
            w = waypoints[name]
            kw = {"z": w[:, 2]} if three_d else {}
            many = len(w) > 300        # a survey's waypoints: small dots, not blobs
            fig.add_trace(scatter(x=w[:, 0], y=w[:, 1], mode="markers",
                                  name=f"{name} waypoints ({len(w)})",
                                  marker={"color": "#222222" if many else c,
                                          "size": (1.5 if many else 3) if three_d else
                                          (3 if many else 6), "symbol": "diamond"}, **kw))
        for label, pt, colour, sym in (("start", p[0], "#2ca02c", "circle"),
                                        ("goal", p[-1], "#ffbf00", "diamond" if three_d else "star")):
            kw = {"z": [pt[2]]} if three_d else {}
            fig.add_trace(scatter(x=[pt[0]], y=[pt[1]], mode="markers", name=f"{name} {label}",
                                  showlegend=i == 0 or len(paths) < 4,
                                  marker={"color": colour, "size": 7 if three_d else 12,
                                          "symbol": sym, "line": {"color": "black", "width": 1}},
                                  **kw))
    if three_d:
        if world is not None:
            b = world.bounds
        else:
            allp = np.concatenate(list(paths.values()))
            b = np.column_stack([allp.min(axis=0), allp.max(axis=0)])
        ext = b[:, 1] - b[:, 0]
        ext = np.where(ext > 0, ext, 1.0)
        fig.update_layout(scene={
            "xaxis_title": "x [m]", "yaxis_title": "y [m]", "zaxis_title": "z [m]",
            "aspectmode": "manual",
            "aspectratio": {"x": 1.0, "y": float(ext[1] / ext[0]),
                            "z": float(max(ext[2] / ext[0], 0.3))},
            "camera": {"eye": {"x": -0.9, "y": -1.3, "z": 0.75}},
        })
    else:
        fig.update_layout(xaxis_title="x [m]", yaxis_title="y [m]",
                          yaxis={"scaleanchor": "x", "scaleratio": 1})
    fig.update_layout(height=620, margin={"l": 0, "r": 0, "t": 10, "b": 0},
                      legend={"x": 0, "y": 1})
    return fig


def _profile_figure(world: Any, paths: Mapping[str, np.ndarray],
                    speeds: Mapping[str, np.ndarray], agl: float | None,
                    styles: Mapping[str, Mapping[str, Any]] | None = None,
                    ideal_agl: Mapping[str, float] | None = None) -> Any:
    import plotly.graph_objects as go
    from plotly.subplots import make_subplots

    styles = styles or {}
    ideal_agl = ideal_agl or {}
    three_d = _is_3d(world, paths)
    agl_row = three_d and world is not None     # a bare path (no world) has no ground
    w_row = bool(speeds) or not three_d
    rows = ((["altitude [m]"] if three_d else []) + (["height above ground [m]"] if agl_row else [])
            + (["W (speed share)"] if w_row else []))
    fig = make_subplots(rows=len(rows), cols=1, shared_xaxes=True, vertical_spacing=0.06,
                        subplot_titles=rows)
    for i, (name, p) in enumerate(paths.items()):
        st = {k: v for k, v in styles.get(name, {}).items() if k in ("color", "dash")}
        c = st.get("color", _COLOURS[i % len(_COLOURS)])
        line = {"color": c, **st}
        s_all = arc_length(p)
        keep = _profile_points(world, p, _LONG_PATH)
        p, s = p[keep], s_all[keep]
        if speeds.get(name) is not None and len(speeds[name]) == len(s_all):
            speeds = {**speeds, name: np.asarray(speeds[name], dtype=float)[keep]}
        r = 1
        if three_d:
            fig.add_trace(go.Scatter(x=s, y=p[:, 2], name=f"{name} altitude", legendgroup=name,
                                     line=line), row=1, col=1)
            g = _ground(world, p)
            if g is not None:
                fig.add_trace(go.Scatter(x=s, y=g, name=f"{name} ground", legendgroup=name,
                                         line={"color": "#8c6d31"}, fill="tozeroy",
                                         fillcolor="rgba(140,109,49,0.25)"), row=1, col=1)
                if name in ideal_agl and ideal_agl[name] is not None:
                    level = float(ideal_agl[name])
                    fig.add_trace(go.Scatter(x=s, y=g + level,
                                             name=f"{name} ideal ({level:g} m AGL)",
                                             legendgroup=name,
                                             line={"color": c, "dash": "dash", "width": 1}),
                                  row=1, col=1)
                fig.add_trace(go.Scatter(x=s, y=p[:, 2] - g, name=f"{name} AGL",
                                         legendgroup=name, line=line), row=2, col=1)
            r = 3 if agl_row else 2
        if w_row and name in speeds and speeds[name] is not None:
            fig.add_trace(go.Scatter(x=s, y=np.asarray(speeds[name], dtype=float),
                                     name=f"{name} W", legendgroup=name,
                                     line={"color": c, "dash": "dot"}), row=r, col=1)
    levels = [] if agl is None else [float(agl)]
    levels += [float(v) for v in ideal_agl.values() if v is not None]
    if agl_row:
        for level in dict.fromkeys(levels):
            fig.add_hline(y=level, line={"color": "black", "dash": "dash", "width": 1},
                          annotation_text=f"flight level {level:g} m", row=2, col=1)
    if agl_row:   # from 0: a steady height reads as steady, not as centimetre noise
        fig.update_yaxes(rangemode="tozero", row=2, col=1)
    fig.update_xaxes(title_text="distance along the path [m]", row=len(rows), col=1)
    fig.update_layout(height=240 * len(rows), margin={"l": 60, "r": 20, "t": 30, "b": 40})
    return fig


_CSS = """
body{font-family:system-ui,-apple-system,Segoe UI,Roboto,sans-serif;margin:0;background:#fafafa;color:#222}
header{background:#1f3b57;color:#fff;padding:10px 24px}header h1{margin:0;font-size:21px}
header p{margin:3px 0 0;opacity:.85}main{padding:10px 18px}
section{background:#fff;border:1px solid #ddd;border-radius:6px;margin:0 0 14px;padding:8px 12px}
h2{font-size:17px;margin:6px 0}.cols{display:flex;gap:16px;flex-wrap:wrap}.cols>div{flex:1;min-width:300px}
table{border-collapse:collapse;font-size:13px;width:100%}th,td{border-bottom:1px solid #eee;padding:3px 8px;text-align:left;vertical-align:top}
th{width:38%;color:#444;font-weight:600}
table.results th{width:auto;white-space:nowrap}
section.overview{display:flex;gap:12px;padding:8px;align-items:stretch}
section.overview .fm2uav-map{flex:1 1 auto;min-width:420px;border-radius:4px;background:#dfe5ea}
section.overview aside{flex:0 0 330px;max-width:360px;overflow-y:auto}
section.overview aside h2{margin-top:2px}
#fm2uav-layers .leaflet-control-layers{box-shadow:none;border:0;margin:0;padding:0;font-size:13px}
#fm2uav-layers .leaflet-control-layers-list{margin:0}
table.figures th{width:46%}table.figures td{font-variant-numeric:tabular-nums}
section.warn{border-color:#ff7f0e;background:#fff4e5}section.warn h2{color:#b35900}
aside section.warn{margin:0 0 8px;padding:4px 8px}aside section.warn ul{margin:4px 0;padding-left:18px;font-size:13px}
details.research{background:#fff;border:1px solid #ddd;border-radius:6px;margin:0 0 14px;padding:8px 12px}
details.research summary{font-weight:600;font-size:16px;cursor:pointer}
footer{font-size:12px;color:#666;padding:8px 24px 24px}
@media (max-width:900px){section.overview{flex-direction:column}section.overview aside{max-width:none;flex:none}}
"""


def report_html(
    world: Any,
    paths: Mapping[str, Any],
    *,
    title: str = "fm2uav report",
    subtitle: str = "",
    speeds: Mapping[str, Any] | None = None,
    waypoints: Mapping[str, Any] | None = None,
    params: Mapping[str, Any] | None = None,
    metrics: Mapping[str, Any] | None = None,
    files: Sequence[str] = (),
    agl: float | None = None,
    max_surface: int = 150,
    styles: Mapping[str, Mapping[str, Any]] | None = None,
    ideal_agl: Mapping[str, float | None] | None = None,
    overlays: Mapping[str, Any] | None = None,
    tables: Mapping[str, Sequence[Mapping[str, Any]]] | None = None,
    notes: Sequence[str] = (),
    figures: Mapping[str, Any] | None = None,
    map_doc: Mapping[str, Any] | None = None,
    map_layers: Sequence[Mapping[str, Any]] = (),
    anchor: Any = None,
) -> str:
    """A self-contained interactive HTML report of paths on a world, opening on its map.

    Parameters
    ----------
    world : World or None
        Drawn as its terrain surface, or its obstacle heights without terrain
        (2D worlds: the occupancy). None: the paths alone (no map, no ground
        profile).
    paths : mapping of str to array (N, ndim)
        Named paths [m] (e.g. ``{"FM² path": plan.path}``); several are overlaid.
        The first is the main route (coloured by height above ground on the map).
    speeds : mapping of str to array (N,), optional
        W along each path (profile panel).
    waypoints : mapping of str to array (n, ndim), optional
        Thinned mission waypoints [m] drawn as markers (numbered on the map).
    params, metrics : mapping, optional
        Rows of the planner's parameter and metric tables (folded away in the
        "Planner and research details" section).
    files : sequence of str, optional
        Names of the other files of the run (listed at the bottom).
    agl : float, optional
        Target flight level [m] drawn on the height-above-ground profile.
    max_surface : int, optional
        Nodes per axis of the drawn surface (subsampled above). Default 150.
    styles : mapping of str to dict, optional
        Per-path plotly line settings, e.g. ``{"flown": {"dash": "dash"}}``
        (``color``, ``dash``, ``width``; ``colorby="distance"`` colours a long
        path by the distance flown in the 3D view).
    ideal_agl : mapping of str to float, optional
        Flight level [m above ground] of each path: its ideal altitude (ground +
        level) is drawn on the altitude profile and the level on the
        height-above-ground profile.
    overlays : mapping of str to array or dict, optional
        Polylines [m] (area outline, bands, flown tracks): an array (n, 2) or
        (n, 3) — NaN rows split it (see :func:`join_polylines`); 2D polylines in
        a 3D world are draped 2 m above the terrain — or a dict with ``points``
        and optional ``color``, ``dash``, ``width``, ``scene`` (False: not in
        the 3D view) and ``map`` (False: not on the map).
    tables : mapping of str to sequence of dict, optional
        Titled result tables, one dict per row (e.g. a reproduced paper table).
    notes : sequence of str, optional
        Warnings shown first, highlighted, beside the map (e.g. the length flown
        over filled DEM nodata, a DEM too coarse for the flight level).
    figures : mapping, optional
        The operator's figures beside the map, label → value text (length, flight
        time, photos, lowest height above ground, ...). Default: per path its
        length and lowest height above the ground with where
        (:func:`path_figures`).
    map_doc : dict, optional
        A map document of the mission (:func:`fm2uav.viz.mapdata.mission_map`,
        with coverage features): its route is the first path, with the mission's
        numbered items, zones and geofence.
    map_layers : sequence of dict, optional
        More map features (:func:`fm2uav.viz.mapdata.extra_feature`), each in a
        named layer of the map's switcher (return paths, rally points, ...).
    anchor : Anchor, optional
        Placement of a world without CRS on the map (default: the exports').

    Returns
    -------
    str
        The HTML document (write it with :func:`write_report`).
    """
    from .reportmap import figures_table, map_body, map_head, report_map_document

    if not paths:
        raise ValueError("report_html needs at least one path")
    ndims = {np.asarray(v).shape[-1] for v in paths.values()}
    if world is None and len(ndims) != 1:
        raise ValueError("report_html without a world needs paths of one dimension (2 or 3)")
    P = {str(k): np.asarray(v, dtype=float) for k, v in paths.items()}
    S = {str(k): np.asarray(v, dtype=float) for k, v in (speeds or {}).items() if v is not None}
    Wp = {str(k): np.asarray(v, dtype=float) for k, v in (waypoints or {}).items()
          if v is not None}
    O = {str(k): _overlay(v) for k, v in (overlays or {}).items()}
    scene = _scene_figure(world, P, Wp, max_surface, styles, O)
    prof = _profile_figure(world, P, S, agl, styles, ideal_agl)
    # plotly.js goes with the first figure on the page: the profiles
    div_prof = prof.to_html(full_html=False, include_plotlyjs=True, config=_CONFIG,
                            div_id="fm2uav-profiles")
    div_scene = scene.to_html(full_html=False, include_plotlyjs=False, config=_CONFIG,
                              div_id="fm2uav-scene")
    doc = report_map_document(world, P, anchor=anchor, base=map_doc, waypoints=Wp,
                              ideal_agl=ideal_agl, agl=agl, styles=styles, overlays=O,
                              extra=map_layers)
    if figures is None:
        figures = path_figures(world, P, anchor=anchor)
    if doc is None:
        map_html = ('<div class="fm2uav-map nomap"><p>No map: the paths are not placed on '
                    "the Earth (no world was given, so there is no CRS or anchor).</p></div>")
        head = ""
    else:
        map_html, head = map_body(doc), map_head()
    world_rows = _world_rows(world)
    tables_html = "".join(_results_table(t, rows) for t, rows in (tables or {}).items())
    data = json.dumps({"paths": {k: int(len(v)) for k, v in P.items()},
                       "map": doc is not None})
    files_html = "".join(f"<li>{html.escape(f)}</li>" for f in files)
    three_d = _is_3d(world, P)
    return f"""<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8">
<meta name="viewport" content="width=device-width, initial-scale=1">
<title>{html.escape(title)}</title><style>{_CSS}</style>{head}</head>
<body><header><h1>{html.escape(title)}</h1><p>{html.escape(subtitle)}</p></header>
<main>
<section class="overview" id="fm2uav-overview"><h2 hidden>Map</h2>
{map_html}
<aside>{_notes(notes)}<h2>Flight</h2>{figures_table(figures)}
{'<h2>Map layers</h2><div id="fm2uav-layers"></div>' if doc is not None else ''}</aside></section>
<section><h2>{'Altitude and height above ground along the path' if three_d else 'Along the path'}</h2>{div_prof}</section>
<section><h2>{'3D view' if three_d else 'Top view'}</h2>{div_scene}</section>
{tables_html}<details class="research" id="fm2uav-details"><summary>Planner and research details
(parameters, metrics, grid)</summary>
<div class="cols"><div><h2>Parameters</h2>{_table(params or {})}</div>
<div><h2>Metrics</h2>{_table(metrics or {})}</div>
<div><h2>World</h2>{_table(world_rows)}</div></div></details>
{f'<section><h2>Files</h2><ul>{files_html}</ul></section>' if files else ''}
</main>
<footer>fm2uav report — map: drag to pan, scroll to zoom, switch layers at its top right;
3D view: drag to rotate, scroll to zoom, double-click to reset.
<script type="application/json" id="fm2uav-data">{data}</script></footer>
</body></html>
"""


def path_figures(world: Any, paths: Mapping[str, np.ndarray], *, anchor: Any = None,
                 limit: int = 4) -> dict[str, str]:
    """Default operator figures of paths: length and, for 3D paths on a world, the lowest
    height above the continuous ground (:meth:`World.ground_height`) with where it is
    (distance along the path, lon/lat).

    Parameters
    ----------
    world : World or None
    paths : mapping of str to array (N, 2|3) [m]
    anchor : Anchor, optional
        Placement of a world without CRS.
    limit : int
        Paths described (the first ones).
    """
    out: dict[str, str] = {}
    items = list(paths.items())
    for name, p in items[:limit]:
        pre = "" if len(items) == 1 else f"{name}: "
        s = arc_length(p)
        out[f"{pre}length"] = _km(s[-1])
        if world is not None and p.shape[1] == 3 and world.ndim == 3:
            agl = p[:, 2] - np.asarray(world.ground_height(p[:, 0], p[:, 1]), dtype=float)
            k = int(np.argmin(agl))
            out[f"{pre}lowest above ground"] = (
                f"{agl[k]:.0f} m at {_km(s[k])} ({_where(world, p[k], anchor)})")
    if len(items) > limit:
        out["more paths"] = f"{len(items) - limit} (see the map's layers)"
    return out


def _km(m: float) -> str:
    return f"{m / 1000:.2f} km" if m >= 1000 else f"{m:.0f} m"


def _where(world: Any, p: np.ndarray, anchor: Any = None) -> str:
    """Latitude and longitude of a world point, as an operator reads them."""
    from ..world.geo import to_lonlat

    q = np.asarray(to_lonlat(world, np.asarray(p, dtype=float)[:2], anchor=anchor),
                   dtype=float)
    return latlon_text(float(q[0]), float(q[1]))


def latlon_text(lon: float, lat: float) -> str:
    """``"46.03000° N, 10.30000° E"`` (5 decimals: about a metre).

    >>> latlon_text(-3.7649, 40.3326)
    '40.33260° N, 3.76490° W'
    """
    return (f"{abs(lat):.5f}° {'N' if lat >= 0 else 'S'}, "
            f"{abs(lon):.5f}° {'E' if lon >= 0 else 'W'}")


def _notes(notes: Sequence[str]) -> str:
    """The highlighted warnings section (empty without notes)."""
    if not notes:
        return ""
    items = "".join(f"<li>{html.escape(str(n))}</li>" for n in notes)
    return f'<section class="warn" id="fm2uav-warnings"><h2>Warnings</h2><ul>{items}</ul></section>\n'


def _world_rows(world: Any) -> dict[str, Any]:
    """Rows of the report's World table (name, grid, spacing [m], origin [m], terrain, CRS)."""
    if world is None:
        return {"world": "none given (paths only)"}
    return {
        "name": getattr(world, "name", "") or "-",
        "grid (nodes)": " x ".join(str(n) for n in world.shape),
        "spacing [m]": world.spacing,
        "origin [m]": world.origin,
        "terrain": "yes" if world.terrain is not None else "no",
        "CRS": _crs_name(world.crs) if world.crs else "none (local anchor)",
    }


def _crs_name(crs: str) -> str:
    from ..world.geo import crs_label

    try:
        return crs_label(crs)
    except Exception:  # a world with a CRS pyproj no longer reads: as it is
        return str(crs)


def plan_report(
    plans: Any,
    *,
    title: str = "fm2uav plan",
    subtitle: str = "",
    waypoints: Mapping[str, Any] | None = None,
    params: Mapping[str, Any] | None = None,
    metrics: Mapping[str, Any] | None = None,
    files: Sequence[str] = (),
    max_surface: int = 150,
) -> str:
    """:func:`report_html` for one :class:`~fm2uav.Plan`, a list or a name → Plan mapping.

    The parameters default to the first plan's ``params`` and the metrics to
    each plan's length, clearance and minimum W.
    """
    if isinstance(plans, Mapping):
        named = dict(plans)
    elif isinstance(plans, Sequence):
        named = {f"path {i + 1}": p for i, p in enumerate(plans)}
    else:
        named = {"FM² path": plans}
    first = next(iter(named.values()))
    if metrics is None:
        metrics = {}
        for name, p in named.items():
            pre = "" if len(named) == 1 else f"{name}: "
            metrics[f"{pre}length [m]"] = round(float(p.length), 1)
            metrics[f"{pre}clearance [m]"] = (round(float(p.clearance), 2)
                                              if np.isfinite(p.clearance) else "inf")
            metrics[f"{pre}min W"] = round(float(np.min(p.w)), 4)
            metrics[f"{pre}points"] = int(len(p.path))
            metrics[f"{pre}planning time [s]"] = round(float(p.timings.get("total", 0.0)), 3)
    agl = first.params.get("agl") if first.params else None
    return report_html(
        first.world,
        {n: p.path for n, p in named.items()},
        title=title, subtitle=subtitle,
        speeds={n: p.w for n, p in named.items()},
        waypoints=waypoints, params=params if params is not None else first.params,
        metrics=metrics, files=files, agl=agl, max_surface=max_surface,
    )


def write_report(file: str | Path, text: str) -> Path:
    """Write a report string to ``file`` (UTF-8); returns the path."""
    path = Path(file)
    path.write_text(text, encoding="utf-8")
    return path
