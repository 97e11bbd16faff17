"""Vehicles: airframe limits, Dubins-airplane / multirotor tracking, feasibility.

Typical use::

    from fm2uav.vehicles import check_feasibility
    report = check_feasibility(plan.path, "disco", world=plan.world, w=plan.w)
    report.feasible, report.reason, report.tracking.max_separation
"""

from .airframes import AIRFRAMES, Airframe, AirframeLimits, FixedWing, Multirotor, get_airframe
from .dubins_airplane import track_dubins
from .feasibility import DEFAULT_TOLERANCE, FeasibilityReport, check_feasibility, collision_check
from .geometric import GeometricCheck, climb_angle_profile, curvature_profile, geometric_check
from .multirotor import track_multirotor
from .speed_profile import SpeedProfile, admissible_speed_from_w, speed_profile, turn_speed_limit
from .tracking import Tracking, TrackingOptions

__all__ = [
    "AIRFRAMES",
    "Airframe",
    "AirframeLimits",
    "FixedWing",
    "Multirotor",
    "get_airframe",
    "track_dubins",
    "track_multirotor",
    "Tracking",
    "TrackingOptions",
    "check_feasibility",
    "FeasibilityReport",
    "DEFAULT_TOLERANCE",
    "collision_check",
    "geometric_check",
    "GeometricCheck",
    "curvature_profile",
    "climb_angle_profile",
    "speed_profile",
    "SpeedProfile",
    "admissible_speed_from_w",
    "turn_speed_limit",
]
