"""Rally point files: MAVLink rally missions and ArduPilot's ``RALLY`` lines.

Rally points go to the vehicle as a mission of type ``MAV_MISSION_TYPE_RALLY``: one
``MAV_CMD_NAV_RALLY_POINT`` (5100) item per point, in
``MAV_FRAME_GLOBAL_RELATIVE_ALT`` (3, altitude relative to home) — how
QGroundControl uploads a plan's ``rallyPoints`` to PX4 and ArduPilot, and how
pymavlink's ``mavwp.MissionItemProtocol_Rally`` (MAVProxy's ``rally`` module)
transfers them. Two files:

* ``rally.waypoints``: that rally mission as ``QGC WPL 110`` (one item a line,
  numbered from 0, no home line), which ``MissionItemProtocol_Rally.load`` reads;
* ``rally.txt``: ArduPilot's older ``RALLY_POINT`` form, one line a point,
  ``RALLY lat lon alt break_alt land_dir flags`` (degrees, m relative to home,
  m, degrees, flags), read by ``mavwp.MAVRallyLoader`` and
  ``MissionItemProtocol_Rally`` (``RALLY_POINT.alt`` is an integer of metres).

Rally *sites* come in as text (``--rally LON,LAT[,AGL]``, ``--rally auto[:K]``:
:func:`parse_rally_text`) or files (:func:`read_rally_sites`: GeoJSON, KML/KMZ,
GeoPackage or Shapefile points — lon/lat unless the file says otherwise, a property
``agl`` for the approach height — or CSV ``lon,lat[,agl]`` with an optional header).

The altitude is what the firmware makes of it (:mod:`fm2uav.autopilot.firmware`):
ArduPilot flies to a rally point at its altitude ("transit / loiter altitude
relative to home"), PX4 measures its return altitude above it.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import IO, Any

from ..autopilot.items import CMD_NAV_RALLY_POINT, FRAME_RELATIVE
from ..errors import InputError

__all__ = ["rally_rows", "write_rally_waypoints", "write_rally_txt", "read_rally_waypoints",
           "parse_rally_text", "read_rally_sites", "RALLY_FLAGS"]

#: Where rally points come from, for messages.
RALLY_FLAGS = "--rally LON,LAT[,AGL] / --rally auto[:K] / --rally-file (mission file rally:)"


def rally_rows(mission: Any) -> list[tuple[float, float, float]]:
    """``[(lat, lon, alt relative to home), ...]`` of a mission's rally points."""
    from ..world.geo import to_lonlat

    rep = getattr(mission, "returns", None)
    if rep is None or not rep.rally:
        return []
    alts = rep.firmware.rally_altitudes if rep.firmware is not None else {}
    out = []
    for r in rep.rally:
        lo, la, _ = to_lonlat(mission.world, [[r.point[0], r.point[1], r.ground]],
                              anchor=mission.options.anchor)[0]
        out.append((float(la), float(lo), float(alts.get(r.name, r.agl))))
    return out


def write_rally_waypoints(fh: IO[str], mission: Any) -> int:
    """Write the rally mission as ``QGC WPL 110``; returns the number of points."""
    rows = rally_rows(mission)
    lines = ["QGC WPL 110"]
    for k, (la, lo, alt) in enumerate(rows):
        lines.append("\t".join([str(k), "0", str(FRAME_RELATIVE), str(CMD_NAV_RALLY_POINT),
                                "0", "0", "0", "0", f"{la:.10f}", f"{lo:.10f}", f"{alt:.3f}",
                                "1"]))
    fh.write("\n".join(lines) + "\n")
    return len(rows)


def write_rally_txt(fh: IO[str], mission: Any) -> int:
    """Write ArduPilot ``RALLY`` lines (integer metres, rounded up); returns the count."""
    rows = rally_rows(mission)
    lines = ["# ArduPilot rally points: RALLY lat lon alt(m, relative to home) break_alt "
             "land_dir flags (mavwp.MAVRallyLoader / MAVProxy 'rally load')"]
    for la, lo, alt in rows:
        lines.append(f"RALLY {la:.8f} {lo:.8f} {int(math.ceil(alt - 1e-6))} 0 0 0")
    fh.write("\n".join(lines) + "\n")
    return len(rows)


def read_rally_waypoints(file: str | Path) -> list[tuple[float, float, float]]:
    """``[(lat, lon, alt), ...]`` of a ``rally.waypoints`` file.

    Raises
    ------
    InputError
        Not ``QGC WPL 110``, a line without 12 fields, or an item that is not a rally point.
    """
    file = Path(file)
    lines = file.read_text().splitlines()
    if not lines or lines[0].strip() != "QGC WPL 110":
        raise InputError(f"{file}: first line must be 'QGC WPL 110'")
    out = []
    for n, ln in enumerate(lines[1:], start=2):
        if not ln.strip():
            continue
        f = ln.split("\t")
        if len(f) != 12 or int(f[3]) != CMD_NAV_RALLY_POINT:
            raise InputError(f"{file}: line {n} is not a NAV_RALLY_POINT item")
        out.append((float(f[8]), float(f[9]), float(f[10])))
    return out


