"""report.html opens on its map (fm2uav.viz.reportmap): the structure of the page, the map's
route equal to path.geojson's, and a real render in headless chromium (Playwright, the app
tests' launcher) read back from the screenshot: relief, route by height above ground, zone,
buildings — offline, no error, nothing fetched.

One ``fm2uav plan`` on a GeoTIFF in lon/lat with buildings and a no-fly zone (module fixture),
one browser for the module. Screenshots are kept under out/report-browser/.
"""

from __future__ import annotations

import io
import json
import re
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from ..app.browser import launch
from ..world.rough_terrain import rough_dem, write_geotiff

SHOTS = Path(__file__).resolve().parents[2] / "out" / "report-browser"
#: the requested height above ground: the route is drawn green (#1a9641) at it
AGL = 80.0


def _box(w, s, e, n):
    return {"type": "Polygon", "coordinates": [[[w, s], [e, s], [e, n], [w, n], [w, s]]]}


def _collection(*features):
    return json.dumps({"type": "FeatureCollection", "features": [
        {"type": "Feature", "properties": p, "geometry": g} for p, g in features]})


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    """``fm2uav plan`` over 3.4 km x 3.3 km of a rough lon/lat DEM, two buildings, a no-fly
    zone; with --report and path.geojson. Returns the output folder."""
    from fm2uav.cli import app

    root = tmp_path_factory.mktemp("report-map")
    dem = write_geotiff(root / "rough.tif", rough_dem(5))
    (root / "buildings.geojson").write_text(_collection(
        ({"height": 40}, _box(-3.7700, 40.3120, -3.7680, 40.3135)),
        ({"height": 25}, _box(-3.7650, 40.3160, -3.7635, 40.3170))))
    (root / "zone.geojson").write_text(_collection(
        ({"name": "school", "floor": 0, "ceiling": 2000},
         _box(-3.7760, 40.3180, -3.7700, 40.3230))))
    out = root / "plan"
    res = CliRunner().invoke(app, [
        "plan", "--dem", str(dem), "--bbox", "-3.79,40.30,-3.75,40.33", "--cell-size", "50",
        "--lonlat", "--start", "-3.785,40.305", "--goal", "-3.755,40.325", "--agl", f"{AGL:g}",
        "--buildings", str(root / "buildings.geojson"), "--no-fly", str(root / "zone.geojson"),
        "--report", "--export", "geojson", "--out", str(out), "--quiet"])
    assert res.exit_code == 0, res.output
    return out


def _map_document(page: str) -> dict:
    m = re.search(r'<script type="application/json" id="fm2uav-map-data">(.*?)</script>',
                  page, re.S)
    assert m, "no map document in the report"
    return json.loads(m.group(1))


def test_the_report_opens_on_the_map_with_the_operator_figures_beside_it(run):
    page = (run / "report.html").read_text(encoding="utf-8")
    body = page[page.index("<body"):]
    # the map is the first thing of the page: before the profiles, the 3D view, the tables
    first = body.index('id="fm2uav-map"')
    assert first < body.index('id="fm2uav-profiles"') < body.index('id="fm2uav-scene"')
    assert first < body.index("<details")
    # the operator's figures beside the map: how long, how long in time, how high, where
    aside = body[body.index("<aside"):body.index("</aside>")]
    figures = re.findall(r"<tr><th>(.*?)</th><td>(.*?)</td></tr>", aside)
    names = [k for k, _ in figures]
    assert names[:2] == ["route length", "flight time"], names
    for name in ("take-off (home)", "lowest above ground", "clearance to terrain and buildings",
                 "nearest no-fly zone"):
        assert name in names, names
    lowest = dict(figures)["lowest above ground"]
    assert re.search(r"\d+ m, .*\d+\.\d{5}° N, \d+\.\d{5}° W", lowest), lowest
    summary = json.loads((run / "summary.json").read_text())
    assert dict(figures)["route length"] == f"{summary['length_m'] / 1000:.2f} km"
    # the research parameters are folded away, not among the operator's figures
    research = body[body.index("<details"):body.index("</details>")]
    assert "<details open" not in body
    for name in ("saturation", "exponent"):
        assert name in research and name not in aside


def test_the_map_route_is_the_path_geojson_route(run):
    doc = _map_document((run / "report.html").read_text(encoding="utf-8"))
    route = next(f for f in doc["features"] if f["properties"]["kind"] == "route")
    exported = json.loads((run / "path.geojson").read_text())
    line = next(f for f in exported["features"] if f["geometry"]["type"] == "LineString")
    ours = np.asarray(route["geometry"]["coordinates"], dtype=float)[:, :2]
    theirs = np.asarray(line["geometry"]["coordinates"], dtype=float)[:, :2]
    assert ours.shape == theirs.shape
    np.testing.assert_allclose(ours, theirs, atol=1e-7)     # ~1 cm
    # the height above ground along it: the path's altitude over the map's ground
    assert route["properties"]["requested_agl"] == AGL
    # the relief: an image placed by its lon/lat corners over the crop
    w, s, e, n = doc["terrain"]["bounds"]
    assert -3.80 < w < -3.789 and -3.751 < e < -3.74 and 40.29 < s < 40.301 and 40.329 < n < 40.34
    assert doc["terrain"]["url"].startswith("data:image/png;base64,")
    kinds = [f["properties"]["kind"] for f in doc["features"]]
    assert kinds.count("building") == 2 and kinds.count("zone") == 1


