"""Leader–follower UAV formations with FM² (thesis ch. 6).

``fly_formation(world, start, goal, config=FormationConfig(...), level=...)`` plans
the leader with FM², then in every cycle re-plans every UAV locally towards its
partial goal (eqs 6.1/6.2), with the other UAVs as obstacles. See :mod:`.mission`
(orchestration), :mod:`.config` (settings), :mod:`.guide` (partial goals, grey
levels), :mod:`.cycles` (the cycles), :mod:`.local` (static maps, local FM²),
:mod:`.heights` (each UAV's final heights: one truth for every file).
"""

from .checks import inside_terrain, min_separation, pair_distances
from .config import GREY_MODES, FormationConfig
from .guide import grey_levels
from .heights import Track, profile_tracks
from .local import StaticMaps, local_path
from .metrics import formation_error
from .mission import FormationResult, fly_formation
from .shapes import SHAPES, FormationShape, formation_shape, slot_offsets, slot_positions

__all__ = [
    "fly_formation",
    "FormationConfig",
    "FormationResult",
    "Track",
    "profile_tracks",
    "formation_shape",
    "FormationShape",
    "slot_offsets",
    "slot_positions",
    "grey_levels",
    "formation_error",
    "inside_terrain",
    "min_separation",
    "pair_distances",
    "StaticMaps",
    "local_path",
    "SHAPES",
    "GREY_MODES",
]
