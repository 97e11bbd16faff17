"""Shared plumbing of the ``fm2uav`` commands.

Every command follows the same contract (issue "operator workflow"):

* exit code 0 = ok, 1 = planning failed (e.g. unreachable goal), 2 = bad input
  (including a start/goal outside the map or inside an obstacle: PointError);
* errors are one line on stderr: what is wrong, where, how to fix it — never a
  traceback (set ``FM2UAV_DEBUG=1`` to see one);
* outputs go to ``--out DIR``; existing files are never overwritten without
  ``--force``; files are written to a temporary name and renamed, so a failed
  run leaves no half-written file;
* ``--json`` prints one JSON document on stdout, ``--quiet`` prints nothing but
  errors.
"""

from __future__ import annotations

import functools
import json
import os
import sys
import tempfile
from collections.abc import Callable, Iterable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any, TypeVar

import numpy as np
import typer
from rich.console import Console
from rich.markup import escape
from rich.table import Table

from ..errors import Fm2uavError, InputError, PlanningError, PointError, WorldError

__all__ = [
    "EXIT_OK",
    "EXIT_PLANNING",
    "EXIT_INPUT",
    "console",
    "err_console",
    "handle_errors",
    "warning_lines",
    "OutputDir",
    "parse_point",
    "print_summary",
    "progress",
    "to_jsonable",
]

EXIT_OK = 0
EXIT_PLANNING = 1
EXIT_INPUT = 2

console = Console()
err_console = Console(stderr=True)

F = TypeVar("F", bound=Callable[..., Any])


