"""Seed 004 §3.5 (Fig. 16): a fixed-wing and a quadcopter fly the FM² paths that best match
the Dubins reference.

The seed runs Simulink's UAV Waypoint Follower (pure pursuit, look-ahead 40 m, heading
gain 2) on "the FM² path that better approximates the Dubins path" and finds the
difference between planned and flown paths "negligible". Here:

* the best match is the (α, β) with the least mean area to the Dubins reference over a
  sweep of the seed's 24 city2d pairs (:func:`best_dubins_match`; the grid step is a
  parameter, a coarse one by default);
* every pair's FM² path at that (α, β) is flown by the pure-pursuit Dubins airplane
  (:func:`fm2uav.vehicles.track_dubins`, the ``disco`` preset) and by the multirotor
  model (:func:`fm2uav.vehicles.track_multirotor`, ``arducopter``), each with the seed's
  40 m look-ahead and with our default (the fixed-wing's turn radius, the multirotor's
  1 s of flight);
* each path's peak curvature (Menger on the path resampled every 1 m, raw and
  DCT-smoothed as in the seed's Figs 10/14) is compared with the bound of the Dubins model,
  1/ξ (0.1 1/m for ξ = 10 m), which the FM² path does not know about.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from .. import progress
from ..vehicles import TrackingOptions, get_airframe, track_dubins, track_multirotor
from .curvature import curvature_config, summarise_run
from .runner import make_config, run_sweep
from .sweep import curvature_profile

__all__ = ["LOOKAHEADS", "VEHICLES", "TrackingRun", "best_dubins_match", "reproduce_tracking",
           "tracking_markdown", "tracking_summary"]

#: The seed's look-ahead [m] and ours (None = the model's default).
LOOKAHEADS: tuple[float | None, ...] = (40.0, None)
#: The two vehicles: (label, airframe preset, simulator).
VEHICLES: tuple[tuple[str, str, Callable[..., Any]], ...] = (
    ("fixed-wing", "disco", track_dubins),
    ("quadcopter", "arducopter", track_multirotor),
)


def best_dubins_match(out_dir: str | Path, *, step: float = 0.1, pairs: int = 24,
                      xi: float = 10.0, workers: int = 1) -> tuple[Any, dict[str, Any]]:
    """Sweep α, β = step:step:1 against the Dubins reference only (resumable in ``out_dir``)
    and return ``(config, summary)`` of :func:`~fm2uav.experiments.curvature.summarise_run`."""
    base = curvature_config(step, pairs=pairs, xi=xi)
    config = make_config({**base.model_dump(), "models": ["dubins"]}, where="reproduce tracking")
    result = run_sweep(config, out_dir, workers=workers)
    _world, summary = summarise_run(config, result)
    return config, summary


@dataclass(eq=False)
class TrackingRun:
    """One row per (pair, vehicle, look-ahead) and the path's curvature per pair."""

    alpha: float
    beta: float
    xi: float
    step: float
    rows: list[dict[str, Any]] = field(default_factory=list)
    paths: list[dict[str, Any]] = field(default_factory=list)
    #: ``(FM² path, Dubins reference)`` [m] of each pair flown, as in ``paths``.
    tracks: list[tuple[np.ndarray, np.ndarray]] = field(default_factory=list, repr=False)


@progress.stage()
def reproduce_tracking(out_dir: str | Path, *, step: float = 0.1, pairs: int = 24,
                       xi: float = 10.0, workers: int = 1,
                       summary: dict[str, Any] | None = None) -> TrackingRun:
    """The tracking experiment on the best area match to Dubins (see the module docstring).

    ``out_dir`` holds the Dubins sweep (resumed when it exists); ``summary``: use the
    :func:`~fm2uav.experiments.curvature.summarise_run` of a finished sweep that includes
    the Dubins model (on the grid ``step``) instead.
    """
    if summary is None:
        progress.step(f"sweeping α, β (step {step:g}) against the Dubins reference "
                      f"({pairs} pairs)", 0.8)
        _config, summary = best_dubins_match(out_dir, step=step, pairs=pairs, xi=xi,
                                             workers=workers)
    best = summary["best"]["area"]["dubins"]
    run = TrackingRun(alpha=best["alpha"], beta=best["beta"], xi=xi, step=step)
    bound = 1.0 / xi
    progress.step(f"flying the FM² paths at α = {best['alpha']:g}, β = {best['beta']:g}", 1.0)
    for k, pair in enumerate(summary["paths"]["area"]["dubins"]):
        if pair is None:
            continue
        fm2, ref = pair
        kp = curvature_profile(fm2, ds=1.0)
        kr = curvature_profile(ref, ds=1.0)
        peak = float(np.abs(kp["kappa"]).max()) if len(kp["kappa"]) else 0.0
        peak_s = float(np.abs(kp["kappa_smooth"]).max()) if len(kp["kappa"]) else 0.0
        info = {"pair": k, "length_m": float(np.linalg.norm(np.diff(fm2, axis=0), axis=1).sum()),
                "peak_kappa": peak, "peak_kappa_smooth": peak_s,
                "reference_peak_kappa": float(np.abs(kr["kappa"]).max()) if len(kr["kappa"]) else 0.0,
                "above_bound": peak > bound, "smooth_above_bound": peak_s > bound}
        run.paths.append(info)
        run.tracks.append((np.asarray(fm2, dtype=float), np.asarray(ref, dtype=float)))
        for label, preset, fly in VEHICLES:
            af = get_airframe(preset)
            for la in LOOKAHEADS:
                tr = fly(fm2, af, tracking=TrackingOptions(lookahead=la))
                run.rows.append({"pair": k, "vehicle": label, "airframe": preset,
                                 "lookahead_m": float(tr.lookahead),
                                 "seed_lookahead": la is not None,
                                 "reached": bool(tr.reached),
                                 "max_error_m": float(tr.max_separation),
                                 "mean_error_m": float(tr.mean_separation),
                                 "saturated_s": float(sum(tr.saturation_time().values())),
                                 "peak_kappa": peak})
    return run


