"""Autopilot waypoints from a planned path: thinning + geo-referencing + altitude frame.

The MAVLink frames used:

* ``MAV_FRAME_GLOBAL_RELATIVE_ALT`` (3): altitude above the home position;
* ``MAV_FRAME_GLOBAL_TERRAIN_ALT`` (10): altitude above the terrain under each
  waypoint (the autopilot follows the ground with its terrain database /
  rangefinder). Chosen for terrain-following plans (planned with ``agl``).

Home is the ground under the start point (its altitude above mean sea level).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from ..errors import InputError
from .georef import Anchor, ground_height, to_lonlat
from .thin import thin_indices

__all__ = [
    "FRAME_GLOBAL",
    "FRAME_RELATIVE",
    "FRAME_TERRAIN",
    "CMD_NAV_WAYPOINT",
    "CMD_NAV_TAKEOFF",
    "Waypoints",
    "mission_waypoints",
]

#: MAV_FRAME_GLOBAL: altitude above mean sea level.
FRAME_GLOBAL = 0
#: MAV_FRAME_GLOBAL_RELATIVE_ALT: altitude above home.
FRAME_RELATIVE = 3
#: MAV_FRAME_GLOBAL_TERRAIN_ALT: altitude above the terrain.
FRAME_TERRAIN = 10
#: MAV_CMD_NAV_WAYPOINT.
CMD_NAV_WAYPOINT = 16
#: MAV_CMD_NAV_TAKEOFF.
CMD_NAV_TAKEOFF = 22

_FRAMES = {"relative": FRAME_RELATIVE, "terrain": FRAME_TERRAIN}


@dataclass(frozen=True)
class Waypoints:
    """Mission waypoints in WGS84 with MAVLink altitudes.

    Attributes
    ----------
    lat, lon : ndarray, shape (n,)
        Waypoint latitude and longitude [deg].
    alt : ndarray, shape (n,)
        Altitude in ``frame`` [m] (above home for 3, above terrain for 10).
    alt_amsl : ndarray, shape (n,)
        Altitude above mean sea level (the world's vertical datum) [m].
    frame : int
        3 (relative to home) or 10 (above terrain).
    home : tuple of float
        ``(lat, lon, alt_amsl)`` of the home position [deg, deg, m].
    points_m : ndarray, shape (n, d)
        The kept world points [m].
    indices : ndarray of int
        Their indices in the dense path.
    takeoff : bool
        Whether writers put a NAV_TAKEOFF to the first waypoint's altitude first.
    """

    lat: np.ndarray
    lon: np.ndarray
    alt: np.ndarray
    alt_amsl: np.ndarray
    frame: int
    home: tuple[float, float, float]
    points_m: np.ndarray
    indices: np.ndarray
    takeoff: bool = True

    def __len__(self) -> int:
        return int(len(self.lat))


def mission_waypoints(
    path_m: Any,
    world: Any,
    *,
    tolerance: float = 5.0,
    frame: str = "auto",
    terrain_following: bool = False,
    anchor: Anchor | None = None,
    flight_alt: float = 30.0,
    max_points: int | None = None,
    takeoff: bool = True,
) -> Waypoints:
    """Thin a dense path and express it as MAVLink waypoints.

    Parameters
    ----------
    path_m : array_like, shape (N, 2) or (N, 3)
        Dense path in world coordinates [m] (e.g. ``Plan.path``).
    world : World
        The world planned on (CRS, terrain).
    tolerance : float, optional
        Douglas–Peucker tolerance [m] (3D). Default 5 m.
    frame : {"auto", "relative", "terrain"}, optional
        Altitude frame; ``"auto"`` → terrain (10) when ``terrain_following`` and
        the world has terrain, else relative (3).
    terrain_following : bool, optional
        The path was planned at a height above ground (``Plan.params["agl"]``).
    anchor : Anchor, optional
        Placement of a world without CRS (see :mod:`fm2uav.io.georef`).
    flight_alt : float, optional
        Altitude above home [m] given to 2D paths. Default 30 m.
    max_points : int, optional
        Cap on the number of waypoints (Douglas–Peucker stops early).
    takeoff : bool, optional
        Writers start with a NAV_TAKEOFF item. Default True.
    """
    p = np.asarray(path_m, dtype=float)
    if p.ndim != 2 or len(p) < 2 or p.shape[1] not in (2, 3):
        raise InputError(f"path must be an (N, 2) or (N, 3) array with N >= 2, got {p.shape}")
    if frame not in ("auto", *_FRAMES):
        raise InputError(f"frame must be 'auto', 'relative' or 'terrain', got {frame!r}")
    idx = thin_indices(p, tolerance, max_points=max_points)
    kept = p[idx]
    ground = ground_height(world, kept)
    home_ground = float(ground_height(world, p[:1])[0])
    if p.shape[1] == 2:
        z = np.full(len(kept), home_ground + float(flight_alt))
        pts3 = np.column_stack([kept, z])
    else:
        pts3 = kept
    geo = to_lonlat(pts3, world, anchor=anchor)
    home_geo = to_lonlat(np.array([[p[0, 0], p[0, 1], home_ground]]), world, anchor=anchor)[0]
    has_terrain = getattr(world, "terrain", None) is not None
    if frame == "auto":
        code = FRAME_TERRAIN if (terrain_following and has_terrain) else FRAME_RELATIVE
    else:
        code = _FRAMES[frame]
    if code == FRAME_TERRAIN:
        alt = pts3[:, 2] - ground
    else:
        alt = pts3[:, 2] - home_ground
    return Waypoints(
        lat=geo[:, 1],
        lon=geo[:, 0],
        alt=alt,
        alt_amsl=geo[:, 2],
        frame=int(code),
        home=(float(home_geo[1]), float(home_geo[0]), float(home_geo[2])),
        points_m=kept,
        indices=idx,
        takeoff=bool(takeoff),
    )
