"""Entry point of the ``fm2uav`` command (console script and ``python -m fm2uav``).

The first instructions make the process safe to stop and to print, before any
import that takes time:

* **stop signals from the first instruction**: SIGINT (Ctrl-C), SIGTERM and
  SIGHUP raise at once (:func:`fm2uav.io._stops.install_stop_signals`, re-exported
  by :mod:`fm2uav.io.outdir`: a light module, loaded before anything else); outside
  a command (start-up, argument parsing) the run ends with one line and exit code
  130, never a traceback.
  While a command runs the output sets' rules apply
  (:func:`fm2uav.io.outdir.interrupt_signals`: the set is removed, the previous
  one kept, exit 130). A stop that is swallowed (one landing in a weakref
  callback of the import system, a ``__del__``, a library's ``except BaseException``)
  is raised again at the next checkpoint (:func:`fm2uav.io.outdir.raise_if_stopped`):
  never lost; an error raised while a stop is pending is reported as the stop;
  once the command has ended, a stop signal is ignored (its outcome is decided);
* **any output encoding**: text that stdout/stderr cannot encode (``LANG=C``
  without UTF-8, ``PYTHONIOENCODING=ascii``) is replaced instead of ending the
  run; a closed pipe (``fm2uav --help | head -1``) ends it quietly.

Then, for ``fm2uav plan`` on a cold numba cache, the notice "compiling kernels,
first use only, ~N s" (:func:`fm2uav._jit.likely_cold`: ~30 ms, numba not
imported), so it is the first thing on screen; the compilation itself (in two
processes) starts once the arguments are parsed (:mod:`fm2uav.cli._first_use`):
a bad flag compiles nothing. ``fm2uav run`` says it once its mission file is read
and valid (:func:`fm2uav.cli._first_use.announce_compile` in the command): a
mission-file error answers without the cache check.

A help page (``fm2uav [command ...] --help``) asked before is copied from the pages
kept between runs (:mod:`fm2uav._help_cache`: keyed on the package's source, the
renderers and the terminal), without typer or rich.

The command line proper is :mod:`fm2uav.cli`, which imports only typer and
rich: ``fm2uav --help``, ``fm2uav plan --help`` and a bad flag answer without
numba, scipy or matplotlib (docs/architecture.md, "The command line stays
light").
"""

from __future__ import annotations

import os
import signal
import sys
from typing import Any

from . import _code_cache, _gc, _help_cache

#: Commands whose first run compiles kernels and whose notice is shown before anything else
#: (``run`` shows it after reading its mission file: a file's error answers sooner).
_COMPILING_COMMANDS = ("plan",)


def _printable_streams() -> None:
    """Replace what stdout/stderr cannot encode instead of failing on it (ASCII locales)."""
    for stream in (sys.stdout, sys.stderr):
        encoding = (getattr(stream, "encoding", None) or "").lower().replace("-", "")
        if encoding != "utf8" and hasattr(stream, "reconfigure"):
            try:
                stream.reconfigure(errors="replace" if stream is sys.stdout
                                   else "backslashreplace")
            except (ValueError, OSError):  # pragma: no cover - a detached stream
                pass


def _stopped(signum: int) -> None:
    """Report a stop signal outside a command and end the process with 130, at once.

    ``os._exit``: no interpreter shutdown, which may end the process with SIGINT itself
    when the KeyboardInterrupt passed through code Python evaluated for it (nothing is
    open here: a command removes its output sets before it reports its own stop).
    """
    _ignore_stops()  # a second signal while reporting the first: no traceback
    what = "SIGINT (Ctrl-C)" if signum == signal.SIGINT else signal.Signals(signum).name
    try:
        sys.stderr.write(f"error: interrupted by {what}; nothing was written\n")
    except (OSError, ValueError):
        pass
    _exit_now(130)


def _ignore_stops() -> None:
    """Ignore SIGINT, SIGTERM and SIGHUP from now on: the run's outcome is decided."""
    for sig_name in ("SIGINT", "SIGTERM", "SIGHUP"):
        try:
            signal.signal(getattr(signal, sig_name), signal.SIG_IGN)
        except (AttributeError, ValueError, OSError):
            pass


def _exit_now(code: int) -> None:
    """End the process at once with ``code`` (stdio flushed; see :func:`_stopped`)."""
    try:
        sys.stdout.flush()
        sys.stderr.flush()
    except (OSError, ValueError):
        pass
    os._exit(code)


