"""``fm2uav sweep`` and ``fm2uav reproduce curvature``: the α–β sweep of seed 004."""

from __future__ import annotations

import json
from pathlib import Path
from typing import TYPE_CHECKING, Any

import typer
from rich.markup import escape
from rich.text import Text

from ._common import (
    EXIT_INTERRUPTED,
    Output,
    err_console,
    handle_errors,
    print_summary,
    to_jsonable,
)
from .options import output_options

if TYPE_CHECKING:
    from ..io.outdir import OutputDir

#: Exit code of a sweep that finished but has failed cases (0 ok, 1 planning, 2 bad input,
#: 130 interrupted, 70 internal error).
EXIT_CASES_FAILED = 3

EXIT_CODES_HELP = (
    "Exit codes: 0 every case ok; 2 bad input, a damaged sweep file or --out in use by another "
    "run (the message names the file and the fix); 3 the sweep finished but some cases failed "
    "(report written; reason in the error column of the results file; the same command "
    "retries them); 130 stopped by SIGINT or SIGTERM (workers stopped, finished cases kept; "
    "the same command resumes); 70 an internal error."
)

REPORT = "report.html"
REPORT_FILES = (
    "tables.md",
    "summary.json",
    "heatmap_frechet.png",
    "heatmap_area.png",
    "best_paths_frechet.png",
    "best_paths_area.png",
    "curvature_frechet.png",
    "curvature_area.png",
)
def _warning(message: str) -> None:
    err_console.print(f"[bold yellow]warning:[/] {escape(message)}", highlight=False, soft_wrap=True)


def run_and_report(config, out: Path, *, force: bool, scheduler: str | None, workers: int | None,
                   retry_failed: bool, as_json: bool, quiet: bool, title: str,
                   report: bool = False) -> None:
    """Run (or resume) a sweep holding its folder, then write tables and figures into ``out``.

    The report files are one output set (:class:`~fm2uav.io.outdir.OutputDir`): staged
    beside ``out`` and moved in at the end. The sweep's own files (log, references,
    config, results) are written into ``out`` by :func:`~fm2uav.experiments.runner.run_sweep`
    as it goes, so the set is merged into the folder, never swapped for it (``OutputDir``
    merges when the folder changed while it was staged, and ``run_sweep`` rewrites
    ``config.json`` on every run). Exits with :data:`EXIT_CASES_FAILED` (report written)
    when a case failed and with :data:`EXIT_INTERRUPTED` on SIGINT/SIGTERM (the finished
    cases are kept, the report is not written).
    """
    from ..errors import InputError
    from ..experiments.runner import (
        SweepInterrupted,
        check_workers,
        raise_on_signals,
        same_sweep,
        sweep_lock,
    )
    from ..io.outdir import OutputDir

    workers = check_workers(workers)  # before anything is written into `out`
    try:
        same = same_sweep(config, out)
    except InputError:  # a damaged config.json: --force starts over
        if not force:
            raise
        same = False
    # the report files belong to the sweep in `out`: a resume rewrites them
    outdir = OutputDir(out, force=force or same)
    outdir.check(REPORT_FILES + ((REPORT,) if report else ()))  # before the sweep writes
    try:
        with sweep_lock(out), raise_on_signals():
            result = _run_and_report(config, out, outdir, fresh=force and not same,
                                     scheduler=scheduler, workers=workers,
                                     retry_failed=retry_failed, as_json=as_json, quiet=quiet,
                                     title=title, report=report)
    except SweepInterrupted as exc:
        message = exc.message
        if "resume" not in message:  # stopped while the report was being written
            message += (f" while writing the report; every case is kept in {out}; run the same "
                        "command again to write it")
        _fail(message, EXIT_INTERRUPTED, prefix="interrupted: ")
    if result.cases_failed:
        outdir.finish()  # the report of the cases that did not fail is written all the same
        first = next(str(e) for e, st in zip(result.columns["error"], result.columns["status"])
                     if st != "ok")
        _fail(f"{result.cases_failed} of {len(result.columns['status'])} cases failed (first: "
              f"{first}); the reasons are in {result.summary} (column error); run the same "
              "command again to retry them", EXIT_CASES_FAILED)


def _fail(message: str, code: int, prefix: str = "error: ") -> None:
    err_console.print(Text.assemble((prefix, "bold red"), str(message)), highlight=False,
                      soft_wrap=True)
    raise typer.Exit(code)


