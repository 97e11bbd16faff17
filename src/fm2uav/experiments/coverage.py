"""The coverage experiments of paper 003 / thesis ch. 5: Tables 5.1 and 5.2.

Table 5.1: the best steering angle and cost of the zigzag over the areas S1–S4
with D = 80 m; Table 5.2: S1 with D = 40 / 60 / 80 / 100 m. Each row comes from
the seeds' Differential Evolution (:func:`~fm2uav.missions.coverage.differential_evolution`),
checked against a 0.1° sweep and scipy's DE; every area is then flown with FM²
along the bands at 100 m above the terrain. :data:`SEEDS_T51` / :data:`SEEDS_T52`
hold the seeds' published numbers next to which ours are printed. Timings (``de_s``,
``plan_s``) are warm: DE and the FM² coverage plan run once untimed first
(:func:`._timing.warm`, numba compilation excluded).
"""

from __future__ import annotations

import csv
import io
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .. import progress
from ..missions.coverage import (
    CoveragePlan,
    differential_evolution,
    plan_coverage,
    scipy_de,
    sweep,
)
from ..scenarios.coverage import (
    COVERAGE_AGL,
    COVERAGE_AREAS,
    COVERAGE_SPACING,
    coverage_area,
    coverage_world,
)
from ..planning import FlightLevel
from ..world import World
from ._timing import warm

__all__ = [
    "SEEDS_T51",
    "SEEDS_T52",
    "TABLE_COLUMNS",
    "TABLE_5_2_SPACINGS",
    "DE_SETTINGS",
    "CoverageRun",
    "angle_search_row",
    "reproduce_coverage",
    "table_csv",
    "tables_markdown",
    "coverage_payload",
]

#: The seeds' Table 5.1 (D = 80) and 5.2 (S1): min cost, α, max cost, α, median, α, mean, α.
SEEDS_T51 = {
    "S1": (5446.504, 37.134, 6104.040, 11.499, 5464.316, 37.684, 5616.718, 37.214),
    "S2": (6748.057, 2.503, 8373.462, 71.434, 6768.528, 3.389, 6870.913, 8.597),
    "S3": (5908.607, 1.012, 7493.887, 65.506, 5980.716, 2.086, 6061.788, 9.452),
    "S4": (7176.987, 1.349, 8223.283, 44.610, 7215.164, 2.581, 7290.188, 7.953),
}
SEEDS_T52 = {
    40: (9679.496, 38.474, 10885.701, 86.879, 10150.668, 36.968, 10066.730, 33.238),
    60: (6909.084, 37.878, 7696.142, 79.164, 6940.380, 36.990, 6982.500, 36.189),
    80: SEEDS_T51["S1"],
    100: (4615.506, 38.368, 5394.695, 57.202, 4658.287, 37.670, 4761.862, 29.829),
}
#: The DE statistics of a table row, in the seeds' column order.
TABLE_COLUMNS = ("min_cost", "min_alpha", "max_cost", "max_alpha", "median_cost",
                 "median_alpha", "mean_cost", "mean_alpha")
#: Band spacings D [m] of Table 5.2.
TABLE_5_2_SPACINGS = (40, 60, 80, 100)
#: The seeds' DE settings, as printed in the tables' titles.
DE_SETTINGS = "Np=20, F=0.8, CR=0.7, 30 generations, α∈[1°,89°]"


def angle_search_row(poly: Any, spacing: float, seed: int) -> tuple[Any, dict[str, float]]:
    """One table row: the seeds' DE vs a 0.1° sweep vs scipy's DE over ``poly`` with D [m].

    Returns the DE result (its ``angle`` [rad] is the chosen steering angle) and the row:
    the DE statistics of :data:`TABLE_COLUMNS` and the sweep / scipy comparison.
    """
    de = differential_evolution(poly, spacing, seed=seed)
    sw = sweep(poly, spacing, step_deg=0.1)
    sp = scipy_de(poly, spacing, seed=seed)
    st = de.stats()
    return de, {**{k: round(st[k], 3) for k in TABLE_COLUMNS},
                "sweep_cost": round(sw.cost, 3),
                "sweep_alpha": round(sw.angle_deg, 3),
                "de_vs_sweep_pct": round(100 * (de.cost - sw.cost) / sw.cost, 4),
                "scipy_cost": round(sp.cost, 3),
                "scipy_alpha": round(sp.angle_deg, 3),
                "de_s": round(de.seconds, 4)}


@dataclass
class CoverageRun:
    """Both tables, the FM² coverage plans of Table 5.1 and the S1 angles of Table 5.2."""

    seed: int
    world: World
    table_5_1: dict[str, dict[str, Any]] = field(default_factory=dict)
    table_5_2: dict[int, dict[str, Any]] = field(default_factory=dict)
    plans: dict[str, CoveragePlan] = field(default_factory=dict)
    s1_angles: dict[int, float] = field(default_factory=dict)


