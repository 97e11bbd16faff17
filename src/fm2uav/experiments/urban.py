"""Thesis §4.4: flight levels in the city (Algorithm 2 among the buildings).

The thesis plans from (60, 10, 40) to (20, 75, 20) cells of 5 m in its 15-building city:

* **§4.4.1 control over flight levels**: levels 23, 30 and 37 cells with p1 = 0.2,
  p2 = 0.8 — each path keeps its level, the x–y route "barely suffers changes" between
  levels, and the climbs are too abrupt for a fixed-wing UAV;
* **§4.4.2 control over smoothness**: level 30 with (p1, p2) = (0.47, 0.53) ("too smooth,
  the imposed flight level is not appreciable"), (0.45, 0.55) ("more predominant, still very
  smooth") and (0.5, 1.5) ("maintained in the majority of the trajectory, sharp ascents and
  descents", VTOL only).

The flight level is the layer ``Surface(i, j) + Lf`` of Algorithm 2: a horizontal layer
``Lf`` cells above the street and ``Lf`` cells above each roof (thesis Fig. 4.2, "the 3D
urban map divided into layers"). Our city (:mod:`fm2uav.scenarios.city`) is a seeded
stand-in (the thesis' layout is not published): :func:`urban_seed` takes the first seed
whose buildings keep :data:`URBAN_MARGIN` from the thesis' start and goal, and the map is
:data:`URBAN_NZ` nodes tall so that the layer over the tallest roof (390 m + 37 cells)
stays inside it. The paths are the FM² geodesics (``FlightLevel(heights="fm2")``), as in
the thesis; ``plan_s`` is warm (:func:`._timing.warm`).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .. import progress
from ..analysis.flight_level import flight_level_deviation
from ..analysis.profiles import path_profiles
from ..analysis.similarity import frechet_distance
from ..errors import WorldError
from ..geometry import resample_path
from ..planning import FlightLevel, Plan, plan
from ..scenarios.city import CITY_CELL, CITY_SHAPE, city_buildings
from ..world import World
from ..world.buildings import from_buildings
from ..world.clearance import clearance_profile
from ._timing import WARM_NOTE, warm

__all__ = [
    "URBAN_START_CELLS",
    "URBAN_GOAL_CELLS",
    "URBAN_MARGIN",
    "URBAN_NZ",
    "LEVEL_CASES",
    "SMOOTH_CASES",
    "UrbanCase",
    "UrbanRun",
    "urban_seed",
    "urban_world",
    "reproduce_urban",
    "URBAN_COLUMNS",
    "urban_markdown",
]

#: Thesis §4.4.1 start and goal [cells of 5 m].
URBAN_START_CELLS = (60, 10, 40)
URBAN_GOAL_CELLS = (20, 75, 20)
#: Least distance [m] from the start/goal to a building for a seed to be used.
URBAN_MARGIN = 20.0
#: Height nodes of the urban map: the tallest roof (390 m = 78 cells) + level 37 + margin.
URBAN_NZ = 120


@dataclass(frozen=True)
class UrbanCase:
    """One thesis case: experiment (§4.4.1 "levels" / §4.4.2 "smoothness"), level [cells],
    p1, p2, and what the thesis says about its path."""

    experiment: str
    level: int
    p1: float
    p2: float
    thesis: str


#: §4.4.1: three levels with p1 = 0.2, p2 = 0.8.
LEVEL_CASES = tuple(UrbanCase("levels", lv, 0.2, 0.8, t) for lv, t in (
    (23, "keeps level 23; abrupt ascents/descents"),
    (30, "keeps level 30; same x-y route"),
    (37, "keeps level 37; same x-y route"),
))
#: §4.4.2: level 30 with three (p1, p2) pairs.
SMOOTH_CASES = (
    UrbanCase("smoothness", 30, 0.47, 0.53, "too smooth, level not appreciable"),
    UrbanCase("smoothness", 30, 0.45, 0.55, "level more predominant, still very smooth"),
    UrbanCase("smoothness", 30, 0.5, 1.5, "level kept on most of the path, sharp climbs (VTOL)"),
)


def urban_world(seed: int) -> World:
    """The city of ``seed`` (15 buildings, 5 m cells) on :data:`URBAN_NZ` height nodes."""
    return from_buildings(city_buildings(seed), CITY_CELL,
                          shape=(CITY_SHAPE[0], CITY_SHAPE[1], URBAN_NZ),
                          origin=(0.0, 0.0, 0.0), name=f"city (seed {seed}, {URBAN_NZ} layers)")


def _points(world: World) -> tuple[np.ndarray, np.ndarray]:
    return (world.to_world(np.asarray(URBAN_START_CELLS, dtype=float)),
            world.to_world(np.asarray(URBAN_GOAL_CELLS, dtype=float)))


def urban_seed(first: int = 0, tries: int = 50) -> int:
    """The first city seed from ``first`` whose buildings keep :data:`URBAN_MARGIN` metres
    from the thesis' start and goal (seed 0 has a building on the start)."""
    for seed in range(first, first + tries):
        w = urban_world(seed)
        s, g = _points(w)
        if clearance_profile(w, np.array([s, g])).min() >= URBAN_MARGIN:
            return seed
    raise WorldError(f"no city seed in {first}..{first + tries - 1} keeps {URBAN_MARGIN:g} m "
                     "from the thesis' start and goal; pass another --seed")


