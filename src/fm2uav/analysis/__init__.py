"""Path analysis: profiles, flight-level deviation, similarity, tuning."""

from .flight_level import FlightLevelReport, flight_level_deviation, ideal_altitude
from .profiles import Profiles, path_profiles

__all__ = [
    "FlightLevelReport",
    "flight_level_deviation",
    "ideal_altitude",
    "Profiles",
    "path_profiles",
]
