"""``fm2uav run MISSION.yaml``: plan a mission file and write its exports and report.

The run itself is :func:`fm2uav.pipeline.run.run_mission` (shared with the web
app); the writer of a plan's output files, :func:`plan_outputs`, is
:mod:`fm2uav.pipeline.outputs`' (re-exported here for the other commands).
"""

from __future__ import annotations

from pathlib import Path

import typer

from .._lazy import lazy_names
from ..pipeline.rows import ground_rows, mission_rows, safety_rows  # noqa: F401  (re-exported)
from ._common import (
    Output,
    handle_errors,
    plan_rows,
)
from ._mission_options import via_points
from ._return_options import ReturnFlags, return_options
from .options import (
    MISSION_FLAGS,
    MissionFlags,
    WorldFlags,
    mission_options,
    output_options,
    point_overrides,
    world_options,
    world_rows,
)

# re-exported from fm2uav.pipeline.outputs on first use (were defined here): a parse error
# or a mission file's does not load it
__getattr__, __dir__ = lazy_names(__name__, dict.fromkeys(
    ("OUTPUT_FILES", "output_names", "plan_outputs", "write_exports"),
    "fm2uav.pipeline.outputs"))

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
@output_options(None, out_help="Output directory. Default: the mission's outputs.dir "
                "(relative to the mission file), else out/<mission file name> in the current "
                "folder.", report_help="Also write report.html (interactive, self-contained) "
                "when outputs.formats leaves it out (the default formats include it).")
@world_options
@mission_options(*MISSION_FLAGS, "thin", "anchor")
@return_options
def run_cmd(
    mission_file: Path = typer.Argument(..., help="Mission YAML file.", show_default=False),
    output: Output = None,
    start: str | None = typer.Option(
        None, help="Override the mission's start: LON,LAT,AGL with --lonlat (degrees, "
        "degrees, metres above ground), else x,y,z metres."),
    goal: str | None = typer.Option(
        None, help="Override the mission's goal (as --start)."),
    lonlat: bool = typer.Option(
        False, "--lonlat", help="Read --start/--goal as LON,LAT,AGL (degrees, degrees, metres "
        "above the ground)."),
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
    returns: ReturnFlags = None,
) -> None:
    """``fm2uav run``: load the mission file (with the flags' overrides),
    :func:`~fm2uav.pipeline.run.run_mission`, print."""
    from .._validate import input_file

    input_file(mission_file, "")  # a missing mission file is refused before the heavy imports
    from ._pydantic_plugins import import_plugin_loader

    import_plugin_loader()  # before the schema's models: no importlib.metadata
    from ..io.mission import load_mission

    returns.check()
    points = point_overrides(start=start, goal=goal, lonlat=lonlat) or {}
    if mission.via:
        points["via"] = via_points(mission.via, lonlat=lonlat)
    if mission.return_to_start is not None:
        points["return"] = mission.return_to_start
    m = load_mission(mission_file, world_overrides=world.overrides(),
                     point_overrides=points or None)
    # the run's modules once the mission file is valid (its error answers without them)
    from ..pipeline.outputs import flown, output_names
    from ..pipeline.rows import returns_rows
    from ..pipeline.run import run_mission
    from ._first_use import announce_compile

    announce_compile(quiet=output.quiet)  # on a cold cache, once the mission file is valid
    options = mission.export_options(m.export_options())
    # outputs.dir is relative to the mission file, like every path in it (io/mission.py)
    target = output.out or m.output_dir() or Path("out") / mission_file.stem
    notice = None if output.out else m.output_dir_notice()
    if notice:
        import warnings

        from ..io.mission import MissionWarning

        warnings.warn(notice, MissionWarning, stacklevel=1)
    formats = list(dict.fromkeys(m.outputs.formats + (["html"] if output.report else [])))
    outdir = output.dir(output_names(formats), path=target)
    planner = {k: v for k, v in (("min_agl", min_agl), ("max_agl", max_agl),
                                 ("saturation_distance", saturation_distance)) if v is not None}
    with output.progress():
        run = run_mission(m, outdir, mission_file=mission_file, options=options,
                          planner=planner, no_fly=no_fly or (), formats=formats,
                          returns=lambda mi, w: returns.options(
                              w, base=mi.return_options(w), anchor=mi.anchor(),
                              crs=mi.world.crs))
    p = flown(run.plan, run.built)
    rows = {
        "mission": m.name,
        "world": run.world_name,
        **plan_rows(p),
        "legs": len(run.route.legs),
        **safety_rows(run.info["safety"]),
        **returns_rows(run.info),
        **mission_rows(run.built),
        "time [s]": f"{p.timings['total']:.2f}",
        **world_rows(run.resolved.world),
    }
    output.summary("fm2uav run", rows, {**run.info, "out": str(target)})


def register(app: typer.Typer, reproduce_app: typer.Typer) -> None:
    """Add the ``run`` command."""
    app.command("run", help=RUN_HELP)(run_cmd)
