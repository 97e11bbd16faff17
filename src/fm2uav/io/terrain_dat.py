"""ArduPilot terrain database files (``terrain/NxxEyyy.DAT``): writer and reader.

The SD card's ``APM/terrain/`` folder (SITL: ``terrain/`` beside the binary) holds
one file per degree of latitude and longitude, named ``N36W085.DAT`` after the
degree's south-west corner. A file is a row of 2048-byte records at offsets
``2048 · (east_blocks · block_x + block_y)`` (``AP_Terrain::seek_offset``), each
holding one grid block of :mod:`fm2uav.autopilot.terrain_grid`, little-endian:

=======  =====  ==============================================================
offset   type   field
=======  =====  ==============================================================
0        u64    bitmap of the 7 x 8 sub-grids present (all 56 bits: complete)
8        i32    latitude of the block's south-west corner [1e-7 deg]
12       i32    longitude of it [1e-7 deg]
16       u16    CRC-16/XMODEM of bytes 0..1820 with this field zero
18       u16    format version (1)
20       u16    grid spacing [m] (must equal ``TERRAIN_SPACING``)
22       i16    28 x 32 heights [m AMSL], north rows of 32 east values
1814     u16    block index north in the degree
1816     u16    block index east
1818     i16    longitude degree
1820     i8     latitude degree
1821     u8     ``version_minor`` (1; outside the CRC; ArduPilot 4.7 refuses
                blocks below 1: "terrain data expired")
1822     —      zeros to 2048
=======  =====  ==============================================================

Records between the written blocks are zeros: ArduPilot reads a zero bitmap as
"not on the card" (``AP_Terrain::read_block``). Files are written sparse (seek,
write). The reader checks every field as the firmware does (version, spacing,
CRC, ``version_minor``) and interpolates heights the firmware's way
(``AP_Terrain::height_amsl``: bilinear between the four surrounding nodes of
the block that holds the location).
"""

from __future__ import annotations

import binascii
import struct
from pathlib import Path
from typing import IO, Any

import numpy as np

from ..autopilot.terrain_grid import (
    BLOCK_MUL_X,
    BLOCK_MUL_Y,
    BLOCK_NODES_X,
    BLOCK_NODES_Y,
    FORMAT_VERSION,
    VERSION_MINOR,
    TerrainBlock,
    TerrainGrid,
    dat_name,
    grid_height,
)
from ..errors import InputError

__all__ = ["IO_BLOCK_SIZE", "CRC_BYTES", "BITMAP_FULL", "pack_block", "unpack_block",
           "write_dat", "terrain_files", "read_dat", "read_terrain_folder", "TerrainReader"]

#: Bytes of one record on the card.
IO_BLOCK_SIZE = 2048
#: Bytes the CRC covers (the block up to ``version_minor``).
CRC_BYTES = 1821
#: Bitmap of a complete block (7 x 8 sub-grids).
BITMAP_FULL = (1 << (BLOCK_MUL_X * BLOCK_MUL_Y)) - 1
_HEAD = struct.Struct("<QiiHHH")
_TAIL = struct.Struct("<HHhbB")


def _crc(data: bytes) -> int:
    """CRC-16/XMODEM (polynomial 0x1021, initial 0): ArduPilot's ``crc16_ccitt(.., 0)``."""
    return binascii.crc_hqx(data, 0)


def pack_block(block: TerrainBlock) -> bytes:
    """The 2048-byte record of a block (module docstring)."""
    h = np.asarray(block.heights, dtype="<i2")
    if h.shape != (BLOCK_NODES_X, BLOCK_NODES_Y):
        raise InputError(f"a terrain block holds {BLOCK_NODES_X} x {BLOCK_NODES_Y} heights, got "
                         f"{h.shape}")
    body = bytearray(_HEAD.pack(BITMAP_FULL, block.lat_e7, block.lon_e7, 0, FORMAT_VERSION,
                                block.spacing))
    body += h.tobytes()
    body += _TAIL.pack(block.bx, block.by, block.lon_deg, block.lat_deg, VERSION_MINOR)
    struct.pack_into("<H", body, 16, _crc(bytes(body[:CRC_BYTES])))
    return bytes(body) + bytes(IO_BLOCK_SIZE - len(body))


