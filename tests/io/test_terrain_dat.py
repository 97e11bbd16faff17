"""ArduPilot terrain files (terrain/NxxEyyy.DAT): the records as AP_Terrain reads them, and
the heights they hold equal the planner's DEM (bilinear) at the file's grid spacing.

The record layout, CRC, block ordering and node positions are decoded here again from
ArduPilot's description (``libraries/AP_Terrain/AP_Terrain.h`` ``struct grid_block``,
``TerrainIO.cpp`` ``east_blocks`` / ``seek_offset`` / ``read_block``,
``AP_Terrain.cpp`` ``calculate_grid_info``, ``tools/create_terrain.py``), not with
fm2uav's reader, so a shared mistake cannot pass.
"""

from __future__ import annotations

import math
import struct

import numpy as np
import pytest

from fm2uav.autopilot.terrain_grid import terrain_grid
from fm2uav.errors import InputError
from fm2uav.io.terrain_dat import (
    pack_block,
    read_dat,
    read_terrain_folder,
    terrain_files,
    unpack_block,
)
from fm2uav.world.geo import from_lonlat, to_lonlat

from ..autopilot.mission_cases import ANCHOR, UTM, bilinear_ground, hill

# -- ArduPilot's constants (AP_Terrain.h, create_terrain.py) ------------------------------
GRID_MAVLINK = 4
MUL_X, MUL_Y = 7, 8
SIZE_X, SIZE_Y = GRID_MAVLINK * MUL_X, GRID_MAVLINK * MUL_Y  # 28 north x 32 east
STEP_X, STEP_Y = GRID_MAVLINK * (MUL_X - 1), GRID_MAVLINK * (MUL_Y - 1)  # 24, 28
IO_BLOCK_SIZE, IO_BLOCK_DATA_SIZE = 2048, 1821
SCALE = 0.011131884502145034  # LOCATION_SCALING_FACTOR [m per 1e-7 deg]
#: TERRAIN_SPACING of the files written here [m]
SPACING = 30


def crc16_xmodem(data: bytes) -> int:
    """CRC-16/XMODEM bit by bit (polynomial 0x1021, initial 0): ArduPilot ``crc16_ccitt``."""
    crc = 0
    for byte in data:
        crc ^= byte << 8
        for _ in range(8):
            crc = ((crc << 1) ^ 0x1021) if crc & 0x8000 else crc << 1
            crc &= 0xFFFF
    return crc


def lon_scale(lat_e7: float) -> float:
    return max(math.cos(math.radians(lat_e7 * 1e-7)), 0.01)


def distance_ne(lat1, lon1, lat2, lon2):
    """``Location::get_distance_NE`` (scale at the mean latitude) [m]."""
    return ((lat2 - lat1) * SCALE, (lon2 - lon1) * SCALE * lon_scale((lat1 + lat2) / 2))


def offset(lat_e7, lon_e7, north, east):
    """``Location::offset`` (truncated to whole 1e-7 degrees)."""
    dlat = int(north / SCALE)
    dlon = int((east / SCALE) / lon_scale(lat_e7 + dlat / 2))
    return lat_e7 + dlat, lon_e7 + dlon


def east_blocks(lat_deg: int, lon_deg: int, spacing: int) -> int:
    lat1, lon1 = lat_deg * 10**7, lon_deg * 10**7
    lat2, lon2 = offset(lat1, (lon_deg + 1) * 10**7, 0.0, 2 * spacing * SIZE_Y)
    return int(distance_ne(lat1, lon1, lat2, lon2)[1] / (spacing * STEP_Y))


