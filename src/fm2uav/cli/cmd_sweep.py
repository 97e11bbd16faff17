"""``fm2uav sweep`` and ``fm2uav reproduce curvature``: the α–β sweep of seed 004."""

from __future__ import annotations

import json
import math
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
_NAMES = {"dubins": "Dubins", "elastica": "Euler–Mumford elastica", "rs": "Reeds–Shepp forward"}


def _fmt(v: Any, digits: int = 3) -> str:
    if v is None or (isinstance(v, float) and not math.isfinite(v)):
        return "–"
    return f"{v:.{digits}g}" if isinstance(v, float) else str(v)


def tables_markdown(summary: dict[str, Any], result: Any) -> str:
    """Tables 1–4 of the seed as Markdown."""
    cfg = result.config
    models = [m for m in cfg.models]
    a, b = result.alphas, result.betas
    lines = [
        "# FM² vs curvature-penalised references (seed 004)",
        "",
        f"Map: {cfg.scenario} ({cfg.cell} m nodes), {len(result.starts)} start/goal pairs "
        f"(seed {cfg.pair_seed}), ξ = {cfg.xi} m, lattice headings max_int={cfg.max_int}. "
        f"Grid: α = {a[0]:g}:{cfg.alpha.step:g}:{a[-1]:g} ({len(a)}), "
        f"β = {b[0]:g}:{cfg.beta.step:g}:{b[-1]:g} ({len(b)}) → {len(a) * len(b)} (α, β) × "
        f"{len(result.starts)} pairs = {len(a) * len(b) * len(result.starts)} FM² runs. "
        f"Distances are means over the pairs, curves resampled every {cfg.ds} m.",
        "",
        "## Table 1 — computation time of all pairs [s]",
        "",
        "| " + " | ".join(_NAMES[m] for m in models) + " | FM² |",
        "|" + "---|" * (len(models) + 1),
        "| " + " | ".join(_fmt(summary["timing"].get(f"{m}_s"), 4) for m in models)
        + f" | {_fmt(summary['timing']['fm2_s'], 4)} |",
        "| " + " | ".join(f"×{_fmt(summary['timing'].get(f'{m}_ratio'), 4)}" for m in models) + " | 1 |",
        "",
        "References: lattice search time (compiled Dijkstra, control set cached); FM²: sum over "
        "pairs of the median `plan()` time over the grid (both Fast Marching waves, descent, "
        "metrics). Both are measured inside the sweep's worker processes, running side by "
        "side on a shared machine, so the ratios are indicative; `benchmarks/bench_reference.py` "
        "times both in one process, one after the other.",
        "",
    ]
    for metric, title, num in (("frechet", "Fréchet distance [m]", 2), ("area", "area between curves [m²]", 3)):
        best = summary["best"].get(metric, {})
        val = summary["valley"].get(metric, {})
        lines += [
            f"## Table {num} — best α, β and {title}",
            "",
            "| | " + " | ".join(_NAMES[m] for m in models) + " |",
            "|---|" + "---|" * len(models),
            "| α | " + " | ".join(_fmt(best.get(m, {}).get("alpha")) for m in models) + " |",
            "| β | " + " | ".join(_fmt(best.get(m, {}).get("beta")) for m in models) + " |",
            f"| {metric} | " + " | ".join(_fmt(best.get(m, {}).get("value"), 4) for m in models) + " |",
            "| valley: Spearman(α, best β) | "
            + " | ".join(_fmt(val.get(m, {}).get("spearman"), 2) for m in models) + " |",
            "",
        ]
    clear = summary["clearance"]
    lines += [
        "## Table 4 — distance to the obstacles [m] (mean over pairs of each path's minimum; "
        "best area match)",
        "",
        "| | " + " | ".join(_NAMES[m] for m in models) + " |",
        "|---|" + "---|" * len(models),
        "| α | " + " | ".join(_fmt(clear.get(m, {}).get("alpha")) for m in models) + " |",
        "| β | " + " | ".join(_fmt(clear.get(m, {}).get("beta")) for m in models) + " |",
        "| reference | " + " | ".join(_fmt(clear.get(m, {}).get("reference_m"), 3) for m in models) + " |",
        "| FM² approximation | " + " | ".join(_fmt(clear.get(m, {}).get("fm2_m"), 3) for m in models) + " |",
        "",
        f"Cases: {result.cases_run} run now, {result.cases_skipped} resumed, "
        f"{result.cases_failed} failed.",
        "",
    ]
    return "\n".join(lines)


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
    from ..experiments.runner import run_sweep, sweep_world
    from ..experiments.sweep import summarise_sweep

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
    world, starts, goals = sweep_world(config)
    summary = summarise_sweep(world, starts, goals, result.columns, result.alphas, result.betas,
                              config.models, result.references, ds=config.ds, order=config.order)
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
    payload = {
        "best": summary["best"],
        "valley_spearman": {m: {k: v["spearman"] for k, v in d.items()}
                            for m, d in summary["valley"].items()},
        "timing_s": summary["timing"],
        "clearance_m": summary["clearance"],
        "grid": {"alpha": [float(result.alphas[0]), config.alpha.step, float(result.alphas[-1])],
                 "beta": [float(result.betas[0]), config.beta.step, float(result.betas[-1])]},
        "pairs": len(result.starts),
        "cases": {"run": result.cases_run, "resumed": result.cases_skipped,
                  "failed": result.cases_failed},
        "wall_s": result.wall_s,
        "results_file": str(out / config.results),
    }
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
        from ..experiments.runner import make_config

        s = 0.02 if full else float(step)
        grid = {"start": s, "stop": 1.0, "step": s}
        cfg = make_config({"pairs": pairs, "alpha": grid, "beta": grid, "xi": xi},
                          where="reproduce curvature")
        run_and_report(cfg, out, force=force, scheduler=scheduler, workers=workers,
                       retry_failed=False, as_json=as_json, quiet=quiet,
                       title="Seed 004: FM² vs curvature-penalised references")
