"""ArduPilot's terrain grid over a mission, filled from the DEM it was planned on.

ArduPilot flies terrain-frame items (``MAV_FRAME_GLOBAL_TERRAIN_ALT``) above its own
terrain database (``libraries/AP_Terrain``; wiki "Terrain Following"): a grid of
heights every ``TERRAIN_SPACING`` metres (default 100), kept on the SD card in
``terrain/`` as one file per degree of latitude and longitude, made of grid
blocks; without the blocks around home and every waypoint the vehicle refuses to
arm ("PreArm: waiting for terrain data", ``AP_Terrain::pre_arm_checks``) unless a
ground station sends them. This module computes the blocks a mission needs and
their heights; :mod:`fm2uav.io.terrain_dat` writes and reads the files.

The grid, as ``AP_Terrain.h`` and ``TerrainUtil.cpp`` define it (written here
from that description, not copied):

* grids start on whole degrees: the reference of a location is the south-west
  corner of its degree, ``floor(lat)``, ``floor(lon)``;
* node ``(x, y)`` of a degree lies ``x`` spacings north and ``y`` spacings east of
  the reference, distances measured as ArduPilot's ``Location::get_distance_NE``
  does: ``Δlat · 0.011131884502145034`` m per 1e-7 degree north, the same times
  ``cos`` of the mean latitude east;
* a **block** holds 28 × 32 nodes (7 × 8 sub-grids of the 4 × 4 nodes one MAVLink
  ``TERRAIN_DATA`` carries) and blocks step 24 nodes north and 28 east, so that
  neighbours overlap by four rows and columns and any point's four surrounding
  nodes lie in one block; block ``(i, j)`` of a degree starts at node
  ``(24 i, 28 j)``, its south-west corner being the reference moved
  ``24 i · spacing`` north and ``28 j · spacing`` east (``Location::offset``);
* a location's height is the bilinear interpolation of its four surrounding
  nodes (``AP_Terrain::height_amsl``).

Which blocks a mission needs (so that it arms and flies on the files alone):
around home and around every point of the route the nine lookups of
``update_surrounding_tiles`` (±0.7 block north and east), and for every waypoint
the four points ten spacings away at 45°, 135°, 225° and 315° that
``update_mission_data`` checks — every block any of them falls in, with a margin
of one block. Nodes beyond the DEM hold the height of its nearest edge (not
measured ground: the summary counts them).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..errors import InputError

__all__ = [
    "GRID_MAVLINK", "BLOCK_MUL_X", "BLOCK_MUL_Y", "BLOCK_NODES_X", "BLOCK_NODES_Y",
    "BLOCK_STEP_X", "BLOCK_STEP_Y", "FORMAT_VERSION", "VERSION_MINOR", "DEFAULT_SPACING",
    "LOCATION_SCALING_FACTOR", "TerrainBlock", "TerrainGrid", "longitude_scale",
    "offset_e7", "distance_ne", "degree_of", "block_of", "block_corner", "node_latlon",
    "east_blocks", "terrain_grid", "grid_points", "grid_height", "default_spacing",
    "mission_terrain", "dat_name", "MIN_SPACING", "MAX_SPACING",
]

#: Nodes per side of the grid one MAVLink TERRAIN_DATA message carries.
GRID_MAVLINK = 4
#: Sub-grids of a block north (7) and east (8).
BLOCK_MUL_X, BLOCK_MUL_Y = 7, 8
#: Nodes of a block north (28) and east (32).
BLOCK_NODES_X, BLOCK_NODES_Y = GRID_MAVLINK * BLOCK_MUL_X, GRID_MAVLINK * BLOCK_MUL_Y
#: Nodes between the starts of neighbouring blocks north (24) and east (28).
BLOCK_STEP_X, BLOCK_STEP_Y = GRID_MAVLINK * (BLOCK_MUL_X - 1), GRID_MAVLINK * (BLOCK_MUL_Y - 1)
#: ``TERRAIN_GRID_FORMAT_VERSION``.
FORMAT_VERSION = 1
#: ``version_minor`` written: ArduPilot 4.7 refuses to arm on blocks below 1 ("terrain data
#: expired"), older firmware ignores the byte (ArduPilot PR #32275).
VERSION_MINOR = 1
#: ``TERRAIN_SPACING`` default [m].
DEFAULT_SPACING = 100
#: Metres per 1e-7 degree of latitude (ArduPilot ``LOCATION_SCALING_FACTOR``).
LOCATION_SCALING_FACTOR = 0.011131884502145034
_INV = 89.83204953368922  # LOCATION_SCALING_FACTOR_INV


def longitude_scale(lat_e7: Any) -> Any:
    """``cos(latitude)``, at least 0.01 (ArduPilot ``Location::longitude_scale``)."""
    return np.maximum(np.cos(np.radians(np.asarray(lat_e7, dtype=float) * 1e-7)), 0.01)


def offset_e7(lat_e7: int, lon_e7: int, north: float, east: float) -> tuple[int, int]:
    """A location moved ``north``, ``east`` metres, in 1e-7 degrees, truncated to whole
    units as ArduPilot's ``Location::offset`` does (scale at the mean latitude)."""
    dlat = int(north * _INV)
    dlon = int((east * _INV) / float(longitude_scale(lat_e7 + dlat / 2)))
    return int(lat_e7 + dlat), int(lon_e7 + dlon)


