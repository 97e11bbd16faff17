"""fm2uav.app.server: the HTTP API, driven without a browser (FastAPI's test client)."""

from __future__ import annotations

import json

import pytest
import yaml
from fastapi.testclient import TestClient

from fm2uav.app import bind
from fm2uav.app.jobs import JobManager
from fm2uav.app.server import create_app
from fm2uav.app.session import Session
from fm2uav.errors import InputError

from .dem import make_dem


@pytest.fixture(scope="module")
def client(tmp_path_factory):
    root = tmp_path_factory.mktemp("server")
    dem = make_dem(root / "dem.tif")
    jobs = JobManager()
    session = Session(root / "session", {"version": 1, "world": {"dem": str(dem)}},
                      root / "mission.yaml")
    with TestClient(create_app(session, jobs), base_url="http://127.0.0.1:8765") as c:
        c.dem, c.root = dem, root
        yield c
    jobs.close()


def events(client, job_id: str) -> list[dict]:
    out = []
    with client.stream("GET", f"/api/jobs/{job_id}/events") as r:
        assert r.headers["content-type"].startswith("text/event-stream")
        for line in r.iter_lines():
            if line.startswith("data: "):
                out.append(json.loads(line[6:]))
    return out


def test_the_page_its_scripts_and_the_session(client):
    html = client.get("/").text
    assert "/web/vendor/leaflet/leaflet.js" in html and "/static/app.js" in html
    for path in ("/web/vendor/leaflet/leaflet.js", "/web/vendor/leaflet-geoman/leaflet-geoman.min.js",
                 "/web/vendor/uplot/uPlot.iife.min.js", "/web/mission-map.js", "/static/app.js",
                 "/static/app.css", "/web/vendor/leaflet/images/marker-icon.png"):
        assert client.get(path).status_code == 200, path
    s = client.get("/api/session").json()
    assert s["mission"]["world"]["dem"] == str(client.dem)
    assert s["choices"]["firmware"] == ["px4", "ardupilot", "generic"]
    assert "disco" in s["choices"]["airframes"]


def test_a_world_job_streams_its_progress_then_the_terrain_is_served(client):
    job = client.post("/api/jobs", json={"kind": "world", "world": {"dem": str(client.dem)},
                                         "agl": 60}).json()
    ev = events(client, job["id"])
    assert ev[-1]["state"] == "done" and ev[-1]["result"]["summary"]["crs"] == "EPSG:32632"
    assert any(e["stage"] == "building the world" for e in ev)
    t = client.post("/api/terrain", json={"dem": [str(client.dem)]}).json()
    w, s, e, n = t["bounds"]
    import morecantile

    tile = morecantile.tms.get("WebMercatorQuad").tile((w + e) / 2, (s + n) / 2, 13)
    r = client.get(f"/api/terrain/{t['id']}/{tile.z}/{tile.x}/{tile.y}.png")
    assert r.status_code == 200 and r.content[:8] == b"\x89PNG\r\n\x1a\n"
    assert client.get(f"/api/terrain/{t['id']}/2/0/0.png").status_code == 204
    h = client.get(f"/api/terrain/{t['id']}/height", params={"lon": (w + e) / 2,
                                                              "lat": (s + n) / 2}).json()
    assert 280 < h["ground_m"] < 480
    assert client.get(f"/api/terrain/{t['id']}/contours").json()["features"]
    assert client.get("/api/terrain/nope/height?lon=0&lat=0").status_code == 404


