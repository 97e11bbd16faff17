"""``fm2uav reproduce city``: thesis ch. 3 — FM² in the 15-building city, Dubins check, RRT."""

from __future__ import annotations

import csv
from typing import TYPE_CHECKING

import typer

from ._common import Output, handle_errors, write_figure, write_json, write_text
from .options import output_options

if TYPE_CHECKING:
    from ..io.outdir import OutputDir

CITY_FILES = (
    "table.csv", "table.md", "rrt.csv", "summary.json", "low_paths.png", "high_paths.png",
    "speed_profiles.png", "rrt.png",
) + tuple(f"{m}_W{e:g}.csv" for m in ("low", "high") for e in (1, 0.5, 0.25))


REPORT = "report.html"


def _write_city_outputs(outdir: OutputDir, run, *, report: bool) -> None:
    """Path CSVs, table.csv/.md, rrt.csv, the figures (and report.html) of a city run."""
    from ..experiments.city import city_markdown, horizontal_slice
    from ..io import write_path_csv
    from ..viz.feasibility import city_cases_figure, rrt_figure, speed_profiles_figure

    rows = run.rows
    for c in run.cases:
        with outdir.open(f"{c.mission}_W{c.exponent:g}.csv") as fh:
            write_path_csv(fh, c.path3, c.plan.w)
    _write_csv(outdir, "table.csv", rows)
    for mission in ("low", "high"):
        mc = [c for c in run.cases if c.mission == mission]
        fig = city_cases_figure(
            mc, mc[0].world3,
            title=f"city, {mission} altitude — FM² planned vs Dubins flown ({run.airframe.name})")
        write_figure(outdir, fig, f"{mission}_paths.png", 90)
    fig = speed_profiles_figure(run.speed_profiles(),
                                title="velocity profiles along the paths (Fig. 3.4)")
    write_figure(outdir, fig, "speed_profiles.png", 100)
    if run.rrt is not None:
        _write_csv(outdir, "rrt.csv", run.rrt_rows)
        sc = run.missions["low"]
        fig = rrt_figure(horizontal_slice(sc.world, float(sc.start[2])), run.rrt["rrt"],
                         run.rrt["fm2"].plan.path,
                         title="low-altitude mission: FM² vs OMPL (Fig. 3.5)")
        write_figure(outdir, fig, "rrt.png", 90)
    write_text(outdir, "table.md", city_markdown(run))
    if report:
        from ..viz.feasibility import city_report_html

        write_text(outdir, REPORT, city_report_html(run, list(CITY_FILES)))


def _write_csv(outdir: OutputDir, name: str, rows: list[dict]) -> None:
    with outdir.open(name) as fh:
        wr = csv.DictWriter(fh, fieldnames=list(rows[0]))
        wr.writeheader()
        wr.writerows(rows)


CITY_HELP = (
    "Thesis ch. 3: low- and high-altitude missions in the 15-building city with W^1, "
    "W^1/2, W^1/4, each flown by a Dubins airplane → table of safety and separation "
    "distances next to Tables 3.1/3.2, velocity profiles (Fig. 3.4), planned vs flown "
    "paths, and FM² vs OMPL RRT / RRT-Connect / RRT* on the low mission; with --report "
    "an interactive report.html of all paths.\n\n"
    "Examples:\n\n"
    "  fm2uav reproduce city --out out/city\n\n"
    "  fm2uav reproduce city --rrt-time 2 --report --out out/city-report"
)


@handle_errors
@output_options("out/city", report_help="Also write report.html (interactive, self-contained).")
def city_cmd(
    seed: int = typer.Option(0, help="Seed of the city layout (and OMPL)."),
    airframe: str = typer.Option("disco", help="Airframe preset flown."),
    tolerance: float = typer.Option(5.0, help="Largest admissible separation (m)."),
    rrt: bool = typer.Option(True, "--rrt/--no-rrt", help="Run the RRT comparison."),
    rrt_time: float = typer.Option(5.0, help="Time cap of RRT / RRT-Connect (s)."),
    rrtstar_time: float = typer.Option(1.0, help="Planning time of RRT* (s)."),
    output: Output = None,
) -> None:
    """``fm2uav reproduce city``: :func:`~fm2uav.experiments.city.reproduce_city`, write, print."""
    from ..experiments.city import city_summary, reproduce_city
    from ..vehicles import get_airframe

    af = get_airframe(airframe)  # a bad --airframe fails before anything is checked
    outdir = output.dir(CITY_FILES + ((REPORT,) if output.report else ()))
    from .. import progress

    with output.progress():
        progress.step("the experiment", 0.9)
        run = reproduce_city(seed, af, tolerance=tolerance, rrt=rrt, rrt_time=rrt_time,
                             rrtstar_time=rrtstar_time)
        progress.step("writing the tables and figures", 0.1)
        _write_city_outputs(outdir, run, report=output.report)
    summary = city_summary(run)
    write_json(outdir, "summary.json", summary)
    show = {
        f"{r['mission']} W^{r['exponent']:g}": (
            f"safety {r['safety_m']:.1f} m (thesis {r['thesis_safety_m']}), separation "
            f"{r['separation_max_m']:.2f} m (thesis {r['thesis_separation_m']}), "
            f"{'feasible' if r['feasible'] else 'INFEASIBLE'}")
        for r in run.rows
    }
    for r in run.rrt_rows:
        show[r["planner"]] = (f"{r['time_s'] * 1e3:.0f} ms, length {r['length_m']:.0f} m, "
                              f"clearance {r['clearance_m']:.1f} m, "
                              f"{'feasible' if r['feasible'] else 'INFEASIBLE'}")
    output.summary(f"thesis ch. 3 city (seed {seed}, {af.name})", show, summary)


def register(app: typer.Typer, reproduce_app: typer.Typer) -> None:
    """Add ``reproduce city``."""
    reproduce_app.command("city", help=CITY_HELP)(city_cmd)