def to_jsonable(obj: Any) -> Any:
    """Convert numpy scalars/arrays and paths into plain JSON types."""
    if isinstance(obj, dict):
        return {str(k): to_jsonable(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [to_jsonable(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return to_jsonable(obj.tolist())
    if isinstance(obj, np.generic):
        return obj.item()
    if isinstance(obj, Path):
        return str(obj)
    if isinstance(obj, float) and not np.isfinite(obj):
        return None
    return obj


def _fail(message: str, code: int) -> None:
    err_console.print(f"[bold red]error:[/] {message}", highlight=False, soft_wrap=True)
    raise typer.Exit(code)


@contextmanager
def warning_lines() -> Iterator[None]:
    """Show fm2uav's warnings (e.g. a DEM below sea level) as one ``warning:`` line each."""
    import warnings

    original = warnings.showwarning

    def show(message, category, filename, lineno, file=None, line=None):  # noqa: ANN001
        if str(getattr(category, "__module__", "")).startswith("fm2uav"):
            err_console.print(f"[bold yellow]warning:[/] {escape(str(message))}",
                              highlight=False, soft_wrap=True)
        else:
            original(message, category, filename, lineno, file, line)

    warnings.showwarning = show
    try:
        yield
    finally:
        warnings.showwarning = original


def handle_errors(func: F) -> F:
    """Map fm2uav errors to one-line messages and exit codes 1 (planning) / 2 (input).

    Warnings of fm2uav (:class:`fm2uav.world.dem.GeodataWarning`, ...) are shown
    as one ``warning:`` line each on stderr.
    """

    @functools.wraps(func)
    def wrapper(*args: Any, **kwargs: Any) -> Any:
        try:
            with warning_lines():
                return func(*args, **kwargs)
        except typer.Exit:
            raise
        except PointError as exc:
            if os.environ.get("FM2UAV_DEBUG"):
                raise
            _fail(str(exc), EXIT_INPUT)
        except PlanningError as exc:
            if os.environ.get("FM2UAV_DEBUG"):
                raise
            _fail(str(exc), EXIT_PLANNING)
        except (InputError, WorldError, Fm2uavError) as exc:
            if os.environ.get("FM2UAV_DEBUG"):
                raise
            _fail(str(exc), EXIT_INPUT)
        except FileNotFoundError as exc:
            if os.environ.get("FM2UAV_DEBUG"):
                raise
            _fail(f"file not found: {exc.filename}; check the path", EXIT_INPUT)

    return wrapper  # type: ignore[return-value]


def parse_point(text: str, ndim: int, what: str) -> np.ndarray:
    """Parse ``"x,y,z"`` (commas or spaces) into a float array of length ``ndim``."""
    parts = [p for p in text.replace(",", " ").split() if p]
    try:
        values = np.array([float(p) for p in parts])
    except ValueError:
        raise InputError(f"--{what} must be {ndim} numbers like 300,300,300; got {text!r}") from None
    if values.size != ndim:
        raise InputError(f"--{what} needs {ndim} numbers (x,y[,z]); got {values.size} in {text!r}")
    return values


def _umask_mode(path: str | os.PathLike[str]) -> None:
    """Give a temporary file the permissions of a normally created file (0666 & ~umask)."""
    mask = os.umask(0)
    os.umask(mask)
    os.chmod(path, 0o666 & ~mask)


class OutputDir:
    """An output directory that refuses to overwrite and writes atomically.

    Parameters
    ----------
    path : path-like
        Directory; created if missing.
    force : bool
        Allow overwriting existing files.
    """

    def __init__(self, path: str | os.PathLike[str], *, force: bool = False) -> None:
        self.path = Path(path)
        self.force = force
        self.written: list[Path] = []

    def check(self, names: Iterable[str]) -> None:
        """Fail (InputError) before any work if a target file exists and not ``force``."""
        if self.path.exists() and not self.path.is_dir():
            raise InputError(f"--out {self.path} exists and is not a directory; choose another path")
        clashes = [n for n in names if (self.path / n).exists()]
        if clashes and not self.force:
            raise InputError(
                f"{self.path / clashes[0]} already exists (and {len(clashes) - 1} more); "
                "pass --force to overwrite or choose another --out"
            )

    @contextmanager
    def open(self, name: str, mode: str = "w") -> Iterator[Any]:
        """Open ``name`` for writing via a temporary file renamed on success."""
        self.path.mkdir(parents=True, exist_ok=True)
        target = self.path / name
        if target.exists() and not self.force:
            raise InputError(f"{target} already exists; pass --force to overwrite")
        fd, tmp = tempfile.mkstemp(prefix=f".{name}.", dir=self.path)
        os.close(fd)
        try:
            with open(tmp, mode) as fh:
                yield fh
            _umask_mode(tmp)
            os.replace(tmp, target)
        except BaseException:
            if os.path.exists(tmp):
                os.unlink(tmp)
            raise
        self.written.append(target)

    def target(self, name: str) -> Path:
        """Temporary path for libraries that write by filename; call :meth:`commit` after."""
        self.path.mkdir(parents=True, exist_ok=True)
        target = self.path / name
        if target.exists() and not self.force:
            raise InputError(f"{target} already exists; pass --force to overwrite")
        suffix = "".join(target.suffixes)
        fd, tmp = tempfile.mkstemp(prefix=f".{target.stem}.", suffix=suffix, dir=self.path)
        os.close(fd)
        return Path(tmp)

    def commit(self, tmp: Path, name: str) -> Path:
        """Move a temporary file from :meth:`target` into place."""
        target = self.path / name
        _umask_mode(tmp)
        os.replace(tmp, target)
        self.written.append(target)
        return target


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
        payload = dict(rows)
        if files is not None:
            payload["files"] = [str(f) for f in files]
        sys.stdout.write(json.dumps(to_jsonable(payload), indent=2) + "\n")
        return
    table = Table(title=title, show_header=False, title_justify="left")
    table.add_column("what", style="bold")
    table.add_column("value")
    for key, value in rows.items():
        table.add_row(escape(str(key)), escape(str(value)))
    console.print(table)
    if files:
        console.print("outputs:")
        for f in files:
            console.print(f"  {f}")


@contextmanager
def progress(enabled: bool = True) -> Iterator[Callable[[str], None]]:
    """Show the current stage of a long command as a rich spinner on stderr.

    Yields a function ``step(message)`` that updates the spinner. Nothing is
    shown when ``enabled`` is False (``--quiet`` / ``--json``) or when stderr
    is not a terminal (scripts, CI), so output stays clean for pipes.

    Example
    -------
    >>> with progress(enabled=False) as step:
    ...     step("planning")
    """
    if not enabled or not err_console.is_terminal:
        yield lambda message: None
        return
    with err_console.status("starting", spinner="dots") as status:
        yield lambda message: status.update(f"[bold]{message}[/]")
