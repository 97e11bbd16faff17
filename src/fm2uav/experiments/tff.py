"""The terrain-following experiments of the TFF paper (§5) and the thesis (§4.3).

Flight levels 2, 5 and 10 cells with (p1, p2) = (0.5, 2.5), (0.5, 1.5), (0.5, 1.3),
and the smoothness cases p2 = 1.0 and 0.8 at level 10 (:data:`SEED_CASES`); with
the capped flight-level reading, level 10 is also planned with the literal
``W**p`` reading for comparison. :func:`run_tff` plans every case on a built-in
scenario and measures it (:func:`fm2uav.analysis.flight_level.tff_metrics`);
:func:`tff_markdown` renders ``tff_table.md``.

What is measured is the FM² path of the seeds' method: the steepest descent of T on
the shaped W (:func:`fm2_geodesic`), whose heights come from the flight-level shaping
alone. ``plan()`` then replaces those heights by the final altitude profile (ground +
agl on the continuous ground, slope-limited; ``Plan.profile``), which follows the
terrain whatever the shaping did; its share on the level is the ``flown_within_all``
column (the FM² route with :func:`~fm2uav.planning.altitude.final_profile`). ``plan_s`` is warm (:func:`._timing.warm`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Literal

import numpy as np

from .. import progress
from ..analysis.flight_level import flight_level_deviation, tff_metrics
from ..errors import InputError
from ..planning import FlightLevel, Plan, Shaping, plan
from ..planning.altitude import final_profile
from ..planning.geodesic import descend
from ..geometry import path_length
from ..scenarios import Scenario, get_scenario
from ..world.clearance import surface_clearance
from ._timing import warm

__all__ = [
    "FlightLevelMode",
    "SEED_CASES",
    "LEVEL_CASES",
    "SMOOTH_CASES",
    "TffCase",
    "TffRun",
    "tff_cases",
    "fm2_geodesic",
    "run_tff",
    "TFF_COLUMNS",
    "tff_table_markdown",
    "tff_table_rows",
    "tff_markdown",
    "READINGS",
    "readings_rows",
    "readings_markdown",
]

#: Flight-level reading (``FlightLevel.mode``).
FlightLevelMode = Literal["capped", "literal"]
MODES: tuple[FlightLevelMode, ...] = ("capped", "literal")


@dataclass(frozen=True)
class TffCase:
    """One terrain-following case: a flight level [cells] and the exponents p1, p2."""

    name: str
    level: int
    p1: float
    p2: float
    mode: FlightLevelMode


#: The seeds' experiments (TFF paper §5, thesis §4.3): (name, level [cells], p1, p2).
SEED_CASES: tuple[tuple[str, int, float, float], ...] = (
    ("level 2", 2, 0.5, 2.5),
    ("level 5", 5, 0.5, 1.5),
    ("level 10", 10, 0.5, 1.3),
    ("smooth p2=1.0", 10, 0.5, 1.0),
    ("smooth p2=0.8", 10, 0.5, 0.8),
)
#: Indices of the flight-level cases and of the level-10 smoothness cases in a run.
LEVEL_CASES = (0, 1, 2)
SMOOTH_CASES = (2, 3, 4)


def tff_cases(mode: FlightLevelMode = "capped") -> list[TffCase]:
    """The seed cases read with ``mode``; with ``"capped"`` also level 10 read literally."""
    if mode not in MODES:
        raise InputError(f"flight-level mode must be 'capped' or 'literal' (--mode), got {mode!r}")
    cases = [TffCase(name, level, p1, p2, mode) for name, level, p1, p2 in SEED_CASES]
    if mode == "capped":
        cases.append(TffCase("level 10, literal W**p", 10, 0.5, 1.3, "literal"))
    return cases


@dataclass
class TffRun:
    """The planned cases: one metrics row and one :class:`~fm2uav.planning.Plan` per case."""

    scenario_name: str
    seed: int
    mode: FlightLevelMode
    scenario: Scenario
    cases: list[TffCase]
    rows: list[dict[str, Any]]
    plans: list[Plan]

    @property
    def labels(self) -> list[str]:
        """One legend label per case: name and exponents."""
        return [f"{r['case']} (p1={r['p1']:g}, p2={r['p2']:g})" for r in self.rows]


def fm2_geodesic(p: Plan) -> Any:
    """The FM² path of a plan before the final altitude profile: the steepest descent of
    ``p.T`` from the start to the goal node, as an object with the ``world``, ``path``,
    ``length`` and ``clearance`` that :func:`~fm2uav.analysis.flight_level.tff_metrics` reads."""
    from types import SimpleNamespace

    world = p.world
    idx = descend(p.T, world.to_index(p.path[0]), world.to_index(p.path[-1]),
                  spacing=world.spacing, step=float(p.params.get("step", 0.5)))
    path = world.to_world(idx)
    return SimpleNamespace(world=world, path=path, length=path_length(path),
                           clearance=float(surface_clearance(world, path).min()))


@progress.stage()
def run_tff(scenario: str = "open-field", seed: int = 0,
            mode: FlightLevelMode = "capped") -> TffRun:
    """Plan and measure the seeds' cases on the built-in ``scenario`` (needs terrain).

    Parameters
    ----------
    scenario : str
        Built-in scenario name (:data:`fm2uav.scenarios.SCENARIOS`).
    seed : int
        Seed of the scenario's random relief.
    mode : {"capped", "literal"}
        Flight-level reading of the seed cases.
    """
    cases = tff_cases(mode)
    sc = get_scenario(scenario, seed=seed)
    dz = sc.world.spacing[2]
    rows, plans = [], []
    for case in progress.each(cases, lambda c: f"{c.name}: level {c.level}, p1 = {c.p1:g}, "
                                               f"p2 = {c.p2:g}"):
        agl = case.level * dz
        # the seeds' experiment measures the FM² path itself (heights="fm2")
        level = FlightLevel(agl=agl, p1=case.p1, p2=case.p2, mode=case.mode, heights="fm2")
        p, seconds = warm(lambda: plan(sc.world, sc.start, sc.goal, level=level), [sc.world])
        m = tff_metrics(fm2_geodesic(p), agl)
        # what plan() flies by default (heights="ground"): the final altitude profile
        flown = final_profile(sc.world, p.path, level).path
        m.update(case=case.name, level=case.level, agl_m=agl, p1=case.p1, p2=case.p2,
                 diff=case.p2 - case.p1, mode=case.mode,
                 transitions=f"{m['start_transition_m']:.0f}/{m['end_transition_m']:.0f}",
                 flown_within_all=flight_level_deviation(sc.world, flown, agl).within_all,
                 plan_s=seconds)
        rows.append(m)
        plans.append(p)
    return TffRun(scenario, seed, mode, sc, cases, rows, plans)


#: Columns of tff_table.md: (header, row key, format).
TFF_COLUMNS = (
    ("case", "case", "{}"),
    ("level [cells]", "level", "{}"),
    ("agl [m]", "agl_m", "{:g}"),
    ("p1", "p1", "{:g}"),
    ("p2", "p2", "{:g}"),
    ("p2−p1", "diff", "{:.1f}"),
    ("within ±1 cell (between transitions)", "within", "{:.0%}"),
    ("on level (all points)", "within_all", "{:.0%}"),
    ("mean abs dev vs terrain+agl [m]", "mean_dev_all_m", "{:.1f}"),
    ("mean abs dev vs layer [m]", "mean_dev_layer_m", "{:.1f}"),
    ("max abs dev between transitions [m]", "max_dev_m", "{:.1f}"),
    ("transitions start/end [m]", "transitions", "{}"),
    ("points inside terrain", "inside_terrain", "{}"),
    ("length [m]", "length_m", "{:.0f}"),
    ("max turn [°/cell]", "turn_max_deg", "{:.1f}"),
    ("p95 turn [°/cell]", "turn_p95_deg", "{:.1f}"),
    ("max climb [°]", "climb_max_deg", "{:.1f}"),
    ("p95 climb [°]", "climb_p95_deg", "{:.1f}"),
    ("max curvature [1/m]", "curvature_max", "{:.4f}"),
    ("p95 curvature [1/m]", "curvature_p95", "{:.4f}"),
    ("min turn radius [m]", "min_turn_radius_m", "{:.0f}"),
    ("flown profile on level (all points)", "flown_within_all", "{:.0%}"),
    ("plan, warm [s]", "plan_s", "{:.2f}"),
)


def tff_table_markdown(rows: list[dict[str, Any]]) -> str:
    """The case table as Markdown (one line per row of :func:`run_tff`)."""
    head = [c[0] for c in TFF_COLUMNS]
    out = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for r in rows:
        out.append("| " + " | ".join(fmt.format(r[key]) for _, key, fmt in TFF_COLUMNS) + " |")
    return "\n".join(out)


def tff_table_rows(rows: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """The rows of the case table as dicts (header → formatted value), for HTML reports."""
    return [{head: fmt.format(r[key]) for head, key, fmt in TFF_COLUMNS} for r in rows]


def tff_markdown(run: TffRun) -> str:
    """``tff_table.md``: title, scenario, definitions and the case table."""
    sc = run.scenario
    md = [
        f"# Terrain-following flight — {run.scenario_name} (seed {run.seed}, flight-level "
        f"mode '{run.mode}')",
        "",
        sc.description,
        "",
        f"start {np.round(sc.start, 1).tolist()} m, goal {np.round(sc.goal, 1).tolist()} m; "
        f"±1 cell = ±{sc.world.spacing[2]:g} m; transitions = the start/goal stretches "
        "before the path first reaches, and after it last leaves, ±1 cell of terrain + agl; "
        "profiles on the path resampled every horizontal cell. The columns measure the "
        "FM² geodesic (heights from the flight-level shaping, as in the seeds); 'flown "
        "profile' is plan()'s final altitude profile (ground + agl, slope-limited). "
        "'plan, warm' = plan() run once untimed first (numba compilation excluded).",
        "",
        tff_table_markdown(run.rows),
        "",
    ]
    return "\n".join(md)


#: The readings of Algorithm 2 compared in docs/tff.md: (label, mode, Shaping).
READINGS: tuple[tuple[str, FlightLevelMode, Shaping], ...] = (
    ("literal", "literal", Shaping()),
    ("literal, walls", "literal", Shaping(walls=True)),
    ("literal, α=0.3", "literal", Shaping(saturation=0.3)),
    ("capped (default)", "capped", Shaping()),
)


def readings_rows(scenario: str = "open-field", seed: int = 0) -> list[dict[str, Any]]:
    """Every seed case under every reading of :data:`READINGS`, measured on the FM² geodesic.

    One row per (reading, case): ``scenario, reading, level, p1, p2, within, within_all,
    mean_dev_m, max_z_m, inside_terrain``.
    """
    sc = get_scenario(scenario, seed=seed)
    dz = sc.world.spacing[2]
    rows = []
    for label, mode, shaping in READINGS:
        for _name, level, p1, p2 in SEED_CASES:
            agl = level * dz
            p = plan(sc.world, sc.start, sc.goal, shaping=shaping,
                     level=FlightLevel(agl=agl, p1=p1, p2=p2, mode=mode, heights="fm2"))
            g = fm2_geodesic(p)
            rep = flight_level_deviation(sc.world, g.path, agl)
            rows.append({"scenario": scenario, "reading": label, "level": level, "p1": p1,
                         "p2": p2, "within": rep.within, "within_all": rep.within_all,
                         "mean_dev_m": rep.mean_dev_all_m, "max_z_m": float(g.path[:, 2].max()),
                         "inside_terrain": int(rep.summary()["inside_terrain"])})
    return rows


def readings_markdown(rows: list[dict[str, Any]]) -> str:
    """The readings table of docs/tff.md (rows of :func:`readings_rows`)."""
    out = ["| scenario | reading | level [cells] | (p1, p2) | within ±1 cell between transitions "
           "| within ±1 cell, all points | mean abs dev [m] | max z [m] | points inside terrain |",
           "|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        out.append(f"| {r['scenario']} | {r['reading']} | {r['level']} | ({r['p1']:g}, {r['p2']:g})"
                   f" | {r['within']:.0%} | {r['within_all']:.0%} | {r['mean_dev_m']:.0f} | "
                   f"{r['max_z_m']:.0f} | {r['inside_terrain']} |")
    return "\n".join(out)
