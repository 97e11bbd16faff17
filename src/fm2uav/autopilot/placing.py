"""World metres → mission items: positions in the mission's altitude frame, map bounds.

:class:`ItemPlacer` makes the position items that are not route waypoints (take-off,
climb-out loiter, landing pattern, loiter at the end) at a world ``(x, y)`` and a
flown altitude, writing param7 in the item's frame (AMSL, above home, above the
terrain) and recording the height above the DEM and the AMSL altitude.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ..world.geo import Anchor, to_lonlat
from .items import FRAME_GLOBAL, FRAME_RELATIVE, FRAME_TERRAIN, MissionItem
from .waypoints import Waypoints, ground_at

__all__ = ["ItemPlacer", "inside_xy", "unit_xy"]


def unit_xy(points: np.ndarray, from_end: bool) -> np.ndarray:
    """Unit horizontal direction of arrival at the end (or of departure from the start),
    measured to the nearest waypoint more than 1 m away."""
    ref = points[-1] if from_end else points[0]
    seq = points[-2::-1] if from_end else points[1:]
    for q in seq:
        d = (ref - q)[:2] if from_end else (q - ref)[:2]
        n = float(np.hypot(d[0], d[1]))
        if n > 1.0:
            return d / n
    return np.array([1.0, 0.0])


def inside_xy(world: Any, xy: np.ndarray) -> np.ndarray:
    """Whether each ``(x, y)`` [m] lies on the map."""
    b = world.bounds
    return ((xy[:, 0] >= b[0, 0]) & (xy[:, 0] <= b[0, 1]) & (xy[:, 1] >= b[1, 0])
            & (xy[:, 1] <= b[1, 1]))


class ItemPlacer:
    """World metres → items, in the mission's altitude frame."""

    def __init__(self, world: Any, anchor: Anchor | None, wps: Waypoints) -> None:
        self.world, self.anchor, self.wps = world, anchor, wps
        self.home_amsl = wps.home[2]

    def ground(self, xy: np.ndarray) -> np.ndarray:
        """Ground height (world z) under ``(n, 2)`` points [m]."""
        return ground_at(self.world, xy)

    def item(self, command: int, frame: int, xy: np.ndarray, z_world: float, *,
             label: str, **params: float) -> MissionItem:
        """A position item at world ``xy`` and flown altitude ``z_world`` [m]."""
        lo, la, amsl = to_lonlat(self.world, [[xy[0], xy[1], z_world]], anchor=self.anchor)[0]
        g = float(self.ground(xy)[0])
        agl = z_world - g
        alt = {FRAME_GLOBAL: amsl, FRAME_RELATIVE: amsl - self.home_amsl,
               FRAME_TERRAIN: agl}[frame]
        return MissionItem.at(command, frame, float(la), float(lo), float(alt), agl=float(agl),
                              alt_amsl=float(amsl), label=label, **params)
