"""``fm2uav plan``: one FM² path on a built-in scenario."""

from __future__ import annotations

from pathlib import Path

import typer

from ..errors import InputError
from ._common import Output, handle_errors, plan_rows
from .options import (
    SCENARIO_NAMES,
    LonLatOpt,
    MissionFlags,
    ScenarioOpt,
    WorldFlags,
    check_point_texts,
    cli_point,
    mission_options,
    output_options,
    scenario_ndim,
    world_options,
    world_rows,
)
from ._planner_options import PlannerFlags, planner_options
from ._return_options import ReturnFlags, return_options
from ..pipeline.rows import mission_rows, safety_rows

PLAN_FILES = ("path.csv", "plan.png", "summary.json")

PLAN_HELP = (
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
    f"Scenarios: {', '.join(SCENARIO_NAMES)}."
)


@handle_errors
@output_options("out/plan", report_help="Also write report.html (interactive, self-contained).")
@world_options
@mission_options()
@return_options
@planner_options(march=True)
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
    planner: PlannerFlags = None,
    no_fly: list[Path] | None = typer.Option(
        None, "--no-fly", help="No-fly zones file (GeoJSON lon/lat, KML/KMZ, GPKG, SHP; points "
        "need a 'radius' in metres); the plan keeps out of them and the .plan carries them "
        "as geofences. Repeatable.", show_default=False),

    seed: int = typer.Option(0, help="Seed of the scenario's random relief."),
    output: Output = None,
    export: str = typer.Option(
        "", help="Also write these exports (comma list): geojson, kml, kmz, plan "
        "(QGroundControl), wpl (MAVLink QGC WPL 110), or 'all'."),
    anchor: str | None = typer.Option(
        None, help="lon,lat[,alt] of world x=y=0 for the exports (worlds without CRS). "
        "Default: -3.7649,40.3326,0 (UC3M Leganés)."),
    thin: float = typer.Option(5.0, help="Waypoint tolerance (m) of the exports (3D "
                               "Douglas–Peucker)."),
    world: WorldFlags = None,
    mission: MissionFlags = None,
    returns: ReturnFlags = None,
) -> None:
    """``fm2uav plan``: parse, :func:`~fm2uav.missions.route.plan_route`, write, print."""
    from ._first_use import announce_compile, fmm_group

    # the flags' own checks before any heavy import (a bad value answers in ~0.2 s)
    returns.check()
    shaping, level, options = planner.objects()
    extra = _extra_formats(export, output.report)
    check_point_texts({"start": start, "goal": goal,
                       **{f"via {k + 1}": v for k, v in enumerate(mission.via or [])}},
                      scenario=scenario, lonlat=lonlat, cells=cells, agl=planner.agl)
    announce_compile(quiet=output.quiet,
                     child_group=fmm_group(order=planner.order, ndim=scenario_ndim(scenario)),
                     preload=("fm2uav.missions.route", "fm2uav.viz", "fm2uav.io"))
    from .. import progress
    from ..missions.route import plan_route
    from ..pipeline.outputs import (output_names, plan_outputs, wind_options, with_wind_on,
                                    write_json)
    from ..world.load import world_summary

    with output.progress():
        progress.step("building the world", 0.1)
        agl = planner.agl
        w, sc, scenario = world.build(scenario, start, goal, seed=seed, lonlat=lonlat, agl=agl)
        description = sc.description if sc is not None else f"real data: {scenario}"
        export_options = mission.export_options(_export_options(anchor, thin))
        outdir = output.dir(PLAN_FILES + tuple(output_names(extra)))

        w, start_m, goal_m, via_m = _points(
            w, sc, start, goal, mission.via, world=world, no_fly=no_fly, lonlat=lonlat,
            cells=cells, agl=agl, anchor=getattr(export_options, "anchor", None))
        export_options = with_wind_on(export_options, w)
        progress.step("planning (FM²)", 0.6)
        route = plan_route(w, start_m, goal_m, via=via_m,
                           return_to_start=bool(mission.return_to_start), shaping=shaping,
                           level=level, options=options,
                           wind=wind_options(export_options))
        p = route.plan
        built = None
        info: dict = {}
        if extra:
            from ..pipeline.outputs import flown

            progress.step("the mission, its safe returns and the report", 0.15)
            ret = returns.options(w, anchor=getattr(export_options, "anchor", None),
                                  crs=world.crs)
            info, built = plan_outputs(outdir, p, extra, export_options,
                                       title=f"FM² plan — {scenario}", subtitle=description,
                                       via=route.junctions[1:-1], returns=ret)
            p = flown(p, built)  # with the planned safe return when the mission carries one
        progress.step("measuring the flight against the ground", 0.05)
        summary = {"scenario": scenario, "world": world_summary(w), **p.summary(),
                   "route": route.summary()}
        if p.path.shape[1] == 3:  # measured on the continuous ground (legs: with the exports)
            from ..analysis.known_ground import check_ground
            from ..analysis.safety import safety_summary

            summary["safety"] = safety_summary(w, p.path, requested=agl, phase=p.phase,
                                               level=p.level)
            if not extra:  # else plan_outputs measures the legs too, and says it there
                check_ground(w, summary["safety"])
        progress.step("drawing plan.png, writing path.csv", 0.1 if extra else 0.25)
        _write_plan(outdir, p, w, title=f"FM² plan — {scenario}",
                    ground=summary.get("safety", {}).get("ground"),
                    anchor=getattr(export_options, "anchor", None))
        if built is not None:
            summary.update(waypoints=info["waypoints"], mavlink_frame=info["mavlink_frame"],
                           home_lat_lon_alt=info["home_lat_lon_alt"],
                           autopilot=info["autopilot"], safety=info["safety"])
            for key in ("returns", "point_of_no_return"):
                if key in info:
                    summary[key] = info[key]
        write_json(outdir, "summary.json", summary)
    output.summary("FM² plan", _rows(scenario, route, w, summary, built, p), summary)


