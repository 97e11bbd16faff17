"""Single-path planning with FM²: the planner, its parameter objects, geodesic extraction."""

from .geodesic import descend
from .params import FlightLevel, PlanOptions, Shaping
from .planner import Plan, base_velocity, max_distance, plan, shaped_velocity

__all__ = [
    "Plan",
    "plan",
    "descend",
    "base_velocity",
    "shaped_velocity",
    "max_distance",
    "Shaping",
    "FlightLevel",
    "PlanOptions",
]
