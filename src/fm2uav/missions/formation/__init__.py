"""Leader–follower UAV formations with FM² (thesis ch. 6).

``fly_formation(world, start, goal, config=FormationConfig(...), level=...)`` plans
the leader with FM², then in every cycle re-plans every UAV locally towards its
partial goal (eqs 6.1/6.2), with the other UAVs as obstacles. See :mod:`.mission`
(orchestration), :mod:`.config` (settings), :mod:`.guide` (partial goals, grey
levels), :mod:`.cycles` (the cycles), :mod:`.local` (static maps, local FM²),
:mod:`.heights` (each UAV's final heights: one truth for every file).
"""

from typing import TYPE_CHECKING

from ..._lazy import lazy_names

if TYPE_CHECKING:  # loaded on first attribute access (PEP 562)
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

#: Where each name lives: ``fm2uav.missions.formation.config`` (what the command line checks
#: --followers with) loads without the planner.
__getattr__, __dir__ = lazy_names(__name__, {
    "inside_terrain": ".checks",
    "min_separation": ".checks",
    "pair_distances": ".checks",
    "GREY_MODES": ".config",
    "FormationConfig": ".config",
    "grey_levels": ".guide",
    "Track": ".heights",
    "profile_tracks": ".heights",
    "StaticMaps": ".local",
    "local_path": ".local",
    "formation_error": ".metrics",
    "FormationResult": ".mission",
    "fly_formation": ".mission",
    "SHAPES": ".shapes",
    "FormationShape": ".shapes",
    "formation_shape": ".shapes",
    "slot_offsets": ".shapes",
    "slot_positions": ".shapes",
}, ("checks", "config", "cycles", "guide", "heights", "local", "metrics", "mission", "shapes"))
