"""The app's HTTP server (FastAPI on uvicorn, 127.0.0.1 only).

Endpoints (JSON unless said otherwise):

==========================================  ==============================================
``GET  /``                                  the map page
``GET  /api/session``                       the starting mission document, save path, choices
``POST /api/upload``                        store a file (multipart ``file``) → ``{path}``
``POST /api/jobs``                          ``{kind: "world", world, agl}``,
                                            ``{kind: "plan", mission}`` or
                                            ``{kind: "cover", mission, area, cover}`` or
                                            ``{kind: "check", job, airframe}`` → the job
``GET  /api/jobs/{id}``                     the job (state, %, stage, result or error)
``GET  /api/jobs/{id}/events``              the job's changes as server-sent events
``POST /api/jobs/{id}/cancel``              cancel it
``GET  /api/jobs/{id}/files/{name}``        download an output of a plan job
``GET  /api/jobs/{id}/mission.yaml``        the mission file the job ran
``POST /api/terrain``                       ``{dem: [...]}`` → basemap id, bounds, heights
``GET  /api/terrain/{id}/{z}/{x}/{y}.png``  shaded relief tile
``GET  /api/terrain/{id}/contours``         contour lines (GeoJSON)
``GET  /api/terrain/{id}/height``           ground height at ``?lon=&lat=``
``POST /api/mission/save``                  ``{mission, path}`` → the saved mission file
==========================================  ==============================================

No endpoint plans or measures anything itself: the jobs run the library's
functions (:mod:`fm2uav.app.worker`), the tiles come from rio-tiler
(:mod:`fm2uav.app.terrain`).
"""

from __future__ import annotations

import asyncio
import hashlib
import json
from importlib import resources
from pathlib import Path
from typing import Any

from fastapi import FastAPI, HTTPException, Request, UploadFile
from fastapi.responses import (FileResponse, HTMLResponse, JSONResponse, Response,
                               StreamingResponse)
from fastapi.staticfiles import StaticFiles

__all__ = ["create_app"]

STATIC = Path(str(resources.files("fm2uav.app") / "static"))
WEB = Path(str(resources.files("fm2uav.viz") / "web"))

#: Host names the app answers to (it listens on 127.0.0.1 only).
LOCAL_HOSTS = ("127.0.0.1", "localhost", "::1")

#: Choices the page offers (the mission file's allowed values).
CHOICES = {
    "firmware": ["px4", "ardupilot", "generic"],
    "vehicle": ["multirotor", "fixed_wing", "vtol"],
    "frame": ["auto", "terrain", "amsl", "relative"],
    "end": ["auto", "rtl", "land", "loiter"],
    "reference": ["amsl", "agl"],
}


