"""``fm2uav plan``: one FM² path on a built-in scenario."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import typer

from ..planning.params import planner_objects
from ..scenarios import SCENARIOS
from ..errors import InputError
from ._common import OutputDir, handle_errors, print_summary, to_jsonable
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
    LonLatOpt,
    NodataOpt,
    NodataValueOpt,
    ScenarioOpt,
    SeaLevelOpt,
    build_world,
    cli_point,
    requested_heights,
    world_rows,
    world_spec,
)
from ._mission_options import (
    CruiseSpeed,
    End,
    Endurance,
    Firmware,
    Frame,
    HoverSpeed,
    MinSpeed,
    Reserve,
    Return,
    SpeedChanges,
    Vehicle,
    Via,
    export_options as mission_export_options,
)
from .cmd_run import mission_rows, output_names, plan_outputs

PLAN_FILES = ("path.csv", "plan.png", "summary.json")


def register(app: typer.Typer, reproduce_app: typer.Typer) -> None:
    """Add the ``plan`` command."""

    @app.command(
        "plan",
        help=(
            "Plan one FM² path on a built-in scenario or on real data (--dem, --buildings) and "
            "write path.csv, plan.png and summary.json.\n\n"
            "Examples:\n\n"
            "  fm2uav plan --scenario open-field --out out/plan\n\n"
            "  fm2uav plan --start 20,20,20 --goal 100,80,30 --cells --exponent 0.5 --out out/b\n\n"
            "  fm2uav plan --agl 150 --p1 0.5 --p2 1.3 --report --export all --out out/tff\n\n"
            "  fm2uav plan --report --export plan,wpl,geojson,kml --out out/c\n\n"
            "  fm2uav plan --agl 150 --via 1400,300,480 --via 500,1100,420 --return --export "
            "plan,wpl --firmware ardupilot --out out/route\n\n"
            "  fm2uav plan --dem dem.tif --bbox 10.05,45.54,10.2,45.66 --lonlat --start "
            "10.06,45.55 --goal 10.19,45.65 --agl 120 --out out/dem\n\n"
            "  fm2uav plan --dem coast.tif --sea-level 0 --buildings osm.geojson "
            "--default-height 10 --lonlat --start 10.06,45.55,60 --goal 10.19,45.65,60 "
            "--out out/city\n\n"
            f"Scenarios: {', '.join(SCENARIOS)}."
        ),
    )
    @handle_errors
    def plan_cmd(
        scenario: ScenarioOpt = None,
        start: str | None = typer.Option(
            None, help="Start x,y,z in metres (cells with --cells; LON,LAT[,AGL] with "
            "--lonlat). Default: the scenario's."
        ),
        goal: str | None = typer.Option(
            None, help="Goal x,y,z in metres (cells with --cells; LON,LAT[,AGL] with "
            "--lonlat). Default: the scenario's."
        ),
        lonlat: LonLatOpt = False,
        cells: bool = typer.Option(False, "--cells", help="Read --start/--goal as grid cells."),
        saturation: float = typer.Option(1.0, help="Saturation α in (0, 1]."),
        saturation_distance: float | None = typer.Option(
            None, help="Distance (m) from the obstacles beyond which W = 1 (overrides "
            "--saturation)."),
        exponent: float = typer.Option(1.0, help="Exponent β > 0 on W (thesis' adjustment)."),
        order: int = typer.Option(2, help="Fast Marching order, 1 or 2."),
        agl: float | None = typer.Option(
            None, help="Flight level (m) above the ground (terrain-following, thesis "
            "Algorithm 2). Default: none."),
        p1: float = typer.Option(0.5, help="Exponent on the flight-level cells (with --agl)."),
        p2: float = typer.Option(1.5, help="Exponent on all other cells (with --agl)."),
        band: float = typer.Option(
            0.0, help="Half-width (m) of the clarified band around the flight level (with "
            "--agl; 0 = the seeds' single layer)."),
        graded: bool = typer.Option(
            False, "--graded", help="Blend the exponent from p1 to p2 across --band."),
        mode: str = typer.Option(
            "capped", help="Flight-level reading: 'capped' or 'literal' (W**p as is)."),

        seed: int = typer.Option(0, help="Seed of the scenario's random relief."),
        out: Path = typer.Option(Path("out/plan"), help="Output directory."),
        force: bool = typer.Option(False, "--force", help="Overwrite existing outputs."),
        as_json: bool = typer.Option(False, "--json", help="Print the summary as JSON."),
        quiet: bool = typer.Option(False, "--quiet", help="Print nothing but errors."),
        report: bool = typer.Option(
            False, "--report", help="Also write report.html (interactive, self-contained)."),
        export: str = typer.Option(
            "", help="Also write these exports (comma list): geojson, kml, kmz, plan "
            "(QGroundControl), wpl (MAVLink QGC WPL 110), or 'all'."),
        anchor: str | None = typer.Option(
            None, help="lon,lat[,alt] of world x=y=0 for the exports (worlds without CRS). "
            "Default: -3.7649,40.3326,0 (UC3M Leganés)."),
        thin: float = typer.Option(5.0, help="Waypoint tolerance (m) of the exports (3D "
                                   "Douglas–Peucker)."),
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
        via: Via = None,
        return_to_start: Return = None,
        firmware: Firmware = None,
        vehicle: Vehicle = None,
        frame: Frame = None,
        end: End = None,
        speed_changes: SpeedChanges = None,
        min_speed: MinSpeed = None,
        cruise_speed: CruiseSpeed = None,
        hover_speed: HoverSpeed = None,
        endurance: Endurance = None,
        reserve: Reserve = None,
    ) -> None:
        from ..missions.route import plan_route

        spec = world_spec(dem=dem, buildings=buildings, bbox=bbox, sea_level=sea_level,
                          cell_size=cell_size, dz=dz, ceiling=ceiling, nodata=nodata,
                          nodata_value=nodata_value, crs=crs, default_height=default_height,
                          allow_filled=allow_filled)
        need_agl, need_top = requested_heights(start, goal, lonlat=lonlat, agl=agl)
        world, sc, scenario = build_world(spec, scenario=scenario, seed=seed, agl=need_agl,
                                          top=need_top)
        description = sc.description if sc is not None else f"real data: {scenario}"
        outdir = OutputDir(out, force=force)
        extra = _extra_formats(export, report)
        export_options = mission_export_options(
            _export_options(anchor, thin), firmware=firmware, vehicle=vehicle, frame=frame,
            end=end, speed_changes=speed_changes, min_speed=min_speed, cruise_speed=cruise_speed,
            hover_speed=hover_speed, endurance=endurance, reserve=reserve)
        outdir.check(PLAN_FILES + tuple(output_names(extra)))

        def point(text: str | None, default: np.ndarray | None, what: str) -> np.ndarray:
            return cli_point(text, what, world, lonlat=lonlat, cells=cells, agl=agl,
                             default=default, anchor=getattr(export_options, "anchor", None))

        start_m = point(start, sc.start if sc else None, "start")
        goal_m = point(goal, sc.goal if sc else None, "goal")
        from ..world.load import check_points, world_summary

        via_m = [point(v, None, f"via {k + 1}") for k, v in enumerate(via or [])]
        check_points(world, {"start": start_m, "goal": goal_m,
                             **{f"via {k + 1}": v for k, v in enumerate(via_m)}},
                     allow_filled=allow_filled)

        level_keys = (dict(agl=agl, p1=p1, p2=p2, band=band, graded=graded, mode=mode)
                      if agl is not None else {})
        shaping, level, options = planner_objects(dict(
            saturation=saturation, saturation_distance=saturation_distance, exponent=exponent,
            order=order, **level_keys))
        route = plan_route(world, start_m, goal_m, via=via_m,
                           return_to_start=bool(return_to_start), shaping=shaping, level=level,
                           options=options)
        p = route.plan
        from ..io import write_path_csv
        from ..viz import plan_figure

        summary = {"scenario": scenario, "world": world_summary(world), **p.summary(),
                   "route": route.summary()}
        georef = getattr(world, "georef", None)
        fig = plan_figure(p, title=f"FM² plan — {scenario}")
        tmp_png = outdir.target("plan.png")
        fig.savefig(tmp_png, dpi=110)
        with outdir.open("path.csv") as fh:
            floor = getattr(getattr(p, "profile", None), "required", None)
            write_path_csv(fh, p.path, p.w, comment=georef.comment() if georef else None,
                           floor=floor if np.shape(floor) == (len(p.path),) else None)
        outdir.commit(tmp_png, "plan.png")
        if extra:
            info, built = plan_outputs(outdir, p, extra, export_options,
                                       title=f"FM² plan — {scenario}", subtitle=description,
                                       via=route.junctions[1:-1])
            summary.update(waypoints=info["waypoints"], mavlink_frame=info["mavlink_frame"],
                           home_lat_lon_alt=info["home_lat_lon_alt"], autopilot=info["autopilot"])
        with outdir.open("summary.json") as fh:
            json.dump(to_jsonable(summary), fh, indent=2)
        rows = {
            "scenario": scenario,
            "start [m]": np.round(p.start, 1).tolist(),
            "goal [m]": np.round(p.goal, 1).tolist(),
            "length [m]": f"{p.length:.1f}",
            "clearance [m]": f"{p.clearance:.1f}",
            "min W on path": f"{p.w.min():.3f}",
            "timings [ms]": ", ".join(f"{k} {v * 1e3:.1f}" for k, v in p.timings.items()),
            **world_rows(world),
        }
        if len(route.legs) > 1:
            rows["legs"] = len(route.legs)
        if "waypoints" in summary:
            rows["waypoints"] = f"{summary['waypoints']} (MAVLink frame {summary['mavlink_frame']})"
            rows.update(mission_rows(built))
        print_summary("FM² plan", rows if not as_json else summary, as_json=as_json,
                      quiet=quiet, files=outdir.written)


_EXPORTS = ("geojson", "kml", "kmz", "plan", "wpl")


def _extra_formats(export: str, report: bool) -> list[str]:
    """Output formats asked with --export/--report beyond path.csv, plan.png, summary.json."""
    names = [e.strip().lower() for e in export.split(",") if e.strip()]
    if names == ["all"]:
        names = list(_EXPORTS)
    bad = [n for n in names if n not in _EXPORTS]
    if bad:
        raise InputError(f"--export {bad[0]!r} is not a known format; allowed: "
                         f"{', '.join(_EXPORTS)} or all")
    return list(dict.fromkeys(names)) + (["html"] if report else [])


def _export_options(anchor: str | None, thin: float):
    from ..io import Anchor, ExportOptions

    if not np.isfinite(thin) or thin < 0:
        raise InputError(f"--thin must be a tolerance >= 0 m, got {thin}")
    a = None
    if anchor is not None:
        parts = anchor.replace(",", " ").split()
        try:
            v = [float(x) for x in parts]
        except ValueError:
            v = []
        if len(v) not in (2, 3):
            raise InputError(f"--anchor must be lon,lat or lon,lat,alt (degrees, degrees, "
                             f"metres), got {anchor!r}")
        a = Anchor(lon=v[0], lat=v[1], alt=v[2] if len(v) == 3 else 0.0)
    return ExportOptions(tolerance=thin, anchor=a)
