"""A coverage mission from an area to its output set (shared by ``fm2uav cover`` and the app).

:func:`run_cover` plans the zigzag bands and FM² along them
(:func:`fm2uav.missions.coverage.plan_coverage`), the camera triggering, the
autopilot mission, and writes the mission files, the figures, ``coverage.html``,
``report.html`` (optional) and ``summary.json`` into an output set.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from .. import progress
from .outputs import write_exports, write_figure, write_json
from .rows import mission_rows, safety_rows, world_rows

__all__ = ["COVER_EXPORTS", "COVER_FILES", "REPORT", "CoverRun", "run_cover", "cover_outputs",
           "cover_rows", "band_cell", "cover_sorties", "sortie_rows", "across_wind_angle"]

#: Mission files of a coverage flight (written by fm2uav.io.export_mission).
COVER_EXPORTS = ("csv", "plan", "wpl", "kml", "kmz", "geojson")
COVER_FILES = ("path.csv", "zigzag.csv", "bands.png", "coverage.png", "coverage.html",
               "summary.json", "mission.plan", "mission.waypoints", "path.kml", "path.kmz",
               "path.geojson")
REPORT = "report.html"


def band_cell(spacing: float, zones: bool) -> tuple[float, str] | None:
    """The largest automatic cell [m] (and why) of a survey with band spacing ``spacing``
    [m] around no-fly zones (``zones``), for :func:`fm2uav.world.load.load_world`'s
    ``max_cell``: the route around them resolves bands only
    :data:`~fm2uav.missions.coverage.zones.ROUTE_BAND_CELLS` cells apart (the corridor
    grid of a survey without zones resolves any spacing: None)."""
    from ..missions.coverage.zones import ROUTE_BAND_CELLS, route_cell

    if not zones:
        return None
    cell = route_cell(spacing)
    return cell, (f"at most D / {ROUTE_BAND_CELLS:g} = {cell:.3g} m so that the route around "
                  "the no-fly zones resolves the bands")


@dataclass(frozen=True)
class CoverRun:
    """What :func:`run_cover` planned and wrote: the coverage plan, the camera plan, the
    autopilot mission, its safety figures and the ``summary.json`` document."""

    coverage: Any
    shots: Any
    built: Any
    safety: dict[str, Any]
    summary: dict[str, Any]


@progress.stage()
def run_cover(outdir: Any, world: Any, area: Any, *, area_label: str, spacing: float,
              level: Any, options: Any, camera: Any = None, front_overlap: float = 0.0,
              trigger_distance: float | None = None, angle_deg: float | None = None,
              search: str = "de", search_options: dict[str, Any] | None = None, seed: int = 0,
              shaping: Any = None, report: bool = False,
              summary: dict[str, Any] | None = None) -> CoverRun:
    """Plan the coverage of ``area`` and write its output set (see the module docstring).

    Parameters
    ----------
    outdir : fm2uav.io.outdir.OutputDir
    world : World
        With the no-fly zones as obstacles (their geofences go into the ``.plan``).
    area : shapely Polygon
        In world metres (:func:`fm2uav.missions.coverage.area.load_area`).
    area_label : str
        How the area is named in titles (``--area``).
    spacing : float
        Band spacing D [m].
    level : FlightLevel
    options : fm2uav.io.ExportOptions
    camera : Camera, optional
    front_overlap, trigger_distance
        Photos along the bands (:func:`fm2uav.missions.coverage.triggers.camera_plan`).
    angle_deg : float, optional
        Steering angle [deg]; default: searched with ``search``.
    search, search_options, seed, shaping
        As :func:`fm2uav.missions.coverage.plan_coverage`.
    report : bool
        Also write ``report.html``.
    summary : dict, optional
        First entries of ``summary.json`` (the area, the world).
    """
    from ..missions.coverage import plan_coverage
    from ..missions.coverage.triggers import camera_plan
    from .outputs import with_wind_on

    options = with_wind_on(options, world)

    progress.step("planning the bands and FM² along them", 0.75)
    cp = plan_coverage(world, area, spacing, level=level,
                       angle=None if angle_deg is None else np.radians(angle_deg),
                       search=search, search_options=search_options or {}, seed=seed,
                       shaping=shaping)
    progress.step("writing the mission files and figures", 0.25)
    shots = camera_plan(cp, camera=camera, front_overlap=front_overlap,
                        trigger_distance=trigger_distance)
    built, safety = cover_outputs(outdir, cp, area_label, report=report,
                                  title=f"coverage of {area_label}", options=options,
                                  camera=shots, cam=camera)
    doc = {**(summary or {}), **cp.summary(), "autopilot": built.summary(), "safety": safety}
    progress.step("splitting the survey by battery", 0.0)
    sorties = cover_sorties(outdir, cp, built, shots, options=options, shaping=shaping)
    if sorties is not None:
        doc["sorties"] = sorties
    write_json(outdir, "summary.json", doc)
    return CoverRun(coverage=cp, shots=shots, built=built, safety=safety, summary=doc)


def _cover_report(outdir: Any, cp, *, title: str, subtitle: str, metrics: dict,
                  mission: Any, shots: Any, safety: dict, options: Any = None,
                  camera: Any = None, files=(), notes=()) -> None:
    """report.html of a coverage mission: the map (area, bands, photo footprints, the
    route by height above ground, numbered items) and the survey's figures first."""
    from ..viz.coverage import coverage_overlays
    from ..viz.mapdata import coverage_features, mission_map
    from ..viz.overlays import filled_overlay, filled_path_overlay, zone_overlays
    from ..viz.report import report_html
    from .outputs import _not_on_map
    from .rows import coverage_figures, mission_figures

    name = "FM² path"
    world = cp.plan.world
    anchor = getattr(options, "anchor", None)
    doc = mission_map(cp.plan, mission, safety, anchor=anchor,
                      points={"start": cp.path[0], "goal": cp.path[-1]})
    photos = coverage_features(cp, shots, camera, anchor, merge_above=2000)
    doc["features"] += photos
    n_photos = sum(f["properties"].get("photos", 1) for f in photos
                   if f["properties"]["kind"] == "photo")
    many = cp.zigzag.n_bands > 40
    cover = {k: {**v, "map": False, **({"scene": False} if many and k == "bands" else {})}
             for k, v in coverage_overlays(cp).items()}
    overlays = {**_not_on_map(filled_overlay(world)),
                **_not_on_map(filled_path_overlay(world, cp.path)), **cover,
                **_not_on_map(zone_overlays(getattr(world, "zones", ())))}
    figures = {**mission_figures(cp.plan.length, mission, safety, world, anchor=anchor),
               **coverage_figures(cp, shots, mission, photos=n_photos, camera=camera)}
    html = report_html(
        world, {name: cp.path}, title=title, subtitle=subtitle,
        speeds={name: cp.plan.w}, ideal_agl={name: cp.level.agl},
        waypoints={name: mission.waypoints.points_m}, styles={name: {"colorby": "distance"}}
        if many else None, overlays=overlays, params=cp.params, metrics=metrics,
        files=files, notes=notes, map_doc=doc, anchor=anchor, figures=figures)
    with outdir.open(REPORT) as fh:
        fh.write(html)


