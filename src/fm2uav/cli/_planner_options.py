"""The FM² planner flags of ``fm2uav plan`` and ``fm2uav routes``, defined once.

``--saturation``, ``--saturation-distance``, ``--exponent``, ``--order`` (with
``march=True`` also ``--threads`` and ``--storage``), then the flight level ``--agl``,
``--p1``, ``--p2``, ``--band``, ``--graded``, ``--mode``, ``--min-agl``, ``--max-agl``:
the names of the mission file's ``planner:`` keys. ``@planner_options(...)`` puts them
in place of the command's ``planner`` parameter, passed as one :class:`PlannerFlags`;
:meth:`PlannerFlags.objects` makes the library's ``(Shaping, FlightLevel, PlanOptions)``.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import asdict, dataclass
from typing import Annotated, Any

import typer

from ..errors import InputError
from .options import option_group

__all__ = ["PlannerFlags", "planner_options"]

AGL_HELP = ("Flight level (m) above the ground (terrain-following, thesis Algorithm 2). "
            "Default: none.")


def _opt(kind: Any, help: str, *decls: str) -> Any:
    return Annotated[kind, typer.Option(*decls, help=help)]


#: ``(parameter, Annotated alias, default)`` of the shaping flags, before the march's.
SHAPING = [
    ("saturation", _opt(float, "Saturation α in (0, 1]."), 1.0),
    ("saturation_distance", _opt(float | None, "Distance (m) from the obstacles beyond which "
                                 "W = 1 (overrides --saturation)."), None),
    ("exponent", _opt(float, "Exponent β > 0 on W (thesis' adjustment)."), 1.0),
    ("order", _opt(int, "Fast Marching order, 1 or 2."), 2),
]
#: ``--threads`` and ``--storage`` of the march (``march=True``).
MARCH = [
    ("threads", _opt(int | None, "Threads of the Fast Marching (>= 1; grids of 1 M nodes or "
                     "more march in parallel, order 1 and 2). Default: FM2UAV_THREADS, else "
                     "every core."), None),
    ("storage", _opt(str, "Grid storage: 'full' (one 3D grid), 'regional' (coarse plan, then "
                     "full-resolution windows along it; terrain + --agl) or 'auto' (regional "
                     "when the full grid would not fit in a quarter of the memory)."), "auto"),
]


def _level(agl_help: str) -> list[tuple[str, Any, Any]]:
    """The flight-level flags (``--agl`` with the command's own help)."""
    return [
        ("agl", _opt(float | None, agl_help), None),
        ("p1", _opt(float, "Exponent on the flight-level cells (with --agl)."), 0.5),
        ("p2", _opt(float, "Exponent on all other cells (with --agl)."), 1.5),
        ("band", _opt(float, "Half-width (m) of the clarified band around the flight level "
                      "(with --agl; 0 = the seeds' single layer)."), 0.0),
        ("graded", _opt(bool, "Blend the exponent from p1 to p2 across --band.", "--graded"),
         False),
        ("mode", _opt(str, "Flight-level reading: 'capped' or 'literal' (W**p as is)."),
         "capped"),
        ("min_agl", _opt(float | None, "Hard floor (m) above the ground for the whole flight "
                         "except the take-off/landing points (with --agl).", "--min-agl"), None),
        ("max_agl", _opt(float | None, "Hard ceiling (m) above the ground, e.g. 120 (with "
                         "--agl).", "--max-agl"), None),
    ]


@dataclass(frozen=True)
class PlannerFlags:
    """The planner flags as given (``--saturation`` ... ``--max-agl``; ``threads`` and
    ``storage`` None where the command has no such flag)."""

    saturation: float = 1.0
    saturation_distance: float | None = None
    exponent: float = 1.0
    order: int = 2
    threads: int | None = None
    storage: str | None = None
    agl: float | None = None
    p1: float = 0.5
    p2: float = 1.5
    band: float = 0.0
    graded: bool = False
    mode: str = "capped"
    min_agl: float | None = None
    max_agl: float | None = None

    def objects(self, **fixed: Any) -> tuple:
        """``(Shaping, FlightLevel or None, PlanOptions)`` of the flags (and ``fixed``, e.g.
        ``storage="full"``): the flight-level ones only with ``--agl``.

        Raises
        ------
        InputError
            ``--min-agl`` / ``--max-agl`` without ``--agl``; a value out of range (names the
            flag and the mission-file key), even of a flight-level flag unused without --agl.
        """
        from ..planning.params import planner_objects

        values = {**asdict(self), **fixed}
        level_keys = ("agl", "p1", "p2", "band", "graded", "mode", "min_agl", "max_agl")
        level = {k: values.pop(k) for k in level_keys}
        if level["agl"] is None:
            if level["min_agl"] is not None or level["max_agl"] is not None:
                raise InputError("--min-agl / --max-agl limit a terrain-following flight; give "
                                 "--agl too (the requested height above ground)")
            from .. import _validate

            # unused without --agl, but never silently garbage (the mission file's ranges)
            for k, hi, low_open in (("p1", 10.0, True), ("p2", 10.0, True),
                                    ("band", 5000.0, False)):
                _validate.in_range(level[k], k, 0.0, hi, low_open=low_open,
                                   where=(f"planner.{k}", f"--{k}"))
            level = {}
        level = {k: v for k, v in level.items()
                 if v is not None or k not in ("min_agl", "max_agl")}
        return planner_objects({**values, **level})


def planner_options(*, march: bool = False, agl_help: str = AGL_HELP
                    ) -> Callable[[Callable[..., Any]], Callable[..., Any]]:
    """``@planner_options(...)``: the planner flags in place of the command's ``planner``
    parameter, passed as one :class:`PlannerFlags`.

    Parameters
    ----------
    march
        Also ``--threads`` and ``--storage`` (after ``--order``).
    agl_help
        The help of ``--agl`` (what else the command reads from it).
    """
    return option_group("planner", [*SHAPING, *(MARCH if march else ()), *_level(agl_help)],
                        PlannerFlags)
