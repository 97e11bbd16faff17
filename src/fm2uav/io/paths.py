"""Path files as CSV: one point a row, columns ``x_m,y_m[,z_m][,speed][,floor_agl_m]``.

``speed`` is the admissible speed share W in [0, 1] of the obstacle distances
(:meth:`fm2uav.Plan.speed_share`: without a flight level's shaping), which
``fm2uav export --speed-changes`` maps onto the airframe's speed range.

``floor_agl_m`` (paths with a final altitude profile, ``Plan.profile.required``)
is the lowest height above the surface each point must keep [m] (``-inf`` at
the take-off and landing points): ``fm2uav export`` checks the legs against it.

A path on a geo-referenced world starts with a comment line saying where it is,
``# crs=EPSG:32632; z=DEM heights, ...; sources: dem x.tif sha256=...``
(:meth:`fm2uav.world.geo.Georef.comment`); readers skip lines starting with ``#``.
"""

from __future__ import annotations

from pathlib import Path
from typing import IO

import numpy as np

from ..errors import InputError

__all__ = ["write_path_csv", "read_path_csv", "read_path_table"]

_AXES = ("x_m", "y_m", "z_m")


def write_path_csv(fh: IO[str], path: np.ndarray, speed: np.ndarray | None = None,
                   *, comment: str | None = None, floor: np.ndarray | None = None) -> None:
    """Write a path [m] (and optionally W along it) as CSV to an open text file.

    ``comment`` (e.g. ``world.georef.comment()``) is written first as a ``# `` line;
    ``floor`` (one value per point [m], e.g. ``Plan.profile.required``) adds the
    ``floor_agl_m`` column.
    """
    path = np.asarray(path, dtype=float)
    if comment:
        fh.write("# " + " ".join(str(comment).split()) + "\n")
    cols = list(_AXES[: path.shape[1]])
    data = path
    if speed is not None:
        cols.append("speed")
        data = np.column_stack([path, speed])
    if floor is not None:
        f = np.asarray(floor, dtype=float)
        if f.shape != (len(path),):
            raise InputError(f"floor must hold one value per path point ({len(path)}), got "
                             f"shape {f.shape}")
        cols.append("floor_agl_m")
        data = np.column_stack([data, f])
    fh.write(",".join(cols) + "\n")
    np.savetxt(fh, data, delimiter=",", fmt="%.6f")


#: Header names of the coordinate columns (after :func:`_column_name`), by axis.
_NAMES = {"x": ("x", "x_m"), "y": ("y", "y_m"), "z": ("z", "z_m")}
#: Other columns fm2uav writes (W along the path, the profile's floor).
_KNOWN = ("speed", "w", "floor_agl_m")


def _column_name(text: str) -> str:
    """A header cell as a name: lower case, no quotes or spaces, no unit suffix
    (``"X [m]"``, ``x (m)`` → ``x``)."""
    import re

    name = text.strip().strip('"').strip("'").strip().lower()
    return re.sub(r"\s*[\[(][^\])]*[\])]\s*$", "", name).replace(" ", "_")


def _is_number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


def read_path_table(file: str | Path) -> tuple[list[str] | None, list[tuple[int, list[str]]]]:
    """The cells of a path CSV: ``(header names or None, [(line number, cells), ...])``.

    Lines starting with ``#`` and blank lines are skipped; a byte-order mark (Excel's
    "CSV UTF-8") is ignored; the separator is ``,`` (``;`` or a tab when the first row
    has no comma: spreadsheets in locales with a decimal comma); cells may be quoted.
    The first row is a header when one of its cells is not a number; its names are
    normalised by :func:`_column_name`.

    Raises
    ------
    InputError
        Not a readable UTF-8 text file, no rows, a row with another number of cells
        than the first (the line is named).
    """
    import csv

    from .. import _validate as v

    file = Path(file)
    # a regular UTF-8 file: a folder, a named pipe (would block) or binary data is refused
    text = v.read_text(file, "path file")
    numbered = [(k + 1, ln) for k, ln in enumerate(text.splitlines())
                if ln.strip() and not ln.lstrip().startswith("#")]
    if not numbered:
        raise InputError(f"path file {file} is empty (no rows of x,y[,z] in metres)")
    first = numbered[0][1]
    sep = "," if "," in first else ";" if ";" in first else "\t" if "\t" in first else ","
    rows = [(n, [c.strip() for c in cells]) for (n, _), cells in
            zip(numbered, csv.reader([ln for _, ln in numbered], delimiter=sep))]
    width = len(rows[0][1])
    for n, cells in rows:
        if len(cells) != width:
            raise InputError(f"path file {file}, line {n}: {len(cells)} values where the first "
                             f"row has {width}; every row needs the same columns")
    if all(_is_number(c) for c in rows[0][1]):
        return None, rows
    names = [_column_name(c) for c in rows[0][1]]
    dup = next((c for c in names if c and names.count(c) > 1), None)
    if dup is not None:
        raise InputError(f"path file {file}: the column {dup!r} appears twice in the header; "
                         "name each column once")
    return names, rows[1:]


