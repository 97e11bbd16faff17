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

__all__ = ["write_path_csv", "read_path_csv"]

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


def read_path_csv(file: str | Path) -> np.ndarray:
    """Read a path written by :func:`write_path_csv` (or any CSV with x,y[,z] columns).

    Lines starting with ``#`` (the CRS comment) are skipped. A header row is
    recognised when its first field is not a number; columns
    named ``x``/``x_m``, ``y``/``y_m``, ``z``/``z_m`` are used if present,
    otherwise the first 2 or 3 columns.

    Raises
    ------
    InputError
        Missing file, fewer than 2 points, non-numeric or non-finite values.
    """
    from .. import _validate as v

    file = Path(file)
    if not file.exists():
        raise InputError(f"path file {file} does not exist")
    # a regular UTF-8 file: a folder, a named pipe (would block) or binary data is refused
    lines = [ln.strip() for ln in v.read_text(file, "path file").splitlines()
             if ln.strip() and not ln.lstrip().startswith("#")]
    if not lines:
        raise InputError(f"path file {file} is empty")
    header = [c.strip().lower() for c in lines[0].split(",")]
    try:
        float(header[0])
        names = None
        rows = lines
    except ValueError:
        names = header
        rows = lines[1:]
    try:
        data = np.array([[float(v) for v in r.split(",")] for r in rows], dtype=float)
    except ValueError as exc:
        raise InputError(f"path file {file} has a non-numeric value: {exc}") from None
    if data.ndim != 2 or len(data) < 2:
        raise InputError(f"path file {file} needs at least 2 points, got {len(data)}")
    if names is not None:
        idx = []
        for ax in ("x", "y", "z"):
            for cand in (ax, f"{ax}_m"):
                if cand in names:
                    idx.append(names.index(cand))
                    break
        if len(idx) < 2:
            idx = list(range(min(3, data.shape[1])))
    else:
        idx = list(range(min(3, data.shape[1])))
    pts = data[:, idx]
    if not np.all(np.isfinite(pts)):
        r = int(np.argwhere(~np.isfinite(pts))[0, 0])
        raise InputError(f"path file {file} has a non-finite coordinate in point {r}")
    return pts
