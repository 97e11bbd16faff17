"""Entry point of the ``fm2uav`` command (console script and ``python -m fm2uav``).

The first instructions make the process safe to stop and to print, before any
import that takes time:

* **stop signals from the first instruction**: SIGINT (Ctrl-C), SIGTERM and
  SIGHUP raise at once; outside a command (start-up, argument parsing) the run
  ends with one line and exit code 130, never a traceback. While a command runs
  its own handlers take over (:func:`fm2uav.io.outdir.interrupt_signals`: the
  output set is removed, the previous one kept, exit 130);
* **any output encoding**: text that stdout/stderr cannot encode (``LANG=C``
  without UTF-8, ``PYTHONIOENCODING=ascii``) is replaced instead of ending the
  run; a closed pipe (``fm2uav --help | head -1``) ends it quietly.

Then, for ``fm2uav plan`` / ``fm2uav run`` on a cold numba cache, the notice
"compiling kernels, first use only, ~N s" (:func:`fm2uav._jit.likely_cold`: a
few ms, numba not imported), so it is the first thing on screen; the
compilation itself (in two processes for ``plan``) starts once the arguments
are parsed (:mod:`fm2uav.cli._first_use`): a bad flag compiles nothing.

The command line proper is :mod:`fm2uav.cli`, which imports only typer and
rich: ``fm2uav --help``, ``fm2uav plan --help`` and a bad flag answer without
numba, scipy or matplotlib (docs/architecture.md, "The command line stays
light").
"""

from __future__ import annotations

import os
import signal
import sys

#: Signals that stop the command line (exit code 130).
_STOP_SIGNALS = ("SIGINT", "SIGTERM", "SIGHUP")

#: Commands whose first run compiles kernels (the notice is shown before anything else).
_COMPILING_COMMANDS = ("plan", "run")


class StartupStop(KeyboardInterrupt):
    """A stop signal outside a command (start-up, argument parsing, the end)."""

    def __init__(self, signum: int) -> None:
        super().__init__(signum)
        self.signum = signum


def _stop(signum: int, frame: object) -> None:  # noqa: ARG001
    raise StartupStop(signum)


def install_stop_signals() -> None:
    """SIGINT / SIGTERM / SIGHUP raise :class:`StartupStop` (a KeyboardInterrupt).

    A signal the parent shell ignores (``nohup``: SIGHUP; a background job:
    SIGINT) stays ignored.
    """
    for name in _STOP_SIGNALS:
        sig = getattr(signal, name, None)
        if sig is None:
            continue
        try:
            if signal.getsignal(sig) is signal.SIG_IGN:
                continue
            signal.signal(sig, _stop)
        except (ValueError, OSError):  # not the main thread, or an exotic platform
            pass


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


def _stopped(signum: int) -> int:
    for sig_name in _STOP_SIGNALS:  # a second signal while reporting the first: no traceback
        try:
            signal.signal(getattr(signal, sig_name), signal.SIG_IGN)
        except (AttributeError, ValueError, OSError):
            pass
    name = {int(getattr(signal, n)): n for n in _STOP_SIGNALS if hasattr(signal, n)}.get(
        signum, f"signal {signum}")
    what = "SIGINT (Ctrl-C)" if name == "SIGINT" else name
    try:
        sys.stderr.write(f"error: interrupted by {what}; nothing was written\n")
        sys.stderr.flush()
    except (OSError, ValueError):
        pass
    return 130


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



def main() -> None:
    """Run the ``fm2uav`` command line."""
    install_stop_signals()  # the first instruction: no traceback for Ctrl-C from here on
    try:
        _printable_streams()
        _notice_if_cold(sys.argv[1:])
        from .cli import main as cli_main


        cli_main()
    except KeyboardInterrupt as exc:  # start-up or argument parsing (a command reports its own)
        code = _stopped(getattr(exc, "signum", signal.SIGINT))
    except BrokenPipeError:
        code = _quiet_broken_pipe()
    else:  # pragma: no cover - cli_main always exits
        code = 0
    sys.exit(code)


if __name__ == "__main__":
    main()