def create_app(session: Any, jobs: Any) -> Any:
    """The FastAPI application of a :class:`~fm2uav.app.session.Session` and its jobs."""
    from .terrain import Terrain

    app = FastAPI(title="fm2uav", docs_url=None, redoc_url=None, openapi_url=None)

    @app.middleware("http")
    async def local_only(request: Request, call_next: Any) -> Any:
        # Only this machine's pages may drive the app: a page from elsewhere that the
        # browser shows (another site, a rebound DNS name) must not write files or plan.
        host = (request.headers.get("host") or "").rsplit(":", 1)[0].strip("[]")
        if host not in LOCAL_HOSTS:
            return JSONResponse({"error": f"requests to the app must name 127.0.0.1 or "
                                          f"localhost, not {host!r}"}, status_code=403)
        if request.method not in ("GET", "HEAD"):
            origin = request.headers.get("origin")
            if origin is not None and origin.split("://", 1)[-1].rsplit(":", 1)[0].strip(
                    "[]") not in LOCAL_HOSTS:
                return JSONResponse({"error": f"the app takes no requests from {origin}"},
                                    status_code=403)
            kind = request.headers.get("content-type", "")
            if not kind.startswith(("application/json", "multipart/form-data")):
                return JSONResponse({"error": "the app takes JSON (or a file upload)"},
                                    status_code=415)
        return await call_next(request)
    app.mount("/static", StaticFiles(directory=STATIC), name="static")
    app.mount("/web", StaticFiles(directory=WEB), name="web")
    terrains: dict[str, Terrain] = {}

    def bad(message: str, status: int = 400) -> JSONResponse:
        return JSONResponse({"error": message}, status_code=status)

    @app.get("/", response_class=HTMLResponse)
    def index() -> Any:
        return HTMLResponse((STATIC / "index.html").read_text(encoding="utf-8"),
                            headers={"Cache-Control": "no-store"})

    @app.get("/api/session")
    def get_session() -> Any:
        from ..vehicles import AIRFRAMES

        return {"mission": session.mission, "mission_path": str(session.mission_path),
                "folder": str(session.root),
                "choices": {**CHOICES, "airframes": {k: f"{a.name} ({a.kind})"
                                                     for k, a in AIRFRAMES.items()}}}

    @app.post("/api/upload")
    async def upload(file: UploadFile) -> Any:
        content = await file.read()
        if not content:
            return bad(f"{file.filename}: the file is empty")
        path = session.upload(file.filename or "upload", content)
        return {"path": str(path), "name": path.name, "bytes": len(content)}

    @app.post("/api/jobs")
    async def submit(request: Request) -> Any:
        body = await request.json()
        kind = body.get("kind")
        if kind == "world":
            job = jobs.submit("world", {"world": body.get("world"), "agl": body.get("agl"),
                                        "source": "mission"})
            return job.public()
        if kind == "plan":
            doc = body.get("mission")
            if not isinstance(doc, dict):
                return bad("the request has no mission document")
            job_id = jobs.new_id()
            mission_file, out = session.job_files(job_id, doc)
            return jobs.submit("plan", {"mission_file": str(mission_file), "out": str(out)},
                               job_id=job_id).public()
        if kind == "cover":
            from ..errors import describe_error

            job_id = jobs.new_id()
            try:
                payload = session.cover_job(job_id, body)
            except Exception as exc:  # noqa: BLE001 - the CLI's words
                known = describe_error(exc)
                if known is None:
                    raise
                return bad(known[0])
            return jobs.submit("cover", payload, job_id=job_id).public()
        if kind == "check":
            src = jobs.get(str(body.get("job")))
            if src is None or src.state != "done" or src.kind not in ("plan", "cover"):
                return bad("plan or cover first: the check flies the last planned path")
            return jobs.submit("check", {
                "path": str(Path(src.payload["out"]).parent / "path_m.npy"),
                "mission_file": src.payload.get("mission_file"),
                "world": src.payload.get("world"),
                "agl": (src.payload.get("cover") or {}).get("agl"),
                "airframe": body.get("airframe") or "arducopter"}).public()
        return bad(f"unknown job kind {kind!r}; allowed: world, plan, cover, check")

    def job_or_404(job_id: str) -> Any:
        job = jobs.get(job_id)
        if job is None:
            raise HTTPException(404, f"no job {job_id}")
        return job

    @app.get("/api/jobs/{job_id}")
    def get_job(job_id: str) -> Any:
        return job_or_404(job_id).public()

    @app.post("/api/jobs/{job_id}/cancel")
    def cancel(job_id: str) -> Any:
        job_or_404(job_id)
        return jobs.cancel(job_id).public()

    @app.get("/api/jobs/{job_id}/events")
    async def events(job_id: str) -> Any:
        job_or_404(job_id)

        async def stream() -> Any:
            version = -1
            while True:
                job = await asyncio.to_thread(jobs.wait, job_id, version, 10.0)
                if job is None:
                    return
                if job.version != version:
                    version = job.version
                    yield f"data: {json.dumps(job.public())}\n\n"
                    if job.final:
                        return
                else:
                    yield ": keep-alive\n\n"

        return StreamingResponse(stream(), media_type="text/event-stream",
                                 headers={"Cache-Control": "no-store"})

    @app.get("/api/jobs/{job_id}/files/{name}")
    def job_file(job_id: str, name: str) -> Any:
        job = job_or_404(job_id)
        out = Path(job.payload.get("out", ""))
        path = out / name
        if job.state != "done" or Path(name).name != name or not path.is_file():
            raise HTTPException(404, f"no file {name} in job {job_id}")
        return FileResponse(path, filename=name, headers={"Cache-Control": "no-store"})

    @app.get("/api/jobs/{job_id}/mission.yaml")
    def job_mission(job_id: str) -> Any:
        job = job_or_404(job_id)
        path = Path(job.payload.get("mission_file", ""))
        if not path.is_file():
            raise HTTPException(404, f"job {job_id} has no mission file")
        return FileResponse(path, media_type="text/yaml", filename="mission.yaml")

    @app.post("/api/terrain")
    async def terrain(request: Request) -> Any:
        body = await request.json()
        dem = body.get("dem")
        paths = [dem] if isinstance(dem, str) else list(dem or [])
        if not paths:
            return bad("no DEM given")
        key = hashlib.sha256("\n".join(paths).encode()).hexdigest()[:16]
        if key not in terrains:
            try:
                terrains[key] = await asyncio.to_thread(Terrain, paths)
            except Exception as exc:  # noqa: BLE001 - validated before; say what rio-tiler said
                return bad(f"the DEM cannot be drawn: {type(exc).__name__}: {exc}")
        return {"id": key, **terrains[key].info()}

    def terrain_or_404(key: str) -> Any:
        t = terrains.get(key)
        if t is None:
            raise HTTPException(404, f"no terrain {key}")
        return t

    @app.get("/api/terrain/{key}/{z}/{x}/{y}.png")
    async def tile(key: str, z: int, x: int, y: int) -> Any:
        t = terrain_or_404(key)
        png = await asyncio.to_thread(t.tile_png, x, y, z)
        if png is None:
            return Response(status_code=204)
        return Response(png, media_type="image/png",
                        headers={"Cache-Control": "max-age=3600"})

    @app.get("/api/terrain/{key}/contours")
    async def contours(key: str) -> Any:
        t = terrain_or_404(key)
        return await asyncio.to_thread(t.contours)

    @app.get("/api/terrain/{key}/height")
    async def height(key: str, lon: float, lat: float) -> Any:
        t = terrain_or_404(key)
        return {"lon": lon, "lat": lat, "ground_m": await asyncio.to_thread(t.height, lon, lat)}

    @app.post("/api/mission/save")
    async def save(request: Request) -> Any:
        from ..errors import describe_error

        body = await request.json()
        doc, path = body.get("mission"), body.get("path") or str(session.mission_path)
        if not isinstance(doc, dict):
            return bad("the request has no mission document")
        try:
            target = session.save(doc, path)
        except Exception as exc:  # noqa: BLE001 - the CLI's words for bad paths
            known = describe_error(exc)
            if known is None:
                raise
            return bad(known[0])
        return {"path": str(target), "command": f"fm2uav run {target}"}

    return app