def firmware_height(folder, lat: float, lon: float, spacing: int) -> float:
    """``AP_Terrain::height_amsl`` on the files: the degree file, the block at its offset,
    the four nodes around the location, bilinear."""
    lat_e7, lon_e7 = round(lat * 1e7), round(lon * 1e7)
    lat_deg, lon_deg = math.floor(lat), math.floor(lon)
    ref_lat, ref_lon = lat_deg * 10**7, lon_deg * 10**7
    dn, de = distance_ne(ref_lat, ref_lon, lat_e7, lon_e7)
    ix, iy = int(dn / spacing), int(de / spacing)
    gx, gy = ix // STEP_X, iy // STEP_Y
    fx, fy = (dn - ix * spacing) / spacing, (de - iy * spacing) / spacing
    name = (f"{'S' if lat_deg < 0 else 'N'}{abs(lat_deg):02d}"
            f"{'W' if lon_deg < 0 else 'E'}{abs(lon_deg):03d}.DAT")
    k = east_blocks(lat_deg, lon_deg, spacing) * gx + gy
    with open(folder / name, "rb") as fh:  # AP_Terrain::seek_offset, then one record
        fh.seek(k * IO_BLOCK_SIZE)
        rec = fh.read(IO_BLOCK_SIZE)
    assert len(rec) == IO_BLOCK_SIZE
    bitmap, blat, blon, crc, version, sp = struct.unpack_from("<QiiHHH", rec, 0)
    assert bitmap == (1 << 56) - 1 and version == 1 and sp == spacing
    assert crc == crc16_xmodem(rec[:16] + b"\0\0" + rec[18:IO_BLOCK_DATA_SIZE])
    corner = offset(ref_lat, ref_lon, gx * STEP_X * float(spacing), gy * STEP_Y * float(spacing))
    assert abs(blat - corner[0]) <= 2 and abs(blon - corner[1]) <= 2  # TERRAIN_LATLON_EQUAL
    tail = struct.unpack_from("<HHhbB", rec, 22 + SIZE_X * SIZE_Y * 2)
    assert tail == (gx, gy, lon_deg, lat_deg, 1)  # indices, degrees, version_minor 1
    h = np.frombuffer(rec, "<i2", SIZE_X * SIZE_Y, 22).reshape(SIZE_X, SIZE_Y).astype(float)
    x, y = ix % STEP_X, iy % STEP_Y
    a1 = (1 - fx) * h[x, y] + fx * h[x + 1, y]
    a2 = (1 - fx) * h[x, y + 1] + fx * h[x + 1, y + 1]
    return (1 - fy) * a1 + fy * a2


def _write(grid, folder):
    folder.mkdir(parents=True, exist_ok=True)
    for name, write in terrain_files(grid).items():
        with open(folder / name, "wb") as fh:
            write(fh)


@pytest.fixture(scope="module", params=[None, UTM], ids=["anchored", "utm"])
def written(request, tmp_path_factory):
    """The hill's terrain at 30 m (TERRAIN_SPACING's finest default) around its area."""
    w = hill(request.param)
    anchor = ANCHOR if request.param is None else None
    b = np.asarray(w.bounds)
    xs, ys = np.meshgrid(np.linspace(b[0, 0], b[0, 1], 5), np.linspace(b[1, 0], b[1, 1], 5))
    pts = np.column_stack([xs.ravel(), ys.ravel(), np.zeros(xs.size)])
    lonlat = to_lonlat(w, pts, anchor=anchor)[:, :2]
    grid = terrain_grid(w, lonlat, spacing=SPACING, anchor=anchor)
    folder = tmp_path_factory.mktemp("terrain")
    _write(grid, folder)
    return w, anchor, grid, folder


