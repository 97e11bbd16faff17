"""``fm2uav reproduce tracking``: seed 004 §3.5 (Fig. 16) — a fixed-wing and a quadcopter
fly the FM² paths that best match the Dubins reference."""

from __future__ import annotations

from pathlib import Path

import typer

from ._common import Output, handle_errors, write_json, write_text
from .options import output_options

TRACKING_FILES = ("table.md", "summary.json")

TRACKING_HELP = (
    "Seed 004 §3.5 (Fig. 16): sweep α, β against the Dubins reference on the 24 "
    "city2d pairs, take the best area match, fly every pair's FM² path with the "
    "pure-pursuit fixed-wing (disco) and the quadcopter model (arducopter), look-ahead "
    "40 m (the seed's) and default → table.md (tracking error per vehicle, peak "
    "curvature per path vs the 1/ξ bound) and summary.json. The sweep is kept in "
    "--sweep-dir and resumed on a rerun.\n\n"
    "Example:\n\n"
    "  fm2uav reproduce tracking --out out/tracking"
)


def _tracking_rows(s: dict) -> dict[str, str]:
    """The printed rows of :func:`~fm2uav.experiments.tracking.tracking_summary` ``s``."""
    show = {"best match (area)": f"α = {s['alpha']:g}, β = {s['beta']:g}",
            "peak curvature": (f"{s['above_bound']} of {s['paths']} paths above "
                               f"{s['bound_per_m']:g} 1/m (median {s['peak_kappa_median']:.3f})")}
    for name, g in s["vehicles"].items():
        show[name] = (f"max error median {g['max_error_median_m']:.2f} m, worst "
                      f"{g['max_error_max_m']:.2f} m, reached {g['reached']}/{g['paths']}")
    return show


@handle_errors
@output_options("out/tracking", report_help="Also write report.html (interactive, "
                "self-contained: the FM² paths flown and the Dubins references on the map, "
                "the tracking table).")
def tracking_cmd(
    step: float = typer.Option(0.1, help="Grid step of α and β (the seed's: 0.02)."),
    pairs: int = typer.Option(24, help="Number of start/goal pairs."),
    xi: float = typer.Option(10.0, help="ξ of the Dubins model [m] (bound 1/ξ)."),
    workers: int = typer.Option(1, help="Worker processes of the sweep."),
    sweep_dir: Path = typer.Option(
        None, help="Folder of the Dubins sweep (default: <out>-sweep; resumed)."),
    output: Output = None,
) -> None:
    """``fm2uav reproduce tracking``: :func:`~fm2uav.experiments.tracking.reproduce_tracking`,
    write, print."""
    from ..experiments.tracking import reproduce_tracking, tracking_markdown, tracking_summary

    outdir = output.dir(TRACKING_FILES + (("report.html",) if output.report else ()))
    out = output.out
    sweep = sweep_dir if sweep_dir is not None else out.with_name(out.name + "-sweep")
    from .. import progress

    with output.progress():
        progress.step("the experiment", 0.95)
        run = reproduce_tracking(sweep, step=step, pairs=pairs, xi=xi, workers=workers)
        progress.step("writing the tables", 0.05)
        write_text(outdir, "table.md", "# Seed 004 §3.5 — tracking the best Dubins-like FM² "
                   "paths\n\n" + tracking_markdown(run) + "\n")
        if output.report and run.tracks:
            from ..experiments.runner import sweep_world
            from ..experiments.curvature import curvature_config
            from ..viz.report import join_polylines, report_html

            world = sweep_world(curvature_config(step, pairs=pairs, xi=xi))[0]
            write_text(outdir, "report.html", report_html(
                world, {f"FM² pair {k + 1}": fm2 for k, (fm2, _ref) in enumerate(run.tracks)},
                overlays={"Dubins references": {"points": join_polylines(
                    [ref for _fm2, ref in run.tracks]), "color": "#d62728", "dash": "dash"}},
                title="Seed 004 §3.5: tracking the best Dubins-like FM² paths",
                subtitle=f"α = {run.alpha:g}, β = {run.beta:g} (best area match), ξ = "
                         f"{run.xi:g} m", params={"grid step": step, "pairs": pairs, "xi [m]": xi},
                tables={"Tracking error per pair, vehicle and look-ahead": run.rows},
                files=list(TRACKING_FILES)))
    s = tracking_summary(run)
    summary = {**s, "rows": run.rows, "paths_curvature": run.paths, "sweep_dir": str(sweep)}
    write_json(outdir, "summary.json", summary)
    output.summary("seed 004 tracking experiment", _tracking_rows(s), summary)


def register(app: typer.Typer, reproduce_app: typer.Typer) -> None:
    """Add ``reproduce tracking``."""
    reproduce_app.command("tracking", help=TRACKING_HELP)(tracking_cmd)
