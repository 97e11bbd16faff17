"""The command line's progress display: :mod:`fm2uav.progress` events as a rich progress bar.

The library marks the stages of long work (``span``/``step``/``count``, no printing);
:func:`progress_display` listens to them while a command runs and draws, on stderr,

    ⠹ planning (FM²): leg 2 of 3: arrival times T (Fast Marching) ━━━━━━╺━━━  48% 0:00:07 ETA 0:00:08

— the open stages, a count where the library gives one (bands, UAVs, cases), the
share done, the time spent and, once the rate is known, the time left. It shows
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
def progress_display(enabled: bool = True, console: Any = None
                     ) -> Iterator[Callable[[str], None]]:
    """Show the progress of the work inside the ``with`` block on ``console`` (stderr).

    Listens to :mod:`fm2uav.progress` (:func:`fm2uav.progress.reporting`) for the
    block and yields ``step(message)``, which names what the command itself does
    between library calls (without changing the share done). Nothing is drawn when
    ``enabled`` is False (``--quiet``/``--json``) or the console is not a terminal;
    the library's events are then not even listened to.

    Example
    -------
    >>> with progress_display(enabled=False) as step:
    ...     step("planning")
    """
    if console is None:
        from ._common import err_console as console
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

    # the stage text takes the room left and is cut with "…"; bar, share and times keep theirs
    what = TextColumn("{task.fields[what]}", markup=False,
                      table_column=Column(ratio=1, no_wrap=True, overflow="ellipsis"))
    bar = Progress(SpinnerColumn(), what, BarColumn(bar_width=20), TaskProgressColumn(),
                   TimeElapsedColumn(), _eta_column(), console=console, transient=True,
                   refresh_per_second=8, expand=True)
    task = bar.add_task("", total=_TOTAL, what="starting")

    def on_event(event: Any) -> None:
        if event.fraction >= 1.0 and not event.stages:
            return    # the end: the summary follows
        # cheap (fields set under a lock): the bar draws them at its refresh rate
        bar.update(task, completed=round(event.fraction * _TOTAL), what=event.message)

    with bar, reporting(on_event):
        yield lambda message: bar.update(task, what=str(message))
