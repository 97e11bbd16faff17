"""Shared plumbing of the ``fm2uav`` commands.

Every command follows the same contract (issue "operator workflow"):

* exit code 0 = ok, 1 = planning failed (e.g. unreachable goal), 2 = bad input
  (including a start/goal outside the map or inside an obstacle: PointError;
  unreadable, non-UTF-8 or malformed files; a grid too large for memory; a
  full disk or read-only ``--out``), 130 = interrupted (SIGINT/SIGTERM), 70 =
  an internal error (a bug: the only case with a traceback, plus a line asking
  to report it);
* errors are one line on stderr: what is wrong, where, how to fix it — printed
  verbatim (never read as rich markup) — never a traceback for bad input (set
  ``FM2UAV_DEBUG=1`` to see one);
* outputs go to ``--out DIR`` as one set (:class:`fm2uav.io.outdir.OutputDir`):
  written into a temporary folder beside it and renamed into place when the
  command succeeds; an existing folder is replaced as a whole only with
  ``--force``; a failed or interrupted run leaves the previous set intact and
  no temporary file; a second run into the same folder is refused (lock);
* ``--json`` prints one JSON document on stdout, ``--quiet`` prints nothing but
  errors.
"""

from __future__ import annotations

import functools
import os
import sys
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any, TypeVar

import typer
from rich.console import Console
from rich.markup import escape
from rich.text import Text

from ..errors import (  # noqa: F401  (exit codes and describe_error: re-exported)
    EXIT_INPUT,
    EXIT_INTERNAL,
    EXIT_INTERRUPTED,
    EXIT_OK,
    EXIT_PLANNING,
    InputError,
    describe_error,
)
from .._lazy import lazy_names
from ..pipeline.rows import plan_rows  # noqa: F401  (re-exported; light: numpy inside)

if TYPE_CHECKING:  # imported when a command runs (fm2uav.io loads numpy & co.)
    import numpy as np

    from ..io.outdir import OutputDir

__all__ = [
    "EXIT_OK",
    "EXIT_PLANNING",
    "EXIT_INPUT",
    "EXIT_INTERRUPTED",
    "EXIT_INTERNAL",
    "describe_error",
    "console",
    "err_console",
    "debug_enabled",
    "handle_errors",
    "warning_lines",
    "OutputDir",
    "Output",
    "write_json",
    "write_figure",
    "write_text",
    "plan_rows",
    "parse_point",
    "print_summary",
    "progress",
    "to_jsonable",
]

console = Console()
err_console = Console(stderr=True)

F = TypeVar("F", bound=Callable[..., Any])


#: Names re-exported on first use (PEP 562): ``OutputDir`` (:mod:`fm2uav.io.outdir`) and the
#: writers of :mod:`fm2uav.pipeline.outputs`, which a parse error does not need.
__getattr__, __dir__ = lazy_names(__name__, {
    "OutputDir": "fm2uav.io.outdir", "to_jsonable": "fm2uav.pipeline.outputs",
    "write_figure": "fm2uav.pipeline.outputs", "write_json": "fm2uav.pipeline.outputs",
    "write_text": "fm2uav.pipeline.outputs"})


def _fail(message: str, code: int) -> None:
    """Print ``error: MESSAGE`` verbatim (no markup) on stderr and exit with ``code``."""
    err_console.print(Text.assemble(("error: ", "bold red"), str(message)), highlight=False,
                      soft_wrap=True)
    raise typer.Exit(code)


def _internal(exc: BaseException) -> None:
    import traceback

    traceback.print_exception(exc, file=sys.stderr)
    err_console.print(Text.assemble(
        ("internal error: ", "bold red"),
        f"{type(exc).__name__}: {exc} — this is a bug in fm2uav, not a problem with your input; "
        "please report it with the command line and the traceback above"),
        highlight=False, soft_wrap=True)
    raise typer.Exit(EXIT_INTERNAL)


def debug_enabled() -> bool:
    """Whether ``FM2UAV_DEBUG`` asks for tracebacks: only ``1``, ``true`` or ``yes`` (any case).

    Anything else — unset, empty, ``0``, ``false``, ``no`` — keeps the one-line errors.
    """
    return os.environ.get("FM2UAV_DEBUG", "").strip().lower() in ("1", "true", "yes")


def _warning_line(text: str) -> None:
    err_console.print(f"[bold yellow]warning:[/] {escape(_for_this_command(str(text)))}",
                      highlight=False, soft_wrap=True)



@contextmanager
def warning_lines() -> Iterator[None]:
    """Warnings while a command runs: fm2uav's as one ``warning:`` line each, library
    warnings and log records in our words or not at all (:func:`fm2uav.cli._noise.captured`)."""
    from ._noise import captured

    with captured(_warning_line, debug=debug_enabled(),
                  raw=lambda text: err_console.print(Text(text), highlight=False,
                                                     soft_wrap=True)):
        yield


