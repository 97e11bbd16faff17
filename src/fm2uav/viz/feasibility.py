"""Figures of the airframe checks: planned vs flown paths, speed profiles, FM² vs RRT.

Drawing only: every number comes from the reports passed in.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

import numpy as np
from matplotlib.figure import Figure

from ..geometry import arc_length

if TYPE_CHECKING:
    from ..baselines.rrt import RRTResult
    from ..experiments.city import CityRun
    from ..vehicles import FeasibilityReport
    from ..world import World

__all__ = ["tracking_figure", "speed_profiles_figure", "city_cases_figure", "rrt_figure",
           "city_report_html"]


def _footprint(ax: Any, world: World | None) -> None:
    if world is None:
        return
    b = world.bounds
    occ = world.occupancy
    top = occ[:, :, 1:].any(axis=2) if occ.ndim == 3 else occ  # skip the ground layer
    ax.imshow(top.T, origin="lower", extent=(b[0, 0], b[0, 1], b[1, 0], b[1, 1]),
              cmap="Greys", vmin=0, vmax=1.4, alpha=0.6, aspect="equal")


def tracking_figure(report: FeasibilityReport, world: World | None = None, *,
                    title: str | None = None, anchor: Any = None) -> Figure:
    """Planned vs flown path (map in lon/lat on a world, else a top view in the path's
    metres; altitude; separation) of one feasibility report."""
    tr = report.tracking
    planned, flown = tr.planned, tr.trajectory
    fig = Figure(figsize=(16, 5))
    axes = fig.subplots(1, 3, gridspec_kw={"width_ratios": [1.1, 1.3, 1.3]})
    ax = axes[0]
    sat = np.zeros(len(flown), bool)
    for v in tr.saturated.values():
        sat |= v
    if world is not None:      # a map in lon/lat: relief, buildings, zones
        from .mapfigure import LonLatMap

        m = LonLatMap(ax, world, anchor)
        m.path(planned, color="tab:blue", lw=2, label="planned")
        m.path(flown, color="crimson", lw=1.2, ls="--", label="flown")
        if sat.any():
            m.path(flown[sat], ls="none", marker=".", color="orange", ms=3,
                   label="limit saturated")
        m.scale_bar()
        m.legend(ncol=2)
        ax.set_title("map")
    else:
        ax.plot(planned[:, 0], planned[:, 1], color="tab:blue", lw=2, label="planned")
        ax.plot(flown[:, 0], flown[:, 1], color="crimson", lw=1.2, ls="--", label="flown")
        if sat.any():
            ax.plot(flown[sat, 0], flown[sat, 1], ".", color="orange", ms=3,
                    label="limit saturated")
        ax.set_xlabel("x [m]")
        ax.set_ylabel("y [m]")
        ax.set_aspect("equal")
        ax.set_title("top view (no world: x/y of the path file)")
        ax.legend(fontsize=8, loc="upper left")
    ax = axes[1]
    ax.plot(arc_length(planned), planned[:, 2], color="tab:blue", lw=2, label="planned")
    ax.plot(tr.progress, flown[:, 2], color="crimson", lw=1.2, ls="--", label="flown")
    ax.set_xlabel("distance along the plan [m]")
    ax.set_ylabel("altitude z [m]")
    ax.set_title("altitude")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    ax = axes[2]
    ax.plot(tr.progress, tr.separation, color="k", lw=1.2)
    ax.axhline(report.tolerance, color="crimson", ls=":", label=f"tolerance {report.tolerance:g} m")
    ax.set_xlabel("distance along the plan [m]")
    ax.set_ylabel("separation flown ↔ planned [m]")
    ax.set_title(f"separation: max {tr.max_separation:.2f} m, mean {tr.mean_separation:.2f} m")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    verdict = "FEASIBLE" if report.feasible else "INFEASIBLE"
    head = f"{title} — " if title else ""
    fig.suptitle(f"{head}{report.airframe.name}: {verdict}\n{report.reason}", fontsize=10)
    fig.tight_layout()
    return fig


def speed_profiles_figure(profiles: dict[str, tuple[np.ndarray, np.ndarray]], *,
                          title: str = "velocity profiles", ylabel: str = "W (0 = stall, 1 = max)"
                          ) -> Figure:
    """Fig. 3.4 style: one curve per label, ``label -> (s [m], value)``."""
    fig = Figure(figsize=(8, 4.2))
    ax = fig.subplots()
    for label, (s, v) in profiles.items():
        ax.plot(s, v, lw=1.6, label=label)
    ax.set_xlabel("distance along the path [m]")
    ax.set_ylabel(ylabel)
    ax.set_ylim(bottom=0)
    ax.grid(alpha=0.3)
    ax.legend()
    ax.set_title(title)
    fig.tight_layout()
    return fig


def city_cases_figure(cases: Sequence[Any], world: World, *, title: str = "") -> Figure:
    """Figs. 3.2/3.3/3.7 style: per exponent, top view and altitude of planned vs flown."""
    n = len(cases)
    fig = Figure(figsize=(5.2 * n, 9))
    axes = fig.subplots(2, n, squeeze=False)
    for j, c in enumerate(cases):
        tr = c.report.tracking
        ax = axes[0, j]
        _footprint(ax, world)
        ax.plot(c.path3[:, 0], c.path3[:, 1], color="tab:blue", lw=2, label="FM² planned")
        ax.plot(tr.trajectory[:, 0], tr.trajectory[:, 1], color="crimson", ls="--", lw=1.2,
                label="Dubins flown")
        ax.set_title(f"W^{c.exponent:g}: safety {c.plan.clearance:.1f} m, "
                     f"separation {tr.max_separation:.2f} m", fontsize=9)
        ax.set_xlabel("x [m]")
        ax.set_ylabel("y [m]")
        ax.legend(fontsize=7, loc="upper left")
        ax = axes[1, j]
        ax.plot(arc_length(c.path3), c.path3[:, 2], color="tab:blue", lw=2, label="planned")
        ax.plot(tr.progress, tr.trajectory[:, 2], color="crimson", ls="--", lw=1.2, label="flown")
        ax.set_xlabel("distance along the plan [m]")
        ax.set_ylabel("z [m]")
        ax.grid(alpha=0.3)
        ax.set_title("feasible" if c.report.feasible else "infeasible: " + c.report.reasons[0][:60],
                     fontsize=8)
    fig.suptitle(title)
    fig.tight_layout()
    return fig


def rrt_figure(world: World, results: dict[str, RRTResult], fm2_path: np.ndarray, *,
               title: str = "FM² vs RRT") -> Figure:
    """Thesis Fig. 3.5 style: trees (black), raw paths (red), smoothed (green), FM² (blue)."""
    n = len(results)
    fig = Figure(figsize=(5.5 * n, 5.5))
    axes = fig.subplots(1, n, squeeze=False)
    for ax, (name, r) in zip(axes[0], results.items()):
        _footprint(ax, world)
        for e in r.tree[: 5000]:
            ax.plot(e[:, 0], e[:, 1], color="k", lw=0.3, alpha=0.5)
        ax.plot(r.raw[:, 0], r.raw[:, 1], color="red", lw=1.2, label="raw")
        ax.plot(r.path[:, 0], r.path[:, 1], color="green", lw=2, label="smoothed")
        ax.plot(fm2_path[:, 0], fm2_path[:, 1], color="tab:blue", lw=2, label="FM²")
        ax.set_title(f"{r.planner}: {r.timings['total'] * 1e3:.0f} ms, clearance {r.clearance:.1f} m",
                     fontsize=9)
        ax.legend(fontsize=7, loc="upper left")
        ax.set_xlabel("x [m]")
        ax.set_ylabel("y [m]")
    fig.suptitle(title)
    fig.tight_layout()
    return fig


def city_report_html(run: CityRun, files: list[str]) -> str:
    """report.html of ``reproduce city``: FM² paths of both missions, their Dubins-flown
    tracks, the RRT paths and both tables."""
    from .report import join_polylines, report_html

    cases, af, rows = run.cases, run.airframe, run.rows
    paths = {f"FM² {c.mission} W^{c.exponent:g}": c.path3 for c in cases}
    speeds = {f"FM² {c.mission} W^{c.exponent:g}": c.plan.w for c in cases}
    paths.update(run.rrt_paths)
    flown = join_polylines([c.report.tracking.trajectory for c in cases])
    cols = ["mission", "exponent", "safety_m", "thesis_safety_m", "separation_max_m",
            "thesis_separation_m", "length_m", "plan_s", "feasible"]
    return report_html(
        cases[0].world3, paths, speeds=speeds,
        title="Thesis ch. 3: FM² in the city, Dubins-flown, vs RRT",
        subtitle=f"low- and high-altitude missions with W^1, W^1/2, W^1/4 flown by the "
                 f"{af.name}; OMPL planners on the low mission",
        overlays={f"flown tracks ({af.name})": {"points": flown, "color": "#222222",
                                               "dash": "dash", "width": 2}},
        params={"seed": run.seed, "airframe": af.name, "tolerance [m]": run.tolerance},
        metrics={f"{r['mission']} W^{r['exponent']:g}": (
            f"safety {r['safety_m']} m, separation {r['separation_max_m']} m, "
            f"{'feasible' if r['feasible'] else 'INFEASIBLE'}") for r in rows},
        tables={"Safety and separation distances (Tables 3.1/3.2)":
                [{c: r[c] for c in cols} for r in rows],
                "FM² vs RRT, low altitude": run.rrt_rows},
        files=files)
