"""Start points of ``fm2uav routes``: a CSV of lon/lat rows or a file of points.

Two kinds of file, told apart by their suffix:

* **CSV** (``.csv``, ``.txt``): a header row, then one start per row. Columns (names
  case-insensitive, any order, other columns ignored): ``lon`` and ``lat`` (WGS84
  degrees, required), ``id`` (optional; default the row's number, 1 = first data row),
  ``agl`` (optional: metres above the ground on a 3D map; default ``--agl``).
* **Points** (GeoJSON, GeoPackage, Shapefile, KML/KMZ: any file the project's vector
  reader takes, in any CRS it declares, else ``--crs``, else lon/lat for GeoJSON;
  :func:`fm2uav.world.vectors.read_vectors`): one start per Point feature; the id
  from the property ``--id-field`` (default ``id``, else ``name``, else the feature's
  number), the height above ground from an ``agl`` property, else ``--agl``.

A row whose numbers are missing or not finite is not a crash: its start is kept with
the reason (:attr:`Starts.problems`) and reported as ``invalid``; a file without the
columns, without any start, or with the same id twice is refused (:class:`InputError`).
"""

from __future__ import annotations

import csv
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import InputError, WorldError
from .starts_path import check_starts_path

__all__ = ["CSV_SUFFIXES", "Starts", "read_starts"]

#: Suffixes read as CSV; every other file goes to the vector reader.
CSV_SUFFIXES = (".csv", ".txt")


@dataclass(frozen=True)
class Starts:
    """Start points read by :func:`read_starts`.

    Attributes
    ----------
    ids : tuple of str
        One id per start, unique, in file order.
    points : ndarray, shape (n, ndim)
        World coordinates [m] (z: the ground plus the height above it on a 3D map);
        NaN on the rows of :attr:`problems`.
    problems : dict of int to str
        Start index → why its row gives no point (a missing or bad number).
    source : str
        The file and how it was read (columns, CRS rule).
    """

    ids: tuple[str, ...]
    points: np.ndarray
    problems: dict[int, str] = field(default_factory=dict)
    source: str = ""

    def __len__(self) -> int:
        return len(self.ids)


def _number(text: Any) -> float | None:
    try:
        v = float(text)
    except (TypeError, ValueError):
        return None
    return v if math.isfinite(v) else None


def _unique(ids: list[str], where: list[str], flag: str) -> None:
    seen: dict[str, str] = {}
    for i, w in zip(ids, where):
        if i in seen:
            raise InputError(f"{flag}: the id {i!r} is given twice ({seen[i]} and {w}); give "
                             "every start its own id")
        seen[i] = w


def _read_csv(path: Path) -> tuple[list[str], list[float | None], list[float | None],
                                   list[float | None], list[str], list[str]]:
    """ids, lons, lats, agls (None where not given), problems per row, row names."""
    try:
        with open(path, newline="", encoding="utf-8-sig") as fh:
            rows = list(csv.reader(fh))
    except (OSError, UnicodeDecodeError) as exc:
        raise InputError(f"--starts {path}: cannot read it as a CSV text file ({exc})") from None
    rows = [r for r in rows if any(c.strip() for c in r)]
    if not rows:
        raise InputError(f"--starts {path} is empty; give a header lon,lat[,id][,agl] and one "
                         "start per row")
    head = [c.strip().lower() for c in rows[0]]
    if "lon" not in head or "lat" not in head:
        raise InputError(f"--starts {path}: the header {rows[0]!r} has no 'lon' and 'lat' "
                         "columns; the first row must name the columns, e.g. lon,lat,id "
                         "(degrees WGS84; optional: id, agl)")
    col = {name: head.index(name) for name in ("lon", "lat", "id", "agl") if name in head}
    ids, lons, lats, agls, problems, where = [], [], [], [], [], []
    for n, row in enumerate(rows[1:], start=1):
        def cell(name: str) -> str | None:
            k = col.get(name)
            return row[k].strip() if k is not None and k < len(row) else None

        line = f"data row {n}"
        ids.append(cell("id") or str(n))
        lon, lat = _number(cell("lon")), _number(cell("lat"))
        agl_text = cell("agl")
        agl = _number(agl_text) if agl_text else None
        bad = ""
        if lon is None or lat is None:
            bad = (f"{line}: lon {cell('lon')!r} / lat {cell('lat')!r} are not finite numbers "
                   "(degrees)")
        elif not (-180 <= lon <= 180 and -90 <= lat <= 90):
            bad = (f"{line}: lon {lon:g}, lat {lat:g} is not a WGS84 position (lon in "
                   "[-180, 180], lat in [-90, 90]; order lon,lat)")
        elif agl_text and agl is None:
            bad = f"{line}: agl {agl_text!r} is not a number (metres above the ground)"
        lons.append(lon)
        lats.append(lat)
        agls.append(agl)
        problems.append(bad)
        where.append(line)
    return ids, lons, lats, agls, problems, where