#: Set by :func:`fm2uav.cli.main` (the real command line): a damaged numba cache may be
#: rebuilt by running the same command line again in this process (``os.execv``).
RERUN_ALLOWED = False
_RERUN_ENV = "FM2UAV_CACHE_REBUILT"


def _cache_fault(path: str) -> None:
    """A damaged numba cache: delete the damaged kernel's cache files (all of fm2uav's when
    the file is not known: :func:`fm2uav._jit.clear_kernel_cache`), then run the command
    again (once, :data:`RERUN_ALLOWED`) or say how. Never returns."""
    from .. import _jit

    removed = _jit.clear_kernel_cache(path)
    what = f"the numba cache of fm2uav's compiled kernels is damaged ({path})"
    if RERUN_ALLOWED and removed and not os.environ.get(_RERUN_ENV):
        _warning_line(f"{what}; deleted its {len(removed)} files, compiling the kernels "
                      "again (once) and running the command again")
        sys.stdout.flush()
        sys.stderr.flush()
        os.environ[_RERUN_ENV] = "1"
        os.execv(sys.executable, [sys.executable, *sys.orig_argv[1:]])
    if removed:
        _fail(f"{what}; deleted its {len(removed)} files: run the command again (the kernels "
              "compile once, then load from a fresh cache)", EXIT_INPUT)
    _fail(f"{what} and could not be deleted; delete the numba cache files of fm2uav "
          "(*.nbi, *.nbc in fm2uav's __pycache__ folders, $NUMBA_CACHE_DIR or "
          "~/.cache/numba) and run the command again", EXIT_INPUT)


def _accepted_flags() -> set[str] | None:
    """The flags of the command being run (None outside a command line context)."""
    try:
        from typer.main import get_current_context
    except ImportError:  # typer versions that use click directly
        from click import get_current_context
    ctx = get_current_context(silent=True)
    if ctx is None:
        return None
    return {o for p in ctx.command.params for o in (*p.opts, *p.secondary_opts)
            if o.startswith("-")}


def _for_this_command(message: str) -> str:
    """``message`` naming only flags this command accepts (:func:`._flags.for_command`)."""
    accepted = _accepted_flags()
    if accepted is None:
        return message
    from ._flags import for_command

    return for_command(message, accepted)


def _report_stop(signum: int) -> None:
    """End the command stopped by ``signum``: one line, exit code 130 (its sets removed)."""
    import signal

    from ..io._stops import stop_reported

    stop_reported()  # reported here: not raised again at the end of the command line
    what = "SIGINT (Ctrl-C)" if signum == signal.SIGINT else signal.Signals(signum).name
    _fail(f"interrupted by {what}; no partial outputs were left (an earlier output set "
          "is as it was)", EXIT_INTERRUPTED)


def handle_errors(func: F) -> F:
    """Run a command: map errors to one-line messages and exit codes, finish its output sets.

    Exit codes: 1 (planning failed), 2 (bad input or environment, see
    :func:`describe_error`), 130 (SIGINT/SIGTERM), 70 (an internal error: a
    traceback plus a line asking to report it). The command's output sets
    (:class:`~fm2uav.io.outdir.OutputDir`) are renamed into place when it returns
    or exits deliberately (``typer.Exit``, e.g. 1 = infeasible with its report);
    on any error they are removed and the previous sets stay. Warnings
    of fm2uav (:class:`fm2uav.world.dem.GeodataWarning`, ...) are shown as one
    ``warning:`` line each on stderr; library warnings and log records are never
    printed raw (:mod:`fm2uav.cli._noise`). An error message names only flags the
    command accepts (:mod:`fm2uav.cli._flags`: a flag it lacks becomes the
    mission-file key). A damaged numba cache is deleted and the command run again
    once (:func:`fm2uav._jit.cache_fault`). ``FM2UAV_DEBUG=1`` (:func:`debug_enabled`)
    lets errors through with their traceback. The command runs with Python's garbage
    collector on (the entry point pauses it while the command line starts:
    :mod:`fm2uav._gc`).
    """

    @functools.wraps(func)
    def wrapper(*args: Any, **kwargs: Any) -> Any:
        from .._gc import resume

        resume()  # the garbage collector, paused while the command line started
        debug = debug_enabled()
        interrupted: tuple[type[BaseException], ...] = (KeyboardInterrupt,)
        try:
            from ..io._stops import Interrupted, abort_all, finish_all, interrupt_signals

            interrupted = (KeyboardInterrupt, Interrupted)
            with interrupt_signals(), warning_lines():
                try:
                    result = func(*args, **kwargs)
                except typer.Exit:
                    # a deliberate exit after the outputs (e.g. 1 = infeasible, with its
                    # report): the set is complete, keep it
                    finish_all()
                    raise
                except BaseException:
                    abort_all()
                    raise
                finish_all()
                return result
        except typer.Exit:
            raise
        except interrupted as exc:
            import signal

            _report_stop(getattr(exc, "signum", signal.SIGINT))
        except Exception as exc:  # noqa: BLE001 - the one place errors become exit codes
            from ..io._stops import unreported_stop

            signum = unreported_stop()
            if signum is not None:  # an error the stop turned into (numba's SystemError "...
                _report_stop(signum)  # returned a result with an exception set"): the stop
            if debug:
                raise
            from .._jit import cache_fault

            damaged = cache_fault(exc)
            if damaged is not None:
                _cache_fault(damaged)
            known = describe_error(exc)
            if known is None:
                _internal(exc)
            else:
                _fail(_for_this_command(known[0]), known[1])

    return wrapper  # type: ignore[return-value]


