"""Bad-input catalogue: library calls (issue 17 item 5).

Every case asserts the error class (an Fm2uavError subclass) and a fragment of its one-line
message. Cases are cheap (tiny grids) so the whole catalogue stays fast.
"""

from __future__ import annotations

import numpy as np
import pytest

from fm2uav import FlightLevel, PlanOptions, Shaping, World, fast_marching, plan
from fm2uav import _validate as v
from fm2uav.errors import (
    Fm2uavError,
    InputError,
    PlanningError,
    PointError,
    UnreachableError,
    WorldError,
)
from fm2uav.planning.geodesic import descend

OPEN2 = np.zeros((20, 20), bool)
WALL2 = OPEN2.copy()
WALL2[10, :] = True
OPEN3 = np.zeros((10, 10, 6), bool)


def w2(occ=OPEN2, spacing=1.0):
    return World(occ, spacing=spacing)


def _speed():
    return np.ones((10, 10))


CASES = [
    # ---- World construction
    ("world-1d", lambda: World(np.zeros(5, bool), spacing=1.0), Fm2uavError, ""),
    ("world-4d", lambda: World(np.zeros((2, 2, 2, 2), bool), spacing=1.0), Fm2uavError, ""),
    ("world-empty", lambda: World(np.zeros((0, 5), bool), spacing=1.0), Fm2uavError, ""),
    ("world-spacing-0", lambda: World(OPEN2, spacing=0.0), Fm2uavError, "spacing"),
    ("world-spacing-neg", lambda: World(OPEN2, spacing=-1.0), Fm2uavError, "spacing"),
    ("world-spacing-nan", lambda: World(OPEN2, spacing=float("nan")), Fm2uavError, "spacing"),
    ("world-spacing-inf", lambda: World(OPEN2, spacing=float("inf")), Fm2uavError, "spacing"),
    ("world-spacing-str", lambda: World(OPEN2, spacing="big"), Fm2uavError, "spacing"),
    ("world-spacing-len", lambda: World(OPEN2, spacing=(1.0, 1.0, 1.0)), Fm2uavError, "spacing"),
    ("world-origin-nan", lambda: World(OPEN2, spacing=1.0, origin=(np.nan, 0.0)), Fm2uavError,
     "origin"),
    ("world-origin-len", lambda: World(OPEN2, spacing=1.0, origin=(0.0, 0.0, 0.0)), Fm2uavError,
     "origin"),
    ("world-occ-float", lambda: World(np.full((4, 4), 0.5), spacing=1.0), Fm2uavError, ""),
    ("world-occ-str", lambda: World(np.array([["a", "b"], ["c", "d"]]), spacing=1.0),
     Fm2uavError, ""),
    ("world-terrain-shape", lambda: World(OPEN3, spacing=1.0, terrain=np.zeros((3, 3))),
     Fm2uavError, "terrain"),
    ("world-all-blocked", lambda: plan(w2(np.ones((5, 5), bool)), (1, 1), (3, 3)), PointError,
     "obstacle"),
    # ---- points given to plan()
    ("plan-start-nan", lambda: plan(w2(), (np.nan, 1), (5, 5)), InputError, "finite"),
    ("plan-start-inf", lambda: plan(w2(), (np.inf, 1), (5, 5)), InputError, "finite"),
    ("plan-goal-nan", lambda: plan(w2(), (1, 1), (5, np.nan)), InputError, "finite"),
    ("plan-start-1d", lambda: plan(w2(), (1,), (5, 5)), InputError, "coordinates"),
    ("plan-start-3d-on-2d", lambda: plan(w2(), (1, 1, 1), (5, 5)), InputError, "coordinates"),
    ("plan-start-str", lambda: plan(w2(), "here", (5, 5)), InputError, "start"),
    ("plan-start-none", lambda: plan(w2(), None, (5, 5)), InputError, "start"),
    ("plan-start-dict", lambda: plan(w2(), {"x": 1}, (5, 5)), InputError, "start"),
    ("plan-start-outside", lambda: plan(w2(), (-5, 1), (5, 5)), PlanningError, "outside"),
    ("plan-goal-outside", lambda: plan(w2(), (1, 1), (500, 5)), PlanningError, "outside"),
    ("plan-start-in-wall", lambda: plan(w2(WALL2), (10, 3), (15, 5)), PointError, "obstacle"),
    ("plan-goal-in-wall", lambda: plan(w2(WALL2), (1, 3), (10, 5)), PointError, "obstacle"),
    ("plan-unreachable", lambda: plan(w2(WALL2), (1, 3), (15, 5)), UnreachableError,
     "cannot be reached"),
    ("plan-start-eq-goal", lambda: plan(w2(), (3, 3), (3, 3)), PointError, "same grid node"),
    ("plan-start-near-goal", lambda: plan(w2(), (3, 3), (3.2, 3.1)), PointError, "same grid node"),
    ("plan-3d-start-eq-goal", lambda: plan(World(OPEN3, spacing=1.0), (2, 2, 2), (2, 2, 2)),
     PointError, "nothing to plan"),
    ("plan-world-not-world", lambda: plan(OPEN2, (1, 1), (5, 5)), InputError, "World"),
    ("plan-shaping-dict", lambda: plan(w2(), (1, 1), (5, 5), shaping={"exponent": 2}),
     InputError, "Shaping"),
    ("plan-level-number", lambda: plan(w2(), (1, 1), (5, 5), level=100.0), InputError, "level"),
    ("plan-options-dict", lambda: plan(w2(), (1, 1), (5, 5), options={"step": 0.5}), InputError,
     "options"),
    ("plan-anisotropic-steps", lambda: plan(World(OPEN2, spacing=(1e-3, 1e4)), (0, 0),
                                            (0.015, 150000)), InputError, "geodesic steps"),
    ("plan-agl-1e308", lambda: plan(World(OPEN3, spacing=1.0), (2, 2, 2), (7, 7, 3),
                                    level=FlightLevel(agl=1e308)), InputError,
     "too large; allowed: at most 5000 m"),
    ("plan-agl-above-map", lambda: plan(World(OPEN3, spacing=1.0), (2, 2, 2), (7, 7, 3),
                                        level=FlightLevel(agl=4000)), PlanningError,
     "leaves the map everywhere"),
    ("plan-speed-map-shape", lambda: plan(w2(), (1, 1), (5, 5),
                                          options=PlanOptions(speed_map=np.ones((3, 3)))),
     InputError, "speed_map"),
    # ---- Shaping
    ("shaping-sat-0", lambda: Shaping(saturation=0.0), InputError, "planner.saturation"),
    ("shaping-sat-2", lambda: Shaping(saturation=2.0), InputError, "--saturation"),
    ("shaping-sat-nan", lambda: Shaping(saturation=float("nan")), InputError, "saturation"),
    ("shaping-sat-str", lambda: Shaping(saturation="high"), InputError, "saturation"),
    ("shaping-exp-0", lambda: Shaping(exponent=0.0), InputError, "planner.exponent"),
    ("shaping-exp-neg", lambda: Shaping(exponent=-1.0), InputError, "--exponent"),
    ("shaping-exp-inf", lambda: Shaping(exponent=float("inf")), InputError, "exponent"),
    ("shaping-exp-bool", lambda: Shaping(exponent=True), InputError, "exponent"),
    ("shaping-satdist-neg", lambda: Shaping(saturation_distance=-3.0), InputError,
     "saturation_distance"),
    ("shaping-method", lambda: Shaping(method="bfs"), InputError, "method"),
    ("shaping-walls-str", lambda: Shaping(walls="yes"), InputError, "walls"),
    # ---- FlightLevel
    ("level-agl-0", lambda: FlightLevel(agl=0.0), InputError, "planner.agl"),
    ("level-agl-neg", lambda: FlightLevel(agl=-10.0), InputError, "--agl"),
    ("level-agl-nan", lambda: FlightLevel(agl=float("nan")), InputError, "agl"),
    ("level-agl-str", lambda: FlightLevel(agl="high"), InputError, "agl"),
    ("level-p1-0", lambda: FlightLevel(agl=50, p1=0.0), InputError, "p1"),
    ("level-p2-neg", lambda: FlightLevel(agl=50, p2=-1.0), InputError, "p2"),
    ("level-band-neg", lambda: FlightLevel(agl=50, band=-1.0), InputError, "band"),
    ("level-mode", lambda: FlightLevel(agl=50, mode="strict"), InputError, "mode"),
    ("level-tolerance-neg", lambda: FlightLevel(agl=50, tolerance=-1.0), InputError, "tolerance"),
    ("level-min-above-agl", lambda: FlightLevel(agl=50, min_agl=60), InputError, "min_agl"),
    ("level-max-below-agl", lambda: FlightLevel(agl=150, max_agl=120), InputError,
     "planner.max_agl"),
    ("level-graded-str", lambda: FlightLevel(agl=50, graded="no"), InputError, "graded"),
    ("level-max-climb-0", lambda: FlightLevel(agl=50, max_climb=0.0), InputError, "max_climb"),
    ("level-max-climb-91", lambda: FlightLevel(agl=50, max_climb=91.0), InputError, "max_climb"),
    # ---- PlanOptions
    ("options-order-3", lambda: PlanOptions(order=3), InputError, "planner.order"),
    ("options-order-float", lambda: PlanOptions(order=1.5), InputError, "order"),
    ("options-step-0", lambda: PlanOptions(step=0.0), InputError, "planner.step"),
    ("options-step-2", lambda: PlanOptions(step=2.0), InputError, "--step"),
    ("options-step-1e-9", lambda: PlanOptions(step=1e-9), InputError, "[0.01, 1]"),
    ("options-step-nan", lambda: PlanOptions(step=float("nan")), InputError, "step"),
    ("options-speed-map-nan", lambda: plan(w2(), (1, 1), (5, 5), options=PlanOptions(
        speed_map=np.full((20, 20), np.nan))), InputError, "finite"),
    ("options-speed-map-neg", lambda: plan(w2(), (1, 1), (5, 5), options=PlanOptions(
        speed_map=-np.ones((20, 20)))), PointError, "velocity map is 0"),
    # ---- fast_marching
    ("fmm-speed-1d", lambda: fast_marching(np.ones(5), [(0,)]), InputError, ""),
    ("fmm-speed-nan", lambda: fast_marching(np.full((5, 5), np.nan), [(0, 0)]), InputError, ""),
    ("fmm-speed-neg", lambda: fast_marching(-np.ones((5, 5)), [(0, 0)]), InputError, ""),
    ("fmm-source-outside", lambda: fast_marching(_speed(), [(20, 20)]), Fm2uavError, ""),
    ("fmm-source-empty", lambda: fast_marching(_speed(), []), InputError, ""),
    ("fmm-source-str", lambda: fast_marching(_speed(), "a"), InputError, ""),
    ("fmm-order-3", lambda: fast_marching(_speed(), [(0, 0)], order=3), InputError, "order"),
    ("fmm-spacing-0", lambda: fast_marching(_speed(), [(0, 0)], spacing=0.0), InputError,
     "spacing"),
    ("fmm-source-blocked", lambda: fast_marching(np.zeros((5, 5)), [(0, 0)]), Fm2uavError, ""),
    # ---- descend
    ("descend-T-nan", lambda: descend(np.full((5, 5), np.nan), (0, 0), (4, 4)), InputError,
     "arrival times"),
    ("descend-T-bool", lambda: descend(np.ones((5, 5), bool), (0, 0), (4, 4)), InputError, "dtype"),
    ("descend-T-1d", lambda: descend(np.ones(5), (0,), (4,)), InputError, "2D or 3D"),
    ("descend-start-outside", lambda: descend(np.ones((5, 5)), (9, 9), (0, 0)), PlanningError,
     "outside the grid"),
    ("descend-start-nan", lambda: descend(np.ones((5, 5)), (np.nan, 0), (0, 0)), InputError,
     "finite"),
    ("descend-max-steps-neg", lambda: descend(np.ones((5, 5)), (1, 1), (0, 0), max_steps=-1),
     InputError, "max_steps"),
    # ---- _validate (the shared checks every layer uses)
    ("validate-positive", lambda: v.positive(-1, "agl", where=("planner.agl", "--agl")),
     InputError, "(mission file: planner.agl; CLI: --agl)"),
    ("validate-in-range", lambda: v.in_range(5, "alpha", 0, 1), InputError, "alpha"),
    ("validate-integer", lambda: v.integer(1.5, "seed"), InputError, "seed"),
    ("validate-choice", lambda: v.choice("x", ("a", "b"), "mode"), InputError, "'a', 'b'"),
    ("validate-flag", lambda: v.flag("yes", "walls"), InputError, "true or false"),
    ("validate-point", lambda: v.point([1, 2], 3, "start"), InputError, "3 coordinates"),
    ("validate-yaml-dup", lambda: v.load_yaml("a: 1\nb: 2\na: 3\n", "config", source="<t>"),
     InputError, "duplicate key 'a' (lines 1 and 3)"),
    ("validate-yaml-dup-nested", lambda: v.load_yaml("w:\n  x: 1\n  x: 2\n", "m", source="<t>"),
     InputError, "duplicate key 'x'"),
    ("validate-yaml-syntax", lambda: v.load_yaml("a: [1, 2\n", "m", source="<t>"),
     InputError, "not valid YAML"),
    ("validate-yaml-deep", lambda: v.load_yaml("[" * 20000, "m", source="<t>"), InputError,
     "nested too deeply"),
    ("validate-input-file-none", lambda: v.input_file(None, "the DEM"), InputError, "file path"),
    ("validate-input-file-empty", lambda: v.input_file("", "the DEM"), InputError, "file path"),
    ("validate-input-file-missing", lambda: v.input_file("/nonexistent/x.tif", "the DEM"),
     InputError, "not found"),
    ("validate-input-file-dir", lambda: v.input_file("/", "the DEM"), InputError,
     "is a directory"),
    ("validate-input-file-device", lambda: v.input_file("/dev/null", "the DEM"), InputError,
     "a device"),
]


@pytest.mark.parametrize("thunk, exc, fragment", [c[1:] for c in CASES],
                         ids=[c[0] for c in CASES])
def test_library_bad_input(thunk, exc, fragment):
    with pytest.raises(exc) as err:
        thunk()
    msg = str(err.value)
    assert isinstance(err.value, Fm2uavError)
    assert fragment in msg
    assert "\n" not in msg.strip(), msg


def test_catalogue_ids_unique():
    ids = [c[0] for c in CASES]
    assert len(ids) == len(set(ids))
