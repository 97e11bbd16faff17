"""The report of many routes from one wave (``fm2uav routes --report``): every route on the
map (the longest coloured by height above ground, the rest as one layer), the operator's
figures, and the table of the starts with their status."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

__all__ = ["routes_report_html", "FAILED_LAYER", "MAX_DRAWN", "MAX_POINTS", "MAX_ROWS"]

#: Routes drawn on the map at most (evenly chosen through the starts file beyond it).
MAX_DRAWN = 2000
#: Points per drawn route at most (every k-th point, the ends kept).
MAX_POINTS = 60
#: Rows of the starts table at most (the failed starts first).
MAX_ROWS = 500
#: Name of the map layer of the failed starts (every one with a position).
FAILED_LAYER = "failed starts ({n})"


def _thinned(path: np.ndarray) -> np.ndarray:
    k = max(1, int(np.ceil(len(path) / MAX_POINTS)))
    return path[np.unique(np.r_[np.arange(0, len(path), k), len(path) - 1])]


def routes_report_html(world: Any, run: Any, figures: Mapping[str, Any], *, title: str,
                       files: Sequence[str] = (), anchor: Any = None) -> str:
    """report.html of ``fm2uav routes``: the routes on the map (the longest coloured by
    height above ground, the others as one layer), the failed starts as a layer of their
    own (red points, where the file puts them), the starts table (the failed first).

    Parameters
    ----------
    world : World
    run : fm2uav.pipeline.routes.RoutesRun
        The planned routes and the rows of ``routes.csv``.
    figures : mapping
        The printed summary rows (the operator's figures beside the map).
    title : str
    files : sequence of str
        The files written beside the report.
    anchor : optional
        lon/lat of x = y = 0 on a world without a CRS.

    Returns
    -------
    str
        A self-contained HTML page (:func:`fm2uav.viz.report.report_html`).
    """
    from .mapdata import extra_feature
    from .report import join_polylines, report_html

    ok = [k for k, row in enumerate(run.rows) if row["status"] == "ok"]
    if not ok:
        raise ValueError("no route to draw (every start failed)")
    longest = max(ok, key=lambda k: run.rows[k]["length_m"])
    drawn = ok if len(ok) <= MAX_DRAWN else [ok[i] for i in
                                             np.linspace(0, len(ok) - 1, MAX_DRAWN).astype(int)]
    others = [k for k in drawn if k != longest]
    main = f"longest route ({run.rows[longest]['id']})"
    route = run.many.routes[longest]
    paths = {main: np.asarray(route.path, dtype=float)}
    overlays: dict[str, Any] = {}
    if others:
        label = (f"every route ({len(ok)})" if len(drawn) == len(ok)
                 else f"{len(drawn)} of the {len(ok)} routes (evenly through the file)")
        overlays[label] = {"points": join_polylines(
            [_thinned(np.asarray(run.many.routes[k].path, dtype=float)) for k in others]),
            "color": "#1f77b4", "width": 2}
    failed = [row for row in run.rows if row["status"] != "ok"]
    shown = (failed + [row for row in run.rows if row["status"] == "ok"])[:MAX_ROWS]
    cols = ("id", "status", "reason", "lon", "lat", "length_m", "time_s", "lowest_agl_m",
            *(("filled_ground_m", "lowest_agl_filled_m")  # unknown ground said where flown
              if any(row.get("filled_ground_m") for row in run.rows) else ()), "message")
    table = [{c: ("" if row.get(c) is None else row.get(c)) for c in cols} for row in shown]
    head = (f"Starts ({len(run.rows)}; failed first"
            + (f", the first {MAX_ROWS} shown — every row is in routes.csv)"
               if len(run.rows) > MAX_ROWS else ")"))
    layers = []
    where = [k for k, row in enumerate(run.rows) if row["status"] != "ok"]
    if where and run.starts is not None:
        pts = np.asarray(run.starts, dtype=float)[where]
        pts = pts[np.isfinite(pts).all(axis=1)]
        if len(pts):
            layers.append(extra_feature(
                world, FAILED_LAYER.format(n=len(pts)), pts[:, :2], anchor,
                style={"color": "#d62728", "fillColor": "#d62728", "fillOpacity": 0.8,
                       "radius": 5, "weight": 1},
                label="failed start (no route: reasons in the starts table)",
                geometry="MultiPoint"))
    agl = getattr(getattr(route, "level", None), "agl", None)
    return report_html(world, paths, title=title, overlays=overlays, figures=dict(figures),
                       speeds={main: route.w}, map_layers=layers,
                       tables={head: table}, files=files, anchor=anchor,
                       agl=float(agl) if agl is not None else None,
                       params=run.summary.get("params") or {})