def test_a_plan_job_and_its_files(client):
    doc = {"version": 1, "name": "api", "world": {"dem": str(client.dem)},
           "start": {"lon": 10.30, "lat": 46.03, "agl": 60},
           "goal": {"lon": 10.355, "lat": 46.03, "agl": 60}, "planner": {"agl": 60},
           "outputs": {"formats": ["plan", "wpl", "json"]}}
    job = client.post("/api/jobs", json={"kind": "plan", "mission": doc}).json()
    ev = events(client, job["id"])
    assert ev[-1]["state"] == "done", ev[-1]["error"]
    assert ev[-1]["result"]["files"] == ["mission.plan", "mission.waypoints", "summary.json"]
    r = client.get(f"/api/jobs/{job['id']}/files/mission.plan")
    assert r.status_code == 200 and json.loads(r.content)["fileType"] == "Plan"
    assert "attachment" in r.headers["content-disposition"]
    m = client.get(f"/api/jobs/{job['id']}/mission.yaml").text
    assert yaml.safe_load(m.split("\n", 1)[1]) == doc
    for bad in ("..%2Fmission.yaml", "..%2F..%2Fjobs", "nope.plan"):
        assert client.get(f"/api/jobs/{job['id']}/files/{bad}").status_code == 404
    assert client.get("/api/jobs/999").status_code == 404
    # can an airframe fly it? (fm2uav check on the planned path, the mission's world)
    check = client.post("/api/jobs", json={"kind": "check", "job": job["id"],
                                           "airframe": "arducopter"}).json()
    ev = events(client, check["id"])
    r = ev[-1]["result"]
    assert ev[-1]["state"] == "done" and r["feasible"] is True
    assert r["rows"]["verdict"] == "FEASIBLE" and r["rows"]["airframe"] == "arducopter (multirotor)"
    flown = r["flown"]["geometry"]["coordinates"]
    assert len(flown) > 10 and 10.29 < flown[0][0] < 10.37
    bad = client.post("/api/jobs", json={"kind": "check", "job": "999"}).json()
    assert "plan or cover first" in bad["error"]
    assert "unknown job kind" in client.post("/api/jobs", json={"kind": "x"}).json()["error"]


def test_upload_and_save(client, tmp_path):
    up = client.post("/api/upload", files={"file": ("up dem.tif", client.dem.read_bytes())})
    path = up.json()["path"]
    assert up.status_code == 200 and path.endswith("/data/up_dem.tif")
    assert client.post("/api/upload", files={"file": ("e.tif", b"")}).status_code == 400
    doc = {"version": 1, "world": {"dem": path},
           "start": {"lon": 10.30, "lat": 46.03, "agl": 60},
           "goal": {"lon": 10.355, "lat": 46.03, "agl": 60}}
    r = client.post("/api/mission/save", json={"mission": doc, "path": str(tmp_path / "s.yaml")})
    assert r.status_code == 200 and r.json()["command"] == f"fm2uav run {tmp_path / 's.yaml'}"
    assert (tmp_path / "up_dem.tif").is_file()
    bad = client.post("/api/mission/save", json={"mission": doc, "path": str(tmp_path / "s.txt")})
    assert bad.status_code == 400 and "ends in .yaml" in bad.json()["error"]


def test_bind_listens_on_loopback_only_and_names_the_flag_when_busy():
    sock = bind(0)
    host, port = sock.getsockname()
    try:
        assert host == "127.0.0.1" and port > 0
        with pytest.raises(InputError, match=rf"--port {port}: cannot listen"):
            bind(port)
    finally:
        sock.close()
    with pytest.raises(InputError, match="--port 70000 is not a TCP port"):
        bind(70000)


def test_only_this_machines_pages_may_drive_the_app(client):
    r = client.get("/api/session", headers={"host": "evil.example:8765"})
    assert r.status_code == 403 and "127.0.0.1 or localhost" in r.json()["error"]
    r = client.post("/api/mission/save", json={"mission": {}},
                    headers={"origin": "http://evil.example"})
    assert r.status_code == 403
    r = client.post("/api/mission/save", content='{"mission": {}}',
                    headers={"content-type": "text/plain"})   # a "simple" cross-site request
    assert r.status_code == 415
    ok = client.post("/api/jobs", json={"kind": "x"}, headers={"origin": "http://127.0.0.1:1"})
    assert ok.status_code == 400