def distance_ne(lat1_e7: Any, lon1_e7: Any, lat2_e7: Any, lon2_e7: Any) -> tuple[Any, Any]:
    """North and east metres from location 1 to 2 (ArduPilot ``get_distance_NE``)."""
    lat1 = np.asarray(lat1_e7, dtype=float)
    lat2 = np.asarray(lat2_e7, dtype=float)
    dn = (lat2 - lat1) * LOCATION_SCALING_FACTOR
    de = ((np.asarray(lon2_e7, dtype=float) - np.asarray(lon1_e7, dtype=float))
          * LOCATION_SCALING_FACTOR * longitude_scale((lat1 + lat2) / 2))
    return dn, de


def degree_of(lat: Any, lon: Any) -> tuple[np.ndarray, np.ndarray]:
    """Whole degrees of the south-west corner of the degree of a location."""
    return (np.floor(np.asarray(lat, dtype=float)).astype(int),
            np.floor(np.asarray(lon, dtype=float)).astype(int))


def block_of(lat: Any, lon: Any, spacing: float) -> tuple[np.ndarray, ...]:
    """``(lat_deg, lon_deg, block_x, block_y, node_x, node_y)`` of locations [deg]: the
    degree, the block holding their four surrounding nodes, and the node below them."""
    la, lo = degree_of(lat, lon)
    lat_e7 = np.asarray(lat, dtype=float) * 1e7
    lon_e7 = np.asarray(lon, dtype=float) * 1e7
    dn, de = distance_ne(la * 1e7, lo * 1e7, lat_e7, lon_e7)
    nx = np.floor(dn / spacing).astype(int)
    ny = np.floor(de / spacing).astype(int)
    return la, lo, nx // BLOCK_STEP_X, ny // BLOCK_STEP_Y, nx, ny


def block_corner(lat_deg: int, lon_deg: int, bx: int, by: int, spacing: float
                 ) -> tuple[int, int]:
    """South-west corner of block ``(bx, by)`` of a degree [1e-7 deg]."""
    return offset_e7(int(lat_deg) * 10_000_000, int(lon_deg) * 10_000_000,
                     bx * BLOCK_STEP_X * float(spacing), by * BLOCK_STEP_Y * float(spacing))


def node_latlon(lat_deg: int, lon_deg: int, nx: Any, ny: Any, spacing: float
                ) -> tuple[np.ndarray, np.ndarray]:
    """Latitude, longitude [deg] of degree nodes ``(nx, ny)``: the exact inverse of the
    firmware's lookup, ``get_distance_NE(reference, node) = (nx, ny) · spacing``."""
    ref_lat, ref_lon = float(lat_deg) * 1e7, float(lon_deg) * 1e7
    lat_e7 = ref_lat + np.asarray(nx, dtype=float) * spacing / LOCATION_SCALING_FACTOR
    lon_e7 = ref_lon + (np.asarray(ny, dtype=float) * spacing
                        / (LOCATION_SCALING_FACTOR * longitude_scale((ref_lat + lat_e7) / 2)))
    return lat_e7 * 1e-7, lon_e7 * 1e-7


