"""The whole app in a real browser (Debian's headless chromium driven by Playwright).

``fm2uav app --dem DEM.tif --port 0 --no-browser`` runs as the operator starts it; the
page is driven with mouse clicks on the map: start and goal, a no-fly zone drawn with
the drawing tool across the direct line, Plan, the route shown and checked to go round
the zone, the ``.plan`` downloaded and compared byte for byte with ``fm2uav run`` on the
mission file the page saved; a bad DEM and a start off the map show the command line's
error in the page. Screenshots are decoded and checked for the route's pixels and kept
in ``out/app-browser/`` (CI artefacts).
"""

from __future__ import annotations

import json
import os
import re
import subprocess
from pathlib import Path

import numpy as np
import pytest

from .browser import (FM2UAV, SHOTS, click_map, lonlat_at, plan_and_wait, route_pixels,
                      wait_for_tiles)

#: The route's colour at the requested height above ground (viz/web/mission-map.js).
ROUTE_GREEN = (26, 150, 65)


def cli(*args: str, cwd: Path) -> subprocess.CompletedProcess:
    return subprocess.run([*FM2UAV, *args], cwd=cwd, capture_output=True, text=True,
                          env={**os.environ, "COLUMNS": "400"}, timeout=300)


def test_page_shows_the_dem_as_a_map_with_scale_graticule_and_cursor_height(page):
    assert page.inner_text("#error") == ""
    page.wait_for_selector(".leaflet-tile-loaded", timeout=20_000)   # shaded relief tiles
    assert page.locator(".leaflet-control-scale-line").inner_text().strip()
    assert page.locator(".fm2-grat").count() >= 2                   # lon/lat labels
    assert "EPSG:32632" in page.inner_text("#world-info")
    lon, lat = lonlat_at(page, 0.3, 0.5)
    x, y = page.evaluate(f"(() => {{ const p = fm2app.map.latLngToContainerPoint([{lat}, {lon}]);"
                         " return [p.x, p.y]; })()")
    box = page.locator("#map").bounding_box()
    page.mouse.move(box["x"] + x, box["y"] + y)
    page.wait_for_function("document.getElementById('readout').textContent.includes(' m')",
                           timeout=10_000)
    text = page.inner_text("#readout")
    ground = float(re.search(r"ground ([\d.]+) m", text).group(1))
    assert 300 <= ground <= 480 and f"{lon:.4f}"[:7] in text


def test_plan_round_a_drawn_zone_download_and_reproduce_with_fm2uav_run(page, app_run,
                                                                        tmp_path):
    from shapely.geometry import LineString, Polygon

    start, goal = lonlat_at(page, 0.12, 0.45), lonlat_at(page, 0.88, 0.45)
    page.click("#tool-start")
    click_map(page, *start)
    page.click("#tool-goal")
    click_map(page, *goal)
    # a no-fly zone drawn with the drawing tool across the direct line
    page.click("#tool-zone-polygon")
    corners = [lonlat_at(page, fx, fy) for fx, fy in
               ((0.45, 0.15), (0.55, 0.15), (0.55, 0.8), (0.45, 0.8))]
    for c in corners + corners[:1]:
        click_map(page, *c)
    doc = page.evaluate("fm2app.missionDoc()")
    assert len(doc["no_fly_zones"]) == 1 and doc["start"]["lon"] == pytest.approx(start[0], abs=1e-4)
    zone = Polygon(doc["no_fly_zones"][0]["polygon"])
    assert zone.intersects(LineString([start, goal]))      # the direct route crosses it

    job = plan_and_wait(page)
    assert job["state"] == "done", job["error"]
    assert page.inner_text("#error") == ""
    result = page.evaluate("fm2app.result")
    route = next(f for f in result["map"]["features"] if f["properties"]["kind"] == "route")
    line = LineString([c[:2] for c in route["geometry"]["coordinates"]])
    assert not line.intersects(zone)                         # it goes round the zone
    assert line.length > LineString([start, goal]).length
    agl = np.array(route["properties"]["agl"])
    assert np.median(agl) == pytest.approx(60.0, abs=3.0)
    cards = page.inner_text("#cards")
    assert "km" in cards and "flight time" in cards and "min" in cards
    assert page.locator("#profile canvas").count() >= 1       # the profile chart is drawn
    assert page.locator(".fm2-item").count() >= 3             # numbered mission items
    assert page.evaluate("fm2app.job.fraction") == 1.0

    wait_for_tiles(page)
    SHOTS.mkdir(parents=True, exist_ok=True)
    shot = page.screenshot(path=str(SHOTS / "app-plan.png"))
    map_shot = page.locator("#map").screenshot(path=str(SHOTS / "app-plan-map.png"))
    green, distinct = route_pixels(map_shot, ROUTE_GREEN)
    assert distinct > 500, "the map screenshot is (nearly) blank"
    assert green > 300, f"only {green} route-coloured pixels on the map"
    assert route_pixels(shot, ROUTE_GREEN)[0] > 300

    # download the .plan and the report, save the mission, reproduce with fm2uav run
    with page.expect_download() as dl:
        page.click("#dl-mission-plan")
    downloaded = tmp_path / "downloaded.plan"
    dl.value.save_as(downloaded)
    with page.expect_download() as dl:
        page.click("#dl-report-html")
    dl.value.save_as(tmp_path / "report.html")
    assert (tmp_path / "report.html").stat().st_size > 10_000
    saved = tmp_path / "saved" / "my mission.yaml"
    page.fill("#save-path", str(saved))
    page.click("#btn-save")
    page.wait_for_selector("#saved-path")
    assert page.inner_text("#saved-path") == str(saved)
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    run = cli("run", str(saved), "--out", str(tmp_path / "cli"), "--quiet", cwd=elsewhere)
    assert run.returncode == 0, run.stderr
    assert downloaded.read_bytes() == (tmp_path / "cli" / "mission.plan").read_bytes()
    plan = json.loads(downloaded.read_text())
    assert plan["fileType"] == "Plan" and len(plan["geoFence"]["polygons"]) == 1
    # can a multirotor fly it? (fm2uav check in the page)
    page.select_option("#check-airframe", "arducopter")
    job = plan_and_wait(page, button="#btn-check", kind="check")
    assert job["state"] == "done", job["error"]
    assert page.inner_text("#check-verdict").startswith("FLYABLE")


