"""Report overlays drawn from the world itself: filled DEM nodata (issue 12 item 4) and the
no-fly zones / operating area (issue 13).

:func:`filled_overlay` turns ``World.filled`` (an (nx, ny) bool mask, True where
the DEM had no data and the nearest valid elevation was used) into a hatch of
horizontal lines across the filled columns, for
:func:`fm2uav.viz.report.report_html` ``overlays=`` (drawn draped on the ground
in 3D, flat in 2D).
"""

from __future__ import annotations

from typing import Any

import numpy as np

__all__ = ["FILLED_NAME", "FILLED_PATH_NAME", "filled_overlay", "filled_path_overlay",
           "zone_overlays"]

#: Legend name of the hatch.
FILLED_NAME = "filled DEM nodata (invented ground)"
#: Legend name of the path stretches over it.
FILLED_PATH_NAME = "path over FILLED ground (unknown)"


def filled_path_overlay(world: Any, paths: Any) -> dict[str, Any]:
    """``{FILLED_PATH_NAME: overlay}``: the stretches of the 3D ``paths`` (one (N, 3) array or
    a list) over filled (unknown) ground, as 3D polylines with NaN rows between them; empty
    when no path crosses filled ground."""
    from ..world.ground import has_unknown_ground

    if getattr(world, "filled", None) is None or not has_unknown_ground(world):
        return {}
    parts: list[np.ndarray] = []
    for p in ([paths] if isinstance(paths, np.ndarray) else list(paths)):
        p = np.asarray(p, dtype=float)
        if p.ndim != 2 or p.shape[1] != 3:
            continue
        on = np.asarray(world.ground_filled(p[:, 0], p[:, 1]), dtype=bool)
        on[1:] |= on[:-1].copy()
        if not on.any():
            continue
        pts = np.where(on[:, None], p, np.nan)
        parts += [pts, np.full((1, 3), np.nan)]
    if not parts:
        return {}
    return {FILLED_PATH_NAME: {"points": np.concatenate(parts[:-1]), "color": "#ff7f0e",
                               "width": 10}}


def filled_overlay(world: Any, *, lines: int = 60) -> dict[str, Any]:
    """``{FILLED_NAME: overlay}`` hatching the filled nodata columns of ``world``.

    Parameters
    ----------
    world : World
        ``world.filled`` (nx, ny) bool, or None / no True value: nothing to draw.
    lines : int
        At most this many hatch rows across the map (every k-th grid row).

    Returns
    -------
    dict
        Empty when nothing was filled; else one overlay ``{"points": (k, 2) [m]
        with NaN rows between segments, "color", "width"}``: a segment per run of
        filled columns along x, extended half a cell either side.
    """
    mask = getattr(world, "filled", None)
    if mask is None:
        return {}
    mask = np.asarray(mask, dtype=bool)
    if mask.ndim != 2 or not mask.any():
        return {}
    nx, ny = mask.shape
    dx, dy = float(world.spacing[0]), float(world.spacing[1])
    x0, y0 = float(world.origin[0]), float(world.origin[1])
    step = max(1, int(np.ceil(ny / max(int(lines), 1))))
    rows = [j for j in range(ny) if mask[:, j].any()]
    picked = [j for j in rows if j % step == 0] or rows[:1]
    segs: list[np.ndarray] = []
    gap = np.full((1, 2), np.nan)
    for j in picked:
        col = np.r_[False, mask[:, j], False].astype(np.int8)
        edges = np.flatnonzero(np.diff(col))
        y = y0 + j * dy
        for a, b in zip(edges[::2], edges[1::2]):  # filled columns a .. b-1
            segs += [np.array([[x0 + (a - 0.5) * dx, y], [x0 + (b - 0.5) * dx, y]]), gap]
    pts = np.concatenate(segs[:-1])
    return {FILLED_NAME: {"points": pts, "color": "#7f7f7f", "width": 2}}


def zone_overlays(zones: Any) -> dict[str, Any]:
    """Report overlays (outlines draped on the terrain) of no-fly zones and the operating area."""
    out: dict[str, Any] = {}
    for k, z in enumerate(zones or ()):
        geoms = getattr(z.geometry, "geoms", [z.geometry])
        rings = []
        for g in geoms:
            rings.append(np.asarray(g.exterior.coords)[:, :2])
            rings.append(np.full((1, 2), np.nan))
        pts = np.concatenate(rings)[:-1]
        name = f"{z.kind}: {z.name or k + 1}"
        out[name] = {"points": pts, "color": "#2ca02c" if z.inclusion else "#d62728",
                     "width": 4}
        if z.buffer > 0:
            grown = z.keep_out()
            parts = getattr(grown, "geoms", [grown])
            ring = np.concatenate([np.vstack([np.asarray(g.exterior.coords)[:, :2],
                                              np.full((1, 2), np.nan)]) for g in parts
                                   if not g.is_empty])[:-1]
            out[f"{name} (buffer {z.buffer:g} m)"] = {"points": ring, "dash": "dash",
                                                      "color": out[name]["color"], "width": 2}
    return out
