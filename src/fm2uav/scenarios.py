"""Built-in scenarios (re-exported from :mod:`fm2uav.world.scenarios`)."""

from .world.scenarios import SCENARIOS, Scenario, fissure, get_scenario, open_field

__all__ = ["SCENARIOS", "Scenario", "fissure", "get_scenario", "open_field"]
