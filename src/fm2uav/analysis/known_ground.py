"""Known and unknown ground under a flown path, and whether the DEM resolves the relief.

**Unknown ground.** Where no DEM measures the ground (nodata filled with
``world.nodata: fill`` or ``error_on_route``), its height is invented: a height
above *that* ground says nothing about the real one. :func:`ground_split`
classifies the path by the rule of :func:`fm2uav.world.ground.ground_source`
(a point is over *filled* ground when any DEM pixel of its bilinear ground
height is filled) and splits every safety figure — length and share, height
above ground (min, p5, median, max, share within ±5 m of the request, the
lowest point), clearance — into "over measured ground" and "over filled
ground", with the filled stretches located in lon/lat. With DEMs in priority
order (``world.dem_fill``) it also says how much each DEM measured.

Lengths are 3D along the path (as ``Plan.length``), split exactly where the
classification can change: each path segment is cut into pieces of at most
:data:`SPLIT_STEP` (so that the map projection is linear over a piece), and each
piece at every crossing of a DEM's pixel-centre lines (of the planning grid's
nodes without a ground model); the parts between are classified at their
middle.

**DEM resolution** (:func:`dem_resolution`). A DEM cannot show relief finer
than its pixel: between two pixel centres ``p`` metres apart, on ground that
rises at slope ``θ``, a hill about ``tan(θ) · p`` high can hide. A flight
``agl`` metres above the DEM is then only ``agl - tan(θ) · p`` above that
hidden ground. The figure takes the slope of the DEM around each cruise point
(over one pixel each way), its 95th percentile along the route, and says the
largest pixel that keeps the hidden relief under
:data:`RESOLUTION_MARGIN` × ``agl``.

:func:`check_ground` turns both into what the operator sees: a warning with
the length flown over filled ground (``nodata: fill``), a
:class:`~fm2uav.errors.PlanningError` naming where the plan crosses it
(``nodata: error_on_route``), and a warning when the DEM is too coarse for
the flight level.
"""

from __future__ import annotations

import warnings
from typing import Any

import numpy as np

from ..errors import PlanningError
from ..planning.altitude import height_figures
from ..world.quiet import GeodataWarning

__all__ = ["SPLIT_STEP", "RESOLUTION_MARGIN", "MAX_SPLIT_SAMPLES", "ground_split",
           "filled_mask", "dem_resolution", "ground_notes", "check_ground", "nodata_rule"]

#: Longest piece [m] of a path segment taken as straight in a DEM's own CRS (then cut at
#: the crossings of its pixel-centre lines).
SPLIT_STEP = 25.0
#: Most pieces along one path (the step grows beyond).
MAX_SPLIT_SAMPLES = 2_000_000
#: Share of the flight height above ground that relief hidden between DEM pixels may take.
RESOLUTION_MARGIN = 0.5
#: Stretches over filled ground listed in full (the rest are counted).
_STRETCHES = 5


def nodata_rule(world: Any) -> str | None:
    """The ``world.nodata`` rule a DEM world was built with (None for other worlds)."""
    g = getattr(world, "georef", None)
    for s in getattr(g, "sources", ()) or ():
        if s.role == "dem" and "nodata_rule" in s.details:
            return str(s.details["nodata_rule"])
    return None


def _sources(world: Any) -> list[str]:
    model = getattr(world, "ground", None)
    if model is not None:
        return [layer.name for layer in model.layers]
    g = getattr(world, "georef", None)
    return [s.path.rsplit("/", 1)[-1] for s in getattr(g, "sources", ()) or ()
            if s.role in ("dem", "dem_fill")][:1] or ["terrain"]


def filled_mask(world: Any, points: Any) -> np.ndarray:
    """Whether each point (x, y[, z]) [m] lies over filled (unknown) ground."""
    p = np.asarray(points, dtype=float)
    return np.asarray(world.ground_filled(p[:, 0], p[:, 1]), dtype=bool)


def _lonlat(world: Any, xy: np.ndarray) -> list[float] | None:
    if getattr(world, "crs", None) is None:
        return None
    from ..world.geo import to_lonlat

    ll = to_lonlat(world, [float(xy[0]), float(xy[1]), 0.0])
    return [round(float(ll[0]), 6), round(float(ll[1]), 6)]


