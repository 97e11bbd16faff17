"""``fm2uav reproduce tff`` (the seeds' terrain-following experiments) and
``fm2uav tune`` (p1/p2/α/β search against airframe limits)."""

from __future__ import annotations

import time
from typing import TYPE_CHECKING

import typer

from ..errors import InputError
from ._common import Output, handle_errors, write_figure, write_json, write_text
from .options import (
    LonLatOpt,
    ScenarioOpt,
    WorldFlags,
    cli_point,
    output_options,
    world_options,
    world_rows,
)

if TYPE_CHECKING:
    from ..io.outdir import OutputDir

TFF_FILES = (
    "tff_table.md",
    "tff_summary.json",
    "tff_3d_levels.png",
    "tff_3d_smoothness.png",
    "tff_profile_levels.png",
    "tff_profile_smoothness.png",
    "tff_kinematics.png",
)
TUNE_FILES = ("tune_table.md", "tune.json", "tune_best_path.csv", "tune_best.png")
REPORT = "report.html"


def _write_tff_outputs(outdir: OutputDir, run, *, report: bool) -> None:
    """The figures, tff_table.md, tff_summary.json (and report.html) of a TFF run."""
    import numpy as np

    from ..experiments.tff import tff_markdown
    from ..viz.tff import tff_figures, tff_report_html

    tmps = {}
    for name, fig in tff_figures(run).items():
        tmp = outdir.target(name)
        fig.savefig(tmp, dpi=100)
        tmps[name] = tmp
    for name, tmp in tmps.items():
        outdir.commit(tmp, name)
    write_text(outdir, "tff_table.md", tff_markdown(run))
    write_json(outdir, "tff_summary.json", {"scenario": run.scenario_name, "seed": run.seed,
                                            "mode": run.mode, "cases": run.rows})
    if report:
        sc = run.scenario
        html = tff_report_html(run.plans, run.rows, run.labels, sc,
                               title=f"Terrain-following flight — {run.scenario_name}",
                               params={"scenario": run.scenario_name, "seed": run.seed,
                                       "flight-level mode": run.mode,
                                       "start [m]": np.round(sc.start, 1),
                                       "goal [m]": np.round(sc.goal, 1),
                                       "vertical cell [m]": sc.world.spacing[2]},
                               files=list(TFF_FILES))
        write_text(outdir, REPORT, html)


def _write_tune_report(outdir: OutputDir, res, sc, s, g, *, agl: float, scenario: str,
                       limits, grid: dict[str, list[float]]) -> None:
    """report.html of the tuned path (or, when none keeps the limits, the closest one)."""
    from ..analysis.flight_level import tff_metrics

    if res.best_plan is not None:
        row, p = res.best, res.best_plan
        label = f"best: p1={row['p1']:g}, p2={row['p2']:g}, α={row['saturation']:g}"
    else:  # nothing keeps the limits: show the Pareto candidate closest to the level
        from ..planning import FlightLevel, Shaping, plan

        row = res.pareto[0]
        p = plan(sc.world, s, g, shaping=Shaping(saturation=row["saturation"],
                                                 exponent=row["exponent"]),
                 level=FlightLevel(agl=agl, p1=row["p1"], p2=row["p2"], heights="fm2"))
        label = (f"closest (breaks the limits): p1={row['p1']:g}, p2={row['p2']:g}, "
                 f"α={row['saturation']:g}")
    m = tff_metrics(p, agl)
    from ..analysis.flight_level import flight_level_deviation

    # the report's table has the reproduce-tff columns, incl. the flown path's share on the
    # level (missing: `tune --report` ended in KeyError 'flown_within_all', exit 70)
    m.update(case=label, level=round(agl / sc.world.spacing[2], 2), agl_m=agl,
             p1=row["p1"], p2=row["p2"], diff=row["p2"] - row["p1"],
             transitions=f"{m['start_transition_m']:.0f}/{m['end_transition_m']:.0f}",
             flown_within_all=flight_level_deviation(sc.world, p.path, agl).within_all,
             plan_s=float(p.timings.get("total", float("nan"))))
    keys = ("p1", "p2", "saturation", "exponent", "deviation_m", "within", "climb_max_deg",
            "min_turn_radius_m", "length_m", "feasible")
    pareto = [{k: (round(r[k], 3) if isinstance(r[k], float) else r[k]) for k in keys}
              for r in res.pareto]
    from ..viz.report import path_figures
    from ..viz.tff import tff_report_html

    keeps = res.best_plan is not None
    figures = {
        "tuned parameters" if keeps else "closest parameters": (f"p1 {row['p1']:g}, p2 {row['p2']:g}, saturation α "
                             f"{row['saturation']:g}, exponent β {row['exponent']:g}"),
        "airframe limits": (
            f"{'kept' if keeps else 'NOT kept by any candidate: the closest is shown'} "
            f"(max climb {limits.max_climb_deg:g}°: path {row['climb_max_deg']:.1f}°; "
            f"min turn radius {limits.min_turn_radius:g} m: path "
            f"{row['min_turn_radius_m']:.0f} m)"),
        "on the flight level (±1 cell)": f"{m['within']:.0%} of the path",
        **path_figures(sc.world, {label: p.path}),
    }
    html = tff_report_html(
        [p], [m], [label], sc, title=f"Auto-tuning — {scenario}, {agl:g} m above ground",
        params={"scenario": scenario, "agl [m]": agl,
                "max climb [deg]": round(limits.max_climb_deg, 9),
                "min turn radius [m]": limits.min_turn_radius,
                **{f"grid {k}": v for k, v in grid.items()}},
        files=list(TUNE_FILES), table_title="The tuned path",
        extra_tables={"Pareto front (deviation ↓, max climb ↓, min turn radius ↑)": pareto},
        figures=figures)
    write_text(outdir, REPORT, html)


