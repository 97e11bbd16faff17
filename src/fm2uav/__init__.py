"""fm2uav: UAV mission planning with the Fast Marching Square (FM²) method.

Conventions: arrays are indexed ``[ix, iy, iz]`` (x first) on a node-centred
grid (node ``i`` at ``origin + i * spacing``); API points are world coordinates
in metres; SI units inside; occupancy True = obstacle; speed 0 = impassable;
unreached arrival time = ``inf``.

Layers, bottom to top (each imports only from those below; see
docs/architecture.md): ``errors``, ``geometry`` → ``eikonal`` → ``world`` →
``planning`` → ``missions`` → ``vehicles`` → ``analysis`` → ``baselines`` →
``scenarios`` → ``experiments`` → ``autopilot`` → ``io`` → ``viz`` → ``cli``.
"""

from typing import TYPE_CHECKING

from . import errors
from ._lazy import lazy_names
from .errors import *  # noqa: F403 -- the error hierarchy (pure Python), listed once in errors.__all__

if TYPE_CHECKING:  # loaded on first attribute access (PEP 562), see __getattr__
    from . import autopilot, baselines, experiments, io, viz
    from .analysis import flight_level_deviation, path_profiles
    from .analysis.tune import tune
    from .eikonal import distance_map, fast_marching, velocity_map
    from .missions import (
        CoveragePlan,
        FormationConfig,
        FormationResult,
        fly_formation,
        plan_coverage,
        zigzag,
    )
    from .planning import FlightLevel, Plan, PlanOptions, Shaping, plan
    from .scenarios import Scenario
    from .vehicles import (
        AIRFRAMES,
        AirframeLimits,
        FeasibilityReport,
        check_feasibility,
        get_airframe,
    )
    from .world import World

#: Where each public name lives. ``import fm2uav`` loads none of them (numba,
#: scipy and the kernels cost ~1 s): each is imported on first access (PEP 562),
#: so the command line can speak before the heavy imports.
_LAZY_NAMES = {
    "flight_level_deviation": ".analysis",
    "path_profiles": ".analysis",
    "tune": ".analysis.tune",
    "distance_map": ".eikonal",
    "fast_marching": ".eikonal",
    "velocity_map": ".eikonal",
    "CoveragePlan": ".missions",
    "FormationConfig": ".missions",
    "FormationResult": ".missions",
    "fly_formation": ".missions",
    "plan_coverage": ".missions",
    "zigzag": ".missions",
    "FlightLevel": ".planning",
    "Plan": ".planning",
    "PlanOptions": ".planning",
    "Shaping": ".planning",
    "plan": ".planning",
    "Scenario": ".scenarios",
    "AIRFRAMES": ".vehicles",
    "AirframeLimits": ".vehicles",
    "FeasibilityReport": ".vehicles",
    "check_feasibility": ".vehicles",
    "get_airframe": ".vehicles",
    "World": ".world",
}

#: Subpackages, also imported on first use (``fm2uav.scenarios.open_field()``
#: works after a bare ``import fm2uav``).
_LAZY_SUBMODULES = (
    "analysis", "autopilot", "baselines", "eikonal", "errors", "experiments", "geometry", "io",
    "missions", "planning", "scenarios", "vehicles", "viz", "world",
)


__getattr__, __dir__ = lazy_names(__name__, _LAZY_NAMES, _LAZY_SUBMODULES)

__version__ = "0.1.0"

__all__ = [
    # eikonal
    "fast_marching",
    "velocity_map",
    "distance_map",
    # planning
    "plan",
    "Plan",
    "Shaping",
    "FlightLevel",
    "PlanOptions",
    "tune",
    "AirframeLimits",
    # world
    "World",
    "Scenario",
    "scenarios",
    # missions
    "plan_coverage",
    "CoveragePlan",
    "zigzag",
    "fly_formation",
    "FormationConfig",
    "FormationResult",
    # vehicles / analysis
    "check_feasibility",
    "FeasibilityReport",
    "get_airframe",
    "AIRFRAMES",
    "flight_level_deviation",
    "path_profiles",
    # subpackages
    "analysis",
    "autopilot",
    "baselines",
    "experiments",
    "geometry",
    "io",
    "missions",
    "scenarios",
    "vehicles",
    "viz",
    # errors
    *errors.__all__,
    "__version__",
]
