"""fm2uav: UAV mission planning with the Fast Marching Square (FM²) method.

Conventions: arrays are indexed ``[ix, iy, iz]`` (x first) on a node-centred
grid (node ``i`` at ``origin + i * spacing``); API points are world coordinates
in metres; SI units inside; occupancy True = obstacle; speed 0 = impassable;
unreached arrival time = ``inf``.

The pipeline: ``world`` (maps, scenarios) → ``eikonal`` (fast_marching,
velocity_map) → ``planning`` (plan, flight levels, tune) → ``missions``
(coverage, formations) → ``vehicles`` / ``analysis`` (feasibility, metrics,
comparisons) → ``io`` / ``viz`` (exports, figures, reports) → ``cli``.
"""

from . import analysis, io, missions, scenarios, vehicles, viz
from .analysis import flight_level_deviation, path_profiles
from .eikonal import distance_map, fast_marching, velocity_map
from .errors import (
    Fm2uavError,
    InputError,
    PlanningError,
    PointError,
    UnreachableError,
    WorldError,
)
from .missions import CoveragePlan, FormationResult, fly_formation, plan_coverage, zigzag
from .planning import Plan, plan
from .planning.tune import AirframeLimits, tune
from .vehicles import AIRFRAMES, FeasibilityReport, check_feasibility, get_airframe
from .world import Scenario, World

__version__ = "0.1.0"

__all__ = [
    # eikonal
    "fast_marching",
    "velocity_map",
    "distance_map",
    # planning
    "plan",
    "Plan",
    "tune",
    "AirframeLimits",
    # world
    "World",
    "Scenario",
    "scenarios",
    # missions
    "plan_coverage",
    "CoveragePlan",
    "zigzag",
    "fly_formation",
    "FormationResult",
    # vehicles / analysis
    "check_feasibility",
    "FeasibilityReport",
    "get_airframe",
    "AIRFRAMES",
    "flight_level_deviation",
    "path_profiles",
    # subpackages
    "analysis",
    "io",
    "missions",
    "vehicles",
    "viz",
    # errors
    "Fm2uavError",
    "InputError",
    "WorldError",
    "PlanningError",
    "PointError",
    "UnreachableError",
    "__version__",
]
