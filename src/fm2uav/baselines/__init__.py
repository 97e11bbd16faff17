"""Other planners, for comparison with FM²: RRT / RRT* / RRT-Connect (OMPL) and the
curvature-penalised lattice references (Dubins, Euler–Mumford elastica, Reeds–Shepp).

A new baseline planner goes in its own module here; nothing below this layer imports it.
"""

from .reference import MODELS, ReferencePath, dubins_length, reference_path
from .rrt import RRTOptions, RRTResult, plan_rrt

__all__ = ["RRTOptions", "RRTResult", "plan_rrt", "MODELS", "ReferencePath", "reference_path", "dubins_length"]
