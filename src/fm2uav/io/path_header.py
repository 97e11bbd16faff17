"""What a ``path.csv`` says about itself: the CRS comment and the W column.

``path.csv`` (:func:`fm2uav.io.write_path_csv`) may start with ``#`` comment
lines such as ``# crs=EPSG:32630; z=DEM heights, ...`` (``World.georef.comment()``)
and may carry W along the path in a ``speed`` (or ``w``) column. ``fm2uav
export`` uses both: the CRS to refuse a path planned on another world, W for
speed changes.
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import InputError

__all__ = ["read_path_header", "read_path_w", "read_path_floor", "read_path_column"]

_CRS = re.compile(r"\bcrs\s*[=:]\s*([^;\s]+)", re.IGNORECASE)


def _lines(file: Path) -> list[str]:
    from .. import _validate as v

    return v.read_text(file, "path file").splitlines()  # no folder / pipe / binary


def read_path_header(file: str | Path) -> dict[str, Any]:
    """``{"crs": str or None, "comments": [str, ...]}`` from the leading ``#`` lines."""
    file = Path(file)
    comments = []
    for ln in _lines(file):
        s = ln.strip()
        if not s:
            continue
        if not s.startswith("#"):
            break
        comments.append(s.lstrip("#").strip())
    crs = None
    for c in comments:
        m = _CRS.search(c)
        if m:
            crs = m.group(1)
            break
    return {"crs": None if crs in (None, "none", "None") else crs, "comments": comments}


def read_path_w(file: str | Path) -> np.ndarray | None:
    """The ``speed`` / ``w`` column of a path CSV (W along the path), or None."""
    return read_path_column(file, ("speed", "w"))


def read_path_floor(file: str | Path) -> np.ndarray | None:
    """The ``floor_agl_m`` column (the final profile's floor above the surface [m]), or None."""
    return read_path_column(file, ("floor_agl_m",))


def read_path_column(file: str | Path, names: tuple[str, ...]) -> np.ndarray | None:
    """The first of the columns ``names`` in a path CSV, as floats, or None (read by
    name, like the coordinates: :func:`fm2uav.io.paths.read_path_table`)."""
    from .paths import read_path_table

    file = Path(file)
    header, rows = read_path_table(file)
    if header is None:
        return None
    col = next((header.index(n) for n in names if n in header), None)
    if col is None:
        return None
    out = np.empty(len(rows))
    for r, (n, cells) in enumerate(rows):
        try:
            out[r] = float(cells[col])
        except ValueError:
            raise InputError(f"path file {file}, line {n}: the {header[col]!r} column has a "
                             f"non-numeric value {cells[col]!r}") from None
    return out