@dataclass(eq=False)
class UrbanRun:
    """The six planned cases: one row and one plan each."""

    seed: int
    world: World = field(repr=False)
    start: np.ndarray = field(repr=False)
    goal: np.ndarray = field(repr=False)
    cases: list[UrbanCase]
    rows: list[dict[str, Any]]
    plans: list[Plan] = field(repr=False)


def _xy_frechet(a: np.ndarray, b: np.ndarray) -> float:
    return frechet_distance(resample_path(a[:, :2], CITY_CELL), resample_path(b[:, :2], CITY_CELL))


@progress.stage()
def reproduce_urban(seed: int | None = None) -> UrbanRun:
    """Plan and measure the six cases of thesis §4.4 (``seed=None``: :func:`urban_seed`)."""
    from .._validate import seed_value

    seed = urban_seed() if seed is None else seed_value(seed, "seed", where=(None, "--seed"))
    world = urban_world(seed)
    start, goal = _points(world)
    for what, p in (("start", start), ("goal", goal)):
        if world.occupancy[world.to_cell(p)]:
            raise WorldError(f"the thesis' {what} {p.tolist()} m is inside a building of city "
                             f"seed {seed}; pass another --seed (or none: the first free one)")
    cases = list(LEVEL_CASES + SMOOTH_CASES)
    rows, plans = [], []
    dz = world.spacing[2]
    for case in progress.each(cases, lambda c: f"§4.4 {c.experiment}: level {c.level}, "
                                               f"p1 = {c.p1:g}, p2 = {c.p2:g}"):
        agl = case.level * dz
        level = FlightLevel(agl=agl, p1=case.p1, p2=case.p2, heights="fm2")
        p, seconds = warm(lambda: plan(world, start, goal, level=level), [world])
        layer = flight_level_deviation(world, p.path, agl, reference="layer")
        prof = path_profiles(p.path, ds=CITY_CELL).summary()
        rows.append({
            "experiment": case.experiment, "level": case.level, "agl_m": agl,
            "p1": case.p1, "p2": case.p2,
            "within": layer.within, "within_all": layer.within_all,
            "mean_dev_layer_m": layer.mean_dev_all_m,
            "climb_max_deg": prof["climb_max_deg"], "climb_p95_deg": prof["climb_p95_deg"],
            "turn_max_deg": prof["turn_max_deg"],
            "min_z_m": float(p.path[:, 2].min()), "max_z_m": float(p.path[:, 2].max()),
            "clearance_m": float(p.clearance), "length_m": float(p.length),
            "plan_s": seconds, "thesis": case.thesis,
        })
        plans.append(p)
    # x-y route against the level-30 route of the same experiment (thesis: "barely changes")
    for exp, ref in (("levels", 1), ("smoothness", 3)):
        for i, r in enumerate(rows):
            if r["experiment"] == exp:
                r["xy_frechet_m"] = _xy_frechet(plans[i].path, plans[ref].path)
    return UrbanRun(seed, world, start, goal, cases, rows, plans)


#: Columns of the urban table: (header, key, format).
URBAN_COLUMNS = (
    ("experiment", "experiment", "{}"),
    ("level [cells]", "level", "{}"),
    ("(p1, p2)", None, None),
    ("on level between transitions", "within", "{:.0%}"),
    ("on level, all points", "within_all", "{:.0%}"),
    ("mean abs dev vs layer [m]", "mean_dev_layer_m", "{:.1f}"),
    ("max climb [°]", "climb_max_deg", "{:.0f}"),
    ("p95 climb [°]", "climb_p95_deg", "{:.0f}"),
    ("x-y route vs the reference case, Fréchet [m]", "xy_frechet_m", "{:.1f}"),
    ("clearance [m]", "clearance_m", "{:.1f}"),
    ("length [m]", "length_m", "{:.0f}"),
    ("plan, warm [s]", "plan_s", "{:.2f}"),
    ("thesis says", "thesis", "{}"),
)


def urban_markdown(run: UrbanRun) -> str:
    """The case table as Markdown, with a caption line."""
    head = [c[0] for c in URBAN_COLUMNS]
    out = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for r in run.rows:
        cells = [f"({r['p1']:g}, {r['p2']:g})" if key is None else fmt.format(r[key])
                 for _, key, fmt in URBAN_COLUMNS]
        out.append("| " + " | ".join(cells) + " |")
    s, g = URBAN_START_CELLS, URBAN_GOAL_CELLS
    out += ["", f"City seed {run.seed} ({run.world.shape[0]}×{run.world.shape[1]}×"
            f"{run.world.shape[2]} nodes of {CITY_CELL:g} m), start {s} → goal {g} cells "
            "(thesis §4.4.1); 'on level' = within ±1 cell of the Algorithm-2 layer (street + "
            f"level, roof + level); reference case of the x-y comparison: level 30 for the levels, "
            "(0.47, 0.53) for the smoothness; FM² geodesics (heights from the shaping); "
            f"{WARM_NOTE}."]
    return "\n".join(out)
