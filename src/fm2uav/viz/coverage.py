"""Figures of coverage plans: bands over the area, 3D path, path vs ideal profile;
the report of the coverage experiments.

Drawing only: every number comes from a :class:`~fm2uav.missions.coverage.Zigzag`,
a :class:`~fm2uav.missions.coverage.CoveragePlan` or a
:class:`~fm2uav.experiments.coverage.CoverageRun`.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np
from matplotlib.figure import Figure

from ..geometry import arc_length
from ._finish import finish

if TYPE_CHECKING:
    from ..experiments.coverage import CoverageRun
    from ..missions.coverage import CoveragePlan, Zigzag

__all__ = ["bands_figure", "coverage_figure", "coverage_html", "coverage_overlays",
           "coverage_tables_report"]


def _draw_area(ax, area, **kw) -> None:
    x, y = area.exterior.xy
    ax.fill(x, y, color=kw.get("color", "tab:blue"), alpha=0.18, lw=0)
    ax.plot(x, y, color=kw.get("color", "tab:blue"), lw=1.5, label=kw.get("label", "area"))
    for ring in area.interiors:
        hx, hy = ring.xy
        ax.fill(hx, hy, color="white", alpha=0.9, lw=0)
        ax.plot(hx, hy, color=kw.get("color", "tab:blue"), lw=1.0, ls="--")


def _draw_zigzag(ax, zz: Zigzag, *, bands_label: str = "bands") -> None:
    path = zz.path()
    ax.plot(path[:, 0], path[:, 1], color="0.35", lw=1.0, ls=":", label="turns / extensions")
    for k, seg in enumerate(zz.bands()):
        x, y = seg.xy
        ax.plot(x, y, color="crimson", lw=2.0, label=bands_label if k == 0 else None)
    for i in range(zz.n_bands - 1):
        arc = zz.arc_points(i)
        ax.plot(arc[:, 0], arc[:, 1], color="darkorange", lw=1.5,
                label="arcs" if i == 0 else None)
    ax.plot(*zz.start, "o", color="limegreen", mec="k", ms=8, label="start")
    ax.plot(*zz.goal, "*", color="gold", mec="k", ms=12, label="end")


def bands_figure(zz: Zigzag, *, title: str | None = None) -> Figure:
    """Top view of the zigzag over the area: bands, arcs, extensions, start/end."""
    fig = Figure(figsize=(7, 6))
    ax = fig.subplots()
    _draw_area(ax, zz.area)
    _draw_zigzag(ax, zz)
    ax.set_aspect("equal")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.legend(loc="best", fontsize=8)
    ax.grid(alpha=0.3)
    sub = (f"α = {zz.angle_deg:.3f}°, D = {zz.spacing:g} m, {zz.n_bands} bands, "
           f"cost {zz.cost:.1f} m")
    ax.set_title(f"{title}\n{sub}" if title else sub, fontsize=10)
    fig.tight_layout()
    return fig


def coverage_figure(cp: CoveragePlan, *, title: str | None = None, anchor: Any = None) -> Figure:
    """Map in lon/lat (relief, buildings, zones, the area, the zigzag and the path coloured by
    height above ground), 3D view and altitude profile (path vs ideal) of a coverage plan."""
    from .mapfigure import LonLatMap

    world = cp.plan.world
    path = cp.path
    b = world.bounds
    fig = Figure(figsize=(18, 5.8))
    ax = fig.add_subplot(1, 3, 1)
    m = LonLatMap(ax, world, anchor)
    area = cp.zigzag.area
    for k, ring in enumerate([area.exterior, *area.interiors]):
        ll = m.lonlat(np.asarray(ring.coords)[:, :2])
        ax.plot(ll[:, 0], ll[:, 1], color="#1f4e9e", lw=2.0 if k == 0 else 1.2,
                ls="-" if k == 0 else "--", zorder=6, label="area" if k == 0 else None)
    zz = m.lonlat(cp.zigzag.path())
    ax.plot(zz[:, 0], zz[:, 1], color="k", lw=0.6, ls=":", zorder=5, label="zigzag (planned)")
    if world.ndim == 3:
        agl = path[:, 2] - np.asarray(world.ground_height(path[:, 0], path[:, 1]), dtype=float)
        # hundreds of bands stay apart: thinner lines the more there are
        n = cp.zigzag.n_bands
        m.agl_path(path, agl, float(cp.level.agl), lw=1.8 if n <= 40 else max(0.4, 60.0 / n),
                   label="FM² path")
    else:
        m.path(path, color="crimson", lw=1.4, label="FM² path")
    m.points(path[0], path[-1])
    m.scale_bar()
    m.legend()
    ax.set_title("map", fontsize=10)

    ax3 = fig.add_subplot(1, 3, 2, projection="3d")
    thin = max(1, len(path) // 4000)
    if world.terrain is not None:
        step = max(1, world.shape[0] // 60)
        gx = world.origin[0] + world.spacing[0] * np.arange(world.shape[0])[::step]
        gy = world.origin[1] + world.spacing[1] * np.arange(world.shape[1])[::step]
        X, Y = np.meshgrid(gx, gy, indexing="ij")
        ax3.plot_surface(X, Y, world.terrain[::step, ::step], cmap="gist_earth", alpha=0.6,
                         linewidth=0, antialiased=False)
    q = path[::thin]
    if cp.zigzag.n_bands > 40:   # hundreds of bands: thin lines coloured by band order
        from mpl_toolkits.mplot3d.art3d import Line3DCollection

        segs = np.stack([q[:-1], q[1:]], axis=1)
        lc = Line3DCollection(segs, cmap="turbo", lw=0.6)
        lc.set_array(np.linspace(0.0, 1.0, len(segs)))
        ax3.add_collection3d(lc)
    else:
        ax3.plot(q[:, 0], q[:, 1], q[:, 2], color="crimson", lw=1.5)
    ax3.set_xlabel("x [m]")
    ax3.set_ylabel("y [m]")
    ax3.set_zlabel("z [m]")
    ax3.set_title("3D view", fontsize=10)

    ax2 = fig.add_subplot(1, 3, 3)
    s = arc_length(path)
    agl = cp.level.agl
    if world.terrain is not None:
        ground = world.ground_height(path[:, 0], path[:, 1])
        ax2.fill_between(s, b[2, 0], ground, color="saddlebrown", alpha=0.45, label="terrain")
        ax2.plot(s, ground + agl, color="k", lw=1.0, ls="--", label=f"ideal ({agl:g} m AGL)")
    ax2.plot(s, path[:, 2], color="crimson", lw=1.5, label="FM² path")
    ax2.set_xlabel("distance along path [m]")
    ax2.set_ylabel("altitude z [m]")
    ax2.legend(loc="upper left", fontsize=7)
    ax2.grid(alpha=0.3)
    ax2.set_title("path vs ideal profile", fontsize=10)
    e = np.abs(cp.agl_error)
    sub = (f"α = {cp.zigzag.angle_deg:.3f}°, D = {cp.zigzag.spacing:g} m, zigzag cost "
           f"{cp.zigzag.cost:.0f} m, FM² length {cp.plan.length:.0f} m, coverage "
           f"{100 * cp.coverage:.2f} %, |AGL error| mean {e.mean():.1f} m / max {e.max():.1f} m")
    return finish(fig, title, sub, fontsize=10)


def coverage_html(cp: CoveragePlan, *, title: str = "coverage plan") -> str:
    """Interactive 3D view (plotly) of the terrain, the area and the path, as an HTML string."""
    import plotly.graph_objects as go

    world = cp.plan.world
    path = cp.path
    data = []
    if world.terrain is not None:
        gx = world.origin[0] + world.spacing[0] * np.arange(world.shape[0])
        gy = world.origin[1] + world.spacing[1] * np.arange(world.shape[1])
        data.append(go.Surface(x=gx, y=gy, z=world.terrain.T, colorscale="Earth",
                               opacity=0.85, showscale=False, name="terrain"))
        ring = np.asarray(cp.zigzag.area.exterior.coords)
        rz = world.ground_height(ring[:, 0], ring[:, 1]) + 2.0
        data.append(go.Scatter3d(x=ring[:, 0], y=ring[:, 1], z=rz, mode="lines",
                                 line=dict(color="white", width=4), name="area"))
    data.append(go.Scatter3d(x=path[:, 0], y=path[:, 1], z=path[:, 2], mode="lines",
                             line=dict(color="crimson", width=5), name="FM² path"))
    fig = go.Figure(data=data)
    fig.update_layout(title=title, scene=dict(aspectmode="data", xaxis_title="x [m]",
                                              yaxis_title="y [m]", zaxis_title="z [m]"))
    return fig.to_html(include_plotlyjs=True, full_html=True)


def coverage_overlays(cp: CoveragePlan, prefix: str = "", colour: str = "#1a1a1a") -> dict:
    """Scene overlays of a coverage plan for :func:`~fm2uav.viz.report.report_html`: the
    area's rings and the bands (2D, draped on the terrain)."""
    from .report import join_polylines

    area = cp.zigzag.area
    rings = [np.asarray(area.exterior.coords)] + [np.asarray(r.coords) for r in area.interiors]
    out = {f"{prefix}area": {"points": join_polylines(rings), "color": colour, "width": 5}}
    bands = [np.asarray(b.coords) for b in cp.zigzag.bands()]
    if bands:
        out[f"{prefix}bands"] = {"points": join_polylines(bands), "color": "#ff7f0e",
                                 "dash": "dash", "width": 2}
    return out


