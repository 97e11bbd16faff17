"""The app's worker process: runs one job at a time with the library's own functions.

Job kinds (``run_job(kind, payload)``):

* ``"world"``: validate a mission's ``world:`` section
  (:func:`fm2uav.io.mission.parse_world`) and build the world
  (:func:`fm2uav.world.load.load_world`), as planning will: its summary, the
  building footprints in lon/lat, the ground range;
* ``"cover"``: ``fm2uav cover`` on the area and zones files the app wrote
  (:func:`fm2uav.pipeline.cover.run_cover`), with the photo footprints on the map;
* ``"check"``: ``fm2uav check`` of a planned path with an airframe
  (:func:`fm2uav.vehicles.check_feasibility`), the flown track in lon/lat;
* ``"plan"``: ``fm2uav run`` on a mission file the app wrote
  (:func:`fm2uav.io.mission.load_mission`, :func:`fm2uav.pipeline.run.run_mission`
  into the job's output folder), then the map document of the result
  (:func:`fm2uav.viz.mapdata.mission_map`).

Errors travel back as the command line prints them (:func:`fm2uav.errors.describe_error`).
"""

from __future__ import annotations

import traceback
import warnings
from pathlib import Path
from typing import Any

import numpy as np

__all__ = ["worker_main", "run_job"]


def _world_job(payload: dict[str, Any]) -> dict[str, Any]:
    from ..io.mission import parse_world
    from ..pipeline.rows import world_rows
    from ..progress import step
    from ..world.geo import bounds_lonlat
    from ..world.load import load_world, world_summary

    step("checking the world's files", 0.2)
    spec = parse_world(payload["world"], source=payload.get("source", "mission"),
                       base_dir=payload.get("base_dir"))
    step("building the world", 0.8)
    world = load_world(spec, agl=payload.get("agl"))
    b = world.bounds
    box = bounds_lonlat((b[0, 0], b[1, 0], b[0, 1], b[1, 1]), world.crs)
    ground = world.terrain if getattr(world, "terrain", None) is not None else None
    out: dict[str, Any] = {
        "summary": world_summary(world), "rows": world_rows(world),
        "bounds": [round(float(v), 7) for v in box],
        "shape": list(world.shape), "spacing": [float(v) for v in world.spacing],
        "ground": None if ground is None else [round(float(ground.min()), 1),
                                               round(float(ground.max()), 1)],
        "buildings": _buildings(spec),
    }
    return out


def _buildings(spec: Any) -> dict[str, Any] | None:
    """The building footprints of the world as GeoJSON lon/lat with their heights."""
    if spec.buildings is None:
        return None
    from shapely.geometry import mapping

    from ..world.buildings import height_and_rule
    from ..world.vectors import read_vectors

    data = read_vectors(spec.buildings, target_crs="EPSG:4326", crs=spec.crs, role="buildings")
    feats = []
    for g, props in zip(data.geometries, data.properties):
        try:
            h, _rule = height_and_rule(props, metres_per_level=spec.metres_per_level,
                                       default_height=spec.default_height)
        except Exception:  # noqa: BLE001 - display only: the world load names bad heights
            h = None
        feats.append({"type": "Feature", "geometry": mapping(g),
                      "properties": {"kind": "building", "height": h}})
    return {"type": "FeatureCollection", "features": feats}


def _plan_job(payload: dict[str, Any]) -> dict[str, Any]:
    from ..io.mission import load_mission
    from ..io.outdir import OutputDir
    from ..pipeline.outputs import output_names
    from ..pipeline.rows import mission_rows, plan_rows, returns_rows, safety_rows, world_rows
    from ..pipeline.run import run_mission
    from ..viz.mapdata import mission_map

    mission_file = Path(payload["mission_file"])
    m = load_mission(mission_file)
    out = Path(payload["out"])
    with OutputDir(out, force=True) as outdir:
        outdir.check(output_names(list(dict.fromkeys(m.outputs.formats))))
        run = run_mission(m, outdir, mission_file=mission_file)
    p, rm = run.plan, run.resolved
    np.save(out.parent / "path_m.npy", np.asarray(p.path, dtype=float))  # for a later check
    rows = {"mission": m.name, "world": run.world_name, **plan_rows(p),
            "legs": len(run.route.legs), **safety_rows(run.info["safety"]),
            **mission_rows(run.built), **returns_rows(run.info),
            "time [s]": f"{p.timings['total']:.2f}",
            **world_rows(rm.world)}
    points = {"start": rm.start, **{f"via {k + 1}": v for k, v in enumerate(rm.via)},
              "goal": rm.goal}
    doc = mission_map(p, run.built, run.info["safety"], points=points, anchor=m.anchor(),
                      rows={k: str(v) for k, v in rows.items()},
                      junctions=run.route.junctions)
    files = sorted(f.name for f in out.iterdir() if f.is_file())
    return {"map": doc, "files": files, "out": str(out)}


