"""Single-path planning with FM²: the planner, its parameter objects, geodesic extraction."""

from .geodesic import descend
from .params import FlightLevel, PlanOptions, Shaping
from .planner import Plan, base_velocity, plan

__all__ = ["Plan", "plan", "descend", "base_velocity", "Shaping", "FlightLevel", "PlanOptions"]
