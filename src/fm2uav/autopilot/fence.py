"""No-fly zones and the operating area of a world as QGroundControl geofences.

:func:`zone_fences` turns ``World.zones`` (:mod:`fm2uav.world.zones`) into the
fences of the ``.plan`` (:mod:`fm2uav.autopilot.geofence`): each no-fly zone an
*exclusion* polygon (or circle, when it is one), the operating area an
*inclusion* polygon. Fences are written as the zones are, without the
planning buffer (the buffer is the planner's margin, the fence the boundary
the autopilot enforces).

QGC / PX4 / ArduPilot fences are two-dimensional: a zone with a floor or a
ceiling (airspace above or below which the plan may fly) cannot be a fence
without the autopilot breaching it when the plan passes over or under it, so
such zones are left out and named in the returned warnings.
"""

from __future__ import annotations

from typing import Any

from .geofence import fences_from_world
from ..world.geo import Anchor

__all__ = ["zone_fences"]


def zone_fences(zones: Any, world: Any, anchor: Anchor | None = None
                ) -> tuple[list[Any], list[str]]:
    """Geofences (WGS84) of the zones, and warnings for zones that cannot be fences.

    Parameters
    ----------
    zones : sequence of Zone
        Usually ``world.zones``.
    world : World
        Gives the CRS (or ``anchor`` for a world without one).
    anchor : Anchor, optional

    Returns
    -------
    fences : list of FencePolygon / FenceCircle
    warnings : list of str
    """
    fences: list[Any] = []
    warnings: list[str] = []
    for k, z in enumerate(zones or ()):
        name = z.name or f"{z.kind} {k + 1}"
        vertical = z.floor is not None or z.ceiling is not None
        if vertical and not z.inclusion:
            warnings.append(f"{z.kind} {name!r} has a floor/ceiling; QGC geofences are 2D, so it "
                            "is not written into the .plan geoFence (the plan keeps out of it)")
            continue
        geom = ("circle", z.circle[0], z.circle[1]) if z.circle is not None else z.geometry
        out, warn = fences_from_world(geom, world, anchor=anchor, inclusion=z.inclusion,
                                      name=name)
        fences.extend(out)
        warnings.extend(warn)
        if vertical:
            warnings.append(f"operating area {name!r}: its floor/ceiling are not part of the "
                            "geofence (QGC fences are 2D)")
    return fences, warnings
