"""``fm2uav batch A.yaml B.yaml DIR/``: many mission files on local processes or Dask.

The library side is :mod:`fm2uav.pipeline.batch` (each mission is what ``fm2uav run
FILE`` does, on the sweep's executors); this module parses the options, prints the
table and writes ``batch.json``.
"""

from __future__ import annotations

import time
from pathlib import Path
from typing import Any

import typer
from rich.markup import escape
from rich.text import Text

from ._common import (
    EXIT_INTERRUPTED,
    Output,
    _for_this_command,
    console,
    err_console,
    handle_errors,
    to_jsonable,
)
from .cmd_sweep import EXIT_CASES_FAILED
from .options import output_options

#: Exit code of a batch that ran to the end with failed missions (their folders are not
#: written; the others are).
EXIT_MISSIONS_FAILED = EXIT_CASES_FAILED

EXIT_CODES_HELP = (
    "Exit codes: 0 every mission ok; 2 bad input to the batch itself, nothing run (a missing "
    "file, two missions writing one folder, an output folder that exists without --force or "
    "is being written, --workers, an unreachable --scheduler); 3 the batch ran to the end but "
    "some missions failed (their reasons in the table and in batch.json; the others' folders "
    "are written); 130 stopped by SIGINT or SIGTERM (the missions finished so far are written "
    "and listed in batch.json, the others are 'not run'); 70 an internal error."
)

BATCH_HELP = (
    "Plan many mission files at once, each exactly as fm2uav run FILE plans it (same files, "
    "byte for byte, but the timings), on local worker processes (--workers) or an existing "
    "Dask cluster (--scheduler). Folders are read as their *.yaml / *.yml files. Each "
    "mission is written to its own folder — its outputs.dir, else OUT/<file name> — as one "
    "set, by this process when the mission's result arrives: a worker that dies costs its "
    "mission one attempt (run again on another worker, then failed with the reason), never "
    "a half-written folder. A mission that fails does not stop the others. The table and "
    "OUT/batch.json give each mission's status (ok / failed / not run), its error, time, "
    "worker and folder.\n\n"
    "--resume keeps the missions an earlier batch into the same --out wrote (unchanged "
    "files) and plans the rest.\n\n"
    "Examples:\n\n"
    "  fm2uav batch missions/*.yaml --out out/batch --workers 2\n\n"
    "  fm2uav batch missions/*.yaml --out out/batch --resume\n\n"
    "  fm2uav batch missions/ --scheduler tcp://10.0.0.5:8786 --out out/batch\n\n"
    "On a Dask cluster the workers read the mission files and the data they name at the "
    "same paths (a shared file system); only this process writes the outputs.\n\n"
    + EXIT_CODES_HELP
)


def _results_payload(results: list[Any], pool: Any, wall_s: float, out: Path,
                     interrupted: str | None = None) -> dict[str, Any]:
    """The content of ``batch.json``."""
    from dataclasses import asdict

    counts = {s: sum(r.status == s for r in results) for s in ("ok", "failed", "not run")}
    payload: dict[str, Any] = {
        "missions": len(results), **counts, "resumed": sum(r.resumed for r in results),
        "worker_deaths": getattr(pool, "deaths", 0), "retried": getattr(pool, "retried", 0),
        "wall_s": round(wall_s, 3), "out": str(out),
        "results": [asdict(r) for r in results],
    }
    if interrupted:
        payload["interrupted"] = interrupted
    return payload


def _table(results: list[Any], title: str) -> None:
    from rich.table import Table

    table = Table(title=escape(title), title_justify="left")
    for col in ("mission file", "status", "time [s]", "output folder / error"):
        table.add_column(escape(col))
    style = {"ok": "green", "failed": "bold red", "not run": "yellow"}
    for r in results:
        status = "ok (kept)" if r.resumed else r.status
        table.add_row(escape(r.file), Text(status, style=style[r.status]),
                      "" if r.time_s is None else f"{r.time_s:.1f}",
                      escape(r.out if r.status == "ok" else (r.error or "")))
    console.print(table)


@handle_errors
@output_options("out", out_help="The batch's folder: batch.json, and OUT/<mission file name> "
                "for each mission without an outputs.dir of its own.",
                force_help="Replace existing mission folders (each as a whole) and batch.json.",
                report_help="Also write report.html for every mission (when its "
                "outputs.formats leaves it out).")
