"""Path analysis: clearance, profiles, comparisons."""

from .clearance import clearance_profile

__all__ = ["clearance_profile"]
