"""The command line's progress display: :mod:`fm2uav.progress` events as a rich progress bar.

The library marks the stages of long work (``span``/``step``/``count``, no printing);
:func:`progress_display` listens to them while a command runs and draws, on stderr,

    ⠹ flying the 3 UAVs — the formation flight  40/95 cycles ━━━━━╺━━━━  48% 0:00:07 ETA 0:08

— the innermost open stage and the one it is part of, a count where the library gives one (bands, cycles,
cases), the share done, the time spent and, once the rate is known, the time left. It shows
nothing when stderr is not a terminal (a pipe, a file, CI) or when the command was
asked for ``--quiet`` / ``--json``, and clears itself when the command ends, so the
summary table follows a clean line.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import Any

__all__ = ["progress_display"]

#: Steps of the bar (the event fractions are floats in [0, 1]).
_TOTAL = 1000


def _eta_column() -> Any:
    from rich.progress import ProgressColumn
    from rich.text import Text

    class EtaColumn(ProgressColumn):
        """``ETA m:ss`` once 3 s have passed and 5 % is done (the rate says something)."""

        def render(self, task: Any) -> Text:
            elapsed = task.elapsed or 0.0
            done = task.completed / (task.total or _TOTAL)
            if elapsed < 3.0 or not 0.05 <= done < 1.0:
                return Text("")
            left = elapsed * (1.0 - done) / done
            m, s = divmod(int(round(left)), 60)
            return Text(f"ETA {m}:{s:02d}", style="progress.remaining")

    return EtaColumn()


@contextmanager
def progress_display(enabled: bool, console: Any) -> Iterator[Callable[[str], None]]:
    """Show the progress of the work inside the ``with`` block on ``console`` (the
    command line's stderr console).

    Listens to :mod:`fm2uav.progress` (:func:`fm2uav.progress.reporting`) for the
    block and yields ``step(message)``, which names what the command itself does
    between library calls (without changing the share done). Nothing is drawn when
    ``enabled`` is False (``--quiet``/``--json``) or the console is not a terminal;
    the library's events are then not even listened to.

    Example
    -------
    >>> with progress_display(False, None) as step:
    ...     step("planning")
    """
    if not enabled or not console.is_terminal:
        yield lambda message: None
        return
    from rich.progress import (
        BarColumn,
        Progress,
        SpinnerColumn,
        TaskProgressColumn,
        TextColumn,
        TimeElapsedColumn,
    )

    from ..progress import reporting

    from rich.table import Column

    # the stage text takes the room left and is cut with "…"; the count, bar, share and
    # times keep theirs
    what = TextColumn("{task.fields[what]}", markup=False,
                      table_column=Column(ratio=1, no_wrap=True, overflow="ellipsis"))
    count = TextColumn("{task.fields[count]}", markup=False, style="progress.download",
                       table_column=Column(no_wrap=True))
    bar = Progress(SpinnerColumn(), what, count, BarColumn(bar_width=20),
                   TaskProgressColumn(), TimeElapsedColumn(), _eta_column(), console=console,
                   transient=True, refresh_per_second=8, expand=True)
    task = bar.add_task("", total=_TOTAL, what="starting", count="")

    def on_event(event: Any) -> None:
        if event.fraction >= 1.0 and not event.stages:
            return    # the end: the summary follows
        # cheap (fields set under a lock): the bar draws them at its refresh rate
        bar.update(task, completed=round(event.fraction * _TOTAL), what=_what(event),
                   count=_count(event))

    with bar, reporting(on_event):
        yield lambda message: bar.update(task, what=str(message), count="")


def _what(event: Any) -> str:
    """What is being done now, then what it is part of: ``"arrival times T (Fast Marching)
    — planning (FM²)"`` (the innermost stage first, so a narrow terminal cuts the context,
    not the news; the outer stages are left out)."""
    return " — ".join(reversed(event.stages[-2:])) if event.stages else "working"


def _count(event: Any) -> str:
    """``"40/95 cycles"`` when the innermost stage counts, else empty."""
    if not event.total:
        return ""
    return f"{event.done}/{event.total}" + (f" {event.unit}" if event.unit else "")