def point_numbers(text: str, ndim: int, what: str) -> list[float]:
    """The ``ndim`` numbers of ``"x,y,z"`` (commas or spaces), pure Python: the command line
    checks a point's text before the world (and numpy) loads.

    Raises
    ------
    InputError
        Not numbers, or not ``ndim`` of them (names ``--<what>``).
    """
    parts = [p for p in text.replace(",", " ").split() if p]
    try:
        values = [float(p) for p in parts]
    except ValueError:
        raise InputError(f"--{what} must be {ndim} numbers like 300,300,300; got {text!r}") from None
    if len(values) != ndim:
        raise InputError(f"--{what} needs {ndim} numbers (x,y[,z]); got {len(values)} in {text!r}")
    return values


def parse_point(text: str, ndim: int, what: str) -> np.ndarray:
    """Parse ``"x,y,z"`` (commas or spaces) into a float array of length ``ndim``
    (:func:`point_numbers`)."""
    import numpy as np

    return np.array(point_numbers(text, ndim, what))


def print_summary(
    title: str,
    rows: dict[str, Any],
    *,
    as_json: bool = False,
    quiet: bool = False,
    files: list[Path] | None = None,
) -> None:
    """Print a summary as a rich table, or as JSON with ``as_json``."""
    if quiet:
        return
    if as_json:
        import json

        from ..pipeline.outputs import to_jsonable

        payload = dict(rows)
        if files is not None:
            payload["files"] = [str(f) for f in files]
        sys.stdout.write(json.dumps(to_jsonable(payload), indent=2) + "\n")
        return
    from rich.table import Table

    table = Table(title=escape(title), show_header=False, title_justify="left")
    table.add_column("what", style="bold")
    table.add_column("value")
    for key, value in rows.items():
        table.add_row(escape(str(key)), escape(str(value)))
    console.print(table)
    if files:
        console.print("outputs:")
        for f in files:
            console.print(Text(f"  {f}"), highlight=False)


def progress(enabled: bool = True) -> Any:
    """The progress display of a long command on stderr (:func:`._progress.progress_display`):
    the :mod:`fm2uav.progress` stages, counts, share done and time left as a rich bar.

    Used as ``with progress(enabled) as step:``; ``step(message)`` names what the
    command does itself. Nothing is shown when ``enabled`` is False (``--quiet`` /
    ``--json``) or when stderr is not a terminal (scripts, CI), so output stays clean
    for pipes.

    Example
    -------
    >>> with progress(enabled=False) as step:
    ...     step("planning")
    """
    from ._progress import progress_display

    return progress_display(enabled, err_console)


@dataclass
class Output:
    """The output flags of a command (``--out``, ``--force``, ``--json``, ``--quiet``,
    ``--report``) and its output set.

    ``dir(names)`` opens the :class:`OutputDir` (checked for ``names``);
    ``summary(title, rows, payload)`` prints ``rows``, or ``payload`` with ``--json``.
    """

    out: Path | None = None
    force: bool = False
    as_json: bool = False
    quiet: bool = False
    report: bool = False
    outdir: OutputDir | None = field(default=None, repr=False)

    @property
    def show_progress(self) -> bool:
        """Whether the progress display may be shown (neither ``--quiet`` nor ``--json``)."""
        return not (self.quiet or self.as_json)

    def progress(self) -> Any:
        """:func:`progress` enabled unless ``--quiet``/``--json``."""
        return progress(enabled=self.show_progress)

    def dir(self, names: Any = None, *, path: Path | None = None) -> OutputDir:
        """The command's :class:`OutputDir` at ``path`` (default ``--out``), checked for
        ``names`` when given."""
        if self.outdir is None:
            from ..io.outdir import OutputDir

            self.outdir = OutputDir(
path if path is not None else self.out, force=self.force)
        if names is not None:
            self.outdir.check(names)
        return self.outdir

    def summary(self, title: str, rows: dict[str, Any], payload: Any = None) -> None:
        """Print ``rows`` as a table (or ``payload``, default ``rows``, with ``--json``)
        followed by the files written."""
        print_summary(title, (rows if payload is None else payload) if self.as_json else rows,
                      as_json=self.as_json, quiet=self.quiet,
                      files=None if self.outdir is None else self.outdir.written)