def _agg(rows: list[dict[str, Any]]) -> dict[str, Any]:
    mx = np.array([r["max_error_m"] for r in rows])
    mean = np.array([r["mean_error_m"] for r in rows])
    return {"paths": len(rows), "reached": sum(r["reached"] for r in rows),
            "max_error_median_m": float(np.median(mx)), "max_error_max_m": float(mx.max()),
            "mean_error_mean_m": float(mean.mean()),
            "worst_pair": int(rows[int(np.argmax(mx))]["pair"]),
            "saturated_s_mean": float(np.mean([r["saturated_s"] for r in rows]))}


def tracking_summary(run: TrackingRun) -> dict[str, Any]:
    """Aggregates per vehicle and look-ahead, and the curvature counts."""
    bound = 1.0 / run.xi
    k = np.array([p["peak_kappa"] for p in run.paths])
    ks = np.array([p["peak_kappa_smooth"] for p in run.paths])
    groups: dict[str, Any] = {}
    for label, _preset, _fly in VEHICLES:
        for seed_la in (True, False):
            rows = [r for r in run.rows if r["vehicle"] == label and r["seed_lookahead"] == seed_la]
            if rows:
                la = "40 m (seed)" if seed_la else "default"
                groups[f"{label}, look-ahead {la}"] = _agg(rows) | {
                    "lookahead_m": float(np.median([r["lookahead_m"] for r in rows]))}
    return {"alpha": run.alpha, "beta": run.beta, "grid_step": run.step, "xi_m": run.xi,
            "bound_per_m": bound, "paths": len(run.paths),
            "peak_kappa_min": float(k.min()), "peak_kappa_median": float(np.median(k)),
            "peak_kappa_max": float(k.max()), "above_bound": int((k > bound).sum()),
            "peak_kappa_smooth_median": float(np.median(ks)),
            "smooth_above_bound": int((ks > bound).sum()),
            "vehicles": groups}


def tracking_markdown(run: TrackingRun) -> str:
    """Two tables: tracking per vehicle and look-ahead; peak curvature per path."""
    s = tracking_summary(run)
    out = [f"Best area match to Dubins on the α, β = {run.step:g}:{run.step:g}:1 grid: "
           f"α = {run.alpha:g}, β = {run.beta:g}; {s['paths']} pairs; bound 1/ξ = "
           f"{s['bound_per_m']:g} 1/m.", "",
           "| vehicle, look-ahead | look-ahead [m] | reached goal | max error, median over paths [m] "
           "| max error, worst path [m] | mean error [m] | limits saturated, mean [s] |",
           "|---|---|---|---|---|---|---|"]
    for name, g in s["vehicles"].items():
        out.append(f"| {name} | {g['lookahead_m']:.1f} | {g['reached']}/{g['paths']} | "
                   f"{g['max_error_median_m']:.2f} | {g['max_error_max_m']:.2f} (pair "
                   f"{g['worst_pair']}) | {g['mean_error_mean_m']:.2f} | "
                   f"{g['saturated_s_mean']:.1f} |")
    out += ["", f"Peak curvature of the FM² paths (resampled every 1 m): raw "
            f"{s['peak_kappa_min']:.3f}–{s['peak_kappa_max']:.3f} 1/m (median "
            f"{s['peak_kappa_median']:.3f}), {s['above_bound']} of {s['paths']} above the "
            f"{s['bound_per_m']:g} 1/m bound; DCT-smoothed (the seed's Figs 10/14) median "
            f"{s['peak_kappa_smooth_median']:.3f} 1/m, {s['smooth_above_bound']} of "
            f"{s['paths']} above it.", "",
            "| pair | length [m] | peak κ raw [1/m] | peak κ smoothed [1/m] | reference peak κ "
            "[1/m] | fixed-wing max error, 40 m [m] | quadcopter max error, 40 m [m] |",
            "|---|---|---|---|---|---|---|"]
    by = {(r["pair"], r["vehicle"]): r for r in run.rows if r["seed_lookahead"]}
    for p in run.paths:
        fw, qc = by.get((p["pair"], "fixed-wing")), by.get((p["pair"], "quadcopter"))
        out.append(f"| {p['pair']} | {p['length_m']:.0f} | {p['peak_kappa']:.3f} | "
                   f"{p['peak_kappa_smooth']:.3f} | {p['reference_peak_kappa']:.3f} | "
                   f"{fw['max_error_m']:.2f} | {qc['max_error_m']:.2f} |")
    return "\n".join(out)
