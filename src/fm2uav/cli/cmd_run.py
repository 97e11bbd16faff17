"""``fm2uav run MISSION.yaml``: plan a mission file and write its exports and report.

The run itself is :func:`fm2uav.pipeline.run.run_mission` (shared with the web
app); the writer of a plan's output files, :func:`plan_outputs`, is
:mod:`fm2uav.pipeline.outputs`' (re-exported here for the other commands).
"""

from __future__ import annotations

from pathlib import Path

import typer

from ..pipeline.outputs import (  # noqa: F401  (re-exported: were defined here)
    OUTPUT_FILES,
    output_names,
    plan_outputs,
    write_exports,
)
from ..pipeline.rows import ground_rows, mission_rows, safety_rows  # noqa: F401  (re-exported)
from ._common import (
    Output,
    handle_errors,
    plan_rows,
)
from ._mission_options import via_points
from .options import (
    LonLatOpt,
    MissionFlags,
    WorldFlags,
    mission_options,
    output_options,
    point_overrides,
    world_options,
    world_rows,
)

RUN_HELP = (
    "Plan the mission described by a YAML file (start, via points, goal, optional "
    "return leg) and write its outputs: path.csv, path.geojson, path.kml, path.kmz, "
    "mission.plan (QGroundControl), mission.waypoints (MAVLink QGC WPL 110), "
    "report.html (interactive), plan.png and summary.json — as listed under "
    "outputs.formats. The mission starts with a takeoff and ends as outputs.end says, "
    "in the altitude frame of outputs.frame (auto: ArduPilot terrain, PX4 AMSL), and "
    "is checked against the firmware's rules before anything is written.\n\n"
    "Examples:\n\n"
    "  fm2uav run examples/open_field_tff.yaml\n\n"
    "  fm2uav run examples/jacksboro_tff.yaml --out out/jacksboro --force\n\n"
    "  fm2uav run examples/open_field_tff.yaml --firmware ardupilot --end rtl "
    "--via 1400,300,300 --return --out out/open_field_ardu\n\n"
    "See docs/operator.md for the mission file format."
)


@handle_errors
@output_options(None, out_help="Output directory. Default: the mission's outputs.dir, else "
                "out/<mission file name>.")
@world_options
@mission_options("via", "return_to_start", "firmware", "vehicle", "frame", "end",
                 "speed_changes", "endurance", "reserve", "power", "battery",
                 "wind", "wind_file")
def run_cmd(
    mission_file: Path = typer.Argument(..., help="Mission YAML file.", show_default=False),
    output: Output = None,
    start: str | None = typer.Option(
        None, help="Override the mission's start: LON,LAT,AGL with --lonlat (degrees, "
        "degrees, metres above ground), else x,y,z metres."),
    goal: str | None = typer.Option(
        None, help="Override the mission's goal (as --start)."),
    lonlat: LonLatOpt = False,
    world: WorldFlags = None,
    mission: MissionFlags = None,
    no_fly: list[Path] | None = typer.Option(
        None, "--no-fly", help="No-fly zones file (GeoJSON lon/lat, KML/KMZ, GPKG, SHP; "
        "points need a 'radius' in metres), added to the mission's no_fly_zones. "
        "Repeatable.", show_default=False),
    min_agl: float | None = typer.Option(
        None, "--min-agl", help="Override planner.min_agl: hard floor (m) above the ground "
        "for the whole flight except the take-off/landing points."),
    max_agl: float | None = typer.Option(
        None, "--max-agl", help="Override planner.max_agl: hard ceiling (m) above the "
        "ground, e.g. 120."),
    saturation_distance: float | None = typer.Option(
        None, "--saturation-distance", help="Override planner.saturation_distance: the "
        "distance (m) from obstacles beyond which W = 1 (a margin that means the same on "
        "any map)."),
) -> None:
    """``fm2uav run``: load the mission file (with the flags' overrides),
    :func:`~fm2uav.pipeline.run.run_mission`, print."""
    from ..io.mission import load_mission
    from ..pipeline.run import run_mission
    from ..progress import reporting

    points = point_overrides(start=start, goal=goal, lonlat=lonlat) or {}
    if mission.via:
        points["via"] = via_points(mission.via, lonlat=lonlat)
    if mission.return_to_start is not None:
        points["return"] = mission.return_to_start
    m = load_mission(mission_file, world_overrides=world.overrides(),
                     point_overrides=points or None)
    options = mission.export_options(m.export_options())
    target = output.out or Path(m.outputs.dir or Path("out") / mission_file.stem)
    formats = list(dict.fromkeys(m.outputs.formats))
    outdir = output.dir(output_names(formats), path=target)
    planner = {k: v for k, v in (("min_agl", min_agl), ("max_agl", max_agl),
                                 ("saturation_distance", saturation_distance)) if v is not None}
    with output.progress() as step, reporting(lambda e: step(e.message)):
        run = run_mission(m, outdir, mission_file=mission_file, options=options,
                          planner=planner, no_fly=no_fly or ())
    p = run.plan
    rows = {
        "mission": m.name,
        "world": run.world_name,
        **plan_rows(p),
        "legs": len(run.route.legs),
        **safety_rows(run.info["safety"]),
        **mission_rows(run.built),
        "time [s]": f"{p.timings['total']:.2f}",
        **world_rows(run.resolved.world),
    }
    output.summary("fm2uav run", rows, {**run.info, "out": str(target)})


def register(app: typer.Typer, reproduce_app: typer.Typer) -> None:
    """Add the ``run`` command."""
    app.command("run", help=RUN_HELP)(run_cmd)
