"""Thesis ch. 3 experiments: FM² paths in the city checked with a Dubins airplane,
and the FM² vs RRT comparison.

* **Low altitude** (§3.3.1): the thesis shows this mission only in the x-y
  plane (its high-altitude section adds "the z-xy plane" as new), so it is
  planned in the horizontal slice of the city at the mission altitude (a 2D
  world of the same 5 m cells) and flown at that constant altitude.
* **High altitude** (§3.3.2): planned in the full 3D city.
* Both plans treat the map border as an obstacle (``walls=True``): without it
  the 3D wave runs to the open sky at the top of the grid, and in 2D the W^1
  path detours along the map edge.
* Safety distance = the plan's clearance (smallest distance from the planned
  path to a building or ground node); separation distance = the largest
  distance from the flown (Dubins) trajectory to the planned path.
* ``plan_s`` / FM² ``time_s`` are warm: each plan runs once untimed first
  (:func:`._timing.warm`, numba compilation excluded, distance cache cleared).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .. import progress
from ..geometry import arc_length
from ..planning import Plan, Shaping, plan
from ..vehicles import FeasibilityReport, TrackingOptions, check_feasibility, get_airframe
from ..world import World
from ..scenarios import Scenario, get_scenario
from ..baselines.rrt import RRTOptions, RRTResult, plan_rrt
from ._timing import WARM_NOTE, warm

__all__ = [
    "THESIS_TABLE_3_1",
    "THESIS_TABLE_3_2",
    "THESIS_TIMES_S",
    "EXPONENTS",
    "horizontal_slice",
    "CityCase",
    "city_missions",
    "run_city_case",
    "city_table",
    "rrt_comparison",
    "CityRun",
    "reproduce_city",
    "CITY_TABLE_COLUMNS",
    "RRT_TABLE_COLUMNS",
    "markdown_table",
    "city_markdown",
    "city_summary",
]

#: Thesis Table 3.1 (low altitude): exponent → (safety distance m, separation m).
THESIS_TABLE_3_1 = {1.0: (20.4, 2.1), 0.5: (15.8, 1.6), 0.25: (10.3, 1.3)}
#: Thesis Table 3.2 (high altitude).
THESIS_TABLE_3_2 = {1.0: (30.4, 1.6), 0.5: (26.5, 0.8), 0.25: (20.1, 0.7)}
#: Thesis §3.3.1 planning times [s] (Matlab): FM² ~1.2 s, RRT ~5 s.
THESIS_TIMES_S = {"FM2": 1.2, "RRT": 5.0}
#: The thesis' exponents on W: W^1, W^1/2, W^1/4.
EXPONENTS = (1.0, 0.5, 0.25)


def horizontal_slice(world: World, z: float) -> World:
    """The 2D world of the node layer nearest to altitude ``z`` [m] of a 3D world."""
    k = int(np.clip(np.floor((z - world.origin[2]) / world.spacing[2] + 0.5), 0, world.shape[2] - 1))
    return World(
        occupancy=world.occupancy[:, :, k],
        spacing=world.spacing[:2],
        origin=world.origin[:2],
        crs=world.crs,
        name=f"{world.name} z={world.origin[2] + k * world.spacing[2]:g} m",
    )


def city_missions(seed: int = 0) -> dict[str, Scenario]:
    """``{"low": city(seed), "high": city_high(seed)}``."""
    return {"low": get_scenario("city", seed=seed), "high": get_scenario("city-high", seed=seed)}


@dataclass(frozen=True, eq=False)
class CityCase:
    """One mission with one exponent: the plan (in metres, 3D) and its check.

    ``path3`` is the planned path in 3D (low altitude: z = mission altitude);
    ``plan`` is the FM² result (2D for the low-altitude slice).
    """

    mission: str
    exponent: float
    plan: Plan = field(repr=False)
    path3: np.ndarray = field(repr=False)
    report: FeasibilityReport = field(repr=False)
    world3: World = field(repr=False)

    def row(self) -> dict[str, Any]:
        """One row of the Tables 3.1/3.2-style table."""
        thesis = (THESIS_TABLE_3_1 if self.mission == "low" else THESIS_TABLE_3_2).get(
            self.exponent, (None, None))
        tr = self.report.tracking
        return {
            "mission": self.mission,
            "exponent": self.exponent,
            "safety_m": round(self.plan.clearance, 2),
            "separation_max_m": round(tr.max_separation, 2),
            "separation_mean_m": round(tr.mean_separation, 2),
            "thesis_safety_m": thesis[0],
            "thesis_separation_m": thesis[1],
            "length_m": round(self.plan.length, 1),
            "plan_s": round(self.plan.timings["total"], 4),
            "min_radius_m": round(self.report.geometric.min_radius, 1),
            "turn_saturated_s": round(self.report.tracking.saturation_time().get("turn", 0.0), 2),
            "feasible": self.report.feasible,
            "reason": self.report.reason,
        }


def run_city_case(
    scenario: Scenario,
    mission: str,
    exponent: float,
    airframe: Any = "disco",
    *,
    tolerance: float = 5.0,
    lookahead: float | None = None,
) -> CityCase:
    """Plan one city mission with W^exponent and check it with the airframe."""
    w3 = scenario.world
    if mission == "low":
        z = float(scenario.start[2])
        w2 = horizontal_slice(w3, z)
        p, _ = warm(lambda: plan(w2, scenario.start[:2], scenario.goal[:2],
                                 shaping=Shaping(exponent=exponent, walls=True)), [w2])
        path3 = np.column_stack([p.path, np.full(len(p.path), z)])
        rep = check_feasibility(path3, airframe, world=w3, w=p.w, tolerance=tolerance,
                                tracking=TrackingOptions(lookahead=lookahead))
    else:
        p, _ = warm(lambda: plan(w3, scenario.start, scenario.goal,
                                 shaping=Shaping(exponent=exponent, walls=True)), [w3])
        path3 = p.path
        rep = check_feasibility(path3, airframe, world=w3, w=p.w, tolerance=tolerance,
                                tracking=TrackingOptions(lookahead=lookahead))
    return CityCase(mission=mission, exponent=float(exponent), plan=p, path3=path3, report=rep,
                    world3=w3)


def city_table(
    seed: int = 0,
    airframe: Any = "disco",
    exponents: tuple[float, ...] = EXPONENTS,
    *,
    tolerance: float = 5.0,
) -> list[CityCase]:
    """Both missions x all exponents (the reproduction of Tables 3.1 and 3.2)."""
    af = get_airframe(airframe)
    cases = []
    for mission, sc in city_missions(seed).items():
        for e in exponents:
            cases.append(run_city_case(sc, mission, e, af, tolerance=tolerance))
    return cases


def rrt_comparison(
    scenario: Scenario,
    mission: str = "low",
    airframe: Any = "disco",
    *,
    planners: tuple[str, ...] = ("rrt", "rrtconnect", "rrtstar"),
    exponent: float = 1.0,
    time_limit: float = 5.0,
    rrtstar_time: float = 1.0,
    tolerance: float = 5.0,
    seed: int = 0,
) -> tuple[list[dict[str, Any]], dict[str, Any]]:
    """FM² vs OMPL planners on one city mission: time, length, clearance, curvature, verdict.

    Returns ``(rows, artefacts)``; artefacts hold the FM² case and the
    :class:`RRTResult` per planner (for figures).
    """
    af = get_airframe(airframe)
    fm = run_city_case(scenario, mission, exponent, af, tolerance=tolerance)
    rows = [{
        "planner": f"FM2 W^{exponent:g}",
        "time_s": round(fm.plan.timings["total"], 4),
        "length_m": round(fm.plan.length, 1),
        "clearance_m": round(fm.plan.clearance, 2),
        "min_radius_m": round(fm.report.geometric.min_radius, 1),
        "separation_max_m": round(fm.report.tracking.max_separation, 2),
        "feasible": fm.report.feasible,
        "reason": fm.report.reason,
    }]
    results: dict[str, RRTResult] = {}
    w3 = scenario.world
    if mission == "low":
        z = float(scenario.start[2])
        wp, s, g = horizontal_slice(w3, z), scenario.start[:2], scenario.goal[:2]
    else:
        wp, s, g = w3, scenario.start, scenario.goal
    for name in planners:
        budget = rrtstar_time if name == "rrtstar" else time_limit
        r = plan_rrt(wp, s, g, planner=name, options=RRTOptions(time_limit=budget, seed=seed))
        path3 = r.path if wp.ndim == 3 else np.column_stack([r.path, np.full(len(r.path), z)])
        rep = check_feasibility(path3, af, world=w3, tolerance=tolerance)
        results[name] = r
        rows.append({
            "planner": f"{r.planner} + shortcut",
            "time_s": round(r.timings["total"], 4),
            "length_m": round(r.length, 1),
            "clearance_m": round(r.clearance, 2),
            "min_radius_m": round(rep.geometric.min_radius, 1),
            "separation_max_m": round(rep.tracking.max_separation, 2),
            "feasible": rep.feasible,
            "reason": rep.reason,
        })
    return rows, {"fm2": fm, "rrt": results}


#: Columns of the safety/separation table in table.md (Tables 3.1/3.2).
CITY_TABLE_COLUMNS = ("mission", "exponent", "safety_m", "thesis_safety_m", "separation_max_m",
                      "thesis_separation_m", "separation_mean_m", "length_m", "plan_s",
                      "feasible")
#: Columns of the FM² vs RRT table in table.md.
RRT_TABLE_COLUMNS = ("planner", "time_s", "length_m", "clearance_m", "min_radius_m",
                     "separation_max_m", "feasible")


@dataclass(eq=False)
class CityRun:
    """``reproduce city``: both missions x all exponents, and the RRT comparison.

    ``rrt_rows`` is empty and ``rrt`` None when the comparison was not run;
    ``rrt_paths`` are the OMPL paths in 3D (the low mission at its altitude).
    """

    seed: int
    airframe: Any
    tolerance: float
    cases: list[CityCase]
    missions: dict[str, Scenario]
    rrt_rows: list[dict[str, Any]] = field(default_factory=list)
    rrt: dict[str, Any] | None = None
    rrt_paths: dict[str, np.ndarray] = field(default_factory=dict)

    @property
    def rows(self) -> list[dict[str, Any]]:
        """One Tables 3.1/3.2 row per case."""
        return [c.row() for c in self.cases]

    def speed_profiles(self) -> dict[str, tuple[np.ndarray, np.ndarray]]:
        """``label -> (arc length [m], W along the path)`` of every case (Fig. 3.4)."""
        return {f"{c.mission} W^{c.exponent:g}": (
            arc_length(c.path3), c.plan.w) for c in self.cases}


@progress.stage()
def reproduce_city(seed: int = 0, airframe: Any = "disco", *, tolerance: float = 5.0,
                   rrt: bool = True, rrt_time: float = 5.0, rrtstar_time: float = 1.0
                   ) -> CityRun:
    """Thesis ch. 3: :func:`city_table` and (``rrt``) :func:`rrt_comparison` on the low mission.

    Parameters
    ----------
    seed : int
        Seed of the city layout and of OMPL.
    airframe : str or Airframe
        The airframe that flies every path.
    tolerance : float
        Largest admissible separation [m].
    rrt_time, rrtstar_time : float
        Time cap of RRT / RRT-Connect and planning time of RRT* [s].

    Each stage is a :mod:`fm2uav.progress` step.
    """
    af = get_airframe(airframe)
    progress.step("planning both missions with W^1, W^1/2, W^1/4 and flying them",
                  0.6 if rrt else 1.0)
    run = CityRun(seed=seed, airframe=af, tolerance=tolerance,
                  cases=city_table(seed, af, tolerance=tolerance), missions=city_missions(seed))
    if rrt:
        progress.step("FM² vs OMPL RRT / RRT-Connect / RRT* (low mission)", 0.4)
        sc = run.missions["low"]
        run.rrt_rows, run.rrt = rrt_comparison(sc, "low", af, time_limit=rrt_time,
                                               rrtstar_time=rrtstar_time, tolerance=tolerance,
                                               seed=seed)
        z = float(sc.start[2])
        for r in run.rrt["rrt"].values():
            p = r.path if r.path.shape[1] == 3 else np.column_stack(
                [r.path, np.full(len(r.path), z)])
            run.rrt_paths[f"{r.planner} low (+ shortcut)"] = p
    return run


def markdown_table(rows: list[dict[str, Any]], cols: tuple[str, ...] | list[str]) -> str:
    """``rows`` as a Markdown table of the columns ``cols``."""
    head = "| " + " | ".join(cols) + " |\n|" + "---|" * len(cols) + "\n"
    return head + "".join("| " + " | ".join(str(r[c]) for c in cols) + " |\n" for r in rows)


def city_markdown(run: CityRun) -> str:
    """``table.md``: the safety/separation table and (when run) FM² vs RRT."""
    text = ("## Safety and separation distances (Tables 3.1/3.2)\n\n"
            + markdown_table(run.rows, CITY_TABLE_COLUMNS)
            + f"\nplan_s = plan() wall time [s]; {WARM_NOTE}.\n")
    if run.rrt is not None:
        text += ("\n## FM² vs RRT, low altitude (thesis: FM² 1.2 s, RRT 5 s)\n\n"
                 + markdown_table(run.rrt_rows, RRT_TABLE_COLUMNS)
                 + "\ntime_s: FM² warm (run once untimed first); OMPL planners single runs "
                 "(no compilation).\n")
    return text


def city_summary(run: CityRun) -> dict[str, Any]:
    """``summary.json`` of a run: airframe, both tables and the thesis' times."""
    return {"seed": run.seed, "airframe": run.airframe.summary(), "table": run.rows,
            "rrt": run.rrt_rows, "thesis_times_s": THESIS_TIMES_S}
