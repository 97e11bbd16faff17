"""Argument checks shared by every layer: points, numbers, choices, flags.

Each check returns the value in its canonical type (``float``, ``int``, ``bool``,
a float array) or raises :class:`~fm2uav.errors.InputError` with a one-line
message that says *what* is wrong, *where* the value comes from and *how* to fix
it. ``where`` names the places a user sets the value, e.g.
``where=("planner.saturation", "--saturation")`` for the mission-file key and the
CLI flag; it is appended as ``(mission file: planner.saturation; CLI: --saturation)``.

Examples
--------
>>> positive(2.5, "agl", unit="m")
2.5
>>> positive(-1, "agl", unit="m", where=("planner.agl", "--agl"))
Traceback (most recent call last):
...
fm2uav.errors.InputError: agl must be a finite number > 0 m, got -1 (mission file: planner.agl; CLI: --agl)
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from .errors import InputError

__all__ = [
    "Where",
    "where_text",
    "number",
    "positive",
    "non_negative",
    "in_range",
    "optional",
    "integer",
    "choice",
    "flag",
    "point",
]

#: Where a value is set: ``None``, one place (``"planner.agl"``) or
#: ``(mission-file key, CLI flag)``; either may be None.
Where = str | tuple[str | None, str | None] | None


def where_text(where: Where) -> str:
    """`` (mission file: KEY; CLI: FLAG)`` for ``where``, or ``""``."""
    if where is None:
        return ""
    if isinstance(where, str):
        return f" ({where})"
    key, flag_ = where
    parts = ([f"mission file: {key}"] if key else []) + ([f"CLI: {flag_}"] if flag_ else [])
    return f" ({'; '.join(parts)})" if parts else ""


def _fmt(v: float) -> str:
    return f"{v:g}"


def number(value: Any, what: str, *, unit: str = "", where: Where = None) -> float:
    """``value`` as a finite float.

    Raises
    ------
    InputError
        Not a number (booleans are refused), NaN or inf.
    """
    u = f" {unit}" if unit else ""
    if isinstance(value, (bool, np.bool_)):
        raise InputError(f"{what} must be a number{u}, got {value!r}{where_text(where)}")
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise InputError(
            f"{what} must be a number{u}, got {value!r}{where_text(where)}"
        ) from None
    if not np.isfinite(v):
        raise InputError(f"{what} must be a finite number{u}, got {value!r}{where_text(where)}")
    return v


def positive(value: Any, what: str, *, unit: str = "", where: Where = None) -> float:
    """``value`` as a finite float > 0 (see :func:`number`)."""
    v = number(value, what, unit=unit, where=where)
    if not v > 0:
        u = f" {unit}" if unit else ""
        raise InputError(f"{what} must be a finite number > 0{u}, got {value!r}{where_text(where)}")
    return v


def non_negative(value: Any, what: str, *, unit: str = "", where: Where = None) -> float:
    """``value`` as a finite float >= 0 (see :func:`number`)."""
    v = number(value, what, unit=unit, where=where)
    if not v >= 0:
        u = f" {unit}" if unit else ""
        raise InputError(f"{what} must be a finite number >= 0{u}, got {value!r}{where_text(where)}")
    return v


def in_range(
    value: Any,
    what: str,
    low: float | None = None,
    high: float | None = None,
    *,
    low_open: bool = False,
    high_open: bool = False,
    unit: str = "",
    where: Where = None,
    hint: str = "",
) -> float:
    """``value`` as a finite float in the interval ``low .. high``.

    ``low_open`` / ``high_open`` exclude the bound (``(0, 1]`` is
    ``low=0, high=1, low_open=True``). ``hint`` is appended to the message.
    """
    v = number(value, what, unit=unit, where=where)
    bad = (low is not None and (v <= low if low_open else v < low)) or (
        high is not None and (v >= high if high_open else v > high)
    )
    if bad:
        left = "(" if low_open else "["
        right = ")" if high_open or high is None else "]"
        lo = "-inf" if low is None else _fmt(low)
        hi = "inf" if high is None else _fmt(high)
        u = f" {unit}" if unit else ""
        extra = f"; {hint}" if hint else ""
        raise InputError(
            f"{what} must be in {left}{lo}, {hi}{right}{u}, got {value!r}{extra}{where_text(where)}"
        )
    return v


def optional(check: Any, value: Any, *args: Any, **kwargs: Any) -> Any:
    """``None`` stays None; anything else goes through ``check(value, *args, **kwargs)``."""
    return None if value is None else check(value, *args, **kwargs)


def integer(
    value: Any, what: str, *, minimum: int | None = None, where: Where = None
) -> int:
    """``value`` as an int (an integral float such as ``2.0`` is accepted), ``>= minimum``."""
    ok = not isinstance(value, (bool, np.bool_))
    if ok and isinstance(value, (int, np.integer)):
        v = int(value)
    elif ok and isinstance(value, (float, np.floating)) and float(value).is_integer():
        v = int(value)
    else:
        raise InputError(f"{what} must be an integer, got {value!r}{where_text(where)}")
    if minimum is not None and v < minimum:
        raise InputError(f"{what} must be an integer >= {minimum}, got {value!r}{where_text(where)}")
    return v


def choice(value: Any, options: Sequence[Any], what: str, *, where: Where = None) -> Any:
    """``value`` if it is one of ``options`` (compared with ``==``), else InputError."""
    if value not in tuple(options):
        allowed = ", ".join(repr(o) for o in options)
        raise InputError(f"{what} must be one of {allowed}, got {value!r}{where_text(where)}")
    return value


def flag(value: Any, what: str, *, where: Where = None) -> bool:
    """``value`` as a bool; only ``True``/``False`` (and numpy bools) are accepted."""
    if not isinstance(value, (bool, np.bool_)):
        raise InputError(f"{what} must be true or false, got {value!r}{where_text(where)}")
    return bool(value)


def point(value: Any, ndim: int, what: str, *, where: Where = None) -> np.ndarray:
    """``value`` as a finite float array of ``ndim`` coordinates [m], shape ``(ndim,)``.

    Raises
    ------
    InputError
        Not numeric, wrong number of coordinates, NaN or inf.
    """
    try:
        arr = np.asarray(value, dtype=float).reshape(-1)
    except (TypeError, ValueError):
        raise InputError(
            f"{what} must be {ndim} coordinates in metres, got {value!r}{where_text(where)}"
        ) from None
    if arr.size != ndim:
        raise InputError(
            f"{what} must have {ndim} coordinates (metres) for this {ndim}D world, got "
            f"{arr.size}{where_text(where)}"
        )
    if not np.all(np.isfinite(arr)):
        raise InputError(f"{what} must be finite, got {arr.tolist()}{where_text(where)}")
    return arr
