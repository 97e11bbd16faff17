"""Missions made of many paths: coverage (zigzag + DE + FM²), formations."""

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