def east_blocks(lat_deg: int, lon_deg: int, spacing: float) -> int:
    """Blocks per row of a degree's file: the degree's width plus two block widths,
    in block steps (``AP_Terrain::east_blocks``)."""
    lat1, lon1 = int(lat_deg) * 10_000_000, int(lon_deg) * 10_000_000
    lat2, lon2 = offset_e7(lat1, (int(lon_deg) + 1) * 10_000_000, 0.0,
                           2.0 * spacing * BLOCK_NODES_Y)
    _, de = distance_ne(lat1, lon1, lat2, lon2)
    return int(float(de) / (spacing * BLOCK_STEP_Y))


@dataclass(frozen=True, eq=False)
class TerrainBlock:
    """One grid block: where it is and its 28 x 32 heights.

    Attributes
    ----------
    lat_deg, lon_deg : int
        The degree (its south-west corner) whose file holds the block.
    bx, by : int
        Block indices north and east in that degree (``grid_idx_x``, ``grid_idx_y``).
    lat_e7, lon_e7 : int
        South-west corner [1e-7 deg].
    spacing : int
        Node spacing [m].
    heights : ndarray of int16, shape (28, 32)
        Heights above mean sea level [m], ``[north, east]``.
    """

    lat_deg: int
    lon_deg: int
    bx: int
    by: int
    lat_e7: int
    lon_e7: int
    spacing: int
    heights: np.ndarray = field(repr=False)

    @property
    def blocknum(self) -> int:
        """Its index in the degree's file (``east_blocks · bx + by``)."""
        return east_blocks(self.lat_deg, self.lon_deg, self.spacing) * self.bx + self.by


@dataclass(frozen=True, eq=False)
class TerrainGrid:
    """The blocks of a mission and what they hold.

    Attributes
    ----------
    spacing : int
        ``TERRAIN_SPACING`` [m].
    blocks : list of TerrainBlock
    info : dict
        Blocks, files, nodes beyond the DEM (edge heights, not measured), nodes over
        filled (unknown) ground, the largest rounding of a height [m].
    """

    spacing: int
    blocks: list[TerrainBlock]
    info: dict[str, Any]

    def files(self) -> dict[str, list[TerrainBlock]]:
        """``"N36W085.DAT"`` → its blocks (the file names ArduPilot opens)."""
        out: dict[str, list[TerrainBlock]] = {}
        for b in self.blocks:
            out.setdefault(dat_name(b.lat_deg, b.lon_deg), []).append(b)
        return out


def grid_height(blocks: dict[tuple[int, int, int, int, int], TerrainBlock], lat: Any, lon: Any,
                spacing: int) -> np.ndarray:
    """Terrain height [m AMSL] at locations [deg] as the firmware looks it up: the block of
    the location's node (``calculate_grid_info``), bilinear between its four surrounding
    nodes (``height_amsl``); NaN where no block holds it.

    ``blocks`` maps ``(lat_deg, lon_deg, spacing, bx, by)`` to blocks.
    """
    lat = np.atleast_1d(np.asarray(lat, dtype=float))
    lon = np.atleast_1d(np.asarray(lon, dtype=float))
    la, lo, bx, by, nx, ny = block_of(lat, lon, spacing)
    dn, de = distance_ne(la * 1e7, lo * 1e7, lat * 1e7, lon * 1e7)
    fx, fy = dn / spacing - nx, de / spacing - ny
    out = np.full(len(lat), np.nan)
    for k in range(len(lat)):
        b = blocks.get((int(la[k]), int(lo[k]), int(spacing), int(bx[k]), int(by[k])))
        if b is None:
            continue
        ix, iy = int(nx[k] - bx[k] * BLOCK_STEP_X), int(ny[k] - by[k] * BLOCK_STEP_Y)
        h = b.heights
        a1 = (1 - fx[k]) * float(h[ix, iy]) + fx[k] * float(h[ix + 1, iy])
        a2 = (1 - fx[k]) * float(h[ix, iy + 1]) + fx[k] * float(h[ix + 1, iy + 1])
        out[k] = (1 - fy[k]) * a1 + fy[k] * a2
    return out


#: The spacings :func:`default_spacing` chooses from [m]: finer than 30 m the files grow
#: past tens of megabytes a degree (the 30 m SRTM tiles ArduPilot serves are the finest).
MIN_SPACING, MAX_SPACING = 30, DEFAULT_SPACING


