"""The output set of a plan: exports, report, figure and summary, written atomically.

Shared by ``fm2uav plan``, ``fm2uav run``, ``fm2uav cover`` and the web app, so
that every front end writes the same files from the same plan. Each file goes
into an :class:`fm2uav.io.outdir.OutputDir` (renamed into place when the whole
set is complete). Stages are reported through :mod:`fm2uav.progress`.
"""

from __future__ import annotations

import json
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from .. import progress
from ..errors import InputError
from ..io.formats import EXPORT_FILES
from .rows import returns_rows, safety_rows

__all__ = ["OUTPUT_FILES", "EXPORT_FILES", "output_names", "write_exports", "plan_outputs",
           "flown", "to_jsonable", "write_json", "write_text", "write_figure", "export_options",
           "parse_anchor", "wind_options", "with_wind_on"]

#: Output format → file name, for every format a command can write.
OUTPUT_FILES = {**EXPORT_FILES, "html": "report.html", "png": "plan.png", "json": "summary.json"}


def to_jsonable(obj: Any) -> Any:
    """Convert numpy scalars/arrays and paths into plain JSON types."""
    import numpy as np

    if isinstance(obj, dict):
        return {str(k): to_jsonable(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [to_jsonable(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return to_jsonable(obj.tolist())
    if isinstance(obj, np.generic):
        return obj.item()
    if isinstance(obj, Path):
        return str(obj)
    if isinstance(obj, float) and not np.isfinite(obj):
        return None
    return obj


def write_json(outdir: Any, name: str, payload: Any) -> None:
    """Write ``payload`` (numpy values allowed) as indented JSON into the output set."""
    with outdir.open(name) as fh:
        json.dump(to_jsonable(payload), fh, indent=2)


def write_text(outdir: Any, name: str, text: str) -> None:
    """Write a text file (Markdown, CSV, HTML) into the output set."""
    with outdir.open(name) as fh:
        fh.write(text)


def write_figure(outdir: Any, fig: Any, name: str, dpi: int = 110) -> None:
    """Save a matplotlib figure as ``name`` (PNG) into the output set."""
    tmp = outdir.target(name)
    try:
        fig.savefig(tmp, dpi=dpi)
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise
    outdir.commit(tmp, name)


def output_names(formats: Sequence[str]) -> list[str]:
    """File names of the given output formats (for ``OutputDir.check``)."""
    return [OUTPUT_FILES[f] for f in formats]


@progress.stage()
def write_exports(outdir: Any, files: dict[str, Any]) -> None:
    """Write :func:`fm2uav.io.export_mission` files into ``outdir`` (atomically each).

    Each file is a :mod:`fm2uav.progress` step.
    """
    for name, f in files.items():
        progress.step(f"writing {name}", 1.0 / max(1, len(files)))
        with outdir.open(name, mode="wb" if f.binary else "w") as fh:
            f.write(fh)


@progress.stage()
def plan_outputs(
    outdir: Any,
    plan: Any,
    formats: Sequence[str],
    options: Any,
    *,
    title: str,
    subtitle: str = "",
    summary: dict[str, Any] | None = None,
    returns: Any = None,
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
    returns : ReturnOptions, optional
        Compute the safe returns (:mod:`fm2uav.autopilot.safe_return`): ``returns`` and
        ``point_of_no_return`` in the summary, the return files, the report's ways back;
        the figures then describe the plan as flown (:func:`flown`).
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
    from ..autopilot.geofence import zone_fences
    from ..io import export_mission

    options = with_wind_on(options, plan.world)
    exports = [f for f in formats if f in EXPORT_FILES]
    zones = tuple(getattr(plan.world, "zones", ()))
    fence_warnings: list[str] = []
    if zones and "fences" not in mission_inputs:  # no-fly zones -> the .plan geoFence
        mission_inputs["fences"], fence_warnings = zone_fences(
            zones, plan.world, getattr(options, "anchor", None))
    progress.step("building the mission (altitudes, waypoints, takeoff, end, firmware checks)"
                  + ("; the ways back, rally points, firmware return settings"
                     if returns is not None and returns.enabled else ""), 0.2)
    mission, files = export_mission(plan, exports, options, returns=returns, **mission_inputs)
    plan = flown(plan, mission)
    wps = mission.waypoints
    progress.step("measuring the flight against the ground, the zones and the limits", 0.2)
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
        "home_lat_lon_alt": [round(v, 9) for v in wps.home[:2]]
        + [round(wps.home[2], 9) if wps.amsl else None],
        "thin_tolerance_m": options.tolerance,
        "safety": safety,
    }
    if getattr(mission, "returns", None) is not None:
        info["returns"] = mission.returns.summary(plan.world, options.anchor)
        info["point_of_no_return"] = mission.returns.pnr
    progress.step("writing the exports", 0.3)
    write_exports(outdir, files)
    if "html" in formats:
        progress.step("writing report.html", 0.2)
        write_text(outdir, "report.html", _plan_report(
            plan, info, mission, options, formats, title=title, subtitle=subtitle, zones=zones,
            fence_warnings=fence_warnings, via=mission_inputs.get("via"),
            returns=mission.returns))
    if "png" in formats:
        from ..viz import plan_figure

        progress.step("writing plan.png", 0.1)
        write_figure(outdir, plan_figure(plan, title=title, ground=safety.get("ground"),
                                         anchor=getattr(options, "anchor", None)), "plan.png")
    if "json" in formats:
        write_json(outdir, "summary.json", {**info, "files": [str(p.name) for p in outdir.written]
                                            + ["summary.json"]})
    return info, mission


def flown(plan: Any, mission: Any) -> Any:
    """The plan as the mission flies it: with the planned safe return appended when the
    mission carries one (:func:`fm2uav.autopilot.safe_return.flown_plan`), else ``plan``."""
    if getattr(mission, "returns", None) is None:
        return plan
    from ..autopilot.safe_return import flown_plan

    return flown_plan(plan, mission)


def _return_overlays(returns: Any) -> dict[str, Any]:
    """Report overlays: the way back from every waypoint, the point of no return's, rally
    points (crosses)."""
    if returns is None:
        return {}
    import numpy as np

    out: dict[str, Any] = {}
    lines = [p for p in returns.waypoint_paths().values() if len(p) >= 2]
    if lines:
        gap = np.full((1, 3), np.nan)
        pts = np.concatenate([np.vstack([p[:, :3], gap]) for p in lines])[:-1]
        out["ways back (from each waypoint)"] = {"points": pts, "color": "#9467bd",
                                                 "width": 2, "dash": "dot"}
    if returns.pnr_path is not None and len(returns.pnr_path) >= 2:
        out["point of no return: way back"] = {"points": returns.pnr_path[:, :3],
                                               "color": "#d62728", "width": 5}
        x, y, z = (float(v) for v in returns.pnr_path[0, :3])
        d = 40.0
        out["point of no return"] = {"points": np.array([
            [x - d, y, z], [x + d, y, z], [np.nan] * 3, [x, y - d, z], [x, y + d, z],
            [np.nan] * 3, [x, y, z - d], [x, y, z + d]]), "color": "#d62728", "width": 8}
    marks = []
    for r in returns.rally:
        x, y = float(r.point[0]), float(r.point[1])
        d = 25.0
        marks += [np.array([[x - d, y], [x + d, y]]), np.full((1, 2), np.nan),
                  np.array([[x, y - d], [x, y + d]]), np.full((1, 2), np.nan)]
    if marks:
        out["rally points"] = {"points": np.concatenate(marks[:-1]), "color": "#ff7f0e",
                               "width": 5}
    return out


def _plan_report(plan: Any, info: dict[str, Any], mission: Any, options: Any,
                 formats: Sequence[str], *, title: str, subtitle: str, zones: Any,
                 fence_warnings: list[str], via: Any = None,
                 returns: Any = None) -> str:
    """report.html of a plan and its autopilot mission (see :func:`plan_outputs`): the
    mission's map and the operator's figures first, the planner's details folded away."""
    import numpy as np

    from ..analysis.known_ground import ground_notes
    from ..viz.mapdata import mission_map
    from ..viz.overlays import filled_overlay, filled_path_overlay, zone_overlays
    from ..viz.report import report_html
    from .rows import mission_figures

    wps = mission.waypoints
    ms, level = info["autopilot"], getattr(plan, "level", None)
    anchor = getattr(options, "anchor", None)
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
        "home (lat, lon, alt AMSL)": [round(v, 7) for v in wps.home[:2]]
        + [round(wps.home[2], 7) if wps.amsl else "unknown"],
        "flight time [min]": round(ms["flight"]["flight_time_s"] / 60, 2),
        "planning time [s]": round(float(plan.timings.get("total", 0.0)), 3),
        **safety_rows(info["safety"]),
        **returns_rows(info),
    }
    path = np.asarray(plan.path, dtype=float)
    junctions = None if via is None else [0, *[int(v) for v in via], len(path) - 1]
    points = {"start": path[0], **{f"via {k + 1}": path[int(v)] for k, v in
                                   enumerate(via if via is not None else [])},
              "goal": path[-1]}
    doc = mission_map(plan, mission, info["safety"], points=points, anchor=anchor,
                      junctions=junctions)
    warnings = list(ground_notes(plan.world, info["safety"]).values())
    warnings += [w for w in ms["warnings"] + fence_warnings if w not in warnings]
    return report_html(
        plan.world, {"FM² path": plan.path}, title=title, subtitle=subtitle,
        speeds={"FM² path": plan.w}, waypoints={"FM² path": wps.points_m},
        params=params, metrics=metrics, files=output_names(formats),
        agl=None if level is None else level.agl,
        overlays={**_not_on_map(filled_overlay(plan.world)),
                  **_not_on_map(filled_path_overlay(plan.world, plan.path)),
                  **_not_on_map(zone_overlays(zones)),
                  **_not_on_map(_return_overlays(returns))},
        notes=warnings, map_doc=doc, anchor=anchor,
        figures=mission_figures(plan.length, mission, info["safety"], plan.world,
                                anchor=anchor))


def _not_on_map(overlays: dict[str, Any]) -> dict[str, Any]:
    """Report overlays for the 3D view only (the map draws zones and filled ground itself)."""
    return {k: {**v, "map": False} for k, v in overlays.items()}


def export_options(base: Any = None, *, firmware: str | None = None, vehicle: str | None = None,
                   frame: str | None = None, end: str | None = None, thin: float | None = None,
                   anchor: str | None = None, speed_changes: bool | None = None,
                   min_speed: float | None = None, cruise_speed: float | None = None,
                   hover_speed: float | None = None, endurance: float | None = None,
                   reserve: float | None = None, terrain: bool | None = None,
                   terrain_spacing: int | None = None, power: str | None = None,
                   battery: float | None = None, wind: str | None = None,
                   wind_file: str | None = None, **more: Any) -> Any:
    """``base`` (default ``ExportOptions()``) with the settings that were given (None =
    not given): the command line's mission flags, the app's aircraft and mission fields.

    ``thin`` is the waypoint tolerance [m], ``endurance`` in minutes, ``anchor`` the
    ``lon,lat[,alt]`` text of ``--anchor``, ``power`` a power-model preset or file,
    ``battery`` in Wh, ``wind`` the ``SPEED@DIR`` text of ``--wind``, ``wind_file`` a
    NetCDF / GeoTIFF wind (checked now, read onto the map by :func:`with_wind_on`).

    Raises
    ------
    InputError
        A tolerance outside [0, 1000] m (the mission file's range), a non-positive
        endurance (naming the flag).
    """
    from dataclasses import replace

    from ..autopilot import ExportOptions
    from ..world.wind import parse_wind_text

    given = {"firmware": firmware, "vehicle": vehicle, "frame": frame, "end": end,
             "tolerance": thin, "anchor": parse_anchor(anchor), "speed_changes": speed_changes,
             "min_speed": min_speed, "cruise_speed": cruise_speed, "hover_speed": hover_speed,
             "endurance_s": None if endurance is None else 60.0 * float(endurance),
             "reserve": reserve, "terrain": terrain, "terrain_spacing": terrain_spacing,
             "power": power, "battery_wh": battery,
             "wind": None if wind is None else parse_wind_text(wind), **more}
    if wind_file is not None:
        if wind is not None:
            raise InputError("give --wind or --wind-file, not both")
        from ..world.wind import WindField
        from ..world.wind_files import check_wind_file

        given["wind"] = WindField.from_file(check_wind_file(wind_file))
    if thin is not None and not 0 <= thin <= 1000:
        raise InputError(f"--thin must be a tolerance in [0, 1000] m (mission file: "
                         f"outputs.thin_tolerance), got {thin}")
    if endurance is not None and not endurance > 0:
        raise InputError(f"--endurance must be > 0 minutes, got {endurance}")
    if battery is not None and not battery > 0:
        raise InputError(f"--battery must be > 0 Wh, got {battery}")
    if power is not None:
        from ..vehicles.power import get_power_model

        get_power_model(power)  # an unknown preset or a bad file: refused before any work
    return replace(base or ExportOptions(), **{k: v for k, v in given.items() if v is not None})


def parse_anchor(text: str | None) -> Any:
    """``"lon,lat[,alt]"`` (``--anchor``) → :class:`~fm2uav.io.Anchor` (None → None)."""
    if text is None:
        return None
    from ..io import Anchor

    try:
        v = [float(x) for x in text.replace(",", " ").split()]
    except ValueError:
        v = []
    if len(v) not in (2, 3):
        raise InputError(f"--anchor must be lon,lat or lon,lat,alt (degrees, degrees, "
                         f"metres), got {text!r}")
    return Anchor(lon=v[0], lat=v[1], alt=v[2] if len(v) == 3 else 0.0)


def wind_options(options: Any) -> Any:
    """The :class:`~fm2uav.planning.wind.WindOptions` of a mission's export options: its
    wind (``--wind`` / ``wind:``) at the forward speed (the airspeed at W = 1), or None."""
    if getattr(options, "wind", None) is None:
        return None
    from ..planning.wind import WindOptions

    return WindOptions(options.wind, options.forward_speed)


def with_wind_on(options: Any, world: Any) -> Any:
    """``options`` with a file's wind read onto ``world`` (any other wind unchanged)."""
    wind = getattr(options, "wind", None)
    if wind is None or wind.kind != "file":
        return options
    from dataclasses import replace

    from ..world.wind_files import resolve_wind

    return replace(options, wind=resolve_wind(wind, world, anchor=getattr(options, "anchor",
                                                                           None)))
