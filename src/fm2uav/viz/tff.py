"""Figures and reports of the terrain-following experiments (TFF paper figs. 7-13).

Drawing only: the caller passes plans and their agl (or a
:class:`~fm2uav.experiments.tff.TffRun`); every number comes from
:mod:`fm2uav.analysis` (profiles, flight-level deviation) and
:mod:`fm2uav.experiments.tff`.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

import numpy as np
from matplotlib.figure import Figure

from ..analysis.flight_level import ideal_altitude
from ..analysis.profiles import path_profiles
from ..geometry import arc_length

if TYPE_CHECKING:
    from ..experiments.tff import TffRun
    from ..planning import Plan
    from ..scenarios import Scenario

__all__ = ["tff_3d_figure", "tff_profile_figure", "tff_kinematics_figure", "tff_figures",
           "tff_report_html"]


def tff_3d_figure(plans: Sequence[Plan], labels: Sequence[str], *, title: str = "") -> Figure:
    """3D view of the terrain (from the first plan's world) with the paths."""
    world = plans[0].world
    fig = Figure(figsize=(8.5, 6.0))
    ax = fig.add_subplot(projection="3d")
    if world.terrain is not None:
        step = max(1, int(max(world.shape[:2]) // 90))
        t = world.terrain[::step, ::step]
        xs = world.origin[0] + np.arange(world.shape[0])[::step] * world.spacing[0]
        ys = world.origin[1] + np.arange(world.shape[1])[::step] * world.spacing[1]
        X, Y = np.meshgrid(xs - world.origin[0], ys - world.origin[1], indexing="ij")
        ax.plot_surface(X, Y, t, cmap="terrain", linewidth=0, alpha=0.35, antialiased=False, zorder=1)
    for p, lab in zip(plans, labels):
        q = p.path
        ax.plot(q[:, 0] - world.origin[0], q[:, 1] - world.origin[1], q[:, 2], lw=2.2, label=lab, zorder=10)
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_zlabel("z [m]")
    ax.legend(loc="upper left", fontsize=8)
    ax.set_title(title)
    ax.view_init(elev=28, azim=-70)
    fig.tight_layout()
    return fig


def tff_profile_figure(
    plans: Sequence[Plan], agls: Sequence[float], labels: Sequence[str], *, title: str = ""
) -> Figure:
    """Path vs ideal path (terrain + agl) vs terrain along the arc length, one panel per plan."""
    n = len(plans)
    fig = Figure(figsize=(8.5, 2.3 * n + 0.6))
    axes = fig.subplots(n, 1, squeeze=False)
    for ax, p, agl, lab in zip(axes[:, 0], plans, agls, labels):
        q = p.path
        s = arc_length(q)
        ground = p.world.surface_height(q[:, 0], q[:, 1])
        ideal = ideal_altitude(p.world, q, agl)
        ax.fill_between(s, p.world.origin[2], ground, color="0.8", label="terrain")
        ax.plot(s, ideal, "g--", lw=1.2, label=f"ideal (terrain + {agl:g} m)")
        ax.plot(s, q[:, 2], "b-", lw=1.6, label="FM² path")
        dz = p.world.spacing[2]
        ax.fill_between(s, ideal - dz, ideal + dz, color="g", alpha=0.12, label="±1 cell")
        lo = float(min(ground.min(), q[:, 2].min())) - 2 * dz
        ax.set_ylim(max(lo, p.world.origin[2]), float(max(q[:, 2].max(), ideal.max())) + 2 * dz)
        ax.set_ylabel("z [m]")
        ax.set_title(lab, fontsize=9)
    axes[-1, 0].set_xlabel("arc length [m]")
    axes[0, 0].legend(fontsize=7, ncol=4, loc="upper right")
    if title:
        fig.suptitle(title)
    fig.tight_layout()
    return fig


def tff_kinematics_figure(
    plans: Sequence[Plan], labels: Sequence[str], *, ds: float | None = None, title: str = ""
) -> Figure:
    """Turn angle, climb angle and curvature profiles (figs. 11-13 of the TFF paper)."""
    fig = Figure(figsize=(8.5, 7.5))
    axes = fig.subplots(3, 1, sharex=True)
    for p, lab in zip(plans, labels):
        step = ds if ds is not None else float(max(p.world.spacing[:2]))
        pr = path_profiles(p.path, ds=step)
        axes[0].plot(pr.s[1:-1], np.degrees(pr.turn), lw=1.2, label=lab)
        axes[1].plot(pr.s[:-1], np.degrees(pr.climb), lw=1.2, label=lab)
        axes[2].plot(pr.s[1:-1], pr.curvature, lw=1.2, label=lab)
    axes[0].set_ylabel("turn angle [deg/step]")
    axes[1].set_ylabel("climb angle [deg]")
    axes[2].set_ylabel("curvature [1/m]")
    axes[2].set_xlabel("arc length [m]")
    axes[0].legend(fontsize=8)
    for ax in axes:
        ax.grid(alpha=0.3)
    if title:
        fig.suptitle(title)
    fig.tight_layout()
    return fig


def tff_figures(run: TffRun) -> dict[str, Figure]:
    """The five figures of ``reproduce tff``, by file name: 3D views, path-vs-ideal
    profiles (flight levels; smoothness at level 10) and turn/climb/curvature profiles."""
    from ..experiments.tff import LEVEL_CASES, SMOOTH_CASES

    plans, labels = run.plans, run.labels
    agls = [r["agl_m"] for r in run.rows]
    lv, sm = LEVEL_CASES, SMOOTH_CASES
    name = run.scenario_name
    return {
        "tff_3d_levels.png": tff_3d_figure([plans[i] for i in lv], [labels[i] for i in lv],
                                           title=f"Flight levels — {name}"),
        "tff_3d_smoothness.png": tff_3d_figure(
            [plans[i] for i in sm], [labels[i] for i in sm],
            title=f"Smoothness at level 10 — {name}"),
        "tff_profile_levels.png": tff_profile_figure(
            [plans[i] for i in lv], [agls[i] for i in lv], [labels[i] for i in lv],
            title="Path vs ideal path vs terrain"),
        "tff_profile_smoothness.png": tff_profile_figure(
            [plans[i] for i in sm], [agls[i] for i in sm], [labels[i] for i in sm],
            title="Path vs ideal path vs terrain (level 10)"),
        "tff_kinematics.png": tff_kinematics_figure(
            [plans[i] for i in sm], [labels[i] for i in sm],
            title="Turn, climb and curvature profiles (level 10)"),
    }


def tff_report_html(plans: Sequence[Plan], rows: list[dict[str, Any]], labels: Sequence[str],
                    sc: Scenario, *, title: str, params: dict[str, Any], files: list[str],
                    table_title: str = "Terrain-following cases",
                    extra_tables: dict[str, list[dict[str, Any]]] | None = None,
                    figures: dict[str, str] | None = None) -> str:
    """report.html of terrain-following paths: each path vs its ideal level, the case table.

    ``rows`` are :func:`fm2uav.experiments.tff.run_tff` rows (or rows with the same keys);
    ``figures``: the operator's figures beside the map (default: length and lowest height
    above ground of each path).
    """
    from ..experiments.tff import tff_table_rows
    from .report import report_html

    return report_html(
        sc.world, {lab: p.path for lab, p in zip(labels, plans)},
        speeds={lab: p.w for lab, p in zip(labels, plans)},
        ideal_agl={lab: r["agl_m"] for lab, r in zip(labels, rows)},
        title=title, subtitle=sc.description, params=params,
        metrics={lab: f"within ±1 cell {r['within']:.0%}, mean |dev| {r['mean_dev_all_m']:.1f} m, "
                      f"max climb {r['climb_max_deg']:.0f}°, length {r['length_m']:.0f} m"
                 for lab, r in zip(labels, rows)},
        tables={table_title: tff_table_rows(rows), **(extra_tables or {})}, files=files,
        figures=figures)