def _cover_job(payload: dict[str, Any]) -> dict[str, Any]:
    """``fm2uav cover`` on the files the server wrote (the area and the zones as GeoJSON)."""
    from ..io.mission import parse_world
    from ..io.outdir import OutputDir
    from ..io.zone_spec import zones_from_cli
    from ..missions.coverage import Camera
    from ..missions.coverage.area import load_area
    from ..pipeline.cover import COVER_FILES, REPORT, band_cell, cover_rows, run_cover
    from ..pipeline.outputs import export_options
    from ..pipeline.rows import safety_rows
    from ..planning import FlightLevel
    from ..planning.params import planner_objects
    from ..progress import step
    from ..viz.mapdata import coverage_features, mission_map
    from ..world.load import load_world, world_summary
    from ..world.zones import with_zones

    c = payload["cover"]
    agl = float(c["agl"])
    limits = {k: float(c[k]) for k in ("min_agl", "max_agl") if c.get(k) is not None}
    level = FlightLevel(agl=agl, p1=float(c.get("p1", 0.5)), p2=float(c.get("p2", 1.3)),
                        **limits)
    cam = None if c.get("camera") is None else Camera(
        *(float(v) * 1e-3 for v in c["camera"][:3]), *(int(v) for v in c["camera"][3:]))
    if (c.get("spacing") is None) == (cam is None):
        from ..errors import InputError

        raise InputError("give exactly one of --spacing (metres) or --camera")
    d = float(c["spacing"]) if cam is None else cam.spacing(agl, float(c.get("side_overlap", 0)))
    area_name = Path(payload["area"]).name
    options = export_options(name=f"coverage of {area_name}", **payload.get("export", {}))
    step("building the map", 0.1)
    spec = parse_world(payload["world"], source="world")
    world = load_world(spec, agl=agl, max_cell=band_cell(d, bool(payload.get("zones"))))
    poly, area_source = load_area(payload["area"], world, crs=spec.crs)
    if payload.get("zones"):
        world = with_zones(world, zones_from_cli(payload["zones"], world, crs=spec.crs))
    shaping = (None if c.get("saturation_distance") is None else
               planner_objects({"saturation_distance": float(c["saturation_distance"])})[0])
    step("coverage", 0.9)
    out = Path(payload["out"])
    with OutputDir(out, force=True) as outdir:
        outdir.check(COVER_FILES + (REPORT,))
        run = run_cover(outdir, world, poly, area_label=area_name, spacing=d, level=level,
                        options=options, camera=cam,
                        front_overlap=float(c.get("front_overlap", 0.0)),
                        trigger_distance=c.get("trigger_distance"), seed=int(c.get("seed", 0)),
                        shaping=shaping, report=True, summary={
                            "area": payload["area"], "scenario": spec.describe(),
                            "world": world_summary(world),
                            **({"area_source": area_source.as_dict()} if area_source else {})})
    np.save(out.parent / "path_m.npy", np.asarray(run.coverage.path, dtype=float))
    rows = {**cover_rows(area_name, d, run.coverage, run.built, world,
                         run.summary.get("sorties")),
            **safety_rows(run.safety)}
    doc = mission_map(run.coverage.plan, run.built, run.safety,
                      rows={k: str(v) for k, v in rows.items()})
    doc["features"] += coverage_features(run.coverage, run.shots, cam)
    cp = run.coverage
    doc["summary"].update(
        area_m2=round(float(cp.zigzag.area.area), 1), bands=int(cp.zigzag.n_bands),
        spacing_m=round(d, 2), angle_deg=round(cp.zigzag.angle_deg, 3),
        coverage=round(float(cp.coverage), 4),
        photos=sum(1 for f in doc["features"] if f["properties"]["kind"] == "photo"),
        gsd_cm_per_px=run.shots.info.get("gsd_cm_per_px"),
        trigger_distance_m=run.shots.trigger_distance)
    files = sorted(f.name for f in out.iterdir() if f.is_file())
    return {"map": doc, "files": files, "out": str(out), "command": payload.get("command")}


