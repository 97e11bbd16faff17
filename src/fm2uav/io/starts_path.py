"""The ``--starts`` file's first check, without numpy (the command line's flag checks run it
before any heavy import, so a wrong path answers at once)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from ..errors import InputError

__all__ = ["check_starts_path"]


def check_starts_path(path: Any) -> Path:
    """``path`` as a :class:`~pathlib.Path` if it names a file, else a one-line InputError.

    Raises
    ------
    InputError
        No such file (or a folder), naming ``--starts`` and what the file should hold.
    """
    path = Path(path)
    if not path.is_file():
        what = "a folder, not a file" if path.is_dir() else "no such file"
        raise InputError(f"--starts {path}: {what}; give a CSV (lon,lat[,id][,agl] with a "
                         "header) or a GeoJSON/GeoPackage/Shapefile/KML of points")
    return path