def parse_rally_text(text: str) -> tuple[str, int] | tuple[float, float, float | None]:
    """``"auto"`` / ``"auto:K"`` → ``("auto", K)``; ``"LON,LAT[,AGL]"`` → ``(lon, lat, agl)``.

    Raises
    ------
    InputError
        Anything else (names ``--rally``).
    """
    t = str(text).strip().lower()
    if t == "auto" or t.startswith("auto:"):
        from ..autopilot.rally import DEFAULT_AUTO_RALLY, MAX_RALLY

        k = DEFAULT_AUTO_RALLY
        if ":" in t:
            try:
                k = int(t.split(":", 1)[1])
            except ValueError:
                k = -1
        if not 1 <= k <= MAX_RALLY:
            raise InputError(f"--rally {text!r}: auto:K needs a whole number 1 <= K <= "
                             f"{MAX_RALLY}")
        return "auto", k
    parts = [p for p in t.replace(",", " ").split() if p]
    try:
        v = [float(p) for p in parts]
    except ValueError:
        v = []
    if len(v) not in (2, 3) or not all(math.isfinite(x) for x in v):
        raise InputError(f"--rally {text!r}: give LON,LAT or LON,LAT,AGL (degrees, degrees, "
                         "metres above the ground), or auto[:K]")
    if not (-180 <= v[0] <= 180 and -90 <= v[1] <= 90):
        raise InputError(f"--rally {text!r}: longitude must be in [-180, 180] and latitude in "
                         "[-90, 90] degrees (order LON,LAT)")
    if len(v) == 3 and not v[2] > 0:
        raise InputError(f"--rally {text!r}: the height above the ground must be > 0 m")
    return v[0], v[1], (v[2] if len(v) == 3 else None)


def _csv_sites(file: Path) -> list[tuple[float, float, float | None]]:
    import csv

    text = file.read_text(encoding="utf-8-sig")
    rows = [r for r in csv.reader(text.splitlines()) if r and not r[0].lstrip().startswith("#")]
    out: list[tuple[float, float, float | None]] = []
    for n, r in enumerate(rows, start=1):
        try:
            v = [float(x) for x in r if x.strip() != ""]
        except ValueError:
            if n == 1:  # a header
                continue
            raise InputError(f"{file}: row {n} is not lon,lat[,agl] numbers: {r}") from None
        if len(v) not in (2, 3):
            raise InputError(f"{file}: row {n} has {len(v)} values; give lon,lat[,agl]")
        out.append((v[0], v[1], v[2] if len(v) == 3 else None))
    return out


def read_rally_sites(file: str | Path, world: Any, *, anchor: Any = None, crs: str | None = None
                     ) -> list[tuple[float, float, float | None]]:
    """Rally sites of a file in world metres: ``[(x, y, agl or None), ...]`` (module docstring).

    Raises
    ------
    InputError
        Unreadable file, no point in it, a CSV row that is not lon,lat[,agl].
    """
    import numpy as np

    from .. import _validate as _v
    from ..world.geo import from_lonlat

    file = Path(file)
    _v.input_file(file, "rally point file (--rally-file)")
    if file.suffix.lower() in (".csv", ".txt"):
        rows = _csv_sites(file)
        if not rows:
            raise InputError(f"{file}: no rally point in it (rows lon,lat[,agl])")
        for lo, la, _ in rows:
            if not (-180 <= lo <= 180 and -90 <= la <= 90):
                raise InputError(f"{file}: ({lo}, {la}) is not lon,lat in degrees")
        xy = from_lonlat(world, np.array([[lo, la] for lo, la, _ in rows]), anchor=anchor)
        return [(float(x), float(y), a) for (x, y), (_, _, a) in zip(np.atleast_2d(xy), rows)]
    from ..errors import WorldError
    from ..world.vectors import read_vectors

    target = world.crs if getattr(world, "crs", None) else "EPSG:4326"
    try:
        data = read_vectors(file, target_crs=target, crs=crs, role="rally points",
                            kinds=("Point", "MultiPoint"))
    except WorldError as exc:
        raise InputError(f"{exc} (--rally-file)") from None
    out: list[tuple[float, float, float | None]] = []
    for g, props in zip(data.geometries, data.properties):
        agl = (props or {}).get("agl")
        try:
            agl = None if agl is None else float(agl)
        except (TypeError, ValueError):
            raise InputError(f"{file}: property agl = {agl!r} is not a number of metres") from None
        for pt in getattr(g, "geoms", [g]):
            out.append((float(pt.x), float(pt.y), agl))
    if not out:
        raise InputError(f"{file}: no point features (rally points are Points)")
    if not getattr(world, "crs", None):  # lon/lat placed through the anchor
        xy = np.atleast_2d(from_lonlat(world, np.array([[x, y] for x, y, _ in out]),
                                       anchor=anchor))
        out = [(float(a), float(b), h) for (a, b), (_, _, h) in zip(xy, out)]
    return out
