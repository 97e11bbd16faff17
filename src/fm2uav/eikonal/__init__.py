"""Eikonal solvers: Fast Marching Method and the FM² velocity map."""

from .fmm import fast_marching

__all__ = ["fast_marching"]
