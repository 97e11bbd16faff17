"""Missions made of many paths: coverage (zigzag + DE + FM²), formations."""

from typing import TYPE_CHECKING

from .._lazy import lazy_names

if TYPE_CHECKING:  # loaded on first attribute access (PEP 562)
    from .coverage import CoveragePlan, Zigzag, plan_coverage, zigzag
    from .formation import FormationConfig, FormationResult, fly_formation, formation_shape

__all__ = [
    "Zigzag",
    "zigzag",
    "plan_coverage",
    "CoveragePlan",
    "fly_formation",
    "FormationConfig",
    "FormationResult",
    "formation_shape",
]

#: Where each name lives (imported on first access: the mission types' light modules, e.g.
#: their settings, load without the planner and the kernels).
__getattr__, __dir__ = lazy_names(__name__, {
    "CoveragePlan": ".coverage",
    "Zigzag": ".coverage",
    "plan_coverage": ".coverage",
    "zigzag": ".coverage",
    "FormationConfig": ".formation",
    "FormationResult": ".formation",
    "fly_formation": ".formation",
    "formation_shape": ".formation",
}, ("coverage", "formation", "route"))
