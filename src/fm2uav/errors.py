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
