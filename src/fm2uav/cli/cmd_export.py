"""``fm2uav export PATH.csv``: an existing path as an autopilot mission (any format)."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path
from types import SimpleNamespace

import typer

from ..errors import InputError
from ._common import Output, handle_errors, write_json, write_text
from .options import MissionFlags, mission_options, output_options
from .cmd_run import mission_rows, write_exports


def _world(mission_file: Path | None, scenario: str | None, seed: int):
    """(world, base ExportOptions or None, FlightLevel or None, description) of the world."""
    if (mission_file is None) == (scenario is None):
        raise InputError("give the world the path was planned on: --mission FILE.yaml (its "
                         "world, airframe and outputs) or --scenario NAME")
    if mission_file is not None:
        from ..io.mission import load_mission

        from ..planning.params import planner_objects

        m = load_mission(mission_file)
        rm = m.resolve()
        level = planner_objects(m.plan_kwargs())[1]
        return rm.world, m.export_options(), level, f"mission {mission_file}"
    from ..scenarios import get_scenario

    return get_scenario(scenario, seed=seed).world, None, None, f"scenario {scenario}"


EXPORT_HELP = (
    "Turn an existing path (path.csv, x_m,y_m,z_m[,speed]) into mission files: "
    "mission.plan (QGroundControl), mission.waypoints (QGC WPL 110), path.kml, "
    "path.kmz, path.geojson — with takeoff, end, altitude frame and firmware checks as "
    "every command writes them, and ArduPilot's terrain files (terrain/*.DAT) with a "
    "terrain-frame mission (--terrain). The world comes from the mission file the path was "
    "planned with (--mission) or a built-in scenario; a path whose '# crs=' header "
    "names another CRS than the world's is refused.\n\n"
    "Examples:\n\n"
    "  fm2uav export out/open_field_tff/path.csv --mission examples/open_field_tff.yaml "
    "--format plan,waypoints --firmware ardupilot --out out/ardu\n\n"
    "  fm2uav export out/plan/path.csv --scenario open-field --agl 150 --format kmz "
    "--out out/kmz\n\n"
    "  fm2uav export out/jacksboro/path.csv --mission examples/jacksboro_tff.yaml "
    "--terrain --terrain-spacing 50 --out out/jacksboro_terrain"
)


@handle_errors
@mission_options("firmware", "vehicle", "frame", "end", "thin", "anchor", "speed_changes",
                 "min_speed", "cruise_speed", "hover_speed", "endurance", "reserve", "terrain",
                 "terrain_spacing", "power", "battery", "wind", "wind_file")
@output_options("out/export", report_help="Also write report.html (interactive, "
                "self-contained: the path, its waypoints and the mission's numbers on the world).")
def export_cmd(
    path_file: Path = typer.Argument(..., help="Path CSV (as written by fm2uav)."),
    fmt: list[str] = typer.Option(
        ["plan,waypoints"], "--format", help="Formats (repeat or comma list): plan, "
        "waypoints (= wpl), kml, kmz, geojson, csv, or all."),
    mission_file: Path | None = typer.Option(
        None, "--mission", help="Mission YAML the path was planned with (world, airframe, "
        "outputs); the flags below override its values."),
    scenario: str | None = typer.Option(None, help="Built-in scenario the path is in."),
    seed: int = typer.Option(0, help="Seed of the scenario's relief."),
    agl: float | None = typer.Option(
        None, help="Requested height above ground (m) the path was planned at (default: "
        "the mission's planner.agl): waypoints on the level get exactly this AGL."),
    mission: MissionFlags = None,
    output: Output = None,
) -> None:
    """``fm2uav export``: read the path, :func:`~fm2uav.io.export_mission`, write, print."""
    from .._validate import input_file

    input_file(path_file, "path file")  # before the library loads: a wrong name answers at once
    from .. import progress
    from ..io import EXPORT_FILES, parse_formats

    formats = parse_formats(",".join(fmt))
    outdir = output.dir([EXPORT_FILES[f] for f in formats] + ["summary.json", "terrain"]
                        + (["report.html"] if output.report else []))
    with output.progress():
        progress.step("building the world", 0.4)
        world, base, mission_level, where = _world(mission_file, scenario, seed)
        progress.step("building the mission (altitudes, waypoints, firmware checks)", 0.5)
        rows, summary = _export(outdir, path_file, world, base, mission_level, where,
                                formats, mission, agl, report=output.report)
    output.summary("fm2uav export", rows, summary)


def _export(outdir, path_file: Path, world, base, mission_level, where: str, formats,
            mission, agl, *, report: bool = False):
    """Read the path, build its mission, write the files (and report.html with ``report``);
    ``(printed rows, summary)``."""
    from .. import progress
    from ..geometry import path_length
    from ..io import export_mission
    from ..io.path_header import read_path_header
    from ..planning import FlightLevel

    header = read_path_header(path_file)
    path, w, floor = _read_path(path_file, header, world, where)
    from ..pipeline.outputs import with_wind_on

    options = with_wind_on(mission.export_options(base), world)
    if options.speed_changes and w is None:
        raise InputError(f"--speed-changes needs W along the path: {path_file} has no "
                         "speed column (write it with fm2uav plan / run)")
    level = (FlightLevel(agl=agl) if agl is not None and mission_level is None else
             mission_level if agl is None else replace(mission_level, agl=agl))
    # a path with a final altitude profile (its floor column): heights as they are, legs
    # checked against the floor (see fm2uav.autopilot.build_mission)
    profile = None if floor is None else SimpleNamespace(
        required=floor, level=level if level is not None else FlightLevel(agl=1.0))
    track = SimpleNamespace(
        path=path, world=world, w=w, level=None, params={}, profile=profile,
        length=path_length(path))
    built, files = export_mission(track, formats, options,
                                  agl=None if level is None else level.agl)
    progress.step("writing the files", 0.1)
    write_exports(outdir, files)
    summary = {"path_file": str(path_file), "world": where, "path_crs": header["crs"],
               "points": len(path), "length_m": round(track.length, 3),
               "autopilot": built.summary()}
    rows = {"path": f"{path_file} ({len(path)} points, {track.length:.1f} m)",
            "world": where, **mission_rows(built)}
    if report:
        from ..viz.report import report_html

        write_text(outdir, "report.html", report_html(
            world, {"path": path}, speeds={"path": w} if w is not None else None,
            waypoints={"path": built.waypoints.points_m}, title=f"fm2uav export — {path_file.name}",
            subtitle=f"{built.summary()['firmware']} {built.summary()['vehicle']} mission on "
                     f"the {where} world", agl=None if level is None else level.agl,
            params={"path file": str(path_file), "formats": ", ".join(formats),
                    "waypoint tolerance [m]": options.tolerance},
            metrics=rows, files=[p.name for p in outdir.written] + ["summary.json"]))
    write_json(outdir, "summary.json", {**summary, "files": [p.name for p in outdir.written]
                                        + ["summary.json"]})
    return rows, summary


def _read_path(path_file: Path, header: dict, world, where: str):
    """``(path, W or None, floor or None)`` of a path CSV, checked against the world."""
    import numpy as np

    from ..io import read_path_csv
    from ..io.path_header import read_path_floor, read_path_w

    from ..world.geo import crs_label, crs_token

    crs = getattr(world, "crs", None)
    if header["crs"] and crs and header["crs"] not in (crs, crs_token(crs)):
        raise InputError(f"{path_file} says crs={header['crs']} but the {where} world is in "
                         f"{crs_label(crs)}: give the mission or scenario the path was planned on")
    if header["crs"] and not crs:
        raise InputError(f"{path_file} says crs={header['crs']} but the {where} world has "
                         "no CRS: give the mission file of that DEM (--mission)")
    path = read_path_csv(path_file)
    if path.shape[1] != world.ndim:
        raise InputError(f"{path_file} has {path.shape[1]} coordinates a point but the "
                         f"{where} world is {world.ndim}D")
    inside = world.contains(path)
    if not np.all(inside):
        k = int(np.argmin(inside))
        raise InputError(f"{path_file}: point {k} {np.round(path[k], 1).tolist()} m lies "
                         f"outside the {where} world; is this the world it was planned on?")
    return path, read_path_w(path_file), read_path_floor(path_file)


def register(app: typer.Typer, reproduce_app: typer.Typer) -> None:
    """Add the ``export`` command."""
    app.command("export", help=EXPORT_HELP)(export_cmd)