def coverage_tables_report(run: CoverageRun, files: list[str]) -> str:
    """report.html of the coverage experiments: the four FM² paths and Tables 5.1 / 5.2."""
    from ..experiments.coverage import DE_SETTINGS, SEEDS_T51, SEEDS_T52
    from ..scenarios.coverage import COVERAGE_AGL, COVERAGE_SPACING
    from .report import report_html

    overlays: dict[str, Any] = {}
    for n, cp in run.plans.items():
        overlays.update(coverage_overlays(cp, prefix=f"{n} "))
    t51_rows = [{"surface": n, **r, "seeds min cost": SEEDS_T51[n][0],
                 "seeds α": SEEDS_T51[n][1]} for n, r in run.table_5_1.items()]
    t52_rows = [{"D [m]": d, **r, "seeds min cost": SEEDS_T52[d][0],
                 "seeds α": SEEDS_T52[d][1]} for d, r in run.table_5_2.items()]
    return report_html(
        run.world, {f"{n} FM² path": cp.path for n, cp in run.plans.items()},
        speeds={f"{n} FM² path": cp.plan.w for n, cp in run.plans.items()},
        ideal_agl={f"{n} FM² path": COVERAGE_AGL for n in run.plans},
        overlays=overlays,
        title="Coverage experiments (paper 003 / thesis ch. 5)",
        subtitle=f"areas {', '.join(run.plans)}, D = {COVERAGE_SPACING:g} m, FM² at "
                 f"{COVERAGE_AGL:g} m above the terrain, steering angle from the DE",
        params={"seed": run.seed, "D [m]": COVERAGE_SPACING, "agl [m]": COVERAGE_AGL,
                "DE": DE_SETTINGS},
        metrics={n: f"α {r['min_alpha']:.3f}°, cost {r['min_cost']:.1f} m, coverage "
                    f"{r['coverage_pct']:.2f} %, FM² {r['fm2_length']:.0f} m"
                 for n, r in run.table_5_1.items()},
        tables={"Table 5.1 — D = 80 m": t51_rows,
                "Table 5.2 — S1, different D": t52_rows},
        files=files)