TFF_HELP = (
    "Reproduce the terrain-following experiments (TFF paper §5 / thesis §4.3): flight "
    "levels 2, 5, 10 cells with (p1,p2) = (0.5,2.5), (0.5,1.5), (0.5,1.3) and the "
    "smoothness cases p2 = 1.0, 0.8 at level 10; writes the 3D views, path-vs-ideal "
    "profiles, turn/climb/curvature profiles and tff_table.md (and with --report an "
    "interactive report.html: every path vs its ideal level).\n\n"
    "Examples:\n\n"
    "  fm2uav reproduce tff --out out/tff\n\n"
    "  fm2uav reproduce tff --report --out out/tff-report\n\n"
    "  fm2uav reproduce tff --scenario jacksboro --out out/tff-jacksboro"
)

TUNE_HELP = (
    "Search p1/p2 (and α/β) for the terrain-following path that keeps an airframe's max "
    "climb angle and min turn radius with the least flight-level deviation; writes the "
    "Pareto table (tune_table.md), tune.json, the best path and its figure (and with "
    "--report an interactive report.html of the best path vs its ideal level).\n\n"
    "Examples:\n\n"
    "  fm2uav tune --agl 150 --max-climb 45 --min-turn-radius 60 --out out/tune\n\n"
    "  fm2uav tune --p1 0.5 --p2 1.3,1.5 --report --out out/tune-report\n\n"
    "  fm2uav tune --dem dem.tif --bbox 10.05,45.54,10.2,45.66 --lonlat --start "
    "10.06,45.55 --goal 10.19,45.65 --agl 120 --out out/tune-dem\n\n"
    "  fm2uav tune --scenario jacksboro --agl 300 --max-climb 20 --min-turn-radius 300 "
    "--saturation 1,0.5 --out out/tune-jb"
)

_REPORT_HELP = "Also write report.html (interactive, self-contained)."


@handle_errors
@output_options("out/tff", report_help=_REPORT_HELP)
def reproduce_tff_cmd(
    scenario: str = typer.Option("open-field", help="Built-in 3D scenario with terrain."),
    seed: int = typer.Option(0, help="Seed of the scenario's random relief."),
    mode: str = typer.Option(
        "capped", help="Flight-level reading: 'capped' (default) or 'literal' (W**p as is)."
    ),
    output: Output = None,
) -> None:
    """``fm2uav reproduce tff``: :func:`~fm2uav.experiments.tff.run_tff`, write, print."""
    from ..experiments.tff import run_tff, tff_cases

    tff_cases(mode)  # bad --mode fails before anything is written
    outdir = output.dir(TFF_FILES + ((REPORT,) if output.report else ()))
    t0 = time.perf_counter()
    from .. import progress

    with output.progress():
        progress.step(f"terrain-following cases on {scenario}", 0.85)
        run = run_tff(scenario, seed, mode)
        progress.step("drawing the figures", 0.15)
        _write_tff_outputs(outdir, run, report=output.report)
    summary = {
        r["case"]: f"within {r['within']:.0%}, mean|dev| {r['mean_dev_all_m']:.1f} m, "
        f"max turn {r['turn_max_deg']:.0f}°, max climb {r['climb_max_deg']:.0f}°"
        for r in run.rows
    }
    summary["total [s]"] = f"{time.perf_counter() - t0:.1f}"
    output.summary("Terrain-following experiments", summary, {"cases": run.rows})


def _grid(**texts: str) -> dict[str, list[float]]:
    """``--p1``/``--p2``/``--saturation``/``--exponent`` comma lists → the tune grid."""
    def values(text: str, what: str) -> list[float]:
        try:
            return [float(v) for v in text.split(",") if v.strip()]
        except ValueError:
            raise InputError(f"--{what} must be a comma list of numbers, got {text!r}") from None

    return {k: values(v, k) for k, v in texts.items()}