def _check_job(payload: dict[str, Any]) -> dict[str, Any]:
    """``fm2uav check`` of a planned path: can this airframe fly it (Dubins airplane /
    multirotor tracking), on the world it was planned on."""
    from ..io.mission import load_mission, parse_world
    from ..progress import step
    from ..vehicles import check_feasibility, get_airframe
    from ..world.geo import to_lonlat
    from ..world.load import load_world

    af = get_airframe(payload["airframe"])
    path = np.load(payload["path"])
    step("building the world", 0.3)
    if payload.get("mission_file"):
        world = load_mission(payload["mission_file"]).resolve().world
    else:
        spec = parse_world(payload["world"], source="world")
        world = load_world(spec, agl=payload.get("agl"))
    step(f"simulating the {af.name} along the path", 0.7)
    rep = check_feasibility(path, af, world=world, tolerance=float(payload.get("tolerance", 5.0)))
    flown = np.asarray(to_lonlat(world, rep.tracking.trajectory), dtype=float)
    return {"feasible": bool(rep.feasible), "reason": rep.reason,
            "rows": {k: str(v) for k, v in rep.summary_rows(af).items()},
            "flown": {"type": "Feature", "properties": {"kind": "flown", "airframe": af.name},
                      "geometry": {"type": "LineString", "coordinates": [
                          [round(float(a), 7), round(float(b), 7), round(float(c), 1)]
                          for a, b, c in flown]}}}


JOBS = {"world": _world_job, "plan": _plan_job, "cover": _cover_job, "check": _check_job}


def run_job(kind: str, payload: dict[str, Any], send: Any = None) -> tuple[str, Any]:
    """Run one job; returns ``("done", result)`` or ``("error", (message, exit code))``.

    ``send(message_tuple)`` receives ``("progress", fraction, stage)`` and
    ``("warning", text)`` while it runs (nothing if None).
    """
    from ..errors import EXIT_INTERNAL, describe_error
    from ..pipeline.outputs import to_jsonable
    from ..progress import reporting

    def report(event: Any) -> None:
        if send is not None:
            send(("progress", float(event.fraction), event.message))

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            with reporting(report):
                result = JOBS[kind](payload)
            outcome: tuple[str, Any] = ("done", to_jsonable(result))
        except Exception as exc:  # noqa: BLE001 - every error becomes a message, as in the CLI
            known = describe_error(exc)
            if known is None:
                outcome = ("error", (
                    f"internal error: {type(exc).__name__}: {exc} — this is a bug in fm2uav, "
                    "not a problem with your input; please report it with the mission file "
                    "and this traceback:\n" + traceback.format_exc(), EXIT_INTERNAL))
            else:
                outcome = ("error", known)
    if send is not None:
        seen = set()
        for w in caught:
            text = str(w.message)
            if str(getattr(w.category, "__module__", "")).startswith("fm2uav") and \
                    text not in seen:
                seen.add(text)
                send(("warning", text))
    return outcome


def worker_main(conn: Any) -> None:  # pragma: no cover - runs in the child process
    """The worker's loop: receive ``(job id, kind, payload)``, send events and the outcome."""
    import signal

    signal.signal(signal.SIGINT, signal.SIG_IGN)   # Ctrl-C stops the server, which stops us
    try:  # load the planner while the page opens
        from ..pipeline import cover, run  # noqa: F401
        from ..viz import coverage, mapdata, report  # noqa: F401
    except Exception:  # noqa: BLE001 - a job will report it
        pass
    while True:
        try:
            job_id, kind, payload = conn.recv()
        except (EOFError, OSError, KeyboardInterrupt):
            return

        def send(message: tuple[Any, ...], job_id: str = job_id) -> None:
            conn.send((message[0], job_id, *message[1:]))

        state, data = run_job(kind, payload, send)
        if state == "done":
            conn.send(("done", job_id, data))
        else:
            conn.send(("error", job_id, data[0], data[1]))
