"""MAVLink plain-text mission files, ``QGC WPL 110``.

One header line ``QGC WPL 110``, then one item a line with 12 tab-separated
fields::

    INDEX CURRENT FRAME COMMAND P1 P2 P3 P4 LAT LON ALT AUTOCONTINUE

Item 0 is the home position (frame 0 = altitude above mean sea level,
CURRENT = 1), as QGroundControl, Mission Planner and pymavlink's ``mavwp``
expect. The mission items follow: an optional NAV_TAKEOFF, then one
NAV_WAYPOINT per waypoint, in frame 3 (above home) or 10 (above terrain).
Latitude/longitude are written with 10 decimals (~0.01 mm).
"""

from __future__ import annotations

from pathlib import Path
from typing import IO, Any

import numpy as np

from ..errors import InputError
from .waypoints import CMD_NAV_TAKEOFF, CMD_NAV_WAYPOINT, FRAME_GLOBAL, Waypoints

__all__ = ["write_wpl", "read_wpl"]

HEADER = "QGC WPL 110"


def _line(seq: int, current: int, frame: int, command: int, lat: float, lon: float,
          alt: float) -> str:
    fields = [
        str(seq), str(current), str(frame), str(command),
        "0", "0", "0", "0",
        f"{lat:.10f}", f"{lon:.10f}", f"{alt:.3f}", "1",
    ]
    return "\t".join(fields)


def write_wpl(fh: IO[str], wps: Waypoints) -> int:
    """Write waypoints as a ``QGC WPL 110`` file to an open text file.

    Returns
    -------
    int
        Number of lines written after the header (home + items).
    """
    lines = [HEADER, _line(0, 1, FRAME_GLOBAL, CMD_NAV_WAYPOINT, wps.home[0], wps.home[1],
                           wps.home[2])]
    seq = 1
    if wps.takeoff:
        lines.append(_line(seq, 0, wps.frame, CMD_NAV_TAKEOFF, wps.lat[0], wps.lon[0],
                           wps.alt[0]))
        seq += 1
    for lat, lon, alt in zip(wps.lat, wps.lon, wps.alt):
        lines.append(_line(seq, 0, wps.frame, CMD_NAV_WAYPOINT, lat, lon, alt))
        seq += 1
    fh.write("\n".join(lines) + "\n")
    return len(lines) - 1


def read_wpl(file: str | Path) -> dict[str, Any]:
    """Read a ``QGC WPL 110`` file.

    Returns
    -------
    dict
        ``home`` (lat, lon, alt) from item 0 and arrays ``seq``, ``frame``,
        ``command``, ``lat``, ``lon``, ``alt`` of the items after it.

    Raises
    ------
    InputError
        Wrong header, a line without 12 fields, or a non-numeric field (the
        line is named).
    """
    file = Path(file)
    try:
        lines = file.read_text().splitlines()
    except OSError as exc:
        raise InputError(f"{file}: cannot read: {exc}") from None
    if not lines or lines[0].strip() != HEADER:
        raise InputError(f"{file}: first line must be {HEADER!r}")
    rows = []
    for n, ln in enumerate(lines[1:], start=2):
        if not ln.strip() or ln.startswith("#"):
            continue
        f = ln.rstrip("\n").split("\t")
        if len(f) != 12:
            raise InputError(f"{file}: line {n} has {len(f)} tab-separated fields, needs 12")
        try:
            rows.append([float(v) for v in f])
        except ValueError:
            raise InputError(f"{file}: line {n} has a non-numeric field") from None
    if not rows:
        raise InputError(f"{file}: no items")
    a = np.array(rows)
    home = (float(a[0, 8]), float(a[0, 9]), float(a[0, 10]))
    a = a[1:]
    return {
        "home": home,
        "seq": a[:, 0].astype(int),
        "frame": a[:, 2].astype(int),
        "command": a[:, 3].astype(int),
        "lat": a[:, 8],
        "lon": a[:, 9],
        "alt": a[:, 10],
    }
