"""Single-path planning with FM²: the planner, its parameter objects, geodesic extraction.

The names are imported on first access (:mod:`fm2uav._lazy`): ``import
fm2uav.planning.params`` — what the command line checks its planner flags with — loads
the parameter objects alone, not the planner and its kernels.
"""

from typing import TYPE_CHECKING

from .._lazy import lazy_names

if TYPE_CHECKING:  # loaded on first attribute access (PEP 562)
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

__getattr__, __dir__ = lazy_names(__name__, {
    "descend": ".geodesic",
    "FlightLevel": ".params",
    "PlanOptions": ".params",
    "Shaping": ".params",
    **{name: ".planner" for name in ("Plan", "base_velocity", "max_distance", "plan",
                                     "shaped_velocity")},
})
