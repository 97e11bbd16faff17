"""Figures of the α–β sweep (seed 004, Figs 8/12, 9/13 and 10/14).

Drawing only: every number comes from :func:`fm2uav.experiments.sweep.summarise_sweep`.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
from matplotlib.colors import LogNorm
from matplotlib.figure import Figure

__all__ = ["heatmap_figure", "best_paths_figure", "curvature_figure", "sweep_report_html"]

_TITLES = {"dubins": "Dubins", "elastica": "Euler–Mumford elastica", "rs": "Reeds–Shepp forward"}
_UNITS = {"frechet": "mean Fréchet distance [m]", "area": "mean area between curves [m²]"}


def heatmap_figure(
    matrices: Mapping[str, np.ndarray],
    alphas: np.ndarray,
    betas: np.ndarray,
    *,
    metric: str,
    best: Mapping[str, Mapping[str, float]] | None = None,
    valleys: Mapping[str, Mapping[str, Any]] | None = None,
    near: Mapping[str, Mapping[str, Any]] | None = None,
) -> Figure:
    """Distance matrices over (α, β), one panel per model (Figs 8 and 12).

    Colours are logarithmic; the white line is the valley (best β for each
    α), the star the best (α, β), the open circles the (α, β) within 1 % of
    the best (``near``: :func:`fm2uav.experiments.sweep.near_best` per model).
    """
    models = list(matrices)
    fig = Figure(figsize=(5.0 * len(models), 4.4), layout="constrained")
    axes = fig.subplots(1, len(models), squeeze=False)[0]
    for ax, model in zip(axes, models):
        m = np.asarray(matrices[model], dtype=float)
        finite = np.isfinite(m) & (m > 0)
        shown = np.where(finite, m, np.nan)
        norm = LogNorm(vmin=np.nanmin(shown), vmax=np.nanmax(shown)) if finite.any() else None
        da = (alphas[1] - alphas[0]) / 2 if len(alphas) > 1 else 0.01
        db = (betas[1] - betas[0]) / 2 if len(betas) > 1 else 0.01
        im = ax.imshow(shown, origin="lower", aspect="auto", cmap="viridis", norm=norm,
                       extent=(betas[0] - db, betas[-1] + db, alphas[0] - da, alphas[-1] + da))
        fig.colorbar(im, ax=ax, label=_UNITS.get(metric, metric))
        if valleys and model in valleys:
            v = valleys[model]
            ax.plot(v["beta_best"], v["alpha"], "w-", lw=1.2, label="best β for each α")
        if near and model in near and near[model].get("points"):
            pts = np.asarray(near[model]["points"], dtype=float)
            ax.plot(pts[:, 1], pts[:, 0], "o", mfc="none", mec="white", ms=6,
                    label=f"within 1 % of the best ({len(pts)})")
        if best and model in best:
            b = best[model]
            ax.plot(b["beta"], b["alpha"], marker="*", color="red", ms=14, mec="white",
                    label=f"best α={b['alpha']:.2f}, β={b['beta']:.2f}")
            ax.legend(loc="upper right", fontsize=8)
        ax.set_xlabel("exponent β")
        ax.set_ylabel("saturation α")
        ax.set_title(_TITLES.get(model, model))
    fig.suptitle(f"FM² vs curvature-penalised references: {_UNITS.get(metric, metric)}")
    return fig


def best_paths_figure(
    world,
    paths: Mapping[str, Sequence[tuple[np.ndarray, np.ndarray] | None]],
    best: Mapping[str, Mapping[str, float]],
    *,
    metric: str,
) -> Figure:
    """FM² paths at the best (α, β) (yellow) and the references (red) (Figs 9 and 13)."""
    models = [m for m in paths if paths[m]]
    fig = Figure(figsize=(5.2 * max(len(models), 1), 4.2), layout="constrained")
    axes = fig.subplots(1, max(len(models), 1), squeeze=False)[0]
    (x0, x1), (y0, y1) = world.bounds
    for ax, model in zip(axes, models):
        ax.imshow(world.occupancy.T, origin="lower", cmap="gray_r", extent=(x0, x1, y0, y1),
                  vmin=0, vmax=1.6)
        for k, pp in enumerate(paths[model]):
            if pp is None:
                continue
            fm2, ref = pp
            ax.plot(ref[:, 0], ref[:, 1], "-", color="red", lw=1.0,
                    label=_TITLES.get(model, model) if k == 0 else None)
            ax.plot(fm2[:, 0], fm2[:, 1], "-", color="gold", lw=1.0, label="FM²" if k == 0 else None)
        b = best.get(model, {})
        ax.set_title(f"{_TITLES.get(model, model)}: α={b.get('alpha', np.nan):.2f}, "
                     f"β={b.get('beta', np.nan):.2f}")
        ax.set_xlabel("x [m]")
        ax.set_ylabel("y [m]")
        ax.legend(loc="lower right", fontsize=8)
    fig.suptitle(f"Best FM² match per model ({metric})")
    return fig


def curvature_figure(profiles: Mapping[str, Mapping[str, Mapping[str, np.ndarray]]], *, metric: str) -> Figure:
    """Curvature of the references (left) and their best FM² match (right) (Figs 10 and 14).

    Raw point-to-point curvature in blue, DCT-PLS smoothed in red.
    """
    models = list(profiles)
    fig = Figure(figsize=(10, 2.6 * max(len(models), 1)), layout="constrained")
    axes = fig.subplots(max(len(models), 1), 2, squeeze=False)
    for row, model in zip(axes, models):
        for ax, which in zip(row, ("reference", "fm2")):
            prof = profiles[model][which]
            ax.plot(prof["s"], prof["kappa"], "-", color="tab:blue", lw=0.7, label="raw")
            if "kappa_smooth" in prof:
                ax.plot(prof["s"], prof["kappa_smooth"], "-", color="red", lw=1.2, label="smoothed")
            name = _TITLES.get(model, model) if which == "reference" else f"FM² ≈ {_TITLES.get(model, model)}"
            ax.set_title(name, fontsize=10)
            ax.set_xlabel("arc length [m]")
            ax.set_ylabel("curvature [1/m]")
            ax.legend(loc="upper right", fontsize=7)
    fig.suptitle(f"Curvature profiles, first pair ({metric} best match)")
    return fig


def sweep_report_html(world, summary: Mapping[str, Any], *, title: str, subtitle: str = "",
                      params: Mapping[str, Any] | None = None,
                      files: Sequence[str] = ()) -> str:
    """report.html of a sweep (``fm2uav sweep --report``): on the map, the FM² paths at
    the best (α, β) by area and the references of every pair (one trace per model), and
    the best-parameter and timing tables of ``summary``
    (:func:`fm2uav.experiments.sweep.summarise_sweep`)."""
    from .report import join_polylines, report_html

    paths: dict[str, np.ndarray] = {}
    overlays: dict[str, Any] = {}
    colours = {"dubins": "#d62728", "elastica": "#9467bd", "rs": "#8c564b"}
    for model, pairs in summary.get("paths", {}).get("area", {}).items():
        done = [pp for pp in (pairs or []) if pp is not None]
        if not done:
            continue
        name = _TITLES.get(model, model)
        paths[f"FM² best area vs {name}, pair 1"] = np.asarray(done[0][0], dtype=float)
        overlays[f"FM² best area vs {name}, all pairs"] = {
            "points": join_polylines([d[0] for d in done]), "color": "#e6b800"}
        overlays[f"{name} references"] = {"points": join_polylines([d[1] for d in done]),
                                          "color": colours.get(model, "#d62728"),
                                          "dash": "dash"}
    if not paths:
        raise ValueError("the sweep has no finished case to draw (every case failed)")
    best_rows = [{"metric": metric, "model": _TITLES.get(model, model),
                  "alpha": b["alpha"], "beta": b["beta"], "value": round(float(b["value"]), 4)}
                 for metric, by_model in summary.get("best", {}).items()
                 for model, b in by_model.items()]
    timing = summary.get("timing", {})
    return report_html(
        world, paths, title=title, subtitle=subtitle, overlays=overlays, params=params or {},
        metrics={k: (round(v, 4) if isinstance(v, float) else v) for k, v in timing.items()},
        tables={"Best (α, β) per metric and model (Tables 2 and 3)": best_rows},
        files=files)