@progress.stage()
def cover_outputs(outdir: Any, cp, area: str, *, report: bool, title: str,
                  options=None, camera=None, cam=None):
    """The mission files (path.csv, mission.plan, .waypoints, KML/KMZ, GeoJSON), zigzag.csv,
    PNGs, coverage.html and report.html; returns ``(built mission, safety figures)`` (the
    no-fly zones of the world go into the .plan geoFence)."""
    from ..io import write_path_csv
    from ..viz.coverage import bands_figure, coverage_figure, coverage_html
    world = cp.plan.world
    georef = getattr(world, "georef", None)
    comment = georef.comment() if georef is not None else None
    from ..analysis.safety import safety_summary
    from ..io import export_mission
    from ..autopilot.geofence import zone_fences

    zones = tuple(getattr(world, "zones", ()))
    fences, fence_warnings = (zone_fences(zones, world, getattr(options, "anchor", None))
                              if zones else ([], []))
    mission, files = export_mission(cp.plan, COVER_EXPORTS, options, agl=cp.level.agl,
                                    camera=camera, fences=fences)
    wps = mission.waypoints
    safety = safety_summary(
        world, cp.path, requested=cp.level.agl, phase=getattr(cp.plan, "phase", None),
        waypoints=wps.points_m, waypoint_indices=wps.indices, terrain_frame=wps.frame == 10,
        waypoint_agl=wps.agl, level=cp.level)
    if zones:
        safety["geofence"] = {"fences": len(fences), "warnings": fence_warnings}
    from ..analysis.known_ground import check_ground, ground_notes

    check_ground(world, safety, what="the survey path")
    progress.step("writing the mission files", 0.3)
    write_exports(outdir, files)
    progress.step("writing the figures", 0.7)
    with outdir.open("zigzag.csv") as fh:
        write_path_csv(fh, cp.zigzag.path(), comment=comment)
    write_figure(outdir, bands_figure(cp.zigzag, title=f"zigzag over {area}"), "bands.png")
    write_figure(outdir, coverage_figure(cp, title=title,
                                         anchor=getattr(options, "anchor", None)),
                 "coverage.png")
    with outdir.open("coverage.html") as fh:
        fh.write(coverage_html(cp, title=title))
    if report:
        e = np.abs(cp.agl_error)
        metrics = {
            "steering angle [deg]": round(cp.zigzag.angle_deg, 3),
            "band spacing D [m]": cp.zigzag.spacing,
            "bands": cp.zigzag.n_bands,
            "zigzag cost [m]": round(cp.zigzag.cost, 1),
            "FM² path length [m]": round(float(cp.plan.length), 1),
            "coverage (FM² path) [%]": round(100 * cp.coverage, 2),
            "|AGL error| mean / max [m]": f"{e.mean():.1f} / {e.max():.1f}",
            "mission": f"{mission.options.firmware} {mission.options.vehicle}, "
                       f"{len(mission.items)} items, frame {mission.frame}, end {mission.end}",
            "camera trigger [m]": mission.info["camera"]["trigger_distance_m"],
            **({"GSD [cm/px]": mission.info["camera"]["gsd_cm_per_px"]}
               if "gsd_cm_per_px" in mission.info["camera"] else {}),
            "planning time [s]": round(cp.timings.get("total", 0.0), 3),
            **safety_rows(safety),
        }
        notes = list(ground_notes(world, safety, what="the survey path").values())
        notes += [w for w in list(mission.warnings) + list(fence_warnings) if w not in notes]
        _cover_report(outdir, cp, title=title,
                      subtitle=f"zigzag bands over {area}, FM² at "
                               f"{cp.level.agl:g} m above the terrain",
                      metrics=metrics, mission=mission, shots=camera, safety=safety,
                      options=options, camera=cam, files=list(COVER_FILES), notes=notes)
    return mission, safety


