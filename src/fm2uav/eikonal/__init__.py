"""Eikonal solvers: Fast Marching Method (also in a wind) and the FM² velocity map."""

from .fmm import fast_marching
from .velocity import distance_map, velocity_map
from .wind import zermelo_march  # also registers the wind march with fast_marching

__all__ = ["fast_marching", "velocity_map", "distance_map", "zermelo_march"]
