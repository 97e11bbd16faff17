"""The error hierarchy of fm2uav.

Every error a user can trigger with bad input derives from :class:`Fm2uavError`
(a :class:`ValueError`), so ``except ValueError`` keeps working for callers that
do not know the package. Messages say *what* is wrong, *where*, and *how to fix it*.
"""

from __future__ import annotations

__all__ = [
    "Fm2uavError",
    "InputError",
    "WorldError",
    "PlanningError",
    "PointError",
    "UnreachableError",
    "MissionError",
    "EXIT_OK",
    "EXIT_PLANNING",
    "EXIT_INPUT",
    "EXIT_INTERRUPTED",
    "EXIT_INTERNAL",
    "describe_error",
]


class Fm2uavError(ValueError):
    """Base class of every error raised on purpose by fm2uav."""


class InputError(Fm2uavError):
    """An argument has the wrong type, shape, value or range."""


class WorldError(Fm2uavError):
    """A world (map, DEM, buildings, scenario) cannot be built or is inconsistent."""


class PlanningError(Fm2uavError):
    """A plan cannot be made: start/goal outside the map, inside an obstacle, ..."""


class UnreachableError(PlanningError):
    """The goal cannot be reached from the start (no free connection between them)."""


class PointError(PlanningError):
    """A start, goal or waypoint lies outside the map or inside an obstacle (bad input)."""


class MissionError(Fm2uavError):
    """A mission cannot be exported as asked: a firmware would reject it, or a
    required setting (frame, end, speeds, camera) is missing or contradictory."""


# -- what an error means to a user: one line and an exit code (CLI and app alike) -----

EXIT_OK = 0
EXIT_PLANNING = 1
EXIT_INPUT = 2
EXIT_INTERNAL = 70  # EX_SOFTWARE (sysexits.h): a bug in fm2uav
EXIT_INTERRUPTED = 130  # 128 + SIGINT, also for SIGTERM (the output set is left as it was)


def _os_message(exc: OSError) -> str:
    import errno

    name = exc.filename if exc.filename is not None else ""
    where = f" {name}" if name != "" else ""
    if isinstance(exc, FileNotFoundError):
        return f"file not found:{where}; check the path"
    if isinstance(exc, IsADirectoryError):
        return f"{name or 'the path'} is a directory, not a file; give the file inside it"
    if isinstance(exc, NotADirectoryError):
        return f"{name or 'the path'}: a part of the path is a file, not a folder; check it"
    if isinstance(exc, PermissionError):
        return f"permission denied:{where}; fix its permissions or choose another path"
    if exc.errno == errno.ENOSPC:
        return f"the disk is full{' writing' + where if where else ''}; free space or choose " \
               "another --out"
    if exc.errno == errno.EROFS:
        return f"read-only file system:{where}; choose another --out"
    return f"cannot read or write{where}: {exc.strerror or exc}; check the path"


def describe_error(exc: BaseException) -> tuple[str, int] | None:
    """``(one-line message, exit code)`` for an error caused by the input or the
    environment, or None for a genuine internal error (a bug).

    Fm2uavError subclasses keep their message (PlanningError → exit 1, others
    → 2); OS errors, undecodable text, malformed YAML/JSON/zip files, invalid
    geometries, inputs nested too deeply and memory exhaustion are named with
    exit 2, so no bad input ends in a traceback.
    """
    if isinstance(exc, PointError):
        return str(exc), EXIT_INPUT
    if isinstance(exc, PlanningError):
        return str(exc), EXIT_PLANNING
    if isinstance(exc, Fm2uavError):
        return str(exc), EXIT_INPUT
    import json  # only for the others: fm2uav's own errors answer without zipfile
    import zipfile

    if isinstance(exc, OSError):
        return _os_message(exc), EXIT_INPUT
    if isinstance(exc, UnicodeDecodeError):
        return (f"an input file is not UTF-8 text (byte {exc.start}: {exc.reason}); give a "
                "text file (YAML, GeoJSON, CSV) or the right format"), EXIT_INPUT
    if isinstance(exc, json.JSONDecodeError):
        return (f"an input file is not valid JSON ({exc.msg} at line {exc.lineno}, column "
                f"{exc.colno}); check the file"), EXIT_INPUT
    if isinstance(exc, zipfile.BadZipFile):
        return f"an input file is not a valid zip archive (KMZ/NPZ): {exc}", EXIT_INPUT
    if isinstance(exc, RecursionError):
        return ("an input is nested too deeply to read (YAML/JSON with hundreds of levels); "
                "flatten it"), EXIT_INPUT
    if isinstance(exc, MemoryError):
        return ("out of memory: the grid or the input is too large for this machine; use a "
                "coarser grid (world.cell_size / --cell-size) or a smaller area (world.bbox / "
                "--bbox)"), EXIT_INPUT
    mod = type(exc).__module__ or ""
    if mod.startswith("yaml"):
        return f"an input file is not valid YAML: {str(exc).splitlines()[0]}", EXIT_INPUT
    if type(exc).__name__ == "GEOSException" or mod.startswith("shapely"):
        return (f"an input geometry is invalid ({exc}); check the polygons (closed rings, "
                "no self-intersections, finite coordinates)"), EXIT_INPUT
    return None
