"""Headless Debian chromium driven by Playwright for the app's tests (never `playwright install`).

:func:`chromium` yields a fresh browser context (a new user-data folder each time), or
skips the test with the reason when chromium or Playwright is missing (CI installs
chromium in ``.ci/run``, so there the tests run).
"""

from __future__ import annotations

import json
import shutil
import sys
from pathlib import Path

import pytest

CHROMIUM = "/usr/bin/chromium"
ARGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
        "--disable-background-networking", "--disable-component-update", "--disable-sync"]
#: The command line, run by this interpreter.
FM2UAV = [sys.executable, "-m", "fm2uav"]
#: Where the screenshots are kept (CI artefacts).
SHOTS = Path(__file__).resolve().parents[2] / "out" / "app-browser"


def chromium_path() -> str:
    """The chromium executable, or skip with the reason."""
    path = CHROMIUM if Path(CHROMIUM).exists() else shutil.which("chromium")
    if not path:
        pytest.skip("Debian's chromium is not installed (apt-get install chromium; .ci/run "
                    "installs it): the app's browser tests need a real browser")
    return path


def launch(playwright, user_data: Path, **context):
    """A persistent (fresh folder) chromium context accepting downloads."""
    return playwright.chromium.launch_persistent_context(
        str(user_data), executable_path=chromium_path(), args=ARGS, headless=True,
        accept_downloads=True, **context)


def route_pixels(png: bytes, rgb: tuple[int, int, int], tol: float = 40.0) -> tuple[int, int]:
    """``(pixels within tol of rgb, distinct colours)`` of a PNG screenshot."""
    import io

    import numpy as np
    from PIL import Image

    a = np.asarray(Image.open(io.BytesIO(png)).convert("RGB"), dtype=float)
    near = np.linalg.norm(a - np.array(rgb, dtype=float), axis=-1) <= tol
    distinct = len(np.unique(a.reshape(-1, 3).astype(np.uint8), axis=0))
    return int(near.sum()), distinct


def lonlat_at(pg, fx: float, fy: float) -> tuple[float, float]:
    """Lon/lat at fractions (fx west→east, fy south→north) of the DEM's bounds."""
    w, s, e, n = pg.evaluate("fm2app.terrain.bounds")
    return w + fx * (e - w), s + fy * (n - s)


def click_map(pg, lon: float, lat: float) -> None:
    """A real mouse click on the map at lon/lat."""
    x, y = pg.evaluate(f"(() => {{ const p = fm2app.map.latLngToContainerPoint([{lat}, {lon}]);"
                       " return [p.x, p.y]; })()")
    box = pg.locator("#map").bounding_box()
    pg.mouse.click(box["x"] + x, box["y"] + y)


def plan_and_wait(pg, timeout: float = 90_000, button: str = "#btn-plan",
                  kind: str = "plan") -> dict:
    """Click Plan (or ``button``) and wait for the job to end; returns the job."""
    before = pg.evaluate("fm2app.job ? fm2app.job.id : null")
    pg.click(button)
    pg.wait_for_function(
        f"fm2app.job && fm2app.job.kind === '{kind}' && fm2app.job.id !== {json.dumps(before)}"
        " && ['done', 'error', 'cancelled'].includes(fm2app.job.state)", timeout=timeout)
    return pg.evaluate("fm2app.job")


def purple_pixels(png: bytes) -> int:
    """Pixels tinted purple (blue and red above green): the photo footprints' colour, which
    neither the terrain's greens and browns nor the route's colours have."""
    import io

    import numpy as np
    from PIL import Image

    a = np.asarray(Image.open(io.BytesIO(png)).convert("RGB"), dtype=int)
    r, g, b = a[..., 0], a[..., 1], a[..., 2]
    return int(((b - g > 12) & (r - g > 4)).sum())


def wait_for_tiles(pg, timeout: float = 30_000) -> None:
    """Wait until the DEM tiles of the current view have all arrived (before a screenshot)."""
    pg.wait_for_function("fm2app.terrainLayer && !fm2app.terrainLayer.isLoading()",
                         timeout=timeout)
