"""Stop signals of the command line: SIGINT, SIGTERM and SIGHUP raise at once, never lost.

The part of :mod:`fm2uav.io.outdir` that the command line needs from its first
instruction (:func:`install_stop_signals`, :func:`raise_if_stopped`,
:func:`unreported_stop`), before it knows whether a command will write anything: a
light module (the standard library's ``signal``, ``sys``, ``threading`` only), so a
help page or a parser's error does not import the output sets' machinery (``shutil``,
``tempfile``, ...). :mod:`fm2uav.io.outdir` re-exports every name and adds the output
sets' rules (:func:`interrupt_signals` while a command runs, the sets in
:data:`_ACTIVE` renamed into place or removed).
"""

from __future__ import annotations

import signal
import sys
import threading
from collections.abc import Iterator
from contextlib import contextmanager
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from .outdir import OutputDir

__all__ = ["Interrupted", "abort_all", "active_sets", "finish_all", "install_stop_signals",
           "interrupt_signals", "raise_if_stopped", "stop_reported", "unreported_stop"]

#: The output sets of this process not finished or aborted yet (:class:`~.outdir.OutputDir`
#: adds and removes itself): a stop signal once they are all in place is too late to undo.
_ACTIVE: list[OutputDir] = []


class Interrupted(BaseException):  # noqa: N818 (it is a signal, like KeyboardInterrupt)
    """Raised in the main thread on SIGTERM while an output set is being written."""

    def __init__(self, signum: int) -> None:
        super().__init__(f"interrupted by signal {signal.Signals(signum).name}")
        self.signum = signum


class _Commit:
    """Whether the command has put its output sets in place (:func:`finish_all`) and
    opened none since: a stop signal then is too late to undo anything."""

    done = False


class _Hold:
    """Stop signals held while a set is renamed into place or removed."""

    depth = 0
    pending: int | None = None


class _Stop:
    """A stop signal raised and not reported yet (:func:`stop_reported`).

    Every stop the handler raises is recorded here until whoever reports it to the user
    calls :func:`stop_reported`, and :func:`raise_if_stopped` raises it again at the next
    checkpoint (a command's start, before its sets are put in place, the end of the
    command line): a stop that something swallowed is never lost. Python ignores an
    exception raised where it cannot propagate — a weakref callback (the import system
    has some), a ``__del__``, the garbage collector — and hands it to
    ``sys.unraisablehook`` (:func:`_keep_swallowed_stops` keeps it, without the
    "Exception ignored in" lines); a library may catch it (``except BaseException``
    without re-raising), a C function may clear it, or turn it into an error of its own
    (numba's dispatcher: "SystemError: ... returned a result with an exception set"):
    :func:`unreported_stop` tells the command line that such an error is the stop. A stop
    held during the renames of a set that then fail is recorded the same way.
    """

    signum: int | None = None
    previous_hook: Any = None


def _stop_exception(signum: int) -> BaseException:
    return KeyboardInterrupt() if signum == signal.SIGINT else Interrupted(signum)


def _deliver(signum: int) -> None:
    if _Commit.done and not _ACTIVE:
        return  # the outputs are in place: the command is ending anyway
    # kept until reported (stop_reported): raised again at the next checkpoint if a library
    # swallows it (an ``except BaseException`` that does not re-raise, a C function that
    # clears errors), never lost
    _Stop.signum = signum
    raise _stop_exception(signum)


def _keep_swallowed_stops(unraisable: Any) -> None:
    """``sys.unraisablehook``: a stop signal Python could not raise is kept for the next
    checkpoint; anything else goes to the hook this one replaced."""
    exc = unraisable.exc_value
    if isinstance(exc, (KeyboardInterrupt, Interrupted)):
        _Stop.signum = getattr(exc, "signum", signal.SIGINT)
        return
    (_Stop.previous_hook or sys.__unraisablehook__)(unraisable)


def _unraisable_stops() -> None:
    """Install :func:`_keep_swallowed_stops` in front of the current ``sys.unraisablehook``."""
    if sys.unraisablehook is not _keep_swallowed_stops:
        _Stop.previous_hook = sys.unraisablehook
        sys.unraisablehook = _keep_swallowed_stops


def raise_if_stopped() -> None:
    """Raise the stop signal that arrived and was not reported (see :class:`_Stop`), if any.

    Raises
    ------
    KeyboardInterrupt
        SIGINT.
    Interrupted
        SIGTERM, SIGHUP.
    """
    if _Stop.signum is not None:
        raise _stop_exception(_Stop.signum)