def unpack_block(record: bytes) -> tuple[TerrainBlock | None, str]:
    """A record → ``(block, "")``, or ``(None, why it is not usable)`` — the firmware's
    checks: a complete bitmap, format version 1, the CRC, ``version_minor`` >= 1."""
    if len(record) != IO_BLOCK_SIZE:
        return None, f"short record ({len(record)} bytes)"
    bitmap, lat, lon, crc, version, spacing = _HEAD.unpack_from(record, 0)
    if bitmap == 0:
        return None, "empty"
    if version != FORMAT_VERSION:
        return None, f"format version {version}"
    body = bytearray(record[:CRC_BYTES])
    struct.pack_into("<H", body, 16, 0)
    if _crc(bytes(body)) != crc:
        return None, "bad CRC"
    off = _HEAD.size + BLOCK_NODES_X * BLOCK_NODES_Y * 2
    bx, by, lon_deg, lat_deg, minor = _TAIL.unpack_from(record, off)
    if minor < VERSION_MINOR:
        return None, f"version_minor {minor} (ArduPilot 4.7: 'terrain data expired')"
    if bitmap & BITMAP_FULL != BITMAP_FULL:
        return None, f"incomplete bitmap {bitmap:#x}"
    h = np.frombuffer(record, dtype="<i2", count=BLOCK_NODES_X * BLOCK_NODES_Y,
                      offset=_HEAD.size).reshape(BLOCK_NODES_X, BLOCK_NODES_Y).astype(np.int16)
    return TerrainBlock(int(lat_deg), int(lon_deg), int(bx), int(by), int(lat), int(lon),
                        int(spacing), h), ""


def write_dat(fh: IO[bytes], blocks: list[TerrainBlock]) -> int:
    """Write one degree's blocks at their offsets into ``fh`` (binary, seekable); the
    records between them stay zero (sparse). Returns the file's length [bytes]."""
    if not blocks:
        raise InputError("a terrain file needs at least one block")
    degs = {(b.lat_deg, b.lon_deg) for b in blocks}
    if len(degs) != 1:
        raise InputError(f"one terrain file holds one degree, got {sorted(degs)}")
    size = 0
    start = fh.tell()
    for b in sorted(blocks, key=lambda b: b.blocknum):
        fh.seek(start + b.blocknum * IO_BLOCK_SIZE)
        fh.write(pack_block(b))
        size = max(size, (b.blocknum + 1) * IO_BLOCK_SIZE)
    fh.seek(start + size)
    return size


def terrain_files(grid: TerrainGrid) -> dict[str, Any]:
    """``"N36W085.DAT"`` → ``write(fh)`` for every file of a grid."""
    out: dict[str, Any] = {}
    for name, blocks in sorted(grid.files().items()):
        out[name] = (lambda bl: (lambda fh: write_dat(fh, bl)))(blocks)
    return out


def read_dat(path: str | Path) -> tuple[list[TerrainBlock], list[str]]:
    """The usable blocks of a ``.DAT`` file and the problems of the others (a record at
    an offset that does not match its block's indices is a problem too)."""
    p = Path(path)
    data = p.read_bytes()
    blocks: list[TerrainBlock] = []
    problems: list[str] = []
    for k in range(len(data) // IO_BLOCK_SIZE):
        rec = data[k * IO_BLOCK_SIZE:(k + 1) * IO_BLOCK_SIZE]
        b, why = unpack_block(rec)
        if b is None:
            if why != "empty":
                problems.append(f"{p.name} record {k}: {why}")
            continue
        if dat_name(b.lat_deg, b.lon_deg) != p.name:
            problems.append(f"{p.name} record {k}: block of {dat_name(b.lat_deg, b.lon_deg)}")
        elif b.blocknum != k:
            problems.append(f"{p.name} record {k}: block ({b.bx}, {b.by}) belongs at {b.blocknum}")
        else:
            blocks.append(b)
    if len(data) % IO_BLOCK_SIZE:
        problems.append(f"{p.name}: {len(data) % IO_BLOCK_SIZE} trailing bytes")
    return blocks, problems


def read_terrain_folder(folder: str | Path) -> TerrainReader:
    """Every ``*.DAT`` of a ``terrain/`` folder, as a :class:`TerrainReader`."""
    blocks: list[TerrainBlock] = []
    problems: list[str] = []
    for f in sorted(Path(folder).glob("*.DAT")):
        b, p = read_dat(f)
        blocks += b
        problems += p
    return TerrainReader(blocks, problems)


class TerrainReader:
    """Heights from terrain blocks, looked up as ArduPilot does.

    Parameters
    ----------
    blocks : list of TerrainBlock
    problems : list of str
        What the reader found unusable (kept for reports).
    """

    def __init__(self, blocks: list[TerrainBlock], problems: list[str] | None = None) -> None:
        self.blocks = {(b.lat_deg, b.lon_deg, b.spacing, b.bx, b.by): b for b in blocks}
        self.problems = list(problems or [])
        self.spacings = sorted({b.spacing for b in blocks})

    def height(self, lat: Any, lon: Any, spacing: int | None = None) -> np.ndarray:
        """Terrain height [m AMSL] at locations [deg] (NaN where no block holds it)."""
        sp = spacing if spacing is not None else (self.spacings[0] if self.spacings else 100)
        return grid_height(self.blocks, lat, lon, int(sp))

    def covers(self, lat: Any, lon: Any, spacing: int | None = None) -> np.ndarray:
        """Whether a complete block holds each location."""
        return np.isfinite(self.height(lat, lon, spacing))
