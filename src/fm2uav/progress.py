"""Progress of long work: stages and shares, reported to whoever listens.

Library functions mark their stages; a caller that wants to know (the web app's
job runner, a progress bar of the command line) installs a callback around the
call with :func:`reporting`. Without a listener every call here is a no-op that
costs a context-variable read, so the numerics never print and never slow down.

Stages nest: :func:`span` gives a part of the enclosing stage's share of the
whole job, :func:`step` moves on to the next part at the same level. A function
that calls :func:`step` runs in a stage of its own (:func:`stage` decorator), so
its steps divide its caller's current part. The
callback receives a :class:`ProgressEvent` with the overall fraction done in
[0, 1] and the names of the open stages, outermost first::

    >>> events = []
    >>> with reporting(events.append):
    ...     with span("planning", 0.5):
    ...         step("velocity map", 0.25)
    ...         step("arrival times", 0.75)
    ...     step("writing files", 0.5)
    >>> [(round(e.fraction, 3), e.message) for e in events]   # doctest: +NORMALIZE_WHITESPACE
    [(0.0, 'planning'), (0.0, 'planning: velocity map'), (0.125, 'planning: arrival times'),
     (0.5, 'writing files'), (1.0, 'done')]

The listener lives in a :mod:`contextvars` variable, so threads and processes
each have their own (a job running in a worker reports only to its own
listener), and nothing has to be threaded through the planners' signatures.
"""

from __future__ import annotations

import functools
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from contextvars import ContextVar
from dataclasses import dataclass, field
from typing import Any, TypeVar

__all__ = ["ProgressEvent", "reporting", "span", "stage", "step", "count", "each"]

F = TypeVar("F", bound=Callable[..., Any])
T = TypeVar("T")


@dataclass(frozen=True)
class ProgressEvent:
    """One report: where the job is.

    Attributes
    ----------
    fraction : float
        Share of the whole job done, in [0, 1] (monotone within one job).
    stages : tuple of str
        Names of the open stages, outermost first (empty at the end).
    done, total : int or None
        A count inside the innermost stage (e.g. leg 2 of 3), when known.
    unit : str
        What is counted (``"cycles"``, ``"cases"``), or ``""``.
    """

    fraction: float
    stages: tuple[str, ...]
    done: int | None = None
    total: int | None = None
    unit: str = ""

    @property
    def message(self) -> str:
        """The stages joined by ``": "`` with the count, e.g. ``"flying: (40 of 95 cycles)"``."""
        text = ": ".join(self.stages) if self.stages else (
            "done" if self.fraction >= 1.0 else "working")
        if self.total:
            text += f" ({self.done} of {self.total}{' ' + self.unit if self.unit else ''})"
        return text


@dataclass
class _Frame:
    name: str
    start: float          # overall fraction where this stage begins
    width: float          # its share of the whole job
    share: float = 1.0    # its share of the enclosing stage
    is_step: bool = False
    cursor: float = 0.0   # share of this stage used by its finished parts, in [0, 1]


@dataclass
class _Tracker:
    callback: Callable[[ProgressEvent], None]
    stack: list[_Frame] = field(default_factory=lambda: [_Frame("", 0.0, 1.0)])
    last: float = 0.0

    def emit(self, fraction: float, done: int | None = None, total: int | None = None,
             unit: str = "") -> None:
        self.last = max(self.last, min(1.0, fraction))
        self.callback(ProgressEvent(self.last, tuple(f.name for f in self.stack[1:] if f.name),
                                    done, total, unit))

    def open(self, name: str, share: float, is_step: bool) -> None:
        parent = self.stack[-1]
        share = max(0.0, min(float(share), 1.0 - parent.cursor))
        frame = _Frame(name, parent.start + parent.width * parent.cursor, parent.width * share,
                       share, is_step)
        self.stack.append(frame)
        if name:  # an anonymous stage only divides the work; nothing new to say
            self.emit(frame.start)

    def close(self, depth: int) -> None:
        """Close the frames above ``depth``, each advancing its parent."""
        while len(self.stack) > depth:
            frame = self.stack.pop()
            parent = self.stack[-1]
            parent.cursor = min(1.0, parent.cursor + frame.share)


_LISTENER: ContextVar[_Tracker | None] = ContextVar("fm2uav_progress", default=None)


@contextmanager
def reporting(callback: Callable[[ProgressEvent], None]) -> Iterator[None]:
    """Send the progress of the work inside the ``with`` block to ``callback``.

    The block is the whole job (fraction 0 → 1); a last event with fraction 1
    and no stages is sent when it ends normally.
    """
    tracker = _Tracker(callback)
    token = _LISTENER.set(tracker)
    try:
        yield
        tracker.close(1)
        tracker.emit(1.0)
    finally:
        _LISTENER.reset(token)


@contextmanager
def span(name: str, share: float = 1.0) -> Iterator[None]:
    """A stage taking ``share`` (0..1, clamped to what is left) of the enclosing stage.

    Inside it, :func:`step` and nested spans divide it further; the steps left
    open inside end with it. Without a listener: nothing.
    """
    tracker = _LISTENER.get()
    if tracker is None:
        yield
        return
    depth = len(tracker.stack)
    tracker.open(name, share, is_step=False)
    try:
        yield
    finally:
        tracker.close(depth)


def stage(name: str = "", share: float = 1.0) -> Callable[[F], F]:
    """Decorator: run the function inside :func:`span` ``(name, share)``.

    A function that marks its parts with :func:`step` runs in a stage of its own,
    so that its steps divide the caller's current part instead of replacing it;
    an empty ``name`` adds no word to the messages.
    """
    def decorate(func: F) -> F:
        @functools.wraps(func)
        def wrapper(*args: Any, **kwargs: Any) -> Any:
            if _LISTENER.get() is None:
                return func(*args, **kwargs)
            with span(name, share):
                return func(*args, **kwargs)
        return wrapper  # type: ignore[return-value]
    return decorate


def step(name: str, share: float) -> None:
    """Begin the next part (``share`` of the enclosing stage) at the current level.

    The previous :func:`step` of the same level ends here. Without a listener: nothing.
    """
    tracker = _LISTENER.get()
    if tracker is None:
        return
    if tracker.stack[-1].is_step:
        tracker.close(len(tracker.stack) - 1)
    tracker.open(name, share, is_step=True)


def count(done: int, total: int, unit: str = "") -> None:
    """Report ``done`` of ``total`` items (``unit``: what they are, e.g. ``"cycles"``) inside
    the innermost open stage; its share done follows ``done / total``."""
    tracker = _LISTENER.get()
    if tracker is None or total <= 0:
        return
    f = tracker.stack[-1]
    done = min(int(done), int(total))
    tracker.emit(f.start + f.width * done / total, done, int(total), unit)


def each(items: Sequence[T], label: Callable[[T], str] | str) -> Iterator[T]:
    """Iterate over ``items``, each a :func:`step` of an equal share named
    ``"<label> (k of n)"`` (``label`` a text or a function of the item).

    >>> events = []
    >>> with reporting(events.append):
    ...     for case in each(["a", "b"], lambda c: f"case {c}"):
    ...         pass
    >>> [(e.fraction, e.message) for e in events]
    [(0.0, 'case a (1 of 2)'), (0.5, 'case b (2 of 2)'), (1.0, 'done')]
    """
    n = len(items)
    for k, item in enumerate(items):
        name = label(item) if callable(label) else str(label)
        step(f"{name} ({k + 1} of {n})", 1.0 / max(n, 1))
        yield item
