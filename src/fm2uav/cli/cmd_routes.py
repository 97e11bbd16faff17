"""``fm2uav routes``: the FM² route from every start of a file to one goal, from one wave."""

from __future__ import annotations

import math
from pathlib import Path

import typer

from ..errors import InputError
from ._common import Output, handle_errors, write_text
from .options import (
    ScenarioOpt,
    WorldFlags,
    check_point_texts,
    output_options,
    scenario_ndim,
    world_options,
    world_rows,
)
from ._mission_options import parse_anchor
from ._planner_options import PlannerFlags, planner_options

ROUTES_HELP = (
    "Plan the FM² route from every start of a file to one goal with one Fast Marching "
    "wave (the same W, shaping, flight level and limits as fm2uav plan; each route is "
    "the one fm2uav plan gives from its start) and write routes.geojson, routes.csv and "
    "summary.json. Starts that cannot be planned (outside the map, in an obstacle or a "
    "no-fly zone, cut off from the goal, ...) are listed with the reason; the command "
    "fails (exit 1) only when no start gets a route.\n\n"
    "--starts: a CSV with a header naming lon,lat (WGS84 degrees) and optionally id and "
    "agl (metres above the ground), or a GeoJSON/GeoPackage/Shapefile/KML of points (any "
    "CRS; ids from --id-field).\n\n"
    "Examples:\n\n"
    "  fm2uav routes --scenario city2d --goal=-3.7630,40.3334 --starts addresses.csv "
    "--out out/routes\n\n"
    "  fm2uav routes --dem dem.tif --goal 10.12,45.60 --starts drops.geojson --agl 120 "
    "--out out/fleet"
)


@handle_errors
@output_options("out/routes", report_help="Also write report.html: every route on the map "
                "(the longest coloured by height above ground), the figures, the starts table.")
@world_options
@planner_options(agl_help="Flight level (m) above the ground (terrain-following); also the "
                 "height of starts without their own. Default: none.")
def routes_cmd(
    goal: str = typer.Option(..., help="Goal (the depot) LON,LAT[,AGL]: degrees, degrees, "
                             "metres above the ground (default --agl)."),
    starts: Path = typer.Option(..., help="Starts file: CSV lon,lat[,id][,agl] with a "
                                "header, or a vector file of points."),
    scenario: ScenarioOpt = None,
    id_field: str | None = typer.Option(
        None, "--id-field", help="Property with each point's id (points files; default "
        "'id', else 'name', else the feature number)."),
    planner: PlannerFlags = None,
    no_fly: list[Path] | None = typer.Option(
        None, "--no-fly", help="No-fly zones file (GeoJSON lon/lat, KML/KMZ, GPKG, SHP); "
        "every route keeps out of them. Repeatable.", show_default=False),
    speed: float = typer.Option(10.0, help="Ground speed (m/s) for each route's time_s."),
    thin: float = typer.Option(1.0, help="Douglas–Peucker tolerance (m) of the lines in "
                               "routes.geojson (0: every point)."),
    threads: int | None = typer.Option(None, help="Threads for the descents (default: "
                                       "every core)."),
    anchor: str | None = typer.Option(
        None, help="lon,lat[,alt] of world x=y=0 on a built-in scenario (no CRS). Default: "
        "-3.7649,40.3326,0 (UC3M Leganés)."),
    seed: int = typer.Option(0, help="Seed of the scenario's random relief."),
    output: Output = None,
    world: WorldFlags = None,
) -> None:
    """``fm2uav routes``: parse, :func:`~fm2uav.pipeline.routes.run_routes`, print."""
    from ._first_use import announce_compile, fmm_group

    # the flags' own checks before any heavy import (a bad value answers in ~0.2 s)
    if not (math.isfinite(speed) and 0.1 <= speed <= 300.0):
        raise InputError(f"--speed must be a ground speed in [0.1, 300] m/s, got {speed:g}")
    if not (math.isfinite(thin) and 0.0 <= thin <= 1000.0):
        raise InputError(f"--thin must be a tolerance in [0, 1000] m, got {thin:g}")
    if threads is not None and threads < 1:
        raise InputError(f"--threads must be at least 1, got {threads}")
    shaping, level, options = planner.objects(storage="full")
    check_point_texts({"goal": goal}, scenario=scenario, lonlat=True, cells=False,
                      agl=planner.agl)
    from ..io.starts_path import check_starts_path

    check_starts_path(starts)  # a wrong path answers before the world and the compile
    from .._jit import ROUTES_KERNELS

    announce_compile(quiet=output.quiet,
                     child_group=fmm_group(order=planner.order, ndim=scenario_ndim(scenario)),
                     also=("many",), kernels=ROUTES_KERNELS, preload=("fm2uav.planning.many",))
    from .. import progress
    from ..io.starts import read_starts
    from ..pipeline.routes import ROUTES_FILES, RouteSettings, routes_rows, run_routes
    from ..world.load import world_summary
    from .options import lonlat_point

    agl = planner.agl
    with output.progress():
        progress.step("building the world", 0.1)
        w, _, label = world.build(scenario, goal, seed=seed, lonlat=True, agl=agl,
                                  default="open-field")
        anchor_ll = parse_anchor(anchor)
        outdir = output.dir(ROUTES_FILES + (("report.html",) if output.report else ()))
        goal_m = lonlat_point(goal, "goal", w, agl=agl, anchor=anchor_ll)
        if no_fly:
            from ..io.zone_spec import zones_from_cli
            from ..world.zones import check_points_allowed, with_zones

            w = with_zones(w, zones_from_cli(no_fly, w, crs=world.crs))
            check_points_allowed(w, {"goal": goal_m})
        progress.step("reading the starts", 0.05)
        table = read_starts(starts, w, agl=agl, crs=world.crs, id_field=id_field,
                            anchor=anchor_ll)
        progress.step("planning every route", 0.85)
        run = run_routes(outdir, w, goal_m, table, shaping=shaping, level=level,
                         options=options,
                         settings=RouteSettings(speed=speed, thin=thin, threads=threads,
                                                anchor=anchor_ll),
                         summary={"world": world_summary(w), "map": label,
                                  "starts_file": table.source})
        if run.summary["routes"] == 0:  # nothing to fly: exit 1, no output set
            from ..errors import PlanningError

            first = run.summary["failures"][0]
            raise PlanningError(
                f"none of the {run.summary['starts']} starts got a route "
                f"({', '.join(f'{n} {r}' for r, n in run.summary['failed_by_reason'].items())}"
                f"); the first, {first['id']!r}: {first['message']}")
        rows = {"map": label, **routes_rows(run), **world_rows(w)}
        if output.report:
            from ..viz.routes import routes_report_html

            progress.step("writing report.html", 0.0)
            write_text(outdir, "report.html", routes_report_html(
                w, run, rows, title=f"FM² routes to {goal}", files=ROUTES_FILES,
                anchor=anchor_ll))
    output.summary("FM² routes", rows, run.summary)


def register(app: typer.Typer, reproduce_app: typer.Typer) -> None:
    """Add the ``routes`` command."""
    app.command("routes", help=ROUTES_HELP)(routes_cmd)
