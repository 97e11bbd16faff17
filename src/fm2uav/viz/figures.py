"""Matplotlib figures of plans (PNG). Drawing only: every number comes from the plan."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np
from matplotlib.figure import Figure

from ..geometry import arc_length
from ._finish import finish

if TYPE_CHECKING:
    from ..planning import Plan

__all__ = ["plan_figure"]


#: Colour of what lies over filled (unknown) ground.
FILLED_COLOUR = "#ff7f0e"


def plan_figure(plan: Plan, *, title: str | None = None,
                ground: dict | None = None, anchor: Any = None) -> Figure:
    """Map in lon/lat and side profile of a plan.

    The map (:class:`fm2uav.viz.mapfigure.LonLatMap`) shows the ground as shaded
    relief with contours, buildings as filled outlines, the no-fly zones with
    their floor and ceiling, the path coloured by its height above ground (colour
    bar), start and goal, a scale bar and lon/lat ticks. Filled DEM nodata (unknown
    ground, ``World.filled``) is hatched orange, the path over it is drawn in
    orange there and on the side profile (with the span shaded), and the subtitle
    says how much of the path flies over it. The side profile shows the ground,
    the roofs under the path and the requested level.

    Parameters
    ----------
    plan : Plan
        The plan to draw.
    title : str, optional
        Figure title.
    ground : dict, optional
        The known/unknown ground split of the summary
        (:func:`fm2uav.analysis.known_ground.ground_split`): its lengths go into
        the subtitle.
    anchor : Anchor, optional
        Placement of a world without CRS (the exports' default anchor).

    Returns
    -------
    matplotlib.figure.Figure
        Save it with ``fig.savefig(path, dpi=...)``.
    """
    from .mapfigure import LonLatMap

    world = plan.world
    path = plan.path
    b = world.bounds
    three_d = world.ndim == 3
    fig = Figure(figsize=(14 if three_d else 8, 6.0))
    axes = fig.subplots(1, 2 if three_d else 1, squeeze=False,
                        gridspec_kw={"width_ratios": [1.25, 1.0]} if three_d else None)
    ax = axes[0, 0]
    m = LonLatMap(ax, world, anchor)
    unknown = _unknown(world, path)
    level = getattr(plan, "level", None)
    requested = None if level is None else float(level.agl)
    if three_d:
        agl = path[:, 2] - np.asarray(world.ground_height(path[:, 0], path[:, 1]), dtype=float)
        m.agl_path(path, agl, requested, label="FM² path")
    else:
        m.path(path, color="crimson", lw=2, label="FM² path")
    if unknown is not None and unknown.any():
        m.path(np.where(_spans(unknown)[:, None], path, np.nan), color=FILLED_COLOUR, lw=3.5,
               label="path over FILLED ground")
    m.points(path[0], path[-1])
    m.scale_bar()
    ax.set_title("map")
    m.legend()
    if three_d:
        ax2 = axes[0, 1]
        s = arc_length(path)
        under = np.asarray(world.ground_height(path[:, 0], path[:, 1]), dtype=float)
        roofs = np.asarray(world.surface_height(path[:, 0], path[:, 1]), dtype=float)
        if world.terrain is not None:
            ax2.fill_between(s, b[2, 0], under, color="saddlebrown", alpha=0.5, label="ground")
        if np.any(roofs > under + 0.5 * world.spacing[2]):
            ax2.fill_between(s, under, np.maximum(roofs, under), color="#5f5f66", alpha=0.8,
                             lw=0, label="buildings under the path", step="mid")
        if requested is not None:
            ax2.plot(s, under + requested, color="#1a9641", lw=1, ls="--",
                     label=f"requested {requested:g} m above ground")
        ax2.plot(s, path[:, 2], color="crimson", lw=2, label="path altitude")
        if unknown is not None and unknown.any():
            on = _spans(unknown)
            ax2.plot(s, np.where(on, path[:, 2], np.nan), color=FILLED_COLOUR, lw=3,
                     label="over FILLED ground (invented heights)")
            for a, c in _runs(on):
                ax2.axvspan(s[a], s[c], color=FILLED_COLOUR, alpha=0.15, lw=0)
        ax2.set_xlabel("distance along path [m]")
        ax2.set_ylabel("altitude z [m]")
        ax2.set_ylim(b[2, 0], b[2, 1])
        ax2.set_title("side profile")
        ax2.legend(loc="upper left", fontsize=8)
        ax2.grid(alpha=0.3)
    p = plan.params
    sub = (f"length {plan.length:.0f} m · clearance {plan.clearance:.1f} m · "
           f"α={p.get('saturation', 1):g} β={p.get('exponent', 1):g}")
    if three_d:
        k = int(np.argmin(agl))
        sub += f" · lowest {agl[k]:.0f} m above ground at {s[k]:.0f} m"
    from ..world.ground import has_unknown_ground

    has_gaps = getattr(world, "filled", None) is not None and has_unknown_ground(world)
    note = _ground_note(ground, unknown) if has_gaps or (ground or {}).get("sources") else ""
    return finish(fig, title, sub + (f"\n{note}" if note else ""))


def _unknown(world, path: np.ndarray) -> np.ndarray | None:
    """Per path point: over filled (unknown) ground; None for worlds without DEM nodata."""
    if path.shape[1] != 3 or getattr(world, "filled", None) is None:
        return None
    return np.asarray(world.ground_filled(path[:, 0], path[:, 1]), dtype=bool)


def _spans(mask: np.ndarray) -> np.ndarray:
    """Points drawn as over filled ground: each flagged point and its neighbours (so a
    segment touching filled ground is drawn whole)."""
    out = mask.copy()
    out[1:] |= mask[:-1]
    out[:-1] |= mask[1:]
    return out


def _runs(mask: np.ndarray) -> list[tuple[int, int]]:
    m = np.r_[False, mask, False].astype(np.int8)
    edges = np.flatnonzero(np.diff(m))
    return [(int(a), int(b) - 1) for a, b in zip(edges[::2], edges[1::2])]


def _ground_note(ground: dict | None, unknown: np.ndarray | None) -> str:
    """The subtitle line about unknown ground (empty when the world has none)."""
    if ground:
        f, total = ground["filled"], ground["length_m"]
        if f["length_m"] > 0:
            low = (f.get("height_above_ground") or {}).get("min_m")
            return (f"WARNING: {f['length_m'] / 1000:.2f} km of {total / 1000:.2f} km "
                    f"({100 * f['share']:.0f} %) over FILLED DEM nodata (unknown ground)"
                    + ("" if low is None else f", lowest {low:.0f} m above invented ground"))
        return "all over measured ground"
    if unknown is not None and unknown.any():
        return "WARNING: part of the path is over FILLED DEM nodata (unknown ground)"
    return ""
