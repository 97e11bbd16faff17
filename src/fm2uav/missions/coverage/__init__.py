"""Coverage path planning: zigzag bands, Differential Evolution, FM² at a flight level.

Pipeline (coverage paper 003, thesis ch. 5): validate the area
(:func:`as_area`) → choose the steering angle minimising the zigzag cost
(:func:`differential_evolution`, checked by :func:`sweep` / :func:`scipy_de`)
→ build the bands (:func:`zigzag`) → FM² along them at a flight level over the
terrain (:func:`plan_coverage`, by default on the corridor unrolled along the
zigzag, :func:`corridor_grid`) → coverage share (:func:`coverage_share`).
"""

from .area import as_area, check_spacing, read_area
from .bands import Zigzag, zigzag
from .camera import Camera, band_spacing
from .cost import ZigzagCost, cost
from .fm2 import (
    GRIDS,
    CoveragePlan,
    corridor_grid_speed,
    corridor_speed,
    coverage_speed_map,
    plan_coverage,
)
from .grid import CorridorGrid, corridor_grid
from .optimise import (
    FULL_BOUNDS_DEG,
    SEEDS_BOUNDS_DEG,
    AngleSearch,
    DESettings,
    differential_evolution,
    optimise_angle,
    scipy_de,
    sweep,
)
from .report import coverage_share, seen_region

__all__ = [
    "as_area", "read_area", "check_spacing",
    "Zigzag", "zigzag",
    "Camera", "band_spacing",
    "ZigzagCost", "cost",
    "AngleSearch", "DESettings", "differential_evolution", "sweep", "scipy_de", "optimise_angle",
    "SEEDS_BOUNDS_DEG", "FULL_BOUNDS_DEG",
    "CoveragePlan", "plan_coverage", "coverage_speed_map", "corridor_speed", "GRIDS",
    "CorridorGrid", "corridor_grid", "corridor_grid_speed",
    "coverage_share", "seen_region",
]
