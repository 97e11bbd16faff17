"""fm2uav: UAV mission planning with the Fast Marching Square (FM²) method.

Conventions: arrays are indexed ``[ix, iy, iz]`` (x first) on a node-centred
grid (node ``i`` at ``origin + i * spacing``); API points are world coordinates
in metres; SI units inside; occupancy True = obstacle; speed 0 = impassable;
unreached arrival time = ``inf``.
"""

from . import scenarios
from .eikonal import distance_map, fast_marching, velocity_map
from .errors import (
    Fm2uavError,
    InputError,
    PlanningError,
    PointError,
    UnreachableError,
    WorldError,
)
from .planning import Plan, plan
from .world import Scenario, World

__version__ = "0.1.0"

__all__ = [
    "fast_marching",
    "velocity_map",
    "distance_map",
    "plan",
    "Plan",
    "World",
    "Scenario",
    "scenarios",
    "Fm2uavError",
    "InputError",
    "WorldError",
    "PlanningError",
    "PointError",
    "UnreachableError",
    "__version__",
]