def _run_and_report(config, out: Path, outdir: OutputDir, *, fresh: bool, scheduler: str | None,
                    workers: int | None, retry_failed: bool, as_json: bool, quiet: bool,
                    title: str, report: bool = False) -> Any:
    from .. import progress
    from ..experiments.runner import run_sweep
    from ._common import progress as progress_display

    with progress_display(not (quiet or as_json)):
        progress.step("the sweep", 0.9)
        result = run_sweep(config, out, workers=workers, scheduler=scheduler,
                           retry_failed=retry_failed, fresh=fresh, on_warning=_warning)
        progress.step("writing the tables and figures", 0.1)
        payload, rows = _write_report(config, out, outdir, result, report=report, title=title)
    print_summary(title, payload if as_json else rows, as_json=as_json, quiet=quiet,
                  files=outdir.written + [out / config.results, result.log])
    return result


def _write_report(config, out: Path, outdir: OutputDir, result: Any, *,
                  report: bool = False, title: str = "") -> tuple[dict, dict]:
    """The sweep's tables, figures, summary.json (and report.html with ``report``); returns the JSON payload and the
    printed rows."""
    from ..experiments.curvature import summarise_run, sweep_payload, tables_markdown

    world, summary = summarise_run(config, result)
    from ..viz.sweep import best_paths_figure, curvature_figure, heatmap_figure

    for metric in ("frechet", "area"):
        figs = {
            f"heatmap_{metric}.png": heatmap_figure(
                summary["matrices"][metric], result.alphas, result.betas, metric=metric,
                best=summary["best"][metric], valleys=summary["valley"][metric],
                near=summary.get("near_best", {}).get(metric)),
            f"best_paths_{metric}.png": best_paths_figure(
                world, summary["paths"][metric], summary["best"][metric], metric=metric),
            f"curvature_{metric}.png": curvature_figure(summary["curvature"][metric], metric=metric),
        }
        for name, fig in figs.items():
            tmp = outdir.target(name)
            fig.savefig(tmp, dpi=110, format="png")
            outdir.commit(tmp, name)
    with outdir.open("tables.md") as fh:
        fh.write(tables_markdown(summary, result))
    if report:
        from ..viz.sweep import sweep_report_html

        n_pairs = config.pairs if isinstance(config.pairs, int) else len(config.pairs)
        with outdir.open(REPORT) as fh:
            fh.write(sweep_report_html(
                world, summary, title=title,
                subtitle=f"{len(result.alphas)} x {len(result.betas)} (α, β), {n_pairs} pairs, "
                         f"ξ = {config.xi:g} m",
                params={k: v for k, v in config.identity().items()
                        if k not in ("alpha", "beta", "pairs")},
                files=list(REPORT_FILES) + [config.results]))
    payload = sweep_payload(summary, result, config, out)
    payload["faults"] = {"cases_retried": result.cases_retried,
                         "worker_deaths": result.worker_deaths, "log_warnings": result.warnings}
    payload["log_file"] = str(result.log)
    with outdir.open("summary.json") as fh:
        json.dump(to_jsonable(payload), fh, indent=2)
    rows: dict[str, Any] = {
        "cases": f"{result.cases_run} run, {result.cases_skipped} resumed, {result.cases_failed} failed",
        "faults": (f"{result.worker_deaths} worker processes died, {result.cases_retried} cases "
                   "run again" if result.worker_deaths else "none"),
        "wall [s]": ", ".join(f"{k} {v:.1f}" for k, v in result.wall_s.items()),
    }
    for metric in ("frechet", "area"):
        for m, b in summary["best"][metric].items():
            rows[f"best {metric} {m}"] = (f"α={b['alpha']:.2f} β={b['beta']:.2f} → {b['value']:.4g}"
                                          f" (valley ρ={summary['valley'][metric][m]['spearman']:.2f})")
            n = b.get("near_best")
            if n:
                rows[f"within 1 % of best {metric} {m}"] = (
                    f"{n['count']} (α {n['alpha_min']:g}–{n['alpha_max']:g}, "
                    f"β {n['beta_min']:g}–{n['beta_max']:g})")
    t = summary["timing"]
    rows["Table 1 [s]"] = ", ".join(
        [f"{m} {t[f'{m}_s']:.3f} (×{t[f'{m}_ratio']:.0f})" for m in config.models] + [f"FM² {t['fm2_s']:.4f}"])
    return payload, rows


