"""The app's worker process: runs one job at a time with the library's own functions.

Job kinds (``run_job(kind, payload)``):

* ``"world"``: validate a mission's ``world:`` section
  (:func:`fm2uav.io.mission.parse_world`) and build the world
  (:func:`fm2uav.world.load.load_world`), as planning will: its summary, the
  building footprints in lon/lat, the ground range;
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
    from ..pipeline.rows import mission_rows, plan_rows, safety_rows, world_rows
    from ..pipeline.run import run_mission
    from ..viz.mapdata import mission_map

    mission_file = Path(payload["mission_file"])
    m = load_mission(mission_file)
    out = Path(payload["out"])
    with OutputDir(out, force=True) as outdir:
        outdir.check(output_names(list(dict.fromkeys(m.outputs.formats))))
        run = run_mission(m, outdir, mission_file=mission_file)
    p, rm = run.plan, run.resolved
    rows = {"mission": m.name, "world": run.world_name, **plan_rows(p),
            "legs": len(run.route.legs), **safety_rows(run.info["safety"]),
            **mission_rows(run.built), "time [s]": f"{p.timings['total']:.2f}",
            **world_rows(rm.world)}
    points = {"start": rm.start, **{f"via {k + 1}": v for k, v in enumerate(rm.via)},
              "goal": rm.goal}
    doc = mission_map(p, run.built, run.info["safety"], points=points, anchor=m.anchor(),
                      rows={k: str(v) for k, v in rows.items()},
                      junctions=run.route.junctions)
    files = sorted(f.name for f in out.iterdir() if f.is_file())
    return {"map": doc, "files": files, "out": str(out)}


JOBS = {"world": _world_job, "plan": _plan_job}


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
        from .. import pipeline  # noqa: F401
        from ..pipeline import run  # noqa: F401
        from ..viz import mapdata  # noqa: F401
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
