"""MAVLink plain-text mission files, ``QGC WPL 110``.

One header line ``QGC WPL 110``, then one item a line with 12 tab-separated
fields::

    INDEX CURRENT FRAME COMMAND P1 P2 P3 P4 LAT LON ALT AUTOCONTINUE

Item 0 is the home position (frame 0 = altitude above mean sea level,
CURRENT = 1), as QGroundControl, Mission Planner and pymavlink's ``mavwp``
expect; the mission items follow (the same list the ``.plan`` is written from).
Unset params are written ``nan`` — in particular the yaw (param 4) of
waypoints, takeoffs and landings, which QGC writes as ``null`` in a ``.plan``:
a 0 there would make a PX4 multirotor turn north at every waypoint.
Latitude/longitude carry 10 decimals (~0.01 mm).
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import IO, Any

import numpy as np

from ..errors import InputError
from ..autopilot.items import CMD_NAV_WAYPOINT, FRAME_GLOBAL, MissionItem

__all__ = ["HEADER", "wpl_text", "write_wpl", "read_wpl"]

HEADER = "QGC WPL 110"


def _fmt(v: float, decimals: int) -> str:
    if not math.isfinite(v):
        return "nan"
    text = f"{v:.{decimals}f}"
    return "0" if float(text) == 0 else text.rstrip("0").rstrip(".") if "." in text else text


def _line(seq: int, current: int, it: MissionItem) -> str:
    p = it.params
    fields = [str(seq), str(current), str(it.frame), str(it.command),
              *(_fmt(v, 6) for v in p[:4]), _fmt(p[4], 10), _fmt(p[5], 10), _fmt(p[6], 3),
              "1" if it.autocontinue else "0"]
    return "\t".join(fields)


def wpl_text(mission: Any) -> str:
    """The ``QGC WPL 110`` text of a built mission (home first)."""
    home = MissionItem(CMD_NAV_WAYPOINT, FRAME_GLOBAL,
                       (0.0, 0.0, 0.0, 0.0, *(float(v) for v in mission.home)))
    lines = [HEADER, _line(0, 1, home)]
    lines += [_line(k + 1, 0, it) for k, it in enumerate(mission.items)]
    return "\n".join(lines) + "\n"


def write_wpl(fh: IO[str], mission: Any) -> int:
    """Write a built mission as ``QGC WPL 110`` to an open text file.

    Returns
    -------
    int
        Number of lines written after the header (home + items).
    """
    text = wpl_text(mission)
    fh.write(text)
    return text.count("\n") - 1


def read_wpl(file: str | Path) -> dict[str, Any]:
    """Read a ``QGC WPL 110`` file.

    Returns
    -------
    dict
        ``home`` (lat, lon, alt) from item 0, ``items`` (list of MissionItem) and
        arrays ``seq``, ``frame``, ``command``, ``params`` (n, 4), ``lat``,
        ``lon``, ``alt`` of the items after it.

    Raises
    ------
    InputError
        Wrong header, a line without 12 fields, or a non-numeric field (the
        line is named).
    """
    file = Path(file)
    from .. import _validate as _v

    _v.input_file(file, "waypoints file")  # no folder / named pipe (would block)
    try:
        lines = file.read_text().splitlines()
    except (OSError, UnicodeDecodeError) as exc:
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
    items = [MissionItem(int(r[3]), int(r[2]), tuple(r[4:11]), autocontinue=bool(r[11]))
             for r in a]
    return {
        "home": home,
        "items": items,
        "seq": a[:, 0].astype(int),
        "frame": a[:, 2].astype(int),
        "command": a[:, 3].astype(int),
        "params": a[:, 4:8],
        "lat": a[:, 8],
        "lon": a[:, 9],
        "alt": a[:, 10],
    }
