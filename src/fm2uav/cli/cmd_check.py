"""``fm2uav check``: can an airframe fly this path? (Dubins airplane / multirotor)."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import typer

from ._common import EXIT_PLANNING, OutputDir, handle_errors, print_summary, progress, to_jsonable
from .options import (
    AllowFilledOpt,
    BboxOpt,
    BuildingsOpt,
    CeilingOpt,
    CellSizeOpt,
    CrsOpt,
    DefaultHeightOpt,
    DemOpt,
    DzOpt,
    NodataOpt,
    NodataValueOpt,
    SeaLevelOpt,
    world_rows,
    world_spec,
)

CHECK_FILES = ("report.json", "flown.csv", "check.png")
REPORT = "report.html"


def _report(rep, world, rows: dict, *, title: str, subtitle: str, params: dict) -> str:
    """report.html of a check: the planned path and the flown track, saturation intervals."""
    from ..viz.report import report_html

    tr = rep.tracking
    flown = f"flown ({rep.airframe.name})"
    return report_html(
        world, {"planned": tr.planned, flown: tr.trajectory}, title=title, subtitle=subtitle,
        styles={flown: {"dash": "dash", "width": 4}},
        params=params, metrics=rows,
        tables={"Where the limits saturate": tr.saturation_intervals()},
        files=list(CHECK_FILES))


def register(app: typer.Typer, reproduce_app: typer.Typer) -> None:
    """Add the ``check`` command."""
    from ..vehicles import AIRFRAMES

    @app.command(
        "check",
        help=(
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
            f"Airframes: {', '.join(AIRFRAMES)}."
        ),
    )
    @handle_errors
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
        out: Path = typer.Option(Path("out/check"), help="Output directory."),
        force: bool = typer.Option(False, "--force", help="Overwrite existing outputs."),
        as_json: bool = typer.Option(False, "--json", help="Print the report as JSON."),
        quiet: bool = typer.Option(False, "--quiet", help="Print nothing but errors."),
        report: bool = typer.Option(
            False, "--report", help="Also write report.html (planned vs flown, interactive)."),
        dem: DemOpt = None,
        buildings: BuildingsOpt = None,
        bbox: BboxOpt = None,
        sea_level: SeaLevelOpt = None,
        cell_size: CellSizeOpt = None,
        dz: DzOpt = None,
        ceiling: CeilingOpt = None,
        nodata: NodataOpt = "error",
        nodata_value: NodataValueOpt = None,
        crs: CrsOpt = None,
        default_height: DefaultHeightOpt = None,
        allow_filled: AllowFilledOpt = False,
    ) -> None:
        from ..io import read_path_csv, write_path_csv
        from ..vehicles import check_feasibility, get_airframe
        from ..viz.feasibility import tracking_figure
        from ..scenarios import get_scenario

        af = get_airframe(airframe)
        path = read_path_csv(path_file)
        spec = world_spec(dem=dem, buildings=buildings, bbox=bbox, sea_level=sea_level,
                          cell_size=cell_size, dz=dz, ceiling=ceiling, nodata=nodata,
                          nodata_value=nodata_value, crs=crs, default_height=default_height,
                          allow_filled=allow_filled)
        if spec is not None and scenario is not None:
            from ..errors import InputError

            raise InputError("give either --scenario or --dem/--buildings, not both")
        if spec is not None:
            from ..world.load import load_world

            # the world the path was planned on: give the same world options as to plan
            top = float(path[:, 2].max()) if path.shape[1] == 3 else None
            world = load_world(spec, top=top)
        else:
            world = get_scenario(scenario, seed=seed).world if scenario else None
        outdir = OutputDir(out, force=force)
        outdir.check(CHECK_FILES + ((REPORT,) if report else ()))
        with progress(enabled=not (quiet or as_json)) as step:
            step(f"simulating the {af.name} along the path")
            rep = check_feasibility(path, af, world=world, tolerance=tolerance,
                                    lookahead=lookahead, lookahead_points=lookahead_points,
                                    speed=speed, dt=dt)
        summary = {"path_file": str(path_file), "scenario": scenario, **rep.summary()}
        if world is not None and getattr(world, "georef", None) is not None:
            from ..world.load import world_summary

            summary["world"] = world_summary(world)
        tmp_png = outdir.target("check.png")
        tracking_figure(rep, world, title=path_file.name).savefig(tmp_png, dpi=100)
        with outdir.open("flown.csv") as fh:
            g = getattr(world, "georef", None)
            write_path_csv(fh, rep.tracking.trajectory, comment=g.comment() if g else None)
        outdir.commit(tmp_png, "check.png")
        with outdir.open("report.json") as fh:
            json.dump(to_jsonable(summary), fh, indent=2)
        tr, geo = rep.tracking, rep.geometric
        wrows = world_rows(world) if world is not None else {}
        sat = ", ".join(f"{k} {v:.1f} s" for k, v in tr.saturation_time().items()) or "none"
        rows = {
            "verdict": "FEASIBLE" if rep.feasible else "INFEASIBLE",
            "reason": rep.reason,
            "airframe": f"{af.name} ({af.kind})",
            "separation max / mean [m]": f"{tr.max_separation:.2f} / {tr.mean_separation:.2f}",
            "limits saturated": sat,
            "geometric check": ("ok" if geo.feasible else "violated") + f": {geo.reason}",
            "min radius of curvature [m]": (f"{geo.min_radius:.1f}"
                                            if math.isfinite(geo.min_radius) else "inf"),
            "max climb / descent [deg]": (f"{np.degrees(geo.climb_angle.max()):.1f} / "
                                          f"{np.degrees(-geo.climb_angle.min()):.1f}"),
        }
        rows.update(wrows)
        if getattr(af, "kind", "") == "fixed-wing":
            rows["R_min [m]"] = f"{af.turn_radius(rep.airframe.cruise_speed):.1f}"
        if report:
            params = {"path file": path_file.name, "scenario": scenario or "none",
                      "tolerance [m]": tolerance, "lookahead [m]": tr.lookahead,
                      "time step [s]": dt, **{f"airframe {k}": v
                                              for k, v in rep.airframe.summary().items()}}
            html = _report(rep, world, rows, title=f"feasibility check — {path_file.name}",
                           subtitle=f"{af.name} ({af.kind}): "
                                    f"{'FEASIBLE' if rep.feasible else 'INFEASIBLE'} — "
                                    f"{rep.reason}", params=params)
            with outdir.open(REPORT) as fh:
                fh.write(html)
        print_summary("feasibility check", summary if as_json else rows, as_json=as_json,
                      quiet=quiet, files=outdir.written)
        if fail_infeasible and not rep.feasible:
            raise typer.Exit(EXIT_PLANNING)
