"""HTML reports: content, self-containment, and a real render in headless Chromium."""

import io
import re

import numpy as np
import pytest

from fm2uav import FlightLevel, World, plan
from fm2uav.viz.report import plan_report, report_html, write_report

from .cdp import Browser, find_chromium

CHROMIUM = find_chromium()


@pytest.fixture(scope="module")
def hill_plan():
    x = np.arange(41)[:, None] * 10.0
    y = np.arange(31)[None, :] * 10.0
    h = 10.0 + 80.0 * np.exp(-((x - 200) ** 2 + (y - 150) ** 2) / (2 * 70.0**2))
    w = World.from_heightmap(h, 10.0, 24, name="hill")
    return plan(w, (20.0, 20.0, 70.0), (380.0, 280.0, 70.0), level=FlightLevel(agl=60.0, p2=1.5))


def _scripts(html):
    return re.findall(r"<script[^>]*>", html)


def test_report_is_self_contained_and_has_the_content(hill_plan):
    html = plan_report(hill_plan, title="Hill <TFF>", subtitle="a & b",
                       waypoints={"FM² path": hill_plan.path[::10]}, files=["mission.plan"])
    assert html.startswith("<!DOCTYPE html>")
    assert len(html) > 1_000_000                        # plotly.js inlined
    assert not any("src=" in s for s in _scripts(html))  # nothing loaded from elsewhere
    assert "Hill &lt;TFF&gt;" in html and "a &amp; b" in html
    for text in ("3D view", "profiles", "height above ground", "flight level 60 m",
                 "saturation", "length [m]", "clearance [m]", "mission.plan", "terrain"):
        assert text in html, text
    assert html.count('class="plotly-graph-div"') == 2


def test_buildings_and_2d_worlds(tmp_path):
    occ = np.zeros((30, 20, 10), bool)
    occ[:, :, 0] = True                 # ground
    occ[10:14, 0:14, :7] = True          # a building
    w = World(occ, spacing=5.0)
    html = report_html(w, {"a": [[5, 5, 20], [140, 90, 20]], "b": [[5, 90, 20], [140, 5, 25]]})
    assert html.count('"name":"obstacles"') == 1 and '"name":"terrain"' not in html
    occ2 = np.zeros((40, 30), bool)
    occ2[18:22, :20] = True
    p = plan(World(occ2, spacing=1.0), (5.0, 5.0), (35.0, 5.0))
    html2 = plan_report(p)
    assert '"type":"heatmap"' in html2.replace(" ", "")
    out = write_report(tmp_path / "r.html", html2)
    assert out.read_text(encoding="utf-8") == html2
    with pytest.raises(ValueError, match="at least one path"):
        report_html(w, {})


def _png_pixels(data: bytes) -> np.ndarray:
    import matplotlib.image as mpimg

    return mpimg.imread(io.BytesIO(data), format="png")


needs_chromium = pytest.mark.skipif(
    CHROMIUM is None,
    reason="Chromium is not installed (Debian: apt-get install -y chromium); "
    "the browser render check needs it")


@pytest.fixture(scope="module")
def browser():
    with Browser(CHROMIUM, timeout=60) as b:
        yield b


@needs_chromium
def test_the_checker_sees_javascript_errors_and_network_requests(browser, tmp_path):
    f = tmp_path / "bad.html"
    f.write_text("<html><body><p>x</p><script>console.error('bad thing');"
                 "fetch('http://127.0.0.1:9/none').catch(() => {});"
                 "setTimeout(() => { throw new Error('boom'); }, 0);</script></body></html>")
    r = browser.load(f.as_uri(), ready_js="true")
    assert any("bad thing" in e for e in r.errors), r.errors
    assert any("boom" in e for e in r.errors), r.errors
    assert any(u.startswith("http://127.0.0.1") for u in r.requests), r.requests


@needs_chromium
def test_report_renders_in_headless_chromium(browser, hill_plan, tmp_path):
    html = plan_report(hill_plan, title="render check",
                       waypoints={"FM² path": hill_plan.path[::10]})
    f = write_report(tmp_path / "report.html", html)
    ready = ("(() => { const d = document.querySelectorAll('.js-plotly-plot');"
             " return d.length === 2 && Array.from(d).every(g => g._fullLayout); })()")
    probe = ("(() => { const g = document.getElementById('fm2uav-scene');"
             " const s = g._fullLayout.scene._scene;"
             " return {webgl: !!(s && s.glplot), traces: g.data.length,"
             " svg: document.querySelectorAll('#fm2uav-profiles .main-svg').length,"
             " lines: document.querySelectorAll('#fm2uav-profiles path.js-line').length}; })()")
    result = browser.load(f.as_uri(), ready_js=ready, probe_js=probe)
    assert result.errors == [], result.errors
    # self-contained: the only request is the file itself
    assert result.requests and all(u.startswith(("file:", "data:", "blob:"))
                                   for u in result.requests), result.requests
    assert result.probe["webgl"] is True, result.probe  # the 3D scene got a WebGL context
    assert result.probe["traces"] >= 4 and result.probe["lines"] >= 3, result.probe
    img = _png_pixels(result.screenshot)[..., :3]
    assert img.shape[:2] == (1000, 1280)
    # non-blank: many colours and a large share of non-background pixels in the scene area
    scene = img[150:700, 200:1100]
    background = np.all(scene > 0.97, axis=-1)
    assert (~background).mean() > 0.15
    assert len(np.unique((scene * 255).astype(np.uint8).reshape(-1, 3), axis=0)) > 500
    # the path is drawn: strongly red pixels (path colour #d62728) appear in the scene
    red = (scene[..., 0] > 0.7) & (scene[..., 1] < 0.35) & (scene[..., 2] < 0.35)
    assert red.sum() > 200