def read_path_csv(file: str | Path) -> np.ndarray:
    """Read a path written by :func:`write_path_csv` (or any CSV with x,y[,z] columns).

    With a header, the coordinates are read **by name** — ``x``/``x_m``,
    ``y``/``y_m`` and, if present, ``z``/``z_m`` (in any order, case and quotes
    ignored, a unit suffix such as ``x [m]`` allowed) — and the other columns fm2uav
    writes (``speed``/``w``, ``floor_agl_m``) are allowed; any other column is
    refused with its name (a ``lon,lat,alt`` file is not silently read as metres).
    Without a header (the first row all numbers) the columns are x, y[, z] by
    position. See :func:`read_path_table` for the file format (``#`` comments, a
    byte-order mark, ``;`` separators).

    Raises
    ------
    InputError
        Missing file, fewer than 2 points, a missing x or y column, an unknown
        column, non-numeric or non-finite values (line and column named).
    """
    file = Path(file)
    names, rows = read_path_table(file)
    if names is None:
        idx = list(range(min(3, len(rows[0][1]))))
        labels = ["x", "y", "z"][: len(idx)]
        if len(idx) < 2:
            raise InputError(f"path file {file} has 1 column; a path needs x,y[,z] in metres")
    else:
        known = {a for al in _NAMES.values() for a in al} | set(_KNOWN)
        unknown = [c for c in names if c not in known]
        geo = {"lon", "lat", "longitude", "latitude"} & set(unknown)
        if geo:
            raise InputError(
                f"path file {file}: the header has {', '.join(sorted(geo))} ({', '.join(names)}), "
                "but a path is read in world metres (x_m, y_m[, z_m]), as fm2uav writes it; "
                f"unknown column {sorted(geo)[0]!r} — lon/lat degrees are not read")
        idx, labels = [], []
        for axis, aliases in _NAMES.items():
            col = next((names.index(a) for a in aliases if a in names), None)
            if col is None and axis != "z":
                raise InputError(
                    f"path file {file}: no {axis} column in the header ({', '.join(names)}); "
                    f"name the columns x_m, y_m[, z_m] (world metres), or remove the header "
                    "to read them as x, y[, z] by position")
            if col is not None:
                idx.append(col)
                labels.append(names[col])
        if unknown:
            raise InputError(
                f"path file {file}: unknown column {unknown[0]!r} in the header "
                f"({', '.join(names)}); allowed: x_m, y_m, z_m (or x, y, z), speed, "
                "floor_agl_m")
    if len(rows) < 2:
        raise InputError(f"path file {file} needs at least 2 points, got {len(rows)}")
    pts = np.empty((len(rows), len(idx)))
    for r, (n, cells) in enumerate(rows):
        for j, (col, label) in enumerate(zip(idx, labels)):
            try:
                pts[r, j] = float(cells[col])
            except ValueError:
                raise InputError(f"path file {file}, line {n}: {label} = {cells[col]!r} is not "
                                 "a number (metres)") from None
            if not np.isfinite(pts[r, j]):
                raise InputError(f"path file {file}, line {n}: {label} = {cells[col]!r} is not "
                                 f"a finite number (point {r}); give metres")
    return pts
