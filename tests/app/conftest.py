"""Fixtures of the app's browser tests: ``fm2uav app`` running, and its page in chromium."""

from __future__ import annotations

import os
import re
import subprocess
import time

import pytest

from .browser import FM2UAV, chromium_path, launch
from .dem import make_dem


@pytest.fixture(scope="module")
def app_run(tmp_path_factory):
    """``fm2uav app`` on a free port with a GeoTIFF; yields (url, folder); stopped after."""
    chromium_path()  # skip before starting anything when there is no browser
    root = tmp_path_factory.mktemp("app")
    dem = make_dem(root / "terrain.tif")
    log = root / "app.log"   # a file, not a pipe: the server never blocks on its output
    with open(log, "w") as out:
        proc = subprocess.Popen(
            [*FM2UAV, "app", "--dem", str(dem), "--port", "0", "--no-browser", "--dir",
             str(root / "session")], cwd=root, stdout=out, stderr=subprocess.STDOUT,
            text=True, env={**os.environ, "COLUMNS": "200"})
    url, t0 = None, time.time()
    while url is None and proc.poll() is None and time.time() - t0 < 60:
        url = re.search(r"http://127\.0\.0\.1:\d+/", log.read_text())
        time.sleep(0.1)
    if url is None:
        proc.kill()
        pytest.fail(f"fm2uav app printed no URL: {log.read_text()!r}")
    yield url.group(0), root
    proc.terminate()
    try:
        proc.wait(timeout=10)
    except subprocess.TimeoutExpired:  # pragma: no cover
        proc.kill()


@pytest.fixture(scope="module")
def page(app_run, tmp_path_factory):
    """The app's page, loaded (world checked, DEM tiles shown)."""
    sync_api = pytest.importorskip("playwright.sync_api",
                                   reason="Playwright (PyPI 'playwright') is not installed")
    with sync_api.sync_playwright() as pw:
        ctx = launch(pw, tmp_path_factory.mktemp("chromium-profile"),
                     viewport={"width": 1400, "height": 900})
        pg = ctx.new_page()
        errors: list[str] = []
        pg.on("pageerror", lambda e: errors.append(str(e)))
        pg.goto(app_run[0])
        pg.wait_for_function("window.fm2app && window.fm2app.loaded", timeout=60_000)
        pg.js_errors = errors
        yield pg
        ctx.close()
