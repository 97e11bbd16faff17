"""Autopilot waypoints from a planned path: altitude profile, thinning, geo-referencing.

Altitudes, for a path planned ``agl`` metres above the ground (``Plan.params["agl"]``):

* the **ground** under every point is the world's terrain interpolated
  bilinearly (``World.ground_height``);
* the path's own height above it is ``z − ground``. Where that is within one
  vertical cell of the request (the flight level: FM² puts it on the grid, up
  to one cell below the request) the waypoint gets the **requested** AGL; the
  climb-out from the start and the descent to the goal keep their own height;
* the flown altitude is ``ground + AGL`` — the same profile in every frame:

  ==========  =====  ======================================================
  frame       code   altitude written
  ==========  =====  ======================================================
  terrain     10     the AGL above (``MAV_FRAME_GLOBAL_TERRAIN_ALT``)
  amsl        0      ground + AGL above mean sea level (``MAV_FRAME_GLOBAL``),
                     what QGroundControl calls "calculated above terrain"
  relative    3      ground + AGL − home (``MAV_FRAME_GLOBAL_RELATIVE_ALT``)
  ==========  =====  ======================================================

Paths planned without ``agl`` keep their own altitudes; 2D paths fly
``flight_alt`` above home. Home is the ground under the start.

Waypoints are kept with 3D Douglas–Peucker (in x, y and the written altitude)
between the points that must be waypoints (``keep``: via points, band ends),
so every forced point is a waypoint and every dropped point lies within the
tolerance of the legs.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from ..errors import InputError
from ..world.geo import Anchor, amsl_known, to_lonlat
from .firmware import PROFILES
from .items import FRAME_GLOBAL, FRAME_RELATIVE, FRAME_TERRAIN, CMD_NAV_TAKEOFF, CMD_NAV_WAYPOINT
from .thin import thin_indices

__all__ = [
    "FRAME_GLOBAL",
    "FRAME_RELATIVE",
    "FRAME_TERRAIN",
    "CMD_NAV_WAYPOINT",
    "CMD_NAV_TAKEOFF",
    "FRAMES",
    "FRAME_CODES",
    "Waypoints",
    "resolve_frame",
    "ground_at",
    "altitude_profile",
    "thin_with_keep",
    "mission_waypoints",
]

#: Altitude frames a mission can be written in (``outputs.frame`` / ``--frame``).
FRAMES = ("auto", "terrain", "amsl", "relative")
#: Frame name → MAV_FRAME.
FRAME_CODES = {"terrain": FRAME_TERRAIN, "amsl": FRAME_GLOBAL, "relative": FRAME_RELATIVE}


def resolve_frame(frame: str, firmware: str, *, terrain_following: bool,
                  has_terrain: bool, amsl: bool = True) -> str:
    """The frame ``"auto"`` stands for, per firmware (other names pass through).

    ``auto``: a terrain-following plan over a world with terrain is written in
    the **terrain** frame for a firmware that flies it (its profile's
    ``terrain_frame``, :mod:`fm2uav.autopilot.firmware`: ArduPilot follows its
    terrain database) and in **amsl** for the others (PX4 has no terrain frame
    for mission items; generic); any other plan in **relative** (above home).
    A world whose altitude above sea level is unknown (``amsl=False``: buildings
    without a DEM or ``world.ground_elevation``, :func:`fm2uav.world.geo.amsl_known`)
    is always written **relative** to home: an AMSL altitude would be one above an
    implicit 0 m.

    Raises
    ------
    InputError
        Unknown frame name; ``amsl`` asked for on a world without an altitude datum.
    """
    if frame not in FRAMES:
        raise InputError(f"frame must be one of {', '.join(FRAMES)}, got {frame!r} "
                         "(mission file outputs.frame, CLI --frame)")
    if not amsl and frame == "amsl":
        raise InputError(
            "outputs.frame = amsl (--frame amsl) needs the ground's altitude above sea level, "
            "which buildings without a DEM do not give: set world.ground_elevation "
            "(--ground-elevation) or add world.dem (--dem), or write the mission relative to "
            "home (frame relative)")
    if frame != "auto":
        return frame
    if not amsl:
        return "relative"
    if terrain_following and has_terrain:
        profile = PROFILES.get(firmware)
        return "terrain" if profile is not None and profile.terrain_frame else "amsl"
    return "relative"


def ground_at(world: Any, xy: Any) -> np.ndarray:
    """Ground height (world z [m]) under points ``(n, 2|3)``: ``World.ground_height``
    (the DEM, bilinear; the grid floor without terrain)."""
    p = np.atleast_2d(np.asarray(xy, dtype=float))
    return np.broadcast_to(np.asarray(world.ground_height(p[:, 0], p[:, 1]), dtype=float),
                           (len(p),)).copy()


@dataclass(frozen=True)
class Waypoints:
    """Mission waypoints in WGS84 with MAVLink altitudes.

    Attributes
    ----------
    lat, lon : ndarray, shape (n,)
        Latitude and longitude [deg].
    alt : ndarray, shape (n,)
        Altitude in ``frame`` [m].
    alt_amsl : ndarray, shape (n,)
        Altitude above mean sea level (the world's vertical datum) [m].
    agl : ndarray, shape (n,)
        Height above the ground (bilinear DEM) [m].
    ground_amsl : ndarray, shape (n,)
        Ground altitude under each waypoint [m].
    frame : int
        MAV_FRAME of the altitudes: 0 (amsl), 3 (relative) or 10 (terrain).
    frame_name : str
        ``"amsl"``, ``"relative"`` or ``"terrain"``.
    home : tuple of float
        ``(lat, lon, alt_amsl)`` [deg, deg, m]: the ground under the start.
    home_source : str
        Where the home altitude comes from.
    points_m : ndarray, shape (n, 3)
        The waypoints in world metres, at their flown altitude (2D paths get
        ``flight_alt`` above home).
    indices : ndarray of int
        Their indices in the dense path.
    requested_agl : float or None
        The plan's requested height above ground [m].
    legs : dict or None
        What the leg check (:func:`fm2uav.autopilot.legs.refine_legs`) did: waypoints
        ``added`` where a straight leg dipped below its floor or entered a zone,
        ``lowest_margin_m`` above the floor along the legs, ...
    amsl : bool
        Whether the world's altitudes are above mean sea level
        (:func:`fm2uav.world.geo.amsl_known`); False: ``alt_amsl``, ``ground_amsl``
        and ``home[2]`` are heights above the world's flat ground, the mission is
        relative to home.
    acceptance : ndarray or None
        Fixed-wing: the acceptance radius of each waypoint [m] (``NAV_WAYPOINT``
        param2; 0 = the firmware's), set where a waypoint must stay on a short leg.
    turns : dict or None
        Fixed-wing: what :func:`fm2uav.autopilot.turns.fit_turns` did.
    """

    lat: np.ndarray
    lon: np.ndarray
    alt: np.ndarray
    alt_amsl: np.ndarray
    agl: np.ndarray
    ground_amsl: np.ndarray
    frame: int
    frame_name: str
    home: tuple[float, float, float]
    home_source: str
    points_m: np.ndarray
    indices: np.ndarray
    requested_agl: float | None = None
    legs: dict[str, Any] | None = None
    amsl: bool = True
    acceptance: np.ndarray | None = None
    turns: dict[str, Any] | None = None

    def __len__(self) -> int:
        return int(len(self.lat))


def altitude_profile(path_m: Any, world: Any, *, agl: float | None = None,
                     flight_alt: float = 30.0, snap: bool | float = True
                     ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The flown profile of a dense path (see the module docstring).

    ``snap``: points whose own height above the ground is within this many
    metres of ``agl`` get exactly ``agl`` (True: one vertical cell, the grid
    bias of FM²'s flight level; False: keep the path's own heights, for a plan
    whose altitudes already are the final profile over the continuous ground,
    ``Plan.profile``).

    Returns
    -------
    points : ndarray, shape (N, 3)
        x, y [m] and the flown altitude ``ground + AGL`` (world z) [m].
    agl : ndarray, shape (N,)
        Height above the ground [m] (the request on the flight level).
    ground : ndarray, shape (N,)
        Ground height under each point (world z) [m].
    """
    p = np.asarray(path_m, dtype=float)
    if p.ndim != 2 or len(p) < 2 or p.shape[1] not in (2, 3) or not np.all(np.isfinite(p)):
        raise InputError(f"path must be a finite (N, 2) or (N, 3) array with N >= 2, got "
                         f"shape {p.shape}")
    ground = ground_at(world, p)
    if p.shape[1] == 2:
        own = np.full(len(p), float(flight_alt)) + ground[0] - ground
    else:
        own = p[:, 2] - ground
    height = own
    if agl is not None and snap is not False and p.shape[1] == 3:
        dz = float(world.spacing[2]) if getattr(world, "ndim", 3) == 3 else 0.0
        tol = dz if snap is True else float(snap)
        on_level = np.abs(own - float(agl)) <= tol + 1e-9
        height = np.where(on_level, float(agl), own)
    return np.column_stack([p[:, :2], ground + height]), height, ground


def thin_with_keep(points: np.ndarray, tolerance: float, *, keep: Any = (),
                   max_points: int | None = None) -> np.ndarray:
    """Douglas–Peucker indices with the ``keep`` indices always kept (sorted, unique).

    Each piece between consecutive kept indices is thinned on its own, so every
    dropped point is within ``tolerance`` of the leg that replaces it.
    ``max_points`` caps the total (the forced points always stay).
    """
    n = len(points)
    forced = np.unique(np.concatenate([[0, n - 1], np.asarray(keep, dtype=int).ravel()]))
    if forced.min() < 0 or forced.max() > n - 1:
        raise InputError(f"keep indices must lie in [0, {n - 1}]")
    out = [forced]
    free = None if max_points is None else max(int(max_points) - len(forced), 0)
    pieces = list(zip(forced[:-1], forced[1:]))
    for a, b in pieces:
        if b - a < 2:
            continue
        cap = None
        if free is not None:
            share = (b - a) / max(n - 1, 1)
            cap = 2 + int(np.floor(free * share))
        out.append(a + thin_indices(points[a:b + 1], tolerance, max_points=cap))
    return np.unique(np.concatenate(out))


def _home_source(world: Any, anchor: Anchor | None) -> str:
    has_terrain = getattr(world, "terrain", None) is not None
    if getattr(world, "crs", None):
        georef = getattr(world, "georef", None)
        roles = {s.role for s in getattr(georef, "sources", ())}
        if not amsl_known(world):
            return ("the flat ground under the start (buildings without a DEM or "
                    "world.ground_elevation / --ground-elevation)")
        if roles == {"buildings"} and getattr(world, "ground", None) is None:
            return (f"flat ground under the start at {float(world.origin[2]):g} m above sea "
                    "level (world.ground_elevation / --ground-elevation)")
        what = "DEM ground (bilinear) under the start" if has_terrain else \
            "flat ground of the world (its bottom) under the start"
        vref = getattr(world, "vertical_reference", None)
        return what + (f", {vref}" if vref else "")
    a = anchor
    where = "the default anchor" if a is None else f"anchor lon {a.lon:g}, lat {a.lat:g}"
    kind = "synthetic relief" if has_terrain else "flat ground"
    return (f"{kind} of a world without CRS under the start, placed at {where} "
            "(z = 0 at the anchor altitude): not the real terrain there")


def mission_waypoints(
    path_m: Any,
    world: Any,
    *,
    frame: str = "relative",
    agl: float | None = None,
    tolerance: float = 5.0,
    anchor: Anchor | None = None,
    flight_alt: float = 30.0,
    max_points: int | None = None,
    keep: Any = (),
    snap: bool | float = True,
    required: Any = None,
    turns: Any = None,
) -> Waypoints:
    """Thin a dense path and express it as MAVLink waypoints.

    Parameters
    ----------
    path_m : array_like, shape (N, 2) or (N, 3)
        Dense path in world coordinates [m] (e.g. ``Plan.path``).
    world : World
        The world planned on (CRS, terrain).
    frame : {"terrain", "amsl", "relative"}, optional
        Altitude frame (resolve ``"auto"`` first with :func:`resolve_frame`).
    agl : float, optional
        The requested height above ground of a terrain-following plan [m].
    tolerance : float, optional
        Douglas–Peucker tolerance [m]. Default 5 m.
    anchor : Anchor, optional
        Placement of a world without CRS (see :func:`fm2uav.world.geo.to_lonlat`).
    flight_alt : float, optional
        Altitude above home [m] of 2D paths. Default 30 m.
    max_points : int, optional
        Cap on the number of waypoints.
    keep : sequence of int, optional
        Dense-path indices that must be waypoints (via points, band ends).
    snap : bool or float, optional
        Give flight-level points the requested ``agl``: True (default) within
        one vertical cell, a number within that many metres, False never (the
        path's own heights: plans with a final altitude profile).
    required : array_like, shape (N,), optional
        Lowest admissible height above the surface at each dense point [m]
        (``Plan.profile.required``); legs that would dip below it, or enter a
        no-fly zone, get more waypoints (:func:`fm2uav.autopilot.legs.refine_legs`).
        Default: no floor (zones are still checked).
    turns : FixedWingNav, optional
        A fixed-wing's navigation: waypoints that make legs too short to turn onto
        are removed where that stays safe (:func:`fm2uav.autopilot.turns.fit_turns`).
    """
    if frame not in FRAME_CODES:
        raise InputError(f"frame must be one of {', '.join(FRAME_CODES)} here, got {frame!r}")
    resolve_frame(frame, "generic", terrain_following=False, has_terrain=False,
                  amsl=amsl_known(world))  # no AMSL altitudes without a datum
    flown, height, ground = altitude_profile(path_m, world, agl=agl, flight_alt=flight_alt,
                                             snap=snap)
    p = np.asarray(path_m, dtype=float)
    space = flown if frame != "terrain" else np.column_stack([flown[:, :2], height])
    if p.shape[1] == 2:
        space = space[:, :2]
    idx = thin_with_keep(space, tolerance, keep=keep, max_points=max_points)
    legs = None
    req = np.full(len(p), -np.inf) if required is None else np.asarray(required, dtype=float)
    if req.shape != (len(p),):
        raise InputError(f"required must hold one floor per path point ({len(p)}), got "
                         f"shape {req.shape}")
    if p.shape[1] == 3 and getattr(world, "ndim", 3) == 3:
        from .legs import refine_legs

        idx, legs = refine_legs(idx, flown, world, required=req, terrain_frame=frame == "terrain")
    acceptance = turned = None
    if turns is not None and len(idx) > 2:
        from .turns import fit_turns

        idx, acceptance, turned = fit_turns(idx, flown, world, required=req, keep=keep, nav=turns,
                                            tolerance=tolerance,
                                            terrain_frame=frame == "terrain")
    kept = flown[idx]
    geo = to_lonlat(world, kept, anchor=anchor)
    gnd = to_lonlat(world, np.column_stack([kept[:, :2], ground[idx]]), anchor=anchor)[:, 2]
    home_world = float(ground[0])
    home_geo = to_lonlat(world, np.array([[p[0, 0], p[0, 1], home_world]]), anchor=anchor)[0]
    if frame == "terrain":
        alt = height[idx]
    elif frame == "amsl":
        alt = geo[:, 2]
    else:
        alt = kept[:, 2] - home_world
    return Waypoints(
        lat=geo[:, 1], lon=geo[:, 0], alt=np.asarray(alt, dtype=float), alt_amsl=geo[:, 2],
        agl=height[idx], ground_amsl=gnd, frame=FRAME_CODES[frame], frame_name=frame,
        home=(float(home_geo[1]), float(home_geo[0]), float(home_geo[2])),
        home_source=_home_source(world, anchor), points_m=kept, indices=idx,
        requested_agl=None if agl is None else float(agl), legs=legs, amsl=amsl_known(world),
        acceptance=acceptance, turns=turned,
    )