def stop_reported() -> None:
    """The stop signal was reported to the user (the process ends with 130): forget it."""
    _Stop.signum = None


def unreported_stop() -> int | None:
    """The stop signal raised in this process and not reported yet (:class:`_Stop`), or None:
    one that a library swallowed, or turned into an exit code (typer's parser) or an error
    of its own, which is then reported as the stop."""
    return _Stop.signum


def _stop_signals() -> list[int]:
    return [signal.SIGTERM, signal.SIGINT] + ([signal.SIGHUP] if hasattr(signal, "SIGHUP")
                                              else [])


def install_stop_signals() -> None:
    """SIGINT raises :class:`KeyboardInterrupt`, SIGTERM and SIGHUP :class:`Interrupted`,
    from now on (the command line's first instruction; :func:`interrupt_signals` adds the
    output sets' rules while a command runs). A signal the parent shell ignores (``nohup``:
    SIGHUP, a background job: SIGINT) stays ignored."""
    _unraisable_stops()
    for sig in _stop_signals():
        try:
            if signal.getsignal(sig) is signal.SIG_IGN:
                continue
            signal.signal(sig, _on_stop_signal)
        except (ValueError, OSError):  # not the main thread, or an exotic platform
            pass


def _on_stop_signal(signum: int, frame: Any) -> None:  # noqa: ARG001
    if _Hold.depth > 0:
        _Hold.pending = signum  # delivered when the renames are done
        return
    _deliver(signum)


@contextmanager
def _signals_held() -> Iterator[None]:
    """Hold the stop signals of :func:`interrupt_signals` for the duration.

    A signal arriving meanwhile is delivered when the block ends (and dropped if
    the block fails: its error is already on its way), so the renames and removals
    of a set are never cut half-way, which could leave a ``.tmp-``/``.old-`` folder
    or the new set with an exit code saying "stopped". Python runs signal
    handlers in the main thread, whichever thread the OS signalled, so a flag is
    enough (an OS signal mask would not be: other threads would take the signal).
    """
    _Hold.depth += 1
    try:
        yield
    except BaseException:
        _Hold.depth -= 1
        if _Hold.depth == 0:
            if _Hold.pending is not None:  # its error goes first; the stop is raised after
                _Stop.signum, _Hold.pending = _Hold.pending, None
        raise
    _Hold.depth -= 1
    if _Hold.depth == 0 and _Hold.pending is not None:
        signum, _Hold.pending = _Hold.pending, None
        _deliver(signum)


@contextmanager
def interrupt_signals() -> Iterator[None]:
    """Turn SIGTERM (and SIGHUP) into :class:`Interrupted` for the duration.

    SIGINT raises :class:`KeyboardInterrupt` as usual. Once the command's output
    sets are renamed into place (and no other set is open), both are ignored: the
    new outputs are complete and the command is ending. A signal the parent ignores
    (``nohup``: SIGHUP; a background job of a shell without job control: SIGINT) stays
    ignored, as in :func:`install_stop_signals`. Outside the main thread (where
    handlers cannot be set) this does nothing.
    """
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    old = {}
    _Commit.done = False
    _unraisable_stops()
    for sig in _stop_signals():
        try:
            if signal.getsignal(sig) is signal.SIG_IGN:
                continue  # ignored by the parent (nohup: SIGHUP; a background job: SIGINT)
            old[sig] = signal.signal(sig, _on_stop_signal)
        except (ValueError, OSError):  # pragma: no cover - exotic platforms
            pass
    try:
        raise_if_stopped()  # a stop Python swallowed before the command started
        yield
    finally:
        for sig, handler in old.items():
            signal.signal(sig, handler)


def active_sets() -> list[OutputDir]:
    """The output sets of this process that are not finished or aborted yet."""
    return list(_ACTIVE)


def finish_all() -> None:
    """Finish every active set (outermost last); on a failure abort the rest.

    The command is ending: from here on a stop signal (under
    :func:`interrupt_signals`) is ignored, since the outputs are complete.
    """
    with _signals_held():
        try:
            raise_if_stopped()  # a stop swallowed while the command ran: nothing is put in place
            for od in reversed(active_sets()):
                od.finish()
        except BaseException:
            abort_all()
            raise
        _Commit.done = True


def abort_all() -> None:
    """Abort every active set: temporary folders removed, targets untouched."""
    for od in reversed(active_sets()):
        od.abort()
