"""``fm2uav run MISSION.yaml``: plan a mission file and write its exports and report.

Also holds :func:`plan_outputs`, the writer of a plan's output files shared by
``fm2uav plan`` and ``fm2uav run``.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

import numpy as np
import typer

from ..io.exports import EXPORT_FILES
from ..viz.overlays import zone_overlays  # noqa: F401  (re-exported: was defined here)
from ._common import (
    Output,
    OutputDir,
    handle_errors,
    plan_rows,
    write_figure,
    write_json,
    write_text,
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

#: Output format → file name, for every format a command can write.
OUTPUT_FILES = {**EXPORT_FILES, "html": "report.html", "png": "plan.png", "json": "summary.json"}


def write_exports(outdir: OutputDir, files: dict[str, Any],
                  step: Callable[[str], None] = lambda message: None) -> None:
    """Write :func:`fm2uav.io.export_mission` files into ``outdir`` (atomically each)."""
    for name, f in files.items():
        step(f"writing {name}")
        with outdir.open(name, mode="wb" if f.binary else "w") as fh:
            f.write(fh)


def mission_rows(mission: Any) -> dict[str, str]:
    """Printed summary rows of a built mission (frame, home, end, items, flight, warnings)."""
    s = mission.summary()
    h = s["home"]
    rows = {
        "autopilot mission": f"{s['firmware']} {s['vehicle']}, {s['items']} items, "
                             f"{s['waypoints']} waypoints, ends with {s['end']}",
        "altitude frame": f"{s['frame']['name']} (MAVLink frame {s['frame']['mav_frame']})",
        "home lat, lon, alt": f"{h['lat']:.7f}, {h['lon']:.7f}, {h['alt_amsl_m']:.1f} m AMSL "
                              f"({h['source']})",
        "flight": f"{s['flight']['flight_distance_m'] / 1000:.2f} km, "
                  f"{s['flight']['flight_time_s'] / 60:.1f} min",
    }
    sc = s["speed_changes"]
    kind = "airspeed" if sc.get("speed_type") == 0 else "ground speed"
    rows["speeds"] = (f"DO_CHANGE_SPEED {kind} {', '.join(f'{v:g}' for v in sc['speeds_mps'])} "
                      f"m/s ({sc['items']} item{'s' if sc['items'] != 1 else ''}, from "
                      f"{sc.get('from', 'the forward speed')})")
    co = s.get("climb_out")
    if co and co.get("mode") in ("straight", "loiter"):
        how = (f"climb in a {co['loiter_radius_m']:g} m loiter to {co['loiter_alt_m']:g} m"
               if co["mode"] == "loiter" else
               f"first waypoint {co['first_waypoint_m']:g} m ahead")
        rows["fixed-wing climb-out"] = (
            f"launch on course {co['course_deg']:g}° (the take-off item's direction), climb "
            f"straight to {co['takeoff_alt_m']:g} m above home in {co['climb_distance_m']:g} "
            f"m, then {how}")
    t = s.get("terrain")
    if t:
        rows["terrain files"] = (f"{', '.join('terrain/' + f for f in t['files'])} "
                                 f"({t['blocks']} blocks, {t['spacing_m']} m): {t['load']}; "
                                 f"{t['without']}")
    for k, w in enumerate(s["warnings"]):
        rows[f"warning {k + 1}"] = w
    return rows


def safety_rows(safety: dict[str, Any]) -> dict[str, str]:
    """Printed / report rows of :func:`fm2uav.analysis.safety.safety_summary`."""
    rows: dict[str, str] = {}
    hag = safety.get("height_above_ground", {})

    def fig(f: dict[str, Any]) -> str:
        band = f.get("within_band")
        share = "" if band is None else f", {100 * band:.0f} % within ±{f['band_m']:g} m"
        return (f"min {f['min_m']:.1f}, p5 {f['p5_m']:.1f}, median {f['median_m']:.1f}, "
                f"max {f['max_m']:.1f}{share}")
    if "cruise" in hag:
        rows["height above ground, cruise [m]"] = fig(hag["cruise"])
    if "path" in hag:
        low = hag["path"]
        rows["height above ground, whole path [m]"] = (
            fig(low) + f"; lowest at ({', '.join(f'{v:.0f}' for v in low['lowest_point_m'])}) m")
    legs = safety.get("legs")
    if legs:
        lc = legs.get("cruise", legs)
        rows["lowest AGL along the legs [m]"] = (f"{legs['min_m']:.1f} (cruise legs "
                                                 f"{lc['min_m']:.1f})")
    if "clearance_m" in safety:
        rows["clearance to the surface [m]"] = f"{safety['clearance_m']:.1f}"
    rows.update(ground_rows(safety))
    z = safety.get("zones")
    if z:
        near = min(z["distance_m"].values()) if z["distance_m"] else float("inf")
        rows["no-fly zones"] = (f"{z['count']}, nearest {near:.0f} m away, "
                                f"{len(z['path_entries'])} entries")
    bad = [k for k, c in safety.get("checks", {}).items() if not c.get("ok", True)]
    if bad:
        rows["limits NOT met"] = ", ".join(bad)
    return rows


def ground_rows(safety: dict[str, Any]) -> dict[str, str]:
    """Printed / report rows of the known/unknown ground split and the DEM resolution
    (:mod:`fm2uav.analysis.known_ground`)."""
    rows: dict[str, str] = {}
    g = safety.get("ground")
    if g:
        m, f = g["measured"], g["filled"]
        km = lambda v: f"{v / 1000:.2f} km"  # noqa: E731
        parts = [f"measured {km(m['length_m'])} ({100 * m['share']:.0f} %)"]
        for src in g.get("sources", [])[1:]:
            parts[0] += f"; of it from the fill DEM {src['dem']}: {km(src['length_m'])}"
        parts.append(f"FILLED (unknown, heights invented) {km(f['length_m'])} "
                     f"({100 * f['share']:.0f} %)" if f["length_m"] > 0 else "filled 0 km")
        rows["ground under the path"] = ", ".join(parts)
        if f["length_m"] > 0:
            for name, part in (("over measured ground", m), ("over FILLED ground", f)):
                hag = part.get("height_above_ground")
                if not hag:
                    continue
                band = hag.get("within_band")
                share = "" if band is None else f", {100 * band:.0f} % within ±{hag['band_m']:g} m"
                clr = f", clearance {part['clearance_m']:.1f}" if "clearance_m" in part else ""
                rows[f"height above ground {name} [m]"] = (
                    f"min {hag['min_m']:.1f}, median {hag['median_m']:.1f}{share}{clr}"
                    + (" (against invented ground)" if part is f else ""))
        legs = (safety.get("legs") or {}).get("ground")
        if legs and legs.get("filled_min_m") is not None:
            rows["lowest AGL along the legs, measured / FILLED ground [m]"] = (
                f"{legs['measured_min_m'] if legs['measured_min_m'] is not None else '-'} / "
                f"{legs['filled_min_m']}")
    r = safety.get("dem_resolution")
    if r:
        rows["DEM resolution"] = (
            f"{r['pixel_m']:.0f} m pixels, slope p95 {r['slope_p95_deg']:.0f}°: up to "
            f"{r['hidden_relief_m']:.0f} m of relief can hide between pixels ("
            + ("ok" if r["ok"] else "TOO COARSE") + f" for {r['agl_m']:g} m above ground"
            + ("" if r["ok"] or not r.get("needed_pixel_m") else
               f"; needs pixels of <= {r['needed_pixel_m']:.0f} m") + ")")
    return rows


def _with_cli_zones(rm: Any, files: Sequence[Path]) -> Any:
    """The resolved mission with the ``--no-fly`` files' zones added to its world."""
    import dataclasses

    from ..io.zone_spec import zones_from_cli
    from ..world.zones import check_points_allowed, with_zones

    world = with_zones(rm.world, zones_from_cli([str(f) for f in files], rm.world))
    check_points_allowed(world, {"start": rm.start, "goal": rm.goal,
                                 **{f"via[{k}]": v for k, v in enumerate(rm.via)}})
    return dataclasses.replace(rm, world=world)