def _crossings(a0: np.ndarray, a1: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(piece index, t in (0, 1)) where the coordinate going from ``a0`` to ``a1`` crosses an
    integer (a pixel-centre line)."""
    lo, hi = np.minimum(a0, a1), np.maximum(a0, a1)
    ok = np.isfinite(lo) & np.isfinite(hi)
    first = np.where(ok, np.floor(lo) + 1, 0)
    count = np.where(ok, np.maximum(np.ceil(hi) - first, 0), 0).astype(np.int64)
    idx = np.repeat(np.arange(len(a0)), count)
    k = first[idx] + (np.arange(int(count.sum())) - np.repeat(np.cumsum(count) - count, count))
    d = (a1 - a0)[idx]
    with np.errstate(invalid="ignore", divide="ignore"):
        t = (k - a0[idx]) / d
    keep = np.isfinite(t) & (t > 0) & (t < 1)
    return idx[keep], t[keep]


def _grids(world: Any) -> list[Any]:
    """Functions (x, y) -> (row, col) of the pixel grids the classification depends on."""
    model = getattr(world, "ground", None)
    if model is not None:
        return [layer.pixel_coords for layer in model.layers]
    x0, y0 = float(world.origin[0]), float(world.origin[1])
    dx, dy = float(world.spacing[0]), float(world.spacing[1])
    return [lambda x, y: ((np.asarray(y) - y0) / dy, (np.asarray(x) - x0) / dx)]


def _subsegments(world: Any, p: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Midpoints, lengths [m] and start arc length [m] of the parts of ``p`` between the
    crossings of the pixel-centre lines of every DEM (see the module docstring)."""
    seg = np.linalg.norm(np.diff(p, axis=0), axis=1)
    total = float(seg.sum())
    step = max(SPLIT_STEP, total / MAX_SPLIT_SAMPLES, 1e-6)
    n = np.maximum(np.ceil(seg / step).astype(np.int64), 1)
    i = np.repeat(np.arange(len(seg)), n)
    k = np.arange(int(n.sum())) - np.repeat(np.cumsum(n) - n, n)
    a = p[i] + (k / n[i])[:, None] * (p[i + 1] - p[i])      # pieces: a -> b
    b = p[i] + ((k + 1) / n[i])[:, None] * (p[i + 1] - p[i])
    s_a = np.concatenate([[0.0], np.cumsum(seg)])[i] + k / n[i] * seg[i]
    L = seg[i] / n[i]
    cuts_i = [np.arange(len(a)), np.arange(len(a))]
    cuts_t = [np.zeros(len(a)), np.ones(len(a))]
    for to_pixels in _grids(world):
        r0, c0 = to_pixels(a[:, 0], a[:, 1])
        r1, c1 = to_pixels(b[:, 0], b[:, 1])
        for u0, u1 in ((np.asarray(r0, float), np.asarray(r1, float)),
                       (np.asarray(c0, float), np.asarray(c1, float))):
            ci, ct = _crossings(u0, u1)
            cuts_i.append(ci)
            cuts_t.append(ct)
    ci = np.concatenate(cuts_i)
    ct = np.concatenate(cuts_t)
    order = np.lexsort((ct, ci))
    ci, ct = ci[order], ct[order]
    same = ci[1:] == ci[:-1]
    j = ci[:-1][same]
    t0, t1 = ct[:-1][same], ct[1:][same]
    tm = 0.5 * (t0 + t1)
    mid = a[j] + tm[:, None] * (b[j] - a[j])
    return mid, L[j] * (t1 - t0), s_a[j] + t0 * L[j]


def ground_split(world: Any, path: Any, agl: np.ndarray, clearance: np.ndarray | None = None,
                 *, requested: float | None = None, s: np.ndarray | None = None
                 ) -> dict[str, Any] | None:
    """Every safety figure of ``path`` split into over measured and over filled ground.

    Parameters
    ----------
    world : World
        A DEM world (``World.filled`` set); other worlds give None.
    path : array_like, shape (N, 3)
        The flown path [m].
    agl : ndarray (N,)
        Height above ground of each point [m].
    clearance : ndarray (N,), optional
        Clearance of each point [m].
    requested : float, optional
        The requested height above ground [m] (share within ±5 m).
    s : ndarray (N,), optional
        Arc length of each point [m].

    Returns
    -------
    dict or None
        ``rule`` (how a point is classified), ``step_m``, ``length_m``,
        ``measured`` and ``filled`` (each ``length_m``, ``share``, ``points``,
        ``height_above_ground`` figures, ``clearance_m``), ``filled.stretches``
        (start/end arc length [m] and lon/lat, the first few) and
        ``filled.stretch_count``; ``sources`` (length and share each DEM
        measured) with several DEMs.
    """
    if getattr(world, "filled", None) is None and getattr(world, "ground", None) is None:
        return None
    p = np.asarray(path, dtype=float)
    if p.ndim != 2 or p.shape[1] != 3 or len(p) < 2:
        return None
    mid, length, s0 = _subsegments(world, p)
    src = np.asarray(world.ground_source(mid[:, 0], mid[:, 1]))
    total = float(length.sum())
    point_filled = filled_mask(world, p)
    out: dict[str, Any] = {
        "rule": "over filled ground where any DEM pixel of the bilinear ground height is "
                "filled nodata (no DEM measures it); the 3D length cut at every crossing of "
                "the DEMs' pixel-centre lines and classified between them",
        "parts": int(len(length)),
        "length_m": round(total, 3),
    }
    for name, sel_seg, sel_pt in (("measured", src >= 0, ~point_filled),
                                  ("filled", src < 0, point_filled)):
        L = float(length[sel_seg].sum())
        part: dict[str, Any] = {"length_m": round(L, 3),
                                "share": round(L / total, 6) if total > 0 else 0.0,
                                "points": int(sel_pt.sum())}
        if sel_pt.any():
            part["height_above_ground"] = height_figures(
                agl[sel_pt], requested, points=p[sel_pt], s=None if s is None else s[sel_pt])
            if clearance is not None:
                part["clearance_m"] = round(float(np.min(clearance[sel_pt])), 3)
        out[name] = part
    runs = _runs(src < 0)
    out["filled"]["stretch_count"] = len(runs)
    out["filled"]["stretches"] = [
        {"from_m": round(float(s0[a]), 1), "to_m": round(float(s0[b] + length[b]), 1),
         "length_m": round(float(length[a:b + 1].sum()), 1),
         "from_lonlat": _lonlat(world, mid[a]), "to_lonlat": _lonlat(world, mid[b])}
        for a, b in runs[:_STRETCHES]]
    names = _sources(world)
    if len(names) > 1:
        out["sources"] = [{"dem": n, "length_m": round(float(length[src == k].sum()), 3),
                           "share": round(float(length[src == k].sum()) / total, 6)
                           if total > 0 else 0.0} for k, n in enumerate(names)]
    return out


def _runs(mask: np.ndarray) -> list[tuple[int, int]]:
    """(first, last) index of each run of True."""
    if not mask.any():
        return []
    m = np.r_[False, mask, False].astype(np.int8)
    edges = np.flatnonzero(np.diff(m))
    return [(int(a), int(b) - 1) for a, b in zip(edges[::2], edges[1::2])]


def dem_resolution(world: Any, path: Any, agl: float | None, *, cruise: Any = None
                   ) -> dict[str, Any] | None:
    """Whether the DEM's pixels resolve the relief for a flight ``agl`` metres above it.

    Parameters
    ----------
    world : World
        A DEM world (other worlds give None).
    path : array_like, shape (N, 3)
        The flown path [m].
    agl : float or None
        The requested height above ground [m]; None gives None.
    cruise : array_like of bool, optional
        The cruise points (default: all).

    Returns
    -------
    dict or None
        ``pixel_m`` (median pixel spacing of the measuring DEM along the route, its
        larger side),
        ``slope_p95_deg``, ``hidden_relief_m`` (95th percentile of tan(slope) ×
        pixel), ``agl_m``, ``limit_m`` (:data:`RESOLUTION_MARGIN` × agl),
        ``needed_pixel_m`` (the largest pixel keeping the hidden relief under
        the limit), ``ok``.
    """
    if agl is None or getattr(world, "filled", None) is None:
        return None
    p = np.asarray(path, dtype=float)
    if p.ndim != 2 or p.shape[1] != 3 or len(p) < 2:
        return None
    if cruise is not None and np.asarray(cruise, dtype=bool).any():
        p = p[np.asarray(cruise, dtype=bool)]
    model = getattr(world, "ground", None)
    if model is not None:
        src = np.asarray(model.source(p[:, 0], p[:, 1]))
        pix_layers = np.array([layer.spacing_m for layer in model.layers])
        pix = np.where(src >= 0, pix_layers[np.clip(src, 0, None)], pix_layers[0])
    else:
        pix = np.full(len(p), float(min(world.spacing[:2])))
    x, y = p[:, 0], p[:, 1]
    g = world.ground_height
    gx = (np.asarray(g(x + pix, y)) - np.asarray(g(x - pix, y))) / (2 * pix)
    gy = (np.asarray(g(x, y + pix)) - np.asarray(g(x, y - pix))) / (2 * pix)
    tan = np.hypot(gx, gy)
    hidden = tan * pix
    limit = RESOLUTION_MARGIN * float(agl)
    tan95 = float(np.percentile(tan, 95))
    hidden95 = float(np.percentile(hidden, 95))
    return {"pixel_m": round(float(np.median(pix)), 2),
            "slope_p95_deg": round(float(np.degrees(np.arctan(tan95))), 2),
            "hidden_relief_m": round(hidden95, 2), "agl_m": float(agl),
            "limit_m": round(limit, 2),
            "needed_pixel_m": (round(limit / tan95, 1) if tan95 > 1e-9 else None),
            "ok": bool(hidden95 <= limit + 1e-9)}


def _where(stretch: dict[str, Any]) -> str:
    a, b = stretch.get("from_lonlat"), stretch.get("to_lonlat")
    if a is None or b is None:
        return f"{stretch['from_m']:.0f}-{stretch['to_m']:.0f} m along the path"
    return (f"{stretch['from_m'] / 1000:.2f}-{stretch['to_m'] / 1000:.2f} km along the path, "
            f"lon {a[0]:.5f}, lat {a[1]:.5f} to lon {b[0]:.5f}, lat {b[1]:.5f}")


def _metres(v: float) -> str:
    return f"{v:.0f}" if v >= 10 else f"{v:.1f}"


def ground_notes(world: Any, safety: dict[str, Any], *, what: str = "the path"
                 ) -> dict[str, str]:
    """What the ground figures of a safety summary mean, in words: ``{"filled": ...,
    "resolution": ...}`` (only the keys that apply); for warnings, reports and figures."""
    notes: dict[str, str] = {}
    split = safety.get("ground") or {}
    filled = split.get("filled") or {}
    L = float(filled.get("length_m", 0.0))
    if L > 0:
        total = float(split.get("length_m", 0.0)) or 1.0
        first = filled["stretches"][0]
        more = (f" ({filled['stretch_count']} stretches; the first {_where(first)})"
                if filled.get("stretch_count", 1) > 1 else f" ({_where(first)})")
        low = (filled.get("height_above_ground") or {}).get("min_m")
        low_txt = ("" if low is None else
                   f"; its lowest height above that invented ground is {low:.1f} m")
        notes["filled"] = (f"{what} flies {L / 1000:.2f} km of {total / 1000:.2f} km "
                           f"({100 * L / total:.0f} %) over filled DEM nodata, unknown ground "
                           f"whose height was invented{more}{low_txt}")
    res = safety.get("dem_resolution")
    if res and not res["ok"]:
        need = res.get("needed_pixel_m")
        notes["resolution"] = (
            f"the DEM's {_metres(res['pixel_m'])} m pixels cannot resolve the relief under {what}: at "
            f"its slopes (95th percentile {res['slope_p95_deg']:.0f}°) ground up to "
            f"~{res['hidden_relief_m']:.0f} m higher than the DEM shows can hide between pixel "
            f"centres, more than half of the {res['agl_m']:g} m flown above it; for this height "
            + (f"use a DEM with pixels of at most ~{need:.0f} m (world.dem / --dem, or a finer "
               "world.dem_fill; slopes measured on this DEM, finer data show them steeper) "
               if need else "use a finer DEM ")
            + "or fly higher (planner.agl / --agl)")
    return notes


#: How to avoid unknown ground, for the messages.
_FIX = ("fill the gap from another DEM (world.dem_fill, CLI --dem-fill FILE), crop the map "
        "(world.bbox, CLI --bbox) or move the route onto measured ground")


def check_ground(world: Any, safety: dict[str, Any], *, what: str = "the path") -> None:
    """Say what the figures of :func:`fm2uav.analysis.safety.safety_summary` mean for the
    ground (:func:`ground_notes`): warn of the length flown over filled ground and of a DEM
    too coarse for the flight level; refuse a plan over filled ground under
    ``nodata: error_on_route``.

    Raises
    ------
    PlanningError
        ``world.nodata: error_on_route`` and some of the path is over filled ground
        (exit 1: the data and the request are valid, the plan found does not meet
        the request — as an unreachable goal).
    """
    notes = ground_notes(world, safety, what=what)
    if "filled" in notes:
        if nodata_rule(world) == "error_on_route":
            raise PlanningError(f"{notes['filled']}; world.nodata: error_on_route (CLI --nodata "
                                f"error_on_route) refuses such plans: {_FIX}")
        warnings.warn(f"{notes['filled']}: the height-above-ground figures there are not "
                      f"known; {_FIX}", GeodataWarning, stacklevel=2)
    if "resolution" in notes:
        warnings.warn(notes["resolution"], GeodataWarning, stacklevel=2)
