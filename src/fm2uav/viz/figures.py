"""Matplotlib figures of plans (PNG). Drawing only: every number comes from the plan."""

from __future__ import annotations

from typing import TYPE_CHECKING

import matplotlib
import numpy as np
from matplotlib.colors import LightSource
from matplotlib.figure import Figure

from ..geometry import arc_length
from ._finish import finish

if TYPE_CHECKING:
    from ..planning import Plan

__all__ = ["plan_figure"]


#: Colour of what lies over filled (unknown) ground.
FILLED_COLOUR = "#ff7f0e"


def plan_figure(plan: Plan, *, title: str | None = None,
                ground: dict | None = None) -> Figure:
    """Top view (on terrain shading or the occupancy) and side profile of a plan.

    Filled DEM nodata (unknown ground, ``World.filled``) is hatched on the top
    view, the path over it is drawn in orange there and on the side profile
    (with the span shaded), and the subtitle says how much of the path flies over
    it.

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

    Returns
    -------
    matplotlib.figure.Figure
        Save it with ``fig.savefig(path, dpi=...)``.
    """
    world = plan.world
    path = plan.path
    b = world.bounds
    extent = (b[0, 0], b[0, 1], b[1, 0], b[1, 1])
    three_d = world.ndim == 3
    fig = Figure(figsize=(13 if three_d else 7, 5.2))
    axes = fig.subplots(1, 2 if three_d else 1, squeeze=False,
                        gridspec_kw={"width_ratios": [1.1, 1.4]} if three_d else None)
    ax = axes[0, 0]
    if three_d and world.terrain is not None:
        ls = LightSource(azdeg=315, altdeg=45)
        rgb = ls.shade(world.terrain.T, cmap=matplotlib.colormaps["gist_earth"], vert_exag=2.0,
                       dx=world.spacing[0], dy=world.spacing[1], blend_mode="soft")
        ax.imshow(rgb, origin="lower", extent=extent, aspect="equal")
        cs = ax.contour(np.linspace(b[0, 0], b[0, 1], world.shape[0]),
                        np.linspace(b[1, 0], b[1, 1], world.shape[1]),
                        world.terrain.T, levels=10, colors="k", linewidths=0.4, alpha=0.5)
        ax.clabel(cs, fontsize=6, fmt="%.0f")
    else:
        occ2d = world.occupancy.any(axis=2) if three_d else world.occupancy
        ax.imshow(occ2d.T, origin="lower", extent=extent, cmap="Greys", aspect="equal")
    unknown = _unknown(world, path)
    if unknown is not None and np.asarray(world.filled).any():
        xs = np.linspace(b[0, 0], b[0, 1], world.shape[0])
        ys = np.linspace(b[1, 0], b[1, 1], world.shape[1])
        ax.contourf(xs, ys, np.asarray(world.filled, dtype=float).T, levels=[0.5, 1.5],
                    colors="none", hatches=["////"])
        ax.contour(xs, ys, np.asarray(world.filled, dtype=float).T, levels=[0.5],
                   colors=FILLED_COLOUR, linewidths=1.0)
        ax.plot([], [], color=FILLED_COLOUR, lw=1, label="filled DEM nodata (unknown ground)")
    ax.plot(path[:, 0], path[:, 1], color="crimson", lw=2, label="FM² path")
    if unknown is not None and unknown.any():
        ax.plot(np.where(_spans(unknown), path[:, 0], np.nan),
                np.where(_spans(unknown), path[:, 1], np.nan), color=FILLED_COLOUR, lw=3.5,
                label="path over FILLED ground")
    ax.plot(*path[0, :2], "o", color="limegreen", mec="k", ms=8, label="start")
    ax.plot(*path[-1, :2], "*", color="gold", mec="k", ms=13, label="goal")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_title("top view")
    ax.legend(loc="upper left", fontsize=8)
    if three_d:
        ax2 = axes[0, 1]
        s = arc_length(path)
        if world.terrain is not None:
            under = world.ground_height(path[:, 0], path[:, 1])
            ax2.fill_between(s, b[2, 0], under, color="saddlebrown", alpha=0.5, label="terrain")
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