def output_names(formats: Sequence[str]) -> list[str]:
    """File names of the given output formats (for ``OutputDir.check``)."""
    return [OUTPUT_FILES[f] for f in formats]


def plan_outputs(
    outdir: OutputDir,
    plan: Any,
    formats: Sequence[str],
    options: Any,
    *,
    title: str,
    subtitle: str = "",
    summary: dict[str, Any] | None = None,
    step: Callable[[str], None] = lambda message: None,
    **mission_inputs: Any,
) -> tuple[dict[str, Any], Any]:
    """Write the requested outputs of a plan into ``outdir`` (atomically each).

    Parameters
    ----------
    outdir : OutputDir
    plan : fm2uav.Plan
    formats : sequence of str
        Keys of :data:`OUTPUT_FILES`.
    options : fm2uav.io.ExportOptions
        Waypoint thinning, frame, anchor, airframe.
    title, subtitle : str
        Of the HTML report and PNG figure.
    summary : dict, optional
        Extra entries of ``summary.json``.
    **mission_inputs
        ``via``, ``camera``, ``fences``, ``agl`` of :func:`fm2uav.io.export_mission`.

    Returns
    -------
    info : dict
        The summary (plan numbers, the autopilot mission, waypoints, home, files).
    mission : fm2uav.io.MissionExport
        The built mission.
    """
    from ..analysis.known_ground import check_ground
    from ..analysis.safety import safety_summary
    from ..io import export_mission
    from ..autopilot.geofence import zone_fences

    exports = [f for f in formats if f in EXPORT_FILES]
    zones = tuple(getattr(plan.world, "zones", ()))
    fence_warnings: list[str] = []
    if zones and "fences" not in mission_inputs:  # no-fly zones -> the .plan geoFence
        mission_inputs["fences"], fence_warnings = zone_fences(
            zones, plan.world, getattr(options, "anchor", None))
    step("building the mission (altitudes, waypoints, takeoff, end, firmware checks)")
    mission, files = export_mission(plan, exports, options, **mission_inputs)
    wps = mission.waypoints
    step("measuring the flight against the ground, the zones and the limits")
    level = getattr(plan, "level", None)
    safety = safety_summary(
        plan.world, plan.path, requested=None if level is None else level.agl,
        phase=getattr(plan, "phase", None), waypoints=wps.points_m,
        waypoint_indices=wps.indices, terrain_frame=wps.frame == 10, waypoint_agl=wps.agl,
        level=level)
    if zones:
        safety["geofence"] = {"fences": len(mission_inputs.get("fences") or ()),
                              "warnings": fence_warnings}
    check_ground(plan.world, safety)  # filled ground: warned, or refused (error_on_route)
    info = {
        **(summary or {}),
        **plan.summary(),
        "autopilot": mission.summary(),
        "waypoints": len(wps),
        "mavlink_frame": wps.frame,
        "home_lat_lon_alt": [round(v, 9) for v in wps.home],
        "thin_tolerance_m": options.tolerance,
        "safety": safety,
    }
    write_exports(outdir, files, step)
    if "html" in formats:
        step("writing report.html")
        write_text(outdir, "report.html", _plan_report(
            plan, info, wps, options, formats, title=title, subtitle=subtitle, zones=zones,
            fence_warnings=fence_warnings))
    if "png" in formats:
        from ..viz import plan_figure

        step("writing plan.png")
        write_figure(outdir, plan_figure(plan, title=title, ground=safety.get("ground")),
                     "plan.png")
    if "json" in formats:
        write_json(outdir, "summary.json", {**info, "files": [str(p.name) for p in outdir.written]
                                            + ["summary.json"]})
    return info, mission