def test_records_are_what_ap_terrain_reads(written):
    _, _, grid, folder = written
    files = sorted(p.name for p in folder.iterdir())
    assert files == grid.info["files"]
    for name in files:
        data = (folder / name).read_bytes()
        assert len(data) % IO_BLOCK_SIZE == 0
        blocks, problems = read_dat(folder / name)
        assert not problems and blocks
        used = 0
        for k in range(len(data) // IO_BLOCK_SIZE):
            rec = data[k * IO_BLOCK_SIZE:(k + 1) * IO_BLOCK_SIZE]
            bitmap = struct.unpack_from("<Q", rec)[0]
            if bitmap == 0:
                assert rec == bytes(IO_BLOCK_SIZE)  # a block not on the card: all zeros
                continue
            used += 1
            gx, gy, lon_deg, lat_deg = struct.unpack_from("<HHhb", rec, 22 + SIZE_X * SIZE_Y * 2)
            assert k == east_blocks(lat_deg, lon_deg, SPACING) * gx + gy  # AP_Terrain::seek_offset
            assert rec[IO_BLOCK_DATA_SIZE + 1:] == bytes(IO_BLOCK_SIZE - IO_BLOCK_DATA_SIZE - 1)
        assert used == len(blocks)


def node_lonlat(lat_deg: int, lon_deg: int, nx, ny):
    """Lon/lat of the degree's nodes ``(nx, ny)``: where ``get_distance_NE(degree corner,
    node) = (nx, ny) · spacing``."""
    ref_lat, ref_lon = lat_deg * 10**7, lon_deg * 10**7
    lat_e7 = ref_lat + np.asarray(nx, float) * SPACING / SCALE
    lon_e7 = ref_lon + np.asarray(ny, float) * SPACING / (
        SCALE * np.cos(np.radians((ref_lat + lat_e7) / 2 * 1e-7)))
    return np.column_stack([np.ravel(lon_e7) * 1e-7, np.ravel(lat_e7) * 1e-7])


def test_heights_equal_the_dem_bilinear_at_the_grid_spacing(written):
    w, anchor, grid, folder = written
    rng = np.random.default_rng(0)
    b = np.asarray(w.bounds)
    xy = np.column_stack([rng.uniform(b[0, 0] + 1, b[0, 1] - 1, 60),
                          rng.uniform(b[1, 0] + 1, b[1, 1] - 1, 60), np.zeros(60)])
    ll = to_lonlat(w, xy, anchor=anchor)
    fw = np.array([firmware_height(folder, la, lo, SPACING) for lo, la in ll[:, :2]])
    ours = read_terrain_folder(folder).height(ll[:, 1], ll[:, 0])
    np.testing.assert_allclose(ours, fw, atol=0.01)  # our reader = the firmware's lookup
    # the DEM (bilinear) at the four nodes around each point, SPACING apart, interpolated
    # bilinearly: the files' heights within the rounding to whole metres
    for (lon, lat), h in zip(ll[:, :2], fw):
        lat_deg, lon_deg = math.floor(lat), math.floor(lon)
        dn, de = distance_ne(lat_deg * 10**7, lon_deg * 10**7, lat * 1e7, lon * 1e7)
        ix, iy = int(dn // SPACING), int(de // SPACING)
        fx, fy = dn / SPACING - ix, de / SPACING - iy
        g = bilinear_ground(w, node_lonlat(lat_deg, lon_deg, [ix, ix + 1, ix, ix + 1],
                                           [iy, iy, iy + 1, iy + 1]), anchor)
        expect = (1 - fy) * ((1 - fx) * g[0] + fx * g[1]) + fy * ((1 - fx) * g[2] + fx * g[3])
        assert abs(h - expect) <= 0.5 + 1e-3
    assert grid.info["max_rounding_m"] <= 0.5


def test_nodes_hold_the_dem_rounded_to_whole_metres(written):
    w, anchor, grid, folder = written
    nx, ny = np.meshgrid(np.arange(SIZE_X), np.arange(SIZE_Y), indexing="ij")
    bounds = np.asarray(w.bounds)
    checked = 0
    for blk in grid.blocks:
        ll = node_lonlat(blk.lat_deg, blk.lon_deg, blk.bx * STEP_X + nx, blk.by * STEP_Y + ny)
        xy = from_lonlat(w, ll, anchor=anchor)
        inside = ((xy[:, 0] >= bounds[0, 0]) & (xy[:, 0] <= bounds[0, 1])
                  & (xy[:, 1] >= bounds[1, 0]) & (xy[:, 1] <= bounds[1, 1]))
        if not inside.any():
            continue
        dem = bilinear_ground(w, ll[inside], anchor)
        h = blk.heights.ravel()[inside].astype(float)
        np.testing.assert_array_less(np.abs(h - dem), 0.5 + 1e-6)
        checked += int(inside.sum())
    assert checked >= 100  # the 400 x 300 m hill holds ~130 nodes 30 m apart


def test_a_corrupt_record_is_refused_as_the_firmware_does(written):
    _, _, grid, _ = written
    rec = bytearray(pack_block(grid.blocks[0]))
    assert unpack_block(bytes(rec))[0] is not None
    rec[100] ^= 0xFF  # a height byte: the CRC no longer matches
    assert unpack_block(bytes(rec)) == (None, "bad CRC")
    old = bytearray(pack_block(grid.blocks[0]))
    old[IO_BLOCK_DATA_SIZE] = 0  # version_minor 0: ArduPilot 4.7 "terrain data expired"
    blk, why = unpack_block(bytes(old))
    assert blk is None and "expired" in why


def test_a_spacing_out_of_range_names_the_flag():
    with pytest.raises(InputError, match="--terrain-spacing"):
        terrain_grid(hill(), [[ANCHOR.lon, ANCHOR.lat]], spacing=2, anchor=ANCHOR)