@progress.stage()
def reproduce_coverage(seed: int = 0) -> CoverageRun:
    """Tables 5.1 and 5.2 on the coverage map of ``seed`` (terrain and DE seed); each area
    and spacing is a :mod:`fm2uav.progress` step."""
    from .._validate import seed_value

    seed = seed_value(seed, "seed", where=(None, "--seed"))
    run = CoverageRun(seed=seed, world=coverage_world(seed))
    for n in progress.each(list(COVERAGE_AREAS), lambda n: f"Table 5.1, area {n}: DE, 0.1° "
                           "sweep, scipy DE and FM² along the bands"):
        poly = coverage_area(n)
        differential_evolution(poly, COVERAGE_SPACING, seed=seed)  # untimed: compiles
        de, r = angle_search_row(poly, COVERAGE_SPACING, seed)
        cp, _ = warm(lambda: plan_coverage(run.world, poly, COVERAGE_SPACING,
                                           level=FlightLevel(agl=COVERAGE_AGL), angle=de.angle),
                     [run.world])
        r.update(coverage_pct=round(100 * cp.coverage, 3),
                 fm2_length=round(cp.plan.length, 1),
                 agl_err_mean=round(float(np.abs(cp.agl_error).mean()), 2),
                 plan_s=round(cp.timings["total"] + de.seconds, 4))
        run.table_5_1[n] = r
        run.plans[n] = cp
    s1 = coverage_area("S1")
    for d in progress.each(list(TABLE_5_2_SPACINGS), lambda d: f"Table 5.2, S1 with D = {d} m"):
        de, r = angle_search_row(s1, float(d), seed)
        run.table_5_2[d] = r
        run.s1_angles[d] = float(de.angle)
    return run


def table_csv(rows: Mapping[Any, Mapping[str, Any]], key: str,
              seeds: Mapping[Any, tuple[float, ...]]) -> str:
    """A table as CSV: the key column, our columns, then the seeds' columns."""
    buf = io.StringIO()
    cols = list(next(iter(rows.values())).keys())
    w = csv.writer(buf)
    w.writerow([key, *cols, *(f"seeds_{c}" for c in TABLE_COLUMNS)])
    for k, r in rows.items():
        w.writerow([k, *(r[c] for c in cols), *seeds[k]])
    return buf.getvalue()


def _table_md(rows: Mapping[Any, Mapping[str, Any]], key: str,
              seeds: Mapping[Any, tuple[float, ...]], title: str) -> str:
    head = (f"### {title}\n\n| {key} | min cost (m) | α (°) | max cost (m) | α (°) | "
            "median cost | α | mean cost | α | 0.1° sweep best (m) | DE−sweep (%) | "
            "seeds min cost | seeds α |\n|" + "---|" * 13 + "\n")
    lines = []
    for k, r in rows.items():
        lines.append(
            f"| {k} | " + " | ".join(f"{r[c]:.3f}" for c in TABLE_COLUMNS)
            + f" | {r['sweep_cost']:.3f} | {r['de_vs_sweep_pct']:+.4f} | "
            f"{seeds[k][0]:.3f} | {seeds[k][1]:.3f} |")
    return head + "\n".join(lines) + "\n"


def tables_markdown(run: CoverageRun) -> str:
    """``tables.md``: Tables 5.1 and 5.2 next to the seeds', and the FM² flights."""
    out = [_table_md(run.table_5_1, "surface", SEEDS_T51,
                     f"Table 5.1 — costs and steering angles, D = 80 m (DE: {DE_SETTINGS})"),
           "\n",
           _table_md(run.table_5_2, "D (m)", SEEDS_T52, "Table 5.2 — S1 with different D"),
           "\n### FM² along the bands (100 m AGL, p1=0.5, p2=1.3)\n\n"
           "| surface | coverage (%) | FM² length (m) | mean abs AGL error (m) | "
           "DE + plan time, warm (s) |\n|---|---|---|---|---|\n"]
    for n, r in run.table_5_1.items():
        out.append(f"| {n} | {r['coverage_pct']:.2f} | {r['fm2_length']:.0f} | "
                   f"{r['agl_err_mean']:.2f} | {r['plan_s']:.3f} |\n")
    out.append("\nwarm = DE and the coverage plan ran once untimed first (numba compilation "
               "excluded, the map's distance cache cleared).\n")
    return "".join(out)


def coverage_payload(run: CoverageRun) -> dict[str, Any]:
    """``summary.json``: both tables and the seeds' tables."""
    return {"table_5_1": run.table_5_1,
            "table_5_2": {str(k): v for k, v in run.table_5_2.items()},
            "seeds_table_5_1": SEEDS_T51, "seeds_table_5_2": SEEDS_T52}
