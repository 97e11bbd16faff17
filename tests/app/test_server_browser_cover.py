"""A survey in a real browser: draw the area, pick a camera, Cover, see bands and photos.

(The app and chromium as in test_server_browser.py; its own file, so each stays short.)
"""

from __future__ import annotations

import numpy as np
import pytest

from .browser import (SHOTS, click_map, lonlat_at, plan_and_wait, purple_pixels, route_pixels,
                      wait_for_tiles)

def test_draw_an_area_and_cover_it_with_a_camera(page):
    page.click("#tool-area")
    corners = [lonlat_at(page, fx, fy) for fx, fy in
               ((0.35, 0.40), (0.50, 0.40), (0.50, 0.60), (0.35, 0.60))]
    for c in corners + corners[:1]:
        click_map(page, *c)
    assert "ha" in page.inner_text("#area-info")
    page.select_option("#c-preset", label='1" 20 MP, 8.8 mm (e.g. Phantom 4 Pro)')
    assert page.input_value("#c-camera") == "13.2,8.8,8.8,5472,3648"
    page.fill("#c-side_overlap", "0.2")
    page.fill("#p-agl", "80")
    job = plan_and_wait(page, button="#btn-cover", kind="cover", timeout=120_000)
    assert job["state"] == "done", job["error"]
    s = job["result"]["map"]["summary"]
    assert s["bands"] >= 3 and s["photos"] > 20 and s["coverage"] > 0.95
    assert s["gsd_cm_per_px"] == pytest.approx(80 * 13.2 / 8.8 / 5472 * 100, rel=1e-3)
    cards = page.inner_text("#cards")
    assert f"{s['photos']} photos" in cards and f"{s['bands']} bands" in cards
    assert "fm2uav cover" in page.inner_text("#command")
    for name in ("mission.plan", "report.html", "coverage.html"):
        assert page.locator(f"#dl-{name.replace('.', '-')}").count() == 1
    # the route stays inside the area's bands' reach at ~80 m above the ground
    route = next(f for f in job["result"]["map"]["features"]
                 if f["properties"]["kind"] == "route")
    agl = np.array(route["properties"]["agl"])
    assert np.median(agl) == pytest.approx(80, abs=4)
    wait_for_tiles(page)
    SHOTS.mkdir(parents=True, exist_ok=True)
    page.screenshot(path=str(SHOTS / "app-cover.png"))
    shot = page.locator("#map").screenshot(path=str(SHOTS / "app-cover-map.png"))
    green_px, distinct = route_pixels(shot, (26, 150, 65))
    assert distinct > 500 and green_px > 200 and purple_pixels(shot) > 5000
    assert not page.js_errors, page.js_errors