@handle_errors
@output_options("out/tune", report_help=_REPORT_HELP)
@world_options
def tune_cmd(
    scenario: ScenarioOpt = None,
    agl: float = typer.Option(150.0, help="Flight level over the ground (m)."),
    max_climb: float = typer.Option(45.0, help="Airframe max climb/descent angle (deg)."),
    min_turn_radius: float = typer.Option(60.0, help="Airframe min turn radius (m)."),
    p1: str = typer.Option("0.3,0.5,0.8", help="Values of p1 to try (comma list)."),
    p2: str = typer.Option("0.6,0.8,1.0,1.3,1.5,2.0,2.5", help="Values of p2 to try."),
    saturation: str = typer.Option("1.0", help="Values of α to try."),
    exponent: str = typer.Option("1.0", help="Values of β to try."),
    start: str | None = typer.Option(None, help="Start x,y,z (m), LON,LAT[,AGL] with "
                                     "--lonlat. Default: the scenario's."),
    goal: str | None = typer.Option(None, help="Goal x,y,z (m), LON,LAT[,AGL] with "
                                    "--lonlat. Default: the scenario's."),
    lonlat: LonLatOpt = False,
    seed: int = typer.Option(0, help="Seed of the scenario's random relief."),
    output: Output = None,
    world: WorldFlags = None,
) -> None:
    """``fm2uav tune``: parse, :func:`~fm2uav.analysis.tune.tune`, write, print."""
    from ..vehicles import AirframeLimits

    grid = _grid(p1=p1, p2=p2, saturation=saturation, exponent=exponent)
    limits = AirframeLimits.from_degrees(max_climb, min_turn_radius)
    with output.progress():
        rows, payload = _tune_run(
            output, world, scenario=scenario, start=start, goal=goal, seed=seed,
            lonlat=lonlat, agl=agl, grid=grid, limits=limits, max_climb=max_climb,
            min_turn_radius=min_turn_radius)
    output.summary("Auto-tuning", rows, payload)


def _tune_run(output: Output, world: WorldFlags, *, scenario, start, goal, seed, lonlat, agl,
              grid, limits, max_climb, min_turn_radius) -> tuple[dict, dict]:
    """The body of ``fm2uav tune`` (inside its progress display): the summary rows and the
    JSON payload."""
    from .. import progress
    from ..analysis.tune import tune
    from ..planning import FlightLevel
    from ..world.load import world_summary

    progress.step("building the world", 0.1)
    w, sc, scenario = world.build(scenario, start, goal, seed=seed, lonlat=lonlat, agl=agl)
    s = cli_point(start, "start", w, lonlat=lonlat, agl=agl, default=sc.start if sc else None)
    g = cli_point(goal, "goal", w, lonlat=lonlat, agl=agl, default=sc.goal if sc else None)
    if sc is None:
        from ..scenarios.scenario import Scenario
        from ..world.load import check_points

        check_points(w, {"start": s, "goal": g}, allow_filled=world.allow_filled)
        sc = Scenario(world=w, start=s, goal=g, description=f"real data: {scenario}")
    outdir = output.dir(TUNE_FILES + ((REPORT,) if output.report else ()))
    n = sum(1 for a in grid["p1"] for b in grid["p2"] if b > a)
    progress.step(f"planning {n * len(grid['saturation']) * len(grid['exponent'])} "
                  "candidates", 0.8)
    res = tune(sc.world, s, g, limits, FlightLevel(agl=agl), grid=grid)
    progress.step("writing the files", 0.1)
    _write_tune_best(outdir, res, w, agl)
    write_text(outdir, "tune_table.md", res.markdown(
        f"Auto-tuning — {scenario}, agl {agl:g} m, max climb {max_climb:g}°, "
        f"min turn radius {min_turn_radius:g} m"))
    payload = {"scenario": scenario, "world": world_summary(w), "agl_m": agl, **res.payload()}
    write_json(outdir, "tune.json", payload)
    if output.report:
        _write_tune_report(outdir, res, sc, s, g, agl=agl, scenario=scenario, limits=limits,
                           grid=grid)
    return {**res.summary_rows(), **world_rows(w)}, payload


def _write_tune_best(outdir: OutputDir, res, world, agl: float) -> None:
    """tune_best_path.csv and tune_best.png of the tuned path (nothing without one)."""
    if res.best_plan is None:
        return
    from ..io import write_path_csv
    from ..viz.tff import tff_profile_figure

    b = res.best
    lab = f"best: p1={b['p1']:g}, p2={b['p2']:g}, α={b['saturation']:g}"
    with outdir.open("tune_best_path.csv") as fh:
        write_path_csv(fh, res.best_plan.path, res.best_plan.w,
                       comment=world.georef.comment() if world.georef else None)
    write_figure(outdir, tff_profile_figure([res.best_plan], [agl], [lab], title="Tuned path"),
                 "tune_best.png", dpi=100)


def register(app: typer.Typer, reproduce_app: typer.Typer) -> None:
    """Add ``reproduce tff`` and ``tune``."""
    reproduce_app.command("tff", help=TFF_HELP)(reproduce_tff_cmd)
    app.command("tune", help=TUNE_HELP)(tune_cmd)