def default_spacing(world: Any) -> int:
    """``TERRAIN_SPACING`` matching the planner's ground: half its resolution (the world's
    horizontal cell, or its source DEM's pixel when finer), in whole metres within
    [30, 100] — a grid resampled at the DEM's own pixel differs from it by up to a
    quarter of the relief between pixels (Jacksboro, 75 m pixels: ±8 m at 75 m, −1.8 to
    +3.3 m at 30 m along the route)."""
    res = float(min(world.spacing[:2]))
    model = getattr(world, "ground", None)
    if model is not None and getattr(model, "pixel_m", 0) > 0:
        res = min(res, float(model.pixel_m))
    return int(min(max(round(res / 2), MIN_SPACING), MAX_SPACING))


def dat_name(lat_deg: int, lon_deg: int) -> str:
    """``N36W085.DAT`` for degree (36, -85) (``AP_Terrain::open_file``)."""
    return (f"{'S' if lat_deg < 0 else 'N'}{min(abs(int(lat_deg)), 99):02d}"
            f"{'W' if lon_deg < 0 else 'E'}{min(abs(int(lon_deg)), 999):03d}.DAT")


def _offsets(spacing: float) -> np.ndarray:
    """North/east offsets [m] the firmware looks up around a location, on a lattice fine
    enough to touch every block in between: ±(0.7 block + 1 block margin)."""
    bn = (0.7 * BLOCK_NODES_X + BLOCK_STEP_X) * spacing
    be = (0.7 * BLOCK_NODES_Y + BLOCK_STEP_Y) * spacing
    step = 0.5 * BLOCK_STEP_X * spacing
    n = np.arange(-bn, bn + step, step)
    e = np.arange(-be, be + step, step)
    return np.array([(a, b) for a in n for b in e])


def grid_points(lat: Any, lon: Any, spacing: float) -> tuple[np.ndarray, np.ndarray]:
    """The locations whose blocks must be on the card, around the given locations [deg]."""
    lat = np.atleast_1d(np.asarray(lat, dtype=float))
    lon = np.atleast_1d(np.asarray(lon, dtype=float))
    off = _offsets(spacing)
    m_lat = off[None, :, 0] / (LOCATION_SCALING_FACTOR * 1e7)
    m_lon = off[None, :, 1] / (LOCATION_SCALING_FACTOR * 1e7 * longitude_scale(lat * 1e7)[:, None])
    return (lat[:, None] + m_lat).ravel(), (lon[:, None] + m_lon).ravel()


def terrain_grid(world: Any, lonlat: Any, *, spacing: float = DEFAULT_SPACING,
                 anchor: Any = None) -> TerrainGrid:
    """The terrain blocks around ``lonlat`` filled from ``world``'s ground.

    Parameters
    ----------
    world : World
        The world the mission was planned on (its ground: the DEM, bilinear).
    lonlat : array_like, shape (n, 2)
        Locations the vehicle uses [deg]: home, every mission item's position, the
        route sampled every few spacings.
    spacing : float
        ``TERRAIN_SPACING`` [m], a whole number from 5 to 1000.
    anchor : Anchor, optional
        Placement of a world without CRS.

    Raises
    ------
    InputError
        A spacing out of range.
    """
    from ..world.geo import from_lonlat, to_lonlat

    sp = float(spacing)
    if not (sp == int(sp) and 5 <= sp <= 1000):
        raise InputError(f"the terrain spacing must be a whole number of metres in [5, 1000], "
                         f"got {spacing!r} (--terrain-spacing)")
    sp_i = int(sp)
    q = np.asarray(lonlat, dtype=float).reshape(-1, 2)
    lat, lon = grid_points(q[:, 1], q[:, 0], sp)
    la, lo, bx, by, _, _ = block_of(lat, lon, sp)
    keys = sorted(set(zip(la.tolist(), lo.tolist(), bx.tolist(), by.tolist())))
    nx = np.arange(BLOCK_NODES_X)[:, None]
    ny = np.arange(BLOCK_NODES_Y)[None, :]
    dz = float(to_lonlat(world, [0.0, 0.0, 0.0], anchor=anchor)[2])
    b = np.asarray(world.bounds, dtype=float)
    blocks: list[TerrainBlock] = []
    outside = filled = 0
    worst_round = 0.0
    for (lad, lod, ix, iy) in keys:
        nlat, nlon = node_latlon(lad, lod, ix * BLOCK_STEP_X + nx + 0 * ny,
                                 iy * BLOCK_STEP_Y + ny + 0 * nx, sp)
        xy = from_lonlat(world, np.column_stack([nlon.ravel(), nlat.ravel()]), anchor=anchor)
        g = np.asarray(world.ground_height(xy[:, 0], xy[:, 1]), dtype=float) + dz
        off = ((xy[:, 0] < b[0, 0]) | (xy[:, 0] > b[0, 1]) | (xy[:, 1] < b[1, 0])
               | (xy[:, 1] > b[1, 1]))
        outside += int(off.sum())
        src = getattr(world, "ground_source", None)
        if src is not None and (~off).any():
            filled += int((np.asarray(src(xy[~off, 0], xy[~off, 1])) < 0).sum())
        if np.any(np.abs(g) > 32767):
            raise InputError("a ground height beyond ±32767 m cannot be stored in a terrain file")
        h = np.rint(g).astype(np.int16).reshape(BLOCK_NODES_X, BLOCK_NODES_Y)
        worst_round = max(worst_round, float(np.abs(h.ravel() - g).max()))
        c_lat, c_lon = block_corner(lad, lod, ix, iy, sp)
        blocks.append(TerrainBlock(int(lad), int(lod), int(ix), int(iy), c_lat, c_lon, sp_i, h))
    nodes = len(blocks) * BLOCK_NODES_X * BLOCK_NODES_Y
    info = {"spacing_m": sp_i, "blocks": len(blocks),
            "files": sorted({dat_name(k[0], k[1]) for k in keys}),
            "nodes": nodes, "nodes_beyond_dem": outside, "nodes_over_filled_ground": filled,
            "max_rounding_m": round(worst_round, 3)}
    return TerrainGrid(sp_i, blocks, info)


