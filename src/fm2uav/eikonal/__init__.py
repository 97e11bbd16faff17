"""Eikonal solvers: Fast Marching Method and the FM² velocity map."""

from .fmm import fast_marching
from .velocity import distance_map, velocity_map

__all__ = ["fast_marching", "velocity_map", "distance_map"]