def _plan_report(plan: Any, info: dict[str, Any], wps: Any, options: Any,
                 formats: Sequence[str], *, title: str, subtitle: str, zones: Any,
                 fence_warnings: list[str]) -> str:
    """report.html of a plan and its autopilot mission's waypoints ``wps`` (see
    :func:`plan_outputs`)."""
    from ..analysis.known_ground import ground_notes
    from ..viz.overlays import filled_overlay, filled_path_overlay
    from ..viz.report import report_html

    ms, level = info["autopilot"], getattr(plan, "level", None)
    params = {**plan.params, "waypoint tolerance [m]": options.tolerance,
              "firmware / airframe": f"{ms['firmware']} / {ms['vehicle']}",
              "MAVLink frame": {0: "0 (AMSL: DEM ground + AGL)", 3: "3 (relative to home)",
                                10: "10 (above terrain)"}.get(wps.frame, wps.frame),
              "mission end": ms["end"]}
    metrics = {
        "length [m]": round(float(plan.length), 1),
        "clearance [m]": (round(float(plan.clearance), 2) if np.isfinite(plan.clearance)
                          else "inf"),
        "min W on path": round(float(np.min(plan.w)), 4),
        "path points": len(plan.path),
        "waypoints": len(wps),
        "mission items": ms["items"],
        "home (lat, lon, alt AMSL)": [round(v, 7) for v in wps.home],
        "flight time [min]": round(ms["flight"]["flight_time_s"] / 60, 2),
        "planning time [s]": round(float(plan.timings.get("total", 0.0)), 3),
        **safety_rows(info["safety"]),
        **{f"warning {k + 1}": w for k, w in enumerate(ms["warnings"] + fence_warnings)},
    }
    return report_html(
        plan.world, {"FM² path": plan.path}, title=title, subtitle=subtitle,
        speeds={"FM² path": plan.w}, waypoints={"FM² path": wps.points_m},
        params=params, metrics=metrics, files=output_names(formats),
        agl=None if level is None else level.agl,
        overlays={**filled_overlay(plan.world), **filled_path_overlay(plan.world, plan.path),
                  **zone_overlays(zones)},
        notes=list(ground_notes(plan.world, info["safety"]).values()))


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
                 "speed_changes", "endurance", "reserve")
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
    :func:`~fm2uav.missions.route.plan_route`, :func:`plan_outputs`, print."""
    from ..io.mission import load_mission
    from ..missions.route import plan_route
    from ..planning.params import planner_objects
    from ..world.load import world_summary

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
    with output.progress() as step:
        step("building the world")
        rm = m.resolve()
        if no_fly:
            rm = _with_cli_zones(rm, no_fly)
        step("planning (FM²)" + (f", {len(rm.via) + 1 + rm.return_to_start} legs"
                                 if rm.via or rm.return_to_start else ""))
        planner = {**m.plan_kwargs(), **{k: v for k, v in (
            ("min_agl", min_agl), ("max_agl", max_agl),
            ("saturation_distance", saturation_distance)) if v is not None}}
        shaping, level, popts = planner_objects(planner)
        route = plan_route(rm.world, rm.start, rm.goal, via=rm.via,
                           return_to_start=rm.return_to_start, shaping=shaping,
                           level=level, options=popts)
        p = route.plan
        world_desc = m.world.scenario or m.world.describe()
        info, built = plan_outputs(
            outdir, p, formats, options,
            title=f"{m.name}", subtitle=f"{world_desc} — {m.description}"
            if m.description else world_desc,
            summary={"mission": m.name, "mission_file": str(mission_file),
                     "world": {**world_summary(rm.world), "name": world_desc},
                     "route": route.summary()},
            step=step, via=route.junctions[1:-1],
        )
    rows = {
        "mission": m.name,
        "world": world_desc,
        **plan_rows(p),
        "legs": len(route.legs),
        **safety_rows(info["safety"]),
        **mission_rows(built),
        "time [s]": f"{p.timings['total']:.2f}",
        **world_rows(rm.world),
    }
    output.summary("fm2uav run", rows, {**info, "out": str(target)})


def register(app: typer.Typer, reproduce_app: typer.Typer) -> None:
    """Add the ``run`` command."""
    app.command("run", help=RUN_HELP)(run_cmd)
