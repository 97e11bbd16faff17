"""Library warnings on the way in: captured, then said once in our words or not at all.

Reading a DEM goes through rasterio (GDAL), pyproj and numpy, which warn in
their own ways: ``warnings.warn`` with a source line (pyproj's "You will likely
lose important projection information", rasterio's ``NotGeoreferencedWarning``,
numpy's "All-NaN slice") and GDAL messages that rasterio logs (printed bare by
Python's last-resort handler). Before an operator's one-line error or summary
they are noise, or worse, a second story. :func:`library_warnings` captures
both while a block runs, then

* re-emits fm2uav's own warnings (:class:`~fm2uav.world.dem.GeodataWarning`)
  unchanged;
* turns GDAL's messages into one :class:`GeodataWarning` naming what was being
  read (a file GDAL had to work around is worth knowing about);
* drops the rest (every question they raise is answered by our own checks: a
  missing CRS is refused, a CRS without EPSG code is named by its name, NaN
  pixels are nodata).
"""

from __future__ import annotations

import logging
import warnings
from collections.abc import Iterator
from contextlib import contextmanager

__all__ = ["GeodataWarning", "library_warnings"]

#: Loggers GDAL's messages arrive on (rasterio routes CPLError through them).
_GDAL_LOGGERS = ("rasterio",)
#: At most this many distinct GDAL messages are repeated.
_MAX_GDAL = 3


class GeodataWarning(UserWarning):
    """Something in the input data deserves the operator's attention (not an error)."""


class _Collect(logging.Handler):
    def __init__(self) -> None:
        super().__init__(level=logging.WARNING)
        self.messages: list[str] = []

    def emit(self, record: logging.LogRecord) -> None:  # pragma: no cover - trivial
        try:
            self.messages.append(record.getMessage())
        except Exception:  # a malformed record: nothing to say
            pass


def _ours(category: type) -> bool:
    return str(getattr(category, "__module__", "")).startswith("fm2uav")


@contextmanager
def library_warnings(what: str) -> Iterator[None]:
    """Capture library warnings while reading ``what`` (e.g. ``"the DEM dem.tif"``).

    Examples
    --------
    >>> import warnings
    >>> with warnings.catch_warnings(record=True) as seen:
    ...     warnings.simplefilter("always")
    ...     with library_warnings("the DEM x.tif"):
    ...         warnings.warn("library noise", UserWarning)
    >>> len(seen)
    0
    """
    handler = _Collect()
    loggers = [logging.getLogger(n) for n in _GDAL_LOGGERS]
    saved = [lg.propagate for lg in loggers]
    for lg in loggers:
        lg.addHandler(handler)
        lg.propagate = False
    seen: list[warnings.WarningMessage] = []
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            try:
                yield
            finally:
                seen = list(caught)
    finally:
        for lg, prop in zip(loggers, saved):
            lg.removeHandler(handler)
            lg.propagate = prop
        _say(seen, handler.messages, what)


def _say(seen: list[warnings.WarningMessage], gdal_messages: list[str], what: str) -> None:
    """Re-emit fm2uav's own warnings once each, and GDAL's messages as one warning (also
    when the block failed: they tell what went before the error)."""
    done: set[str] = set()
    for w in seen:
        if _ours(w.category):
            key = f"{w.category.__name__}:{w.message}"
            if key not in done:
                done.add(key)
                warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
    gdal = list(dict.fromkeys(m.strip() for m in gdal_messages if m.strip()))
    if gdal:
        more = f" (and {len(gdal) - _MAX_GDAL} more)" if len(gdal) > _MAX_GDAL else ""
        text = "; ".join(m.splitlines()[0] for m in gdal[:_MAX_GDAL])
        warnings.warn(f"GDAL had to work around something reading {what}: {text}{more}; "
                      "the data were read, but check the file (gdalinfo FILE)",
                      GeodataWarning, stacklevel=4)