def mission_terrain(world: Any, *, home_latlon: tuple[float, float], items: Any, path_m: Any,
                    anchor: Any = None, spacing: float | None = None) -> TerrainGrid:
    """The terrain blocks of a mission (module docstring): around home, every position
    item and the dense path (sampled every few spacings), filled from ``world``.

    The grid's ``info`` adds how the vehicle's terrain (the files, interpolated as the
    firmware does) differs from the planner's ground along the path [m].
    """
    from ..world.geo import to_lonlat

    sp = default_spacing(world) if spacing is None else spacing
    p = np.asarray(path_m, dtype=float)
    if p.shape[1] == 2:
        p = np.column_stack([p, np.zeros(len(p))])
    ll = to_lonlat(world, p, anchor=anchor)
    seg = np.hypot(*np.diff(p[:, :2], axis=0).T)
    cum = np.concatenate([[0.0], np.cumsum(seg)])
    pick = np.unique(np.searchsorted(cum, np.arange(0.0, cum[-1] + 1e-9, 5.0 * float(sp))))
    pick = np.unique(np.concatenate([pick, [len(p) - 1]]))
    pos = [(it.lon, it.lat) for it in items if it.has_position]
    where = np.vstack([[home_latlon[1], home_latlon[0]], *(pos or [])] if pos else
                      [[home_latlon[1], home_latlon[0]]])
    where = np.vstack([where, ll[pick, :2]])
    grid = terrain_grid(world, where, spacing=sp, anchor=anchor)
    lookup = {(b.lat_deg, b.lon_deg, b.spacing, b.bx, b.by): b for b in grid.blocks}
    dense = np.unique(np.searchsorted(cum, np.arange(0.0, cum[-1] + 1e-9,
                                                     0.25 * float(sp))))
    vehicle = grid_height(lookup, ll[dense, 1], ll[dense, 0], grid.spacing)
    dz = float(to_lonlat(world, [0.0, 0.0, 0.0], anchor=anchor)[2])
    planner = np.asarray(world.ground_height(p[dense, 0], p[dense, 1]), dtype=float) + dz
    diff = vehicle - planner
    grid.info["route_difference_m"] = {
        "vehicle_minus_planner_min": round(float(np.nanmin(diff)), 2),
        "vehicle_minus_planner_max": round(float(np.nanmax(diff)), 2),
        "mean_abs": round(float(np.nanmean(np.abs(diff))), 2),
        "samples": int(len(dense)), "uncovered": int(np.isnan(vehicle).sum())}
    return grid