def across_wind_angle(wind: Any, world: Any, area: Any) -> float:
    """Steering angle [deg, from the x axis] of bands across the wind (``--bands wind``).

    Legs across the wind fly at ``sqrt(V² − w²)`` both ways, legs along it at ``V − w``
    and ``V + w``: out and back, ``2L / sqrt(V² − w²)`` against ``2L V / (V² − w²)``, so
    across is the faster (and the cheaper) orientation in any wind. The wind is the
    field's at the area's centroid (a profile's at its reference height).

    Raises
    ------
    InputError
        No wind given, or a calm one (no direction to orient to).
    """
    from ..errors import InputError

    if wind is None:
        raise InputError("--bands wind needs a wind: give --wind SPEED@DIR or --wind-file "
                         "(mission file wind:)")
    c = area.centroid
    u, v = np.asarray(wind.at([[c.x, c.y]]), dtype=float)[0]
    if np.hypot(u, v) < 1e-9:
        raise InputError("--bands wind: the wind is calm over the area, it gives no direction; "
                         "give --angle or let the search choose (--bands search)")
    return float((np.degrees(np.arctan2(v, u)) + 90.0) % 180.0)


def cover_sorties(outdir: Any, cp: Any, mission: Any, camera: Any, *, options: Any,
                  shaping: Any = None) -> dict[str, Any] | None:
    """The survey split into sorties by battery, one mission each
    (:func:`fm2uav.autopilot.sorties.build_sorties`): writes ``sortie-01.plan``,
    ``sortie-01.waypoints``, ... (every format of :data:`COVER_EXPORTS`) and returns the
    summary's ``sorties`` (None when one battery flies the survey; ``count`` None and the
    reason when it cannot be split).

    The ways between home and the survey are the FM² return field of home on the
    planner's map of the survey's world, flight level and ``shaping``; where no field can
    be marched, straight lines clearing the surface (the summary says which).
    """
    from ..autopilot.sorties import build_sorties, field_ways, straight_ways
    from ..errors import InputError, MissionError, PlanningError
    from ..io import export_mission

    if (mission.info.get("energy") or {}).get("ok", True):
        return None
    world = cp.plan.world
    home = np.asarray(cp.path[0], dtype=float)
    agl = None if cp.level is None else float(cp.level.agl)
    try:
        ways = field_ways(world, home, shaping=shaping, level=cp.level)
    except (InputError, PlanningError) as exc:
        ways = straight_ways(world, home, agl=agl, note=f"straight lines clearing the surface "
                             f"by the flight level's height (no return field: {exc})")

    def build(plan: Any, opt: Any, **inputs: Any) -> tuple[Any, dict[str, Any]]:
        return export_mission(plan, COVER_EXPORTS, opt, **inputs)

    try:
        found = build_sorties(mission, cp.plan, ways=ways, camera=camera,
                              fences=mission.fences, agl=agl, build=build)
    except (PlanningError, MissionError) as exc:
        return {"count": None, "error": str(exc)}
    if found is None:
        return None
    for s in found.sorties:
        write_exports(outdir, s.files)
    return found.summary(anchor=getattr(options, "anchor", None))


