"""Headless Debian chromium driven by Playwright for the app's tests (never `playwright install`).

:func:`chromium` yields a fresh browser context (a new user-data folder each time), or
skips the test with the reason when chromium or Playwright is missing (CI installs
chromium in ``.ci/run``, so there the tests run).
"""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

CHROMIUM = "/usr/bin/chromium"
ARGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
        "--disable-background-networking", "--disable-component-update", "--disable-sync"]
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
