"""The cyclic garbage collector paused while the command line starts (issue 27: an
instant command line).

Starting ``fm2uav`` imports ~150-400 modules (typer, rich, and for a mission file
pydantic and yaml) and builds the command's parameters: hundreds of thousands of
objects allocated, almost none freed. The collector runs a pass every 700 net
allocations and a full pass (every object) every few tens of thousands: ~10 % of the
instructions of a help page or a one-line error, and the collections at interpreter exit
traverse the whole heap once more (~5-8 %). So the entry point (:mod:`fm2uav.__main__`)
calls :func:`pause` first; a command calls :func:`resume` when it starts running (its
arguments parsed: :func:`fm2uav.cli._common.handle_errors`), which moves every object
alive then, the modules' code, classes and tables, out of the collector's sight for the
rest of the process (``gc.freeze``) and turns it on again, so the command itself runs
with the collector as usual (and its full passes no longer walk the import-time objects).
:func:`at_exit` freezes what is alive at the end, so the exit does not traverse it (the
OS reclaims the memory; every output file is closed by the command itself).

Only the entry point pauses: :func:`resume` and :func:`at_exit` do nothing in a process
that did not call :func:`pause` (the library, tests running commands in process, a
program that turned the collector off itself keeps its setting).

Bottom layer (the standard library's ``gc`` only).
"""

from __future__ import annotations

import gc

__all__ = ["at_exit", "pause", "paused", "resume"]


class _State:
    paused = False  # pause() turned the collector off and resume() has not run yet
    owner = False  # pause() ran in this process (at_exit freezes only then)


def pause() -> None:
    """Turn the collector off until :func:`resume` (the entry point's first instruction);
    a no-op when it is off already."""
    if gc.isenabled():
        gc.disable()
        _State.paused = _State.owner = True


def paused() -> bool:
    """Whether :func:`pause` turned the collector off and :func:`resume` has not run."""
    return _State.paused


def resume() -> None:
    """The command starts: freeze what is alive (``gc.freeze``) and turn the collector on
    again, if :func:`pause` turned it off (else nothing)."""
    if _State.paused:
        _State.paused = False
        gc.freeze()
        gc.enable()


def at_exit() -> None:
    """The process ends: freeze what is alive, so the interpreter's exit does not traverse
    it (only in a process that called :func:`pause`)."""
    if _State.owner:
        gc.freeze()