def _points(w, sc, start: str | None, goal: str | None, via: list[str] | None, *,
            world: WorldFlags, no_fly: list[Path] | None, **how) -> tuple:
    """``(world, start, goal, via points)`` in metres, checked (free, not over filled
    nodata, outside the ``--no-fly`` zones, which become obstacles of the world)."""
    import numpy as np

    from ..world.load import check_points

    def point(text: str | None, default: np.ndarray | None, what: str) -> np.ndarray:
        return cli_point(text, what, w, default=default, **how)

    start_m = point(start, sc.start if sc else None, "start")
    goal_m = point(goal, sc.goal if sc else None, "goal")
    via_m = [point(v, None, f"via {k + 1}") for k, v in enumerate(via or [])]
    named = {"start": start_m, "goal": goal_m, **{f"via {k + 1}": v for k, v in enumerate(via_m)}}
    check_points(w, named, allow_filled=world.allow_filled)
    if no_fly:  # no-fly zones become obstacles of the world
        from ..io.zone_spec import zones_from_cli
        from ..world.zones import check_points_allowed, with_zones

        w = with_zones(w, zones_from_cli(no_fly, w, crs=world.crs))
        check_points_allowed(w, named)
    return w, start_m, goal_m, via_m


def _write_plan(outdir, p, world, *, title: str, ground: dict | None = None,
                anchor=None) -> None:
    """plan.png (with the known/unknown ground split ``ground``) and path.csv (with the final
    profile's floor) of a plan on ``world``."""
    import numpy as np

    from ..io import write_path_csv
    from ..viz import plan_figure

    georef = getattr(world, "georef", None)
    fig = plan_figure(p, title=title, ground=ground, anchor=anchor)
    tmp_png = outdir.target("plan.png")
    fig.savefig(tmp_png, dpi=110)
    with outdir.open("path.csv") as fh:
        floor = getattr(getattr(p, "profile", None), "required", None)
        write_path_csv(fh, p.path, p.w, comment=georef.comment() if georef else None,
                       floor=floor if np.shape(floor) == (len(p.path),) else None)
    outdir.commit(tmp_png, "plan.png")


def _rows(scenario: str, route, world, summary: dict, built, p) -> dict:
    """The printed summary of ``fm2uav plan`` (``p``: the plan as flown)."""
    from ..pipeline.rows import returns_rows

    rows = {
        "scenario": scenario,
        **plan_rows(p),
        "min W on path": f"{p.w.min():.3f}",
        "timings [ms]": ", ".join(f"{k} {v * 1e3:.1f}" for k, v in p.timings.items()),
        **world_rows(world),
    }
    if len(route.legs) > 1:
        rows["legs"] = len(route.legs)
    if "safety" in summary:
        rows.update(safety_rows(summary["safety"]))
    if "waypoints" in summary:
        rows["waypoints"] = f"{summary['waypoints']} (MAVLink frame {summary['mavlink_frame']})"
        rows.update(returns_rows(summary))
        rows.update(mission_rows(built))
    return rows


def register(app: typer.Typer, reproduce_app: typer.Typer) -> None:
    """Add the ``plan`` command."""
    app.command("plan", help=PLAN_HELP)(plan_cmd)


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
    import numpy as np

    from ..autopilot import ExportOptions
    from ..pipeline.outputs import parse_anchor

    if not (np.isfinite(thin) and 0 <= thin <= 1000):
        raise InputError(f"--thin must be a tolerance in [0, 1000] m (mission file: "
                         f"outputs.thin_tolerance), got {thin}")
    return ExportOptions(tolerance=thin, anchor=parse_anchor(anchor))