def test_a_point_off_the_map_shows_the_cli_error_in_the_page(page, app_run, tmp_path):
    w, s, e, n = page.evaluate("fm2app.terrain.bounds")
    page.evaluate(f"fm2app.map.fitBounds([[{s}, {w - 0.5 * (e - w)}], [{n}, {e}]])")
    page.click("#tool-start")
    click_map(page, w - 0.25 * (e - w), s + 0.5 * (n - s))    # west of the DEM
    job = plan_and_wait(page)
    assert job["state"] == "error"
    shown = page.inner_text("#error")
    assert shown.startswith("error: start = (") and "lies outside the map" in shown
    # the same words as fm2uav run on the mission file the job ran
    mission = Path(app_run[1]) / "session" / "jobs" / job["id"] / "mission.yaml"
    run = cli("run", str(mission), "--out", str(tmp_path / "o"), cwd=tmp_path)
    assert run.returncode == 2
    assert shown.strip() == " ".join(run.stderr.split())
    page.locator("#map").screenshot(path=str(SHOTS / "app-error-off-map.png"))
    page.click("#btn-clear-points")


def test_a_bad_dem_shows_the_cli_error_in_the_page(page, tmp_path):
    bad = tmp_path / "bad.tif"
    bad.write_text("this is not a raster\n")
    page.fill("#dem-path", str(bad))
    before = page.evaluate("fm2app.job.id")
    page.click("#btn-dem-add")
    page.wait_for_function(f"fm2app.job.id !== {json.dumps(before)} && "
                           "['done', 'error'].includes(fm2app.job.state)", timeout=60_000)
    shown = page.inner_text("#error")
    assert "world.dem" in shown and "cannot be read as a raster" in shown
    m = tmp_path / "m.yaml"     # the page's world (the good DEM and the bad one) in a file
    world = page.evaluate("fm2app.missionDoc().world")
    m.write_text(json.dumps({"world": world, "start": {"lon": 10, "lat": 46, "agl": 60},
                             "goal": {"lon": 10.1, "lat": 46, "agl": 60}}))
    run = cli("run", str(m), cwd=tmp_path)
    assert run.returncode == 2
    cli_words = " ".join(run.stderr.split()).split("world.dem", 1)[1]
    assert shown.split("world.dem", 1)[1].strip() == cli_words.strip()
    page.screenshot(path=str(SHOTS / "app-error-bad-dem.png"))
    assert not page.js_errors, page.js_errors