def _quiet_broken_pipe() -> int:
    """The reader of stdout went away: stop writing, without a traceback."""
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
    except (OSError, ValueError):
        pass
    return 141  # 128 + SIGPIPE, as a shell reports a process killed by it


def _notice_if_cold(argv: list[str]) -> None:
    """The compile notice of a first ``plan`` / ``run`` on a cold cache, before any import."""
    if not argv or argv[0] not in _COMPILING_COMMANDS or {"--help", "-h"} & set(argv):
        return
    from . import _jit

    if _jit.likely_cold():
        _jit.mark_announced()  # neither the command nor the numba-event fallback repeats it
        if "--quiet" not in argv:
            from rich.console import Console

            Console(stderr=True).print(_jit.NOTICE.format(seconds=_jit.cold_estimate_s()),
                                       style="yellow", highlight=False)


def _render_and_keep(cli_main: Any, page: str) -> None:
    """Run a help request, keeping its page (stdout) when it exits 0 with nothing on stderr."""
    out, err = _help_cache.Recorder(sys.stdout), _help_cache.Recorder(sys.stderr)
    real = sys.stdout, sys.stderr
    sys.stdout, sys.stderr = out, err
    try:
        cli_main()
    except SystemExit as exc:
        if exc.code in (0, None) and not err.parts:
            _help_cache.keep(page, "".join(out.parts))
        raise
    finally:
        sys.stdout, sys.stderr = real


def _run() -> int:
    """The command line's exit code (stop signals: 130 with one line, never a traceback)."""
    from .io._stops import Interrupted, install_stop_signals, raise_if_stopped, unreported_stop

    try:
        install_stop_signals()  # no traceback for a stop signal from here on
        try:
            _printable_streams()
            served, page = _help_cache.serve(sys.argv[1:])
            if served:  # a help page kept from an earlier run: no typer, no rich
                return 0
            # generated source compiled once (fm2uav._code_cache), a table per command
            _code_cache.install(sys.argv[1] if len(sys.argv) > 1 else "")
            _notice_if_cold(sys.argv[1:])
            from .cli import main as cli_main

            if page is None:
                cli_main()
            else:
                _render_and_keep(cli_main, page)
        except SystemExit as exc:
            raise_if_stopped()  # a stop Python swallowed (start-up, parsing): 130 all the same
            if exc.code == 130:  # stopped: a command reported it, or typer's parser exited
                signum = unreported_stop()  # with 130 in silence
                if signum is not None:
                    _stopped(signum)
                _exit_now(130)
            raise
        raise_if_stopped()
    except (KeyboardInterrupt, Interrupted) as exc:  # outside a command (a command reports
        _stopped(getattr(exc, "signum", signal.SIGINT))  # its own: handle_errors)
    except BrokenPipeError:
        return _quiet_broken_pipe()
    except Exception:  # an error a stop turned into (a library's, while it was raised)
        signum = unreported_stop()
        if signum is not None:
            _stopped(signum)
        raise
    return 0  # pragma: no cover - cli_main always exits


def main() -> None:
    """Run the ``fm2uav`` command line.

    The cyclic garbage collector is paused while the command line starts and until the
    command runs (:mod:`fm2uav._gc`: ~10 % of a help page's or an error's instructions).
    The command line loads no third-party pydantic plugins (``PYDANTIC_DISABLE_PLUGINS``
    defaults to ``__all__`` in this process: pydantic otherwise reads the entry points of
    every installed distribution when the mission schema is built, ~20 ms of a mission-file
    error's answer); a value set in the environment is kept.
    """
    _gc.pause()  # until the command runs (fm2uav._gc): start-up frees almost nothing
    os.environ.setdefault("PYDANTIC_DISABLE_PLUGINS", "__all__")
    try:
        code = _run()
    except KeyboardInterrupt:  # Ctrl-C before the handlers are in place (Python's own)
        _stopped(signal.SIGINT)
    finally:
        # the command has ended, its outputs in place or not written: a stop signal now
        # changes nothing (and the interpreter's shutdown would give it the default action:
        # a finished run killed, exit status -15)
        _ignore_stops()
        _code_cache.save()  # the code this run compiled first, for the next runs
        _gc.at_exit()  # the exit does not traverse the heap
    sys.exit(code)


if __name__ == "__main__":
    main()
