"""Path analysis: clearance, profiles, comparisons."""

from .clearance import clearance_profile
from .flight_level import FlightLevelReport, flight_level_deviation, ideal_altitude
from .profiles import Profiles, path_profiles

__all__ = [
    "clearance_profile",
    "FlightLevelReport",
    "flight_level_deviation",
    "ideal_altitude",
    "Profiles",
    "path_profiles",
]
