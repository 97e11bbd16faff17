"""Reference planners of the curvature study (seed 004, eq. (5)).

Dubins, Euler–Mumford elastica and Reeds–Shepp forward shortest paths among
obstacles on a 2D map, by a compiled (x, y, θ) lattice search with biarc
motion primitives, and the exact free-space Dubins length for validation.
"""

from .dubins import dubins_length
from .lattice import DEFAULT_XI, ReferencePath, reference_path
from .primitives import MODELS, build_primitives, lattice_headings

__all__ = [
    "MODELS",
    "DEFAULT_XI",
    "ReferencePath",
    "reference_path",
    "dubins_length",
    "build_primitives",
    "lattice_headings",
]
