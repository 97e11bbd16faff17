"""``fm2uav reproduce urban``: thesis §4.4 — flight levels among the city's buildings."""

from __future__ import annotations

import typer

from ._common import Output, handle_errors, write_json, write_text
from .options import output_options

URBAN_FILES = ("table.md", "summary.json") + tuple(f"case{i + 1}.csv" for i in range(6))

URBAN_HELP = (
    "Thesis §4.4: flight levels in the 15-building city — levels 23/30/37 with "
    "p1 = 0.2, p2 = 0.8 and level 30 with (p1, p2) = (0.47, 0.53), (0.45, 0.55), "
    "(0.5, 1.5), from (60, 10, 40) to (20, 75, 20) cells → table.md (share on the "
    "level, climbs, x-y route changes, clearance, warm planning time), summary.json "
    "and one path CSV per case.\n\n"
    "Example:\n\n"
    "  fm2uav reproduce urban --out out/urban"
)


@handle_errors
@output_options("out/urban", report_help="Also write report.html (interactive, self-contained: "
                "the six paths among the buildings and the table).")
def urban_cmd(
    seed: int = typer.Option(
        None, help="City seed (default: the first whose buildings keep 20 m from the "
        "thesis' start and goal)."),
    output: Output = None,
) -> None:
    """``fm2uav reproduce urban``: :func:`~fm2uav.experiments.urban.reproduce_urban`, write,
    print."""
    from ..experiments.urban import reproduce_urban, urban_markdown
    from ..io import write_path_csv

    outdir = output.dir(URBAN_FILES + (("report.html",) if output.report else ()))
    from .. import progress

    with output.progress():
        progress.step("the six cases", 0.95)
        run = reproduce_urban(seed)
        progress.step("writing the table and paths", 0.05)
        for i, p in enumerate(run.plans):
            with outdir.open(f"case{i + 1}.csv") as fh:
                write_path_csv(fh, p.path, p.w)
        write_text(outdir, "table.md", "# Thesis §4.4 — flight levels in the city\n\n"
                   + urban_markdown(run) + "\n")
        if output.report:
            from ..viz.report import report_html

            names = [f"case {i + 1}: level {r['level']} (p1={r['p1']:g}, p2={r['p2']:g})"
                     for i, r in enumerate(run.rows)]
            write_text(outdir, "report.html", report_html(
                run.world, {n: p.path for n, p in zip(names, run.plans)},
                speeds={n: p.w for n, p in zip(names, run.plans)},
                title="Thesis §4.4: flight levels in the city",
                subtitle=f"city seed {run.seed}, start {run.start.tolist()} m, goal "
                         f"{run.goal.tolist()} m", params={"city seed": run.seed},
                tables={"Flight levels (thesis §4.4)": run.rows}, files=list(URBAN_FILES)))
    summary = {"seed": run.seed, "start_m": run.start, "goal_m": run.goal, "cases": run.rows}
    write_json(outdir, "summary.json", summary)
    show = {f"level {r['level']} (p1={r['p1']:g}, p2={r['p2']:g})":
            f"on level {r['within_all']:.0%}, max climb {r['climb_max_deg']:.0f}°, "
            f"clearance {r['clearance_m']:.1f} m" for r in run.rows}
    output.summary(f"thesis §4.4 urban flight levels (city seed {run.seed})", show, summary)


def register(app: typer.Typer, reproduce_app: typer.Typer) -> None:
    """Add ``reproduce urban``."""
    reproduce_app.command("urban", help=URBAN_HELP)(urban_cmd)