def batch_cmd(
    missions: list[Path] = typer.Argument(..., help="Mission YAML files, or folders of them.",
                                          show_default=False),
    workers: int | None = typer.Option(
        None, help="Local worker processes (default: all cores; 1 runs in this process)."),
    scheduler: str | None = typer.Option(
        None, help="Address of an existing Dask scheduler, e.g. tcp://host:8786 (default: "
        "local processes)."),
    resume: bool = typer.Option(
        False, "--resume", help="Keep the missions OUT/batch.json lists as ok (their mission "
        "file unchanged, their files there) and plan the others: failed, not run, new or "
        "changed ones."),
    output: Output = None,
) -> None:
    """``fm2uav batch``: :func:`~fm2uav.pipeline.batch.prepare_batch`,
    :func:`~fm2uav.pipeline.batch.run_batch`, the table and ``batch.json``."""
    from ..experiments._executors import check_workers
    from ..pipeline.batch import batch_lock

    n_workers = check_workers(workers)
    with batch_lock(output.out):  # one batch at a time writes a folder and its batch.json
        _batch_locked(missions, n_workers, scheduler, resume, output)


def _batch_locked(missions: list[Path], n_workers: int, scheduler: str | None, resume: bool,
                  output: Output) -> None:
    """The batch itself, with its folder held (:func:`batch_cmd`)."""
    from .. import progress
    from ..experiments._executors import make_pool
    from ..io.outdir import Interrupted, stop_reported
    from ..pipeline.batch import prepare_batch, run_batch, write_batch_file

    todo, results = prepare_batch(missions, output.out, force=output.force,
                                  report=output.report, resume=resume)
    for r in results:
        r.error = _for_this_command(r.error)
    pool = make_pool(n_workers, scheduler)
    total = len(results)
    finished = [total - len(todo)]

    def on_result(r: Any) -> None:
        r.error = _for_this_command(r.error)
        finished[0] += 1
        progress.count(finished[0], total, "missions")

    t0 = time.perf_counter()
    interrupted = None
    try:
        with output.progress():
            progress.step("missions", 1.0)
            progress.count(finished[0], total, "missions")
            run_batch(todo, results, pool, force=output.force, on_result=on_result)
    except (KeyboardInterrupt, Interrupted) as exc:
        import signal

        stop_reported()
        signum = getattr(exc, "signum", signal.SIGINT)
        interrupted = ("SIGINT (Ctrl-C)" if signum == signal.SIGINT
                       else signal.Signals(signum).name)
    payload = _results_payload(results, pool, time.perf_counter() - t0, output.out,
                               interrupted=interrupted and f"interrupted by {interrupted}")
    summary = write_batch_file(output.out, payload)
    if interrupted:
        err_console.print(Text.assemble(
            ("interrupted: ", "bold red"),
            f"by {interrupted}; {payload['ok']} of {total} missions were written, "
            f"{payload['not run']} not run (listed in {summary}); the same command with "
            "--resume plans the rest"), highlight=False, soft_wrap=True)
        raise typer.Exit(EXIT_INTERRUPTED)
    if output.as_json and not output.quiet:
        import json
        import sys

        sys.stdout.write(json.dumps(to_jsonable({**payload, "file": str(summary)}),
                                    indent=2) + "\n")
    elif not output.quiet:
        _table(results, f"fm2uav batch: {payload['ok']} of {total} missions ok"
               + (f", {payload['failed']} failed" if payload["failed"] else "")
               + (f" ({payload['worker_deaths']} worker deaths)"
                  if payload["worker_deaths"] else ""))
        console.print(Text(f"summary: {summary}"), highlight=False)
    if payload["failed"]:
        first = next(r for r in results if r.status == "failed")
        err_console.print(Text.assemble(
            ("error: ", "bold red"),
            f"{payload['failed']} of {total} missions failed (first: {first.file}: "
            f"{first.error}); the others are written; reasons in {summary}; fix them and run the "
            "same command with --resume"),
            highlight=False, soft_wrap=True)
        raise typer.Exit(EXIT_MISSIONS_FAILED)


def register(app: typer.Typer, reproduce_app: typer.Typer) -> None:
    """Add the ``batch`` command."""
    app.command("batch", help=BATCH_HELP)(batch_cmd)
