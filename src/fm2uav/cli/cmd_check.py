"""``fm2uav check``: can an airframe fly this path? (Dubins airplane / multirotor)."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import typer

from ._common import EXIT_PLANNING, Output, handle_errors, write_json, write_text
from .options import AIRFRAME_NAMES, WorldFlags, output_options, world_options, world_rows


if TYPE_CHECKING:
    import numpy as np

CHECK_FILES = ("report.json", "flown.csv", "check.png")
REPORT = "report.html"


def _report(rep, world, rows: dict, *, title: str, subtitle: str, params: dict) -> str:
    """report.html of a check: the planned path and the flown track, saturation intervals."""
    import numpy as np

    from ..viz.report import path_figures, report_html

    tr = rep.tracking
    flown = f"flown ({rep.airframe.name})"
    paths = {"planned": tr.planned, flown: tr.trajectory}
    figures = {"verdict": f"{'FEASIBLE' if rep.feasible else 'INFEASIBLE'} — {rep.reason}",
               "airframe": f"{rep.airframe.name} ({rep.airframe.kind})",
               "largest separation from the plan": f"{float(np.max(tr.separation)):.1f} m",
               **path_figures(world, paths)}
    return report_html(
        world, paths, title=title, subtitle=subtitle, figures=figures,
        styles={flown: {"dash": "dash", "width": 4}},
        params=params, metrics=rows,
        tables={"Where the limits saturate": tr.saturation_intervals()},
        files=list(CHECK_FILES))


def _help() -> str:
    return (
        "Check whether an airframe can fly a path file (x_m,y_m[,z_m] CSV): simulate the "
        "Dubins airplane (fixed-wing) or a multirotor following it, report the separation "
        "from the plan, where the turn/climb limits saturate, a geometric check (curvature "
        "vs 1/R, climb angle) and a verdict. Writes report.json, flown.csv and check.png "
        "(and with --report an interactive report.html: planned vs flown).\n\n"
        "Examples:\n\n"
        "  fm2uav check out/plan/path.csv --airframe disco --out out/check\n\n"
        "  fm2uav check out/plan/path.csv --scenario open-field --report --out out/check\n\n"
        "  fm2uav check path.csv --airframe crosswind --scenario city --tolerance 3 --json\n\n"
        "  fm2uav check out/dem/path.csv --dem dem.tif --bbox 10.05,45.54,10.2,45.66 "
        "--out out/check-dem   (the world of the plan: same DEM options)\n\n"
        f"Airframes: {', '.join(AIRFRAME_NAMES)}."
    )


@handle_errors
@output_options("out/check", json_help="Print the report as JSON.",
                report_help="Also write report.html (planned vs flown, interactive).")
@world_options
def check_cmd(
    path_file: Path = typer.Argument(..., help="Path CSV (as written by fm2uav plan)."),
    airframe: str = typer.Option("disco", help="Airframe preset."),
    scenario: str | None = typer.Option(
        None, help="Also check collisions of the flown path in this built-in scenario."
    ),
    seed: int = typer.Option(0, help="Seed of the scenario."),
    tolerance: float = typer.Option(5.0, help="Largest admissible separation (m)."),
    lookahead: float | None = typer.Option(None, help="Carrot distance (m) (default R_min)."),
    lookahead_points: int | None = typer.Option(
        None, help="Or the thesis' a: look this many path points ahead."
    ),
    speed: float | None = typer.Option(None, help="Fixed-wing airspeed (m/s) (default cruise)."),
    dt: float = typer.Option(0.05, help="Simulation step (s)."),
    fail_infeasible: bool = typer.Option(
        False, "--fail-infeasible", help="Exit with code 1 when the path is infeasible."
    ),
    output: Output = None,
    world: WorldFlags = None,
) -> None:
    """``fm2uav check``: parse, :func:`~fm2uav.vehicles.check_feasibility`, write, print."""
    from .._validate import input_file

    input_file(path_file, "path file")  # before the library loads: a wrong name answers at once
    from .. import progress
    from ..io import read_path_csv
    from ..vehicles import TrackingOptions, check_feasibility, get_airframe

    af = get_airframe(airframe)
    path = read_path_csv(path_file)
    with output.progress():
        progress.step("building the world", 0.2)
        w = _check_world(world.spec(), scenario, seed, path)
        outdir = output.dir(CHECK_FILES + ((REPORT,) if output.report else ()))
        progress.step(f"simulating the {af.name} along the path", 0.5)
        rep = check_feasibility(path, af, world=w, tolerance=tolerance, speed=speed,
                                tracking=TrackingOptions(lookahead=lookahead,
                                                         lookahead_points=lookahead_points,
                                                         dt=dt))
        progress.step("writing the files", 0.3)
        summary = {"path_file": str(path_file), "scenario": scenario, **rep.summary()}
        if w is not None and getattr(w, "georef", None) is not None:
            from ..world.load import world_summary

            summary["world"] = world_summary(w)
        _write_track(outdir, rep, w, path_file.name)
        write_json(outdir, "report.json", summary)
        rows = _rows(rep, af, w)
        if output.report:
            params = {"path file": path_file.name, "scenario": scenario or "none",
                      "tolerance [m]": tolerance, "lookahead [m]": rep.tracking.lookahead,
                      "time step [s]": dt, **{f"airframe {k}": v
                                              for k, v in rep.airframe.summary().items()}}
            write_text(outdir, REPORT, _report(
                rep, w, rows, title=f"feasibility check — {path_file.name}",
                subtitle=f"{af.name} ({af.kind}): "
                         f"{'FEASIBLE' if rep.feasible else 'INFEASIBLE'} — {rep.reason}",
                params=params))
    output.summary("feasibility check", rows, summary)
    if fail_infeasible and not rep.feasible:
        raise typer.Exit(EXIT_PLANNING)


def _check_world(spec, scenario: str | None, seed: int, path: np.ndarray):
    """The world the path was planned on (world options, a scenario, or None)."""
    if spec is not None and scenario is not None:
        from ..errors import InputError

        raise InputError("give either --scenario or --dem/--buildings, not both")
    if spec is not None:
        from ..world.load import load_world

        # the world the path was planned on: give the same world options as to plan
        top = float(path[:, 2].max()) if path.shape[1] == 3 else None
        return load_world(spec, top=top)
    from ..scenarios import get_scenario

    return get_scenario(scenario, seed=seed).world if scenario else None


def _write_track(outdir, rep, world, name: str) -> None:
    """check.png and flown.csv of a check."""
    from ..io import write_path_csv
    from ..viz.feasibility import tracking_figure

    tmp_png = outdir.target("check.png")
    tracking_figure(rep, world, title=name).savefig(tmp_png, dpi=100)
    with outdir.open("flown.csv") as fh:
        g = getattr(world, "georef", None)
        write_path_csv(fh, rep.tracking.trajectory, comment=g.comment() if g else None)
    outdir.commit(tmp_png, "check.png")


def _rows(rep, af, world) -> dict:
    """The printed summary of ``fm2uav check``: the verdict rows and the world's."""
    return {**rep.summary_rows(af), **(world_rows(world) if world is not None else {})}


def register(app: typer.Typer, reproduce_app: typer.Typer) -> None:
    """Add the ``check`` command."""
    app.command("check", help=_help())(check_cmd)
