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


def plan_figure(plan: Plan, *, title: str | None = None) -> Figure:
    """Top view (on terrain shading or the occupancy) and side profile of a plan.

    Parameters
    ----------
    plan : Plan
        The plan to draw.
    title : str, optional
        Figure title.

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
    ax.plot(path[:, 0], path[:, 1], color="crimson", lw=2, label="FM² path")
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
            ground = world.ground_height(path[:, 0], path[:, 1])
            ax2.fill_between(s, b[2, 0], ground, color="saddlebrown", alpha=0.5, label="terrain")
        ax2.plot(s, path[:, 2], color="crimson", lw=2, label="path altitude")
        ax2.set_xlabel("distance along path [m]")
        ax2.set_ylabel("altitude z [m]")
        ax2.set_ylim(b[2, 0], b[2, 1])
        ax2.set_title("side profile")
        ax2.legend(loc="upper left", fontsize=8)
        ax2.grid(alpha=0.3)
    p = plan.params
    sub = (f"length {plan.length:.0f} m · clearance {plan.clearance:.1f} m · "
           f"α={p.get('saturation', 1):g} β={p.get('exponent', 1):g}")
    return finish(fig, title, sub)
