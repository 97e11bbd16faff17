"""``fm2uav sweep`` and ``fm2uav reproduce curvature``: the α–β sweep of seed 004."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import typer

from ._common import OutputDir, handle_errors, print_summary, to_jsonable

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
def _progress(quiet: bool):
    if quiet:
        return None, None
    from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeRemainingColumn

    prog = Progress(TextColumn("{task.description}"), BarColumn(), MofNCompleteColumn(),
                    TextColumn("failed {task.fields[failed]}"), TimeRemainingColumn(),
                    transient=False)
    tasks: dict[str, Any] = {}

    def update(stage: str, done: int, total: int, failed: int) -> None:
        if stage not in tasks:
            label = "references" if stage == "references" else "FM² cases"
            tasks[stage] = prog.add_task(label, total=total, failed=0)
        prog.update(tasks[stage], completed=done, total=total, failed=failed)

    return prog, update


def run_and_report(config, out: Path, *, force: bool, scheduler: str | None, workers: int | None,
                   retry_failed: bool, as_json: bool, quiet: bool, title: str) -> None:
    """Run (or resume) a sweep, then write tables and figures into ``out``."""
    from ..experiments.curvature import summarise_run, sweep_payload, tables_markdown
    from ..experiments.runner import run_sweep

    cfg_file = out / "config.json"
    same = cfg_file.exists() and json.loads(cfg_file.read_text()) == json.loads(
        json.dumps(config.identity()))
    # the report files belong to the sweep in `out`: a resume rewrites them
    outdir = OutputDir(out, force=force or same)
    outdir.check(REPORT_FILES)
    prog, update = _progress(quiet or as_json)
    if prog is not None:
        prog.start()
    try:
        result = run_sweep(config, out, workers=workers, scheduler=scheduler,
                           retry_failed=retry_failed, fresh=force and not same, on_progress=update)
    finally:
        if prog is not None:
            prog.stop()
    world, summary = summarise_run(config, result)
    from ..viz.sweep import best_paths_figure, curvature_figure, heatmap_figure

    for metric in ("frechet", "area"):
        figs = {
            f"heatmap_{metric}.png": heatmap_figure(
                summary["matrices"][metric], result.alphas, result.betas, metric=metric,
                best=summary["best"][metric], valleys=summary["valley"][metric]),
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
    payload = sweep_payload(summary, result, config, out)
    with outdir.open("summary.json") as fh:
        json.dump(to_jsonable(payload), fh, indent=2)
    rows: dict[str, Any] = {
        "cases": f"{result.cases_run} run, {result.cases_skipped} resumed, {result.cases_failed} failed",
        "wall [s]": ", ".join(f"{k} {v:.1f}" for k, v in result.wall_s.items()),
    }
    for metric in ("frechet", "area"):
        for m, b in summary["best"][metric].items():
            rows[f"best {metric} {m}"] = (f"α={b['alpha']:.2f} β={b['beta']:.2f} → {b['value']:.4g}"
                                          f" (valley ρ={summary['valley'][metric][m]['spearman']:.2f})")
    t = summary["timing"]
    rows["Table 1 [s]"] = ", ".join(
        [f"{m} {t[f'{m}_s']:.3f} (×{t[f'{m}_ratio']:.0f})" for m in config.models] + [f"FM² {t['fm2_s']:.4f}"])
    print_summary(title, payload if as_json else rows, as_json=as_json, quiet=quiet,
                  files=outdir.written + [out / config.results])


def register(app: typer.Typer, reproduce_app: typer.Typer) -> None:
    """Add ``sweep`` and ``reproduce curvature``."""

    @app.command(
        "sweep",
        help=(
            "Run (or resume) an α–β sweep of FM² against the Dubins, elastica and Reeds–Shepp "
            "references from a YAML config; results stream to --out as cases finish, then "
            "Tables 1-4 (tables.md), heat maps and curvature profiles are written.\n\n"
            "Examples:\n\n"
            "  fm2uav sweep sweep.yaml --out out/sweep\n\n"
            "  fm2uav sweep sweep.yaml --scheduler tcp://10.0.0.5:8786 --out out/sweep\n\n"
            "Config keys (all optional): scenario: city2d, cell: 2.0, pairs: 24, pair_seed: 0, "
            "alpha: {start: 0.02, stop: 1.0, step: 0.02}, beta: {...}, models: [dubins, elastica, "
            "rs], xi: 10.0, max_int: 4, ds: 1.0, order: 2, results: results.parquet (or .csv)."
        ),
    )
    @handle_errors
    def sweep_cmd(
        config: Path = typer.Argument(..., help="YAML sweep configuration."),
        scheduler: str | None = typer.Option(
            None, help="Address of an existing Dask scheduler, e.g. tcp://host:8786 "
            "(default: local processes)."),
        workers: int | None = typer.Option(None, help="Local worker processes (default: all cores)."),
        retry_failed: bool = typer.Option(False, "--retry-failed", help="Run failed cases again."),
        out: Path = typer.Option(Path("out/sweep"), help="Output directory (resumed if it holds "
                                 "the same sweep)."),
        force: bool = typer.Option(False, "--force", help="Discard a different sweep in --out."),
        as_json: bool = typer.Option(False, "--json", help="Print the summary as JSON."),
        quiet: bool = typer.Option(False, "--quiet", help="Print nothing but errors."),
    ) -> None:
        from ..experiments.runner import load_config

        cfg = load_config(config)
        run_and_report(cfg, out, force=force, scheduler=scheduler, workers=workers,
                       retry_failed=retry_failed, as_json=as_json, quiet=quiet,
                       title="α–β sweep")

    @reproduce_app.command(
        "curvature",
        help=(
            "Seed 004 (Sensors 2022): FM² α–β sweep against Dubins, Euler–Mumford elastica and "
            "Reeds–Shepp forward references on the 2D city map, 24 pairs → Tables 1-4, heat maps "
            "(Figs 8/12), best matches (Figs 9/13), curvature profiles (Figs 10/14).\n\n"
            "The default is the seed's full grid α, β = 0.02:0.02:1 (2500 × 24 = 60000 FM² runs; "
            "~5 min on 2 cores, about half of it for the 72 reference paths); --step 0.04 gives a "
            "coarser 25 × 25 grid.\n\n"
            "Examples:\n\n"
            "  fm2uav reproduce curvature --out out/curvature\n\n"
            "  fm2uav reproduce curvature --step 0.1 --pairs 8 --out out/curvature-quick"
        ),
    )
    @handle_errors
    def curvature_cmd(
        full: bool = typer.Option(False, "--full", help="Force the seed's grid 0.02:0.02:1 "
                                  "(the default; overrides --step)."),
        step: float = typer.Option(0.02, help="Grid step of α and β: the grid is step:step:1."),
        pairs: int = typer.Option(24, help="Number of start/goal pairs."),
        xi: float = typer.Option(10.0, help="ξ of the references, in metres."),
        scheduler: str | None = typer.Option(None, help="Dask scheduler address (tcp://...)."),
        workers: int | None = typer.Option(None, help="Local worker processes (default: all cores)."),
        out: Path = typer.Option(Path("out/curvature"), help="Output directory."),
        force: bool = typer.Option(False, "--force", help="Discard a different sweep in --out."),
        as_json: bool = typer.Option(False, "--json", help="Print the summary as JSON."),
        quiet: bool = typer.Option(False, "--quiet", help="Print nothing but errors."),
    ) -> None:
        from ..experiments.curvature import curvature_config

        cfg = curvature_config(step=None if full else step, pairs=pairs, xi=xi)
        run_and_report(cfg, out, force=force, scheduler=scheduler, workers=workers,
                       retry_failed=False, as_json=as_json, quiet=quiet,
                       title="Seed 004: FM² vs curvature-penalised references")
