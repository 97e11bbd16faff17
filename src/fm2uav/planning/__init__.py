"""Single-path planning with FM²: the planner, geodesic extraction, speed shaping."""

from .geodesic import descend
from .planner import Plan, base_velocity, plan

__all__ = ["Plan", "plan", "descend", "base_velocity"]