def _read_points(path: Path, world: Any, crs: Any, id_field: str | None
                 ) -> tuple[list[str], np.ndarray, list[float | None], str]:
    """ids, xy in world metres, agls, how the file was read."""
    from ..world.vectors import read_vectors

    try:
        data = read_vectors(path, target_crs=getattr(world, "crs", None), crs=crs,
                            role="starts", kinds=("Point",))
    except WorldError as exc:
        raise InputError(f"--starts {path}: {exc}") from None
    if len(data) == 0:
        raise InputError(f"--starts {path} holds no Point features"
                         + (f" (left out: {data.skipped})" if data.skipped else ""))
    keys = [id_field] if id_field else ["id", "name"]
    ids, agls = [], []
    for n, props in enumerate(data.properties, start=1):
        v = next((props[k] for k in keys if props.get(k) not in (None, "")), None)
        if id_field and v is None:
            raise InputError(f"--id-field {id_field}: feature {n} of {path} has no property "
                             f"{id_field!r} (its properties: {sorted(props)})")
        ids.append(str(v) if v is not None else str(n))
        agls.append(_number(props.get("agl")) if props.get("agl") is not None else None)
    xy = np.array([[g.x, g.y] for g in data.geometries], dtype=float)
    how = f"points, CRS {data.source.crs or 'the map metres'} ({data.source.crs_rule})"
    return ids, xy, agls, how


def read_starts(path: str | Path, world: Any, *, agl: float | None = None, crs: Any = None,
                id_field: str | None = None, anchor: Any = None) -> Starts:
    """The start points of a file in world metres (see the module docstring).

    Parameters
    ----------
    path : path
        CSV (``lon,lat[,id][,agl]`` with a header) or a vector file of points.
    world : World
        The map: its CRS (or ``anchor``) places lon/lat; its ground sets the heights.
    agl : float, optional
        Height above the ground [m] of starts without their own (3D maps; ``--agl``).
    crs : optional
        CRS of a points file that declares none (``--crs``).
    id_field : str, optional
        The property holding a point's id (points files; ``--id-field``).
    anchor : optional
        lon/lat of x = y = 0 for a world without a CRS (default the exports' anchor).

    Returns
    -------
    Starts

    Raises
    ------
    InputError
        Unreadable file, no lon/lat columns, no start, an id twice, a 3D map without a
        height for a start (no ``agl`` column/property and no ``--agl``).
    """
    from ..world.geo import from_lonlat

    path = check_starts_path(path)
    problems: dict[int, str] = {}
    if path.suffix.lower() in CSV_SUFFIXES:
        ids, lons, lats, agls, bad, where = _read_csv(path)
        _unique(ids, where, f"--starts {path}")
        ok = [k for k, b in enumerate(bad) if not b]
        problems = {k: b for k, b in enumerate(bad) if b}
        xy = np.full((len(ids), 2), np.nan)
        if ok:
            xy[ok] = from_lonlat(world, [[lons[k], lats[k]] for k in ok], anchor=anchor)
        how = "CSV lon,lat (WGS84)" + ("" if world.crs is None else f" → {world.crs}")
    else:
        ids, xy, agls, how = _read_points(path, world, crs, id_field)
        _unique(ids, [f"feature {k + 1}" for k in range(len(ids))], f"--starts {path}")
    if not ids:
        raise InputError(f"--starts {path} has a header but no start rows")
    if world.ndim == 2:
        return Starts(tuple(ids), xy, problems, f"{path} ({how})")
    heights = np.array([a if a is not None else (np.nan if agl is None else float(agl))
                        for a in agls], dtype=float)
    missing = [k for k in range(len(ids)) if np.isnan(heights[k]) and k not in problems]
    if missing:
        raise InputError(f"--starts {path}: start {ids[missing[0]]!r} has no height on this 3D "
                         "map; give --agl (metres above the ground) or an 'agl' column/property")
    b = world.bounds
    inside = np.isfinite(xy).all(axis=1)
    gx = np.clip(np.where(inside, xy[:, 0], b[0, 0]), b[0, 0], b[0, 1])
    gy = np.clip(np.where(inside, xy[:, 1], b[1, 0]), b[1, 0], b[1, 1])
    ground = np.asarray(world.ground_height(gx, gy), dtype=float)  # clipped: outside stays so
    z = np.where(inside, ground + heights, np.nan)
    return Starts(tuple(ids), np.column_stack([xy, z]), problems, f"{path} ({how})")