SWEEP_HELP = (
    "Run (or resume) an α–β sweep of FM² against the Dubins, elastica and Reeds–Shepp "
    "references from a YAML config; every case is appended to --out/cases.jsonl as it "
    "finishes (checksummed lines), then the results file, Tables 1-4 (tables.md), heat "
    "maps and curvature profiles are written.\n\n"
    "Re-running the same command resumes: finished cases are kept, missing and failed "
    "ones are run (--keep-failed keeps failed ones). A worker process that dies costs "
    "only its case: it is run once more, then recorded as failed with the reason. "
    "SIGINT/SIGTERM stop the workers and keep every finished case. A second sweep into "
    "the same --out is refused while one runs.\n\n"
    "Examples:\n\n"
    "  fm2uav sweep sweep.yaml --out out/sweep\n\n"
    "  fm2uav sweep sweep.yaml --scheduler tcp://10.0.0.5:8786 --out out/sweep\n\n"
    "Config keys (all optional): scenario: city2d, cell: 2.0, pairs: 24, pair_seed: 0, "
    "alpha: {start: 0.02, stop: 1.0, step: 0.02}, beta: {...}, models: \\[dubins, elastica, "
    "rs], xi: 10.0, max_int: 4, ds: 1.0, order: 2, results: results.parquet (or .csv)."
    "\n\n" + EXIT_CODES_HELP
)

CURVATURE_HELP = (
    "Seed 004 (Sensors 2022): FM² α–β sweep against Dubins, Euler–Mumford elastica and "
    "Reeds–Shepp forward references on the 2D city map, 24 pairs → Tables 1-4, heat maps "
    "(Figs 8/12), best matches (Figs 9/13), curvature profiles (Figs 10/14).\n\n"
    "The default is the seed's full grid α, β = 0.02:0.02:1 (2500 × 24 = 60000 FM² runs; "
    "~5 min on 2 cores, about half of it for the 72 reference paths); --step 0.04 gives a "
    "coarser 25 × 25 grid.\n\n"
    "Examples:\n\n"
    "  fm2uav reproduce curvature --out out/curvature\n\n"
    "  fm2uav reproduce curvature --step 0.1 --pairs 8 --out out/curvature-quick\n\n"
    "Resumes like fm2uav sweep (failed cases are run again). " + EXIT_CODES_HELP
)

_FORCE_HELP = "Discard a different sweep in --out."


_REPORT_HELP = ("Also write report.html (interactive, self-contained: the best FM² paths and "
                "the references on the map, the best-parameter and timing tables).")


@handle_errors
@output_options("out/sweep", out_help="Output directory (resumed if it holds the same sweep).",
                force_help=_FORCE_HELP, report_help=_REPORT_HELP)
def sweep_cmd(
    config: Path = typer.Argument(..., help="YAML sweep configuration."),
    scheduler: str | None = typer.Option(
        None, help="Address of an existing Dask scheduler, e.g. tcp://host:8786 "
        "(default: local processes)."),
    workers: int | None = typer.Option(None, help="Local worker processes (default: all "
                                       "cores; 1 runs in this process)."),
    retry_failed: bool = typer.Option(
        True, "--retry-failed/--keep-failed",
        help="On a resume, run the cases (and references) that failed before again "
        "(default), or keep them as failed."),
    output: Output = None,
) -> None:
    """``fm2uav sweep``: :func:`~fm2uav.experiments.runner.load_config`, :func:`run_and_report`."""
    from ..experiments.runner import load_config

    run_and_report(load_config(config), output.out, force=output.force, scheduler=scheduler,
                   workers=workers, retry_failed=retry_failed, as_json=output.as_json,
                   quiet=output.quiet, title="α–β sweep", report=output.report)


@handle_errors
@output_options("out/curvature", force_help=_FORCE_HELP, report_help=_REPORT_HELP)
def curvature_cmd(
    full: bool = typer.Option(False, "--full", help="Force the seed's grid 0.02:0.02:1 "
                              "(the default; overrides --step)."),
    step: float = typer.Option(0.02, help="Grid step of α and β: the grid is step:step:1."),
    pairs: int = typer.Option(24, help="Number of start/goal pairs."),
    xi: float = typer.Option(10.0, help="ξ of the references, in metres."),
    scheduler: str | None = typer.Option(None, help="Dask scheduler address (tcp://...)."),
    workers: int | None = typer.Option(None, help="Local worker processes (default: all cores)."),
    output: Output = None,
) -> None:
    """``fm2uav reproduce curvature``: the seed's sweep config, :func:`run_and_report`."""
    from ..experiments.curvature import curvature_config

    cfg = curvature_config(step=None if full else step, pairs=pairs, xi=xi)
    run_and_report(cfg, output.out, force=output.force, scheduler=scheduler, workers=workers,
                   retry_failed=True, as_json=output.as_json, quiet=output.quiet,
                   title="Seed 004: FM² vs curvature-penalised references",
                   report=output.report)


def register(app: typer.Typer, reproduce_app: typer.Typer) -> None:
    """Add ``sweep`` and ``reproduce curvature``."""
    app.command("sweep", help=SWEEP_HELP)(sweep_cmd)
    reproduce_app.command("curvature", help=CURVATURE_HELP)(curvature_cmd)
