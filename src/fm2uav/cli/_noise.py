"""Warnings and log records while a command runs: one mechanism, our words only.

:func:`captured` is entered by :func:`fm2uav.cli._common.handle_errors` around
every command. Within it:

* **fm2uav's own warnings** (a category defined in fm2uav:
  :class:`~fm2uav.world.dem.GeodataWarning`, ...) are printed at once as one
  ``warning: ...`` line each, each distinct text once;
* **library warnings** (numpy, rasterio, pyogrio, shapely, pyproj, numba, ...)
  and **library log records** (GDAL messages logged by rasterio / pyogrio,
  which Python would otherwise print raw on stderr) are never printed raw:
  those listed in :data:`LIBRARY_WARNINGS` are said once in our words, every
  other one is dropped (what they could tell is either checked by fm2uav and
  reported as an error or a ``warning:`` line, or numerical detail of a library
  call). ``FM2UAV_DEBUG=1`` prints them as they are, once each, after the
  command (see :func:`fm2uav.cli._common.debug_enabled`).

A new library message worth showing gets a row in :data:`LIBRARY_WARNINGS`
(a regular expression on ``"<category or logger>: <text>"`` and our line).
"""

from __future__ import annotations

import logging
import re
import warnings
from collections.abc import Callable, Iterator
from contextlib import contextmanager

__all__ = ["LIBRARY_WARNINGS", "captured", "library_line"]

#: ``(pattern, our words or None)``: a library warning or log record whose
#: ``"<category or logger name>: <text>"`` matches ``pattern`` is shown as
#: ``warning: <our words>`` (once), or dropped when None. First match wins;
#: unmatched ones are dropped.
LIBRARY_WARNINGS: tuple[tuple[str, str | None], ...] = (
    # numpy on NaN/inf inputs: fm2uav checks its inputs and results for finiteness
    (r"^RuntimeWarning: (invalid value|divide by zero|overflow) encountered", None),
    # numba's performance hints are for developers
    (r"^Numba\w*Warning:", None),
)


def library_line(origin: str, text: str) -> str | None:
    """Our line for a library warning / log record (None: drop it): :data:`LIBRARY_WARNINGS`."""

    key = f"{origin}: {text}"
    for pattern, ours in LIBRARY_WARNINGS:
        if re.search(pattern, key):
            return ours
    return None


def _is_ours(category: type) -> bool:
    return str(getattr(category, "__module__", "")).split(".")[0] == "fm2uav"


class _Records(logging.Handler):
    """Collects the WARNING+ records of other packages' loggers instead of printing them."""

    def __init__(self, sink: Callable[[str, str], None]) -> None:
        super().__init__(logging.WARNING)
        self.sink = sink

    def emit(self, record: logging.LogRecord) -> None:
        try:
            self.sink(record.name, record.getMessage())
        except Exception:  # noqa: BLE001 - a malformed record must not end the command
            pass


@contextmanager
def captured(say: Callable[[str], None], *, debug: bool = False,
             raw: Callable[[str], None] | None = None) -> Iterator[None]:
    """Show fm2uav's warnings as ``say(text)`` lines; library warnings and log records in
    our words or not at all (``debug``: also every one as it is, via ``raw``, at the end).

    Parameters
    ----------
    say : callable
        Prints one ``warning:`` line (the text without the prefix).
    debug : bool
        Keep the library messages and print them raw (``raw``) when the block ends.
    raw : callable, optional
        Prints one raw line (default: ``say``).
    """
    shown: set[str] = set()
    kept: list[str] = []

    def once(text: str) -> None:
        if text not in shown:
            shown.add(text)
            say(text)

    def library(origin: str, text: str) -> None:
        ours = library_line(origin, text)
        if ours is not None:
            once(ours)
        if debug and f"{origin}: {text}" not in kept:
            kept.append(f"{origin}: {text}")

    def show(message, category, filename, lineno, file=None, line=None):  # noqa: ANN001
        if _is_ours(category):
            once(str(message))
        else:
            library(category.__name__, str(message))

    original = warnings.showwarning
    handler = _Records(library)
    root = logging.getLogger()
    warnings.showwarning = show
    root.addHandler(handler)
    try:
        yield
    finally:
        root.removeHandler(handler)
        warnings.showwarning = original
        for text in kept:
            (raw or say)(f"(library) {text}")
