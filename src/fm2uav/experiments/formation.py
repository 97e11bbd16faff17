"""The leader–follower formation experiments of thesis ch. 6.

The triangle formation crosses the fissure without (case 1) and with (case 2)
the flight level of 7 cells. Case 1 is read as the thesis describes it (docs/formation.md):
the UAVs fly at "30 cells, approximately" and deform between the fissure's mountains, so
the map's border and ceiling are obstacles (``walls``, which keeps the FM² path half-way
between the ground and the ceiling instead of at the ceiling) and the stand-in relief is
scaled so that its mountains rise above that flight (:data:`CASE1_RELIEF_TOP`), with the
thesis' 8-cell (120 m) spacing; the stand-in relief as built (whose ridges stay below the
start altitude) is flown too (``case1-over-ridges``); case 2 is flown with the thesis' p1 = 1, p2 = 0.5
and with the planner's p1 = 0.5, p2 = 1.5 (:data:`THESIS_CASES`). Our times are
compared with the thesis' Matlab times (:data:`THESIS_TIMES`); ours are warm: every
case is flown once untimed first (:func:`._timing.warm`, numba compilation excluded).
:func:`fly_and_summarise` is also the library side of ``fm2uav formation``.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from functools import lru_cache
from typing import Any

from .. import progress
from ..analysis.flight_level import flight_level_deviation
from ..errors import WorldError
from ..missions.formation import FormationConfig, FormationResult, fly_formation, inside_terrain
from ..planning import FlightLevel, Shaping
from ..scenarios import Scenario, get_scenario
from ._timing import warm

__all__ = [
    "THESIS_TIMES",
    "FormationCase",
    "THESIS_CASES",
    "level_keeping",
    "fly_and_summarise",
    "summary_rows",
    "ThesisRun",
    "reproduce_formation",
    "thesis_table",
    "thesis_markdown",
]

#: Thesis ch. 6 wall times of the whole formation planning (Matlab) [s].
THESIS_TIMES = {"case1": 130.6, "case2": 135.6}


@dataclass(frozen=True)
class FormationCase:
    """One thesis case: output folder, title, the thesis case it compares with, and the
    flight level [vertical cells] with its exponents (``level=None``: no flight level)."""

    folder: str
    title: str
    thesis_key: str
    level: float | None = None
    p1: float | None = None
    p2: float | None = None
    #: map border and ceiling as obstacles (``Shaping(walls=True)``)
    walls: bool = False
    #: relief scaled so that its highest point is this many vertical cells (None: as built)
    relief_top: float | None = None
    #: distance between the UAVs [m] (None: the FormationConfig default)
    dist: float | None = None

    def options(self, dz: float) -> dict[str, Any]:
        """The ``fly_formation`` keyword arguments of this case on vertical cells of ``dz`` m."""
        out: dict[str, Any] = {}
        if self.level is not None:  # the seeds' Algorithm 2 itself: FM²'s own heights
            out["level"] = FlightLevel(agl=self.level * dz, p1=self.p1, p2=self.p2,
                                       heights="fm2")
        if self.walls:
            out["shaping"] = Shaping(walls=True)
        if self.dist is not None:
            out["config"] = FormationConfig(dist=self.dist)
        return out


#: Case 1's relief top [vertical cells]: the lateral mountains rise above the ~30-cell flight.
CASE1_RELIEF_TOP = 36.0


def case_scenario(seed: int, case: FormationCase) -> Scenario:
    """The fissure of ``seed``; with ``case.relief_top`` its relief scaled to that top [cells]
    (same start/goal cells, same horizontal layout)."""
    sc = get_scenario("fissure", seed=seed)
    if case.relief_top is None:
        return sc
    return _deep_fissure(seed, float(case.relief_top))


@lru_cache(maxsize=2)
def _deep_fissure(seed: int, top: float) -> Scenario:
    import numpy as np

    from ..scenarios.field import OPEN_FIELD_CELL, OPEN_FIELD_HEIGHT_CELLS
    from ..world import World
    from ..world.terrain import OPEN_FIELD_SHAPE, open_field_heights

    base = get_scenario("fissure", seed=seed)
    h = open_field_heights(seed, OPEN_FIELD_SHAPE)
    world = World.from_heightmap(h * (top / float(h.max())) * OPEN_FIELD_CELL, OPEN_FIELD_CELL,
                                 OPEN_FIELD_HEIGHT_CELLS, name=f"fissure, relief to {top:g} cells")
    start = world.to_world(world.to_index(base.start))
    goal = world.to_world(world.to_index(base.goal))
    for what, p in (("start", start), ("goal", goal)):
        if world.occupancy[world.to_cell(p)]:
            raise WorldError(f"the fissure {what} is inside the relief scaled to {top:g} cells; "
                             "lower the relief top")
    return Scenario(world=world, start=start, goal=goal,
                    description=f"{base.description}; relief scaled to a top of {top:g} cells "
                                f"({top * OPEN_FIELD_CELL:g} m)")


THESIS_CASES = (
    FormationCase("case1", "case 1: no flight level, walls, relief to 36 cells, dist 120 m",
                  "case1", walls=True, relief_top=CASE1_RELIEF_TOP, dist=120.0),
    FormationCase("case1-over-ridges", "case 1 on the stand-in relief (flies over the ridges)",
                  "case1"),
    FormationCase("case2-thesis-p", "case 2: level 7, p1 = 1, p2 = 0.5 (thesis)", "case2",
                  level=7, p1=1.0, p2=0.5),
    FormationCase("case2", "case 2: level 7, p1 = 0.5, p2 = 1.5", "case2",
                  level=7, p1=0.5, p2=1.5),
)


def level_keeping(result: FormationResult) -> dict[str, Any]:
    """Share of each UAV's flight within one cell of its flight level, mean deviation [m]
    and lowest height above ground [m] (UAVs without a flight level are left out)."""
    out = {}
    for name, agl, i in zip(result.names, result.agl, range(result.n_uav)):
        if agl is None:
            continue
        rep = flight_level_deviation(result.world, result.positions[:, i], agl)
        out[name] = {"within_1_cell": round(rep.within, 3),
                     "mean_dev_m": round(rep.mean_dev_m, 2),
                     "min_agl_m": round(rep.min_agl_m, 2)}
    return out


def fly_and_summarise(sc: Scenario, **options: Any) -> tuple[FormationResult, dict[str, Any]]:
    """Fly a formation from ``sc.start`` to ``sc.goal`` (:func:`fly_formation` ``options``);
    return the result and its summary with samples inside the terrain and level keeping."""
    result = fly_formation(sc.world, sc.start, sc.goal, **options)
    summary = result.summary()
    summary["inside_terrain_samples"] = int(inside_terrain(result.world, result.positions).sum())
    summary["level_keeping"] = level_keeping(result)
    return result, summary


def summary_rows(summary: dict[str, Any]) -> dict[str, Any]:
    """The headline numbers of a :func:`fly_and_summarise` summary, as label → text."""
    return {
        "completed / settled": f"{summary['completed']} / {summary['settled']}",
        "mission time [s]": summary["mission_time_s"],
        "cycles": summary["cycles"],
        "min separation [m]": (f"{summary['min_separation_m']:.1f} "
                               f"(bound {summary['separation_bound_m']:g})"),
        "samples inside terrain": summary["inside_terrain_samples"],
        "shape error max / final [m]": (f"{summary['max_shape_error_m']:.1f} / "
                                        f"{summary['final_shape_error_m']:.1f}"),
        "min grey level": summary["min_grey"],
        "on the level (±1 cell)": ", ".join(
            f"{k} {v['within_1_cell']:.0%}" for k, v in summary["level_keeping"].items()) or "-",
        "cycle [ms] median / p95 / max": "{median} / {p95} / {max}".format(**summary["cycle_ms"]),
        "computed in [s]": summary["timings_s"]["total"],
    }


@dataclass(eq=False)
class ThesisRun:
    """The thesis cases flown: results and summaries by case folder."""

    seed: int
    scenario: Scenario
    cases: tuple[FormationCase, ...]
    flights: dict[str, FormationResult]
    summaries: dict[str, dict[str, Any]]
    #: each case's own scenario (case 1's relief differs), by case folder
    scenarios: dict[str, Scenario] = field(default_factory=dict)

    @property
    def completed(self) -> bool:
        """Whether every case reached its goal."""
        return all(s["completed"] for s in self.summaries.values())


@progress.stage()
def reproduce_formation(
    seed: int = 0, *, cases: tuple[FormationCase, ...] = THESIS_CASES,
    on_case: Callable[[FormationCase, FormationResult, dict[str, Any]], None] = (
        lambda case, result, summary: None),
) -> ThesisRun:
    """Fly the thesis' cases across the fissure of ``seed``.

    ``on_case`` is called after each flight (e.g. to write its folder, so a
    flight's arrays can be dropped early); each flight is a :mod:`fm2uav.progress` step.
    """
    sc = get_scenario("fissure", seed=seed)
    dz = sc.world.spacing[2]
    run = ThesisRun(seed=seed, scenario=sc, cases=cases, flights={}, summaries={})
    for case in progress.each(cases, lambda c: c.title):
        csc = case_scenario(seed, case)
        run.scenarios[case.folder] = csc
        (result, summary), _ = warm(lambda: fly_and_summarise(csc, **case.options(dz)),
                                    [csc.world])
        run.flights[case.folder], run.summaries[case.folder] = result, summary
        on_case(case, result, summary)
    return run


def thesis_table(run: ThesisRun) -> list[dict[str, Any]]:
    """One row per case: our time next to the thesis', separation, shape error, grey level."""
    table = []
    for case in run.cases:
        s = run.summaries[case.folder]
        lead = s["level_keeping"].get("leader", {}).get("within_1_cell", "-")
        table.append({
            "case": case.title, "our time, warm [s]": s["timings_s"]["total"],
            "thesis [s]": THESIS_TIMES[case.thesis_key],
            "min separation [m] (≥ 30)": s["min_separation_m"],
            "inside terrain": s["inside_terrain_samples"],
            "max / final shape error [m]": f"{s['max_shape_error_m']:.0f} / "
                                           f"{s['final_shape_error_m']:.0f}",
            "min grey": s["min_grey"], "leader on level": lead,
            "cycle median [ms]": s["cycle_ms"]["median"], "completed": s["completed"]})
    return table


def thesis_markdown(run: ThesisRun) -> str:
    """``table.md``: the cases next to the thesis' times."""
    lines = [
        "| case | our time, warm [s] | thesis [s] | min separation [m] (≥ 30) | inside terrain | "
        "max / final shape error [m] | min grey | leader on level | cycle median [ms] |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for case in run.cases:
        s = run.summaries[case.folder]
        lead = s["level_keeping"].get("leader", {}).get("within_1_cell", "-")
        lines.append(
            f"| {case.title} | {s['timings_s']['total']:.2f} | {THESIS_TIMES[case.thesis_key]} | "
            f"{s['min_separation_m']:.1f} | {s['inside_terrain_samples']} | "
            f"{s['max_shape_error_m']:.0f} / {s['final_shape_error_m']:.0f} | "
            f"{s['min_grey']} | {lead} | {s['cycle_ms']['median']} |"
        )
    return "\n".join(lines) + "\n"