def sortie_rows(sorties: dict[str, Any] | None) -> dict[str, str]:
    """Printed rows of :func:`cover_sorties`."""
    if not sorties:
        return {}
    if sorties["count"] is None:
        return {"sorties": sorties["error"]}
    even = sorties["even_split_count"]
    rows = {"sorties": f"{sorties['count']} (one battery each, {sorties['usable_wh']:.1f} Wh "
                       "usable; an even split of the waypoints needs "
                       + (f"{even})" if even is not None else "more: one leg alone is too long)")}
    for k, s in enumerate(sorties["sorties"], 1):
        lon, lat, _ = s["resume_lon_lat_alt"]
        files = [f for f in s.get("files", ()) if f.endswith((".plan", ".waypoints"))]
        rows[f"sortie {k}"] = (f"legs {s['from_waypoint']}→{s['to_waypoint']}, "
                               f"{s['energy_wh']:.1f} Wh, {s['time_s'] / 60:.1f} min, resume at "
                               f"{lat:.6f}, {lon:.6f}"
                               + (f" (item {s['resume_item']}); {' / '.join(files)}"
                                  if files else ""))
    if "ways" in sorties:
        rows["sorties: ways out and home"] = sorties["ways"]["kind"]
    return rows


def cover_rows(area: str, d: float, cp, mission, world, sorties: dict[str, Any] | None = None
               ) -> dict:
    """The printed summary of ``fm2uav cover`` (and the app's coverage rows)."""
    return {
        "area": area,
        "band spacing D [m]": f"{d:.1f}",
        "steering angle [deg]": f"{cp.zigzag.angle_deg:.3f}",
        "bands": cp.zigzag.n_bands,
        "zigzag cost [m]": f"{cp.zigzag.cost:.1f}",
        "FM² path length [m]": f"{cp.plan.length:.1f}",
        "coverage (FM² path) [%]": f"{100 * cp.coverage:.2f}",
        "|AGL error| mean/max [m]": f"{np.abs(cp.agl_error).mean():.1f} / "
                                    f"{np.abs(cp.agl_error).max():.1f}",
        "camera": ", ".join(
            f"{k} {v}" for k, v in mission.info["camera"].items()
            if k in ("gsd_cm_per_px", "side_overlap", "front_overlap", "trigger_distance_m",
                     "trigger_items")),
        **mission_rows(mission),
        **sortie_rows(sorties),
        "timings [ms]": ", ".join(f"{k} {v * 1e3:.0f}" for k, v in cp.timings.items()),
        **world_rows(world),
    }


