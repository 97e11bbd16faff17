"""Worlds, plans and routes shared by the mission tests (built once per session, small)."""

from __future__ import annotations

from functools import lru_cache

import numpy as np
from scipy import ndimage

from fm2uav import FlightLevel, World, plan
from fm2uav.world.geo import Anchor, from_lonlat

#: PX4 SITL's home (QGC docs example), used to place the synthetic worlds.
ANCHOR = Anchor(lon=8.545594, lat=47.3977419, alt=488.0)
UTM = "EPSG:32632"
UTM_ORIGIN = (464000.0, 5249000.0, 400.0)


def hill_heights(origin_z: float = 0.0) -> np.ndarray:
    """41 x 31 ground heights [m] on 10 m cells: a Gaussian hill (90 m) in the middle."""
    x = np.arange(41)[:, None] * 10.0
    y = np.arange(31)[None, :] * 10.0
    return origin_z + 10.0 + 80.0 * np.exp(-((x - 200) ** 2 + (y - 150) ** 2) / (2 * 70.0**2))


@lru_cache(maxsize=None)
def hill(crs: str | None = None) -> World:
    """The hill world: no CRS (anchored) or in ``crs`` at :data:`UTM_ORIGIN`."""
    if crs is None:
        return World.from_heightmap(hill_heights(), 10.0, 24, name="hill")
    h = hill_heights(UTM_ORIGIN[2])
    base = World.from_heightmap(h, 10.0, 24, origin=UTM_ORIGIN)
    return World(occupancy=base.occupancy, spacing=10.0, origin=UTM_ORIGIN, terrain=h, crs=crs,
                 name="hill-utm")


@lru_cache(maxsize=None)
def hill_tff(crs: str | None = None):
    """A plan 60 m above the ground across the hill."""
    w = hill(crs)
    o = np.asarray(w.origin)
    return plan(w, o + (20.0, 20.0, 70.0), o + (380.0, 280.0, 70.0), level=FlightLevel(agl=60.0))


@lru_cache(maxsize=None)
def hill_free():
    """A plan without a flight level (relative frame) across the hill."""
    return plan(hill(), (20.0, 20.0, 150.0), (380.0, 280.0, 150.0))


def bilinear_ground(world: World, lonlat: np.ndarray, anchor: Anchor | None = ANCHOR) -> np.ndarray:
    """Ground under lon/lat points, interpolated bilinearly on the terrain map (independent of
    fm2uav.autopilot.waypoints: back to world metres, then scipy's linear interpolation)."""
    xy = from_lonlat(world, np.asarray(lonlat)[:, :2], anchor=anchor)
    idx = (xy - np.asarray(world.origin[:2])) / np.asarray(world.spacing[:2])
    g = ndimage.map_coordinates(world.terrain, idx.T, order=1, mode="nearest")
    offset = 0.0 if world.crs else (anchor.alt if anchor is not None else 0.0)
    return g + offset
