"""Seed 004 (Sensors 2022): FM² over an α–β grid against curvature-penalised references.

The sweep (:mod:`.runner`, :mod:`.sweep`) plans FM² for every (α, β) and start/goal pair
of the 2D city map and compares each path with the Dubins, Euler–Mumford elastica and
Reeds–Shepp forward references (:mod:`fm2uav.baselines.reference`). This module holds
the seed's grid (:func:`curvature_config`), the summary of a finished sweep
(:func:`summarise_run`) and its Tables 1–4 (:func:`tables_markdown`). Tables 2/3 give
the argmin and the set of (α, β) within 1 % of it (count, α and β ranges): the valley is
flat, so the argmin alone moves with the grid step.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

from ..world import World
from .runner import SweepConfig, make_config, sweep_world
from .sweep import summarise_sweep

__all__ = ["SEED_STEP", "curvature_config", "summarise_run", "tables_markdown",
           "sweep_payload"]

#: The seed's grid step of α and β: 0.02:0.02:1 (50 x 50 values).
SEED_STEP = 0.02


def curvature_config(step: float | None = None, pairs: int = 24, xi: float = 10.0) -> SweepConfig:
    """The sweep of the seed: α, β = step:step:1 (``None``: :data:`SEED_STEP`), ``pairs``
    start/goal pairs, references with ξ = ``xi`` [m]; everything else the config defaults."""
    s = SEED_STEP if step is None else float(step)
    grid = {"start": s, "stop": 1.0, "step": s}
    return make_config({"pairs": pairs, "alpha": grid, "beta": grid, "xi": xi},
                       where="reproduce curvature")


def summarise_run(config: SweepConfig, result: Any) -> tuple[World, dict[str, Any]]:
    """The map and :func:`~fm2uav.experiments.sweep.summarise_sweep` of a finished sweep."""
    world, starts, goals = sweep_world(config)
    summary = summarise_sweep(world, starts, goals, result.columns, result.alphas, result.betas,
                              config.models, result.references, ds=config.ds, order=config.order)
    return world, summary


_NAMES = {"dubins": "Dubins", "elastica": "Euler–Mumford elastica", "rs": "Reeds–Shepp forward"}


def _fmt(v: Any, digits: int = 3) -> str:
    if v is None or (isinstance(v, float) and not math.isfinite(v)):
        return "–"
    return f"{v:.{digits}g}" if isinstance(v, float) else str(v)


def _near_count(best: dict[str, Any] | None) -> str:
    near = (best or {}).get("near_best")
    return "–" if not near else f"{near['count']} ({near['share']:.1%} of the grid)"


def _near_range(best: dict[str, Any] | None, key: str) -> str:
    near = (best or {}).get("near_best")
    return "–" if not near else f"{near[key + '_min']:g}–{near[key + '_max']:g}"


def tables_markdown(summary: dict[str, Any], result: Any) -> str:
    """Tables 1–4 of the seed as Markdown."""
    cfg = result.config
    models = [m for m in cfg.models]
    a, b = result.alphas, result.betas
    lines = [
        "# FM² vs curvature-penalised references (seed 004)",
        "",
        f"Map: {cfg.scenario} ({cfg.cell} m nodes), {len(result.starts)} start/goal pairs "
        f"(seed {cfg.pair_seed}), ξ = {cfg.xi} m, lattice headings max_int={cfg.max_int}. "
        f"Grid: α = {a[0]:g}:{cfg.alpha.step:g}:{a[-1]:g} ({len(a)}), "
        f"β = {b[0]:g}:{cfg.beta.step:g}:{b[-1]:g} ({len(b)}) → {len(a) * len(b)} (α, β) × "
        f"{len(result.starts)} pairs = {len(a) * len(b) * len(result.starts)} FM² runs. "
        f"Distances are means over the pairs, curves resampled every {cfg.ds} m.",
        "",
        "## Table 1 — computation time of all pairs [s]",
        "",
        "| " + " | ".join(_NAMES[m] for m in models) + " | FM² |",
        "|" + "---|" * (len(models) + 1),
        "| " + " | ".join(_fmt(summary["timing"].get(f"{m}_s"), 4) for m in models)
        + f" | {_fmt(summary['timing']['fm2_s'], 4)} |",
        "| " + " | ".join(f"×{_fmt(summary['timing'].get(f'{m}_ratio'), 4)}" for m in models) + " | 1 |",
        "",
        "References: lattice search time (compiled Dijkstra, control set cached); FM²: sum over "
        "pairs of the median `plan()` time over the grid (both Fast Marching waves, descent, "
        "metrics), warm: a worker's first, compiling call is one case of the grid and the "
        "median does not see it. Both are measured inside the sweep's worker processes, running side by "
        "side on a shared machine, so the ratios are indicative; `benchmarks/bench_reference.py` "
        "times both in one process, one after the other.",
        "",
    ]
    for metric, title, num in (("frechet", "Fréchet distance [m]", 2), ("area", "area between curves [m²]", 3)):
        best = summary["best"].get(metric, {})
        val = summary["valley"].get(metric, {})
        lines += [
            f"## Table {num} — best α, β and {title}",
            "",
            "| | " + " | ".join(_NAMES[m] for m in models) + " |",
            "|---|" + "---|" * len(models),
            "| α | " + " | ".join(_fmt(best.get(m, {}).get("alpha")) for m in models) + " |",
            "| β | " + " | ".join(_fmt(best.get(m, {}).get("beta")) for m in models) + " |",
            f"| {metric} | " + " | ".join(_fmt(best.get(m, {}).get("value"), 4) for m in models) + " |",
            "| valley: Spearman(α, best β) | "
            + " | ".join(_fmt(val.get(m, {}).get("spearman"), 2) for m in models) + " |",
            "| (α, β) within 1 % of the best | "
            + " | ".join(_near_count(best.get(m)) for m in models) + " |",
            "| their α range | "
            + " | ".join(_near_range(best.get(m), "alpha") for m in models) + " |",
            "| their β range | "
            + " | ".join(_near_range(best.get(m), "beta") for m in models) + " |",
            "",
        ]
    clear = summary["clearance"]
    lines += [
        "## Table 4 — distance to the obstacles [m] (mean over pairs of each path's minimum; "
        "best area match)",
        "",
        "| | " + " | ".join(_NAMES[m] for m in models) + " |",
        "|---|" + "---|" * len(models),
        "| α | " + " | ".join(_fmt(clear.get(m, {}).get("alpha")) for m in models) + " |",
        "| β | " + " | ".join(_fmt(clear.get(m, {}).get("beta")) for m in models) + " |",
        "| reference | " + " | ".join(_fmt(clear.get(m, {}).get("reference_m"), 3) for m in models) + " |",
        "| FM² approximation | " + " | ".join(_fmt(clear.get(m, {}).get("fm2_m"), 3) for m in models) + " |",
        "",
        f"Cases: {result.cases_run} run now, {result.cases_skipped} resumed, "
        f"{result.cases_failed} failed.",
        "",
    ]
    return "\n".join(lines)


def sweep_payload(summary: dict[str, Any], result: Any, config: SweepConfig,
                  out: Path) -> dict[str, Any]:
    """``summary.json`` of a sweep: best matches, valleys, timings, clearance, grid, cases."""
    return {
        "best": summary["best"],
        "valley_spearman": {m: {k: v["spearman"] for k, v in d.items()}
                            for m, d in summary["valley"].items()},
        "near_best": summary.get("near_best", {}),
        "timing_s": summary["timing"],
        "clearance_m": summary["clearance"],
        "grid": {"alpha": [float(result.alphas[0]), config.alpha.step, float(result.alphas[-1])],
                 "beta": [float(result.betas[0]), config.beta.step, float(result.betas[-1])]},
        "pairs": len(result.starts),
        "cases": {"run": result.cases_run, "resumed": result.cases_skipped,
                  "failed": result.cases_failed},
        "wall_s": result.wall_s,
        "results_file": str(out / config.results),
    }