@pytest.fixture(scope="module")
def shown(run, tmp_path_factory):
    """The report in headless chromium: (screenshot PNG bytes, probe, JS errors, requests)."""
    sync_api = pytest.importorskip("playwright.sync_api",
                                   reason="Playwright (PyPI 'playwright') is not installed")
    with sync_api.sync_playwright() as pw:
        ctx = launch(pw, tmp_path_factory.mktemp("chromium-profile"),
                     viewport={"width": 1400, "height": 900}, offline=True)
        pg = ctx.new_page()
        errors: list[str] = []
        requests: list[str] = []
        pg.on("pageerror", lambda e: errors.append(str(e)))
        pg.on("console", lambda m: errors.append(m.text) if m.type == "error" else None)
        pg.on("request", lambda r: requests.append(r.url))
        pg.goto((run / "report.html").as_uri())
        pg.wait_for_function("window.fm2report && window.fm2report.ready", timeout=60_000)
        pg.wait_for_function("Array.from(document.querySelectorAll('.leaflet-image-layer'))"
                             ".every(i => i.complete && i.naturalWidth > 0)", timeout=30_000)
        probe = pg.evaluate("""(() => {
          const m = fm2report.map, box = document.getElementById('fm2uav-map')
            .getBoundingClientRect();
          const route = fm2report.doc.features.find(f => f.properties.kind === 'route');
          const c = route.geometry.coordinates;
          const at = ([lon, lat]) => { const p = m.latLngToContainerPoint([lat, lon]);
                                       return [box.left + p.x, box.top + p.y]; };
          const zone = fm2report.doc.features.find(f => f.properties.kind === 'zone');
          const ring = zone.geometry.coordinates[0];
          const lons = ring.map(p => p[0]), lats = ring.map(p => p[1]);
          return {map: [box.left, box.top, box.width, box.height],
                  route: c.map(at),
                  zone_centre: at([(Math.min(...lons) + Math.max(...lons)) / 2,
                                   (Math.min(...lats) + Math.max(...lats)) / 2]),
                  layers: Array.from(document.querySelectorAll(
                    '#fm2uav-layers .leaflet-control-layers-overlays label'))
                    .map(l => l.textContent.trim()),
                  legend: (document.querySelector('.fm2-legend') || {}).textContent || '',
                  zone_labels: Array.from(document.querySelectorAll('.fm2-zone-label'))
                    .map(e => e.textContent),
                  graticule: Array.from(document.querySelectorAll('.fm2-grat'))
                    .map(e => e.textContent)};
        })()""")
        png = pg.screenshot()
        SHOTS.mkdir(parents=True, exist_ok=True)
        (SHOTS / "plan-report.png").write_bytes(png)
        pg.screenshot(path=str(SHOTS / "plan-report-full.png"), full_page=True)
        ctx.close()
    return png, probe, errors, requests


@pytest.mark.slow
def test_the_report_renders_offline_without_errors(shown):
    _, probe, errors, requests = shown
    assert errors == [], errors
    assert requests and all(u.startswith(("file:", "data:", "blob:")) for u in requests), [
        u for u in requests if not u.startswith(("file:", "data:", "blob:"))]
    for layer in ("terrain (shaded relief)", "buildings", "no-fly zones", "FM² path"):
        assert any(layer in t for t in probe["layers"]), probe["layers"]


@pytest.mark.slow
def test_the_screenshot_shows_relief_route_and_zone(shown):
    from PIL import Image

    png, probe, _, _ = shown
    img = np.asarray(Image.open(io.BytesIO(png)).convert("RGB"), dtype=float)
    x0, y0, w, h = (int(round(v)) for v in probe["map"])
    assert w > 600 and h > 400 and y0 < 200         # the map is at the top of the page
    area = img[y0:y0 + h, x0:x0 + w]
    # not blank: the relief gives many colours over most of the map
    assert len(np.unique(area.reshape(-1, 3).astype(np.uint8), axis=0)) > 2000
    grey_bg = np.all(np.abs(area - [223, 229, 234]) < 6, axis=-1)    # the map's background
    assert grey_bg.mean() < 0.5
    # the route: at the requested height it is drawn green (#1a9641) all along — look at
    # points along it (a few pixels around each)
    pts = np.asarray(probe["route"], dtype=float)
    inside = [(px, py) for px, py in pts[:: max(1, len(pts) // 40)]
              if x0 + 3 < px < x0 + w - 3 and y0 + 3 < py < y0 + h - 3]
    assert len(inside) >= 20

    def near(px, py, rgb, tol=45.0):
        r, c = int(round(py)), int(round(px))
        patch = img[r - 3:r + 4, c - 3:c + 4].reshape(-1, 3)
        return bool((np.linalg.norm(patch - rgb, axis=1) < tol).any())

    # (the numbered waypoint badges cover the route at some of them)
    green = sum(near(px, py, (26, 150, 65)) for px, py in inside)
    assert green >= 0.6 * len(inside), (green, len(inside))
    # the no-fly zone: its red outline is drawn around its centre
    zx, zy = probe["zone_centre"]
    r0, c0 = int(round(zy)), int(round(zx))
    box = img[max(r0 - 90, 0):r0 + 90, max(c0 - 90, 0):c0 + 90]
    red = (box[..., 0] > 170) & (box[..., 1] < 110) & (box[..., 2] < 110)
    assert red.sum() > 40, red.sum()
    # the colour bar of the height above ground says the requested height
    assert "requested 80 m" in probe["legend"], probe["legend"]
    assert probe["zone_labels"] == ["school: 0–2000 m AMSL"], probe["zone_labels"]
    # lon/lat lines labelled with their hemisphere: west of Greenwich, north
    grat = probe["graticule"]
    assert any(t.endswith("° W") for t in grat) and any(t.endswith("° N") for t in grat), grat
