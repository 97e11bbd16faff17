"""docs/app.md's commands run as written (the app started as the guide says, stopped after)."""

from __future__ import annotations

import json
import os
import re
import shlex
import signal
import subprocess
import sys
import urllib.request
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
DOC = (ROOT / "docs" / "app.md").read_text()


def _commands() -> list[str]:
    block = re.search(r"```bash\n(.*?)```", DOC, flags=re.S).group(1)
    return [line.split("  #")[0].strip() for line in block.splitlines() if line.strip()]


def test_the_guide_shows_the_three_steps():
    cmds = _commands()
    assert [c.split()[1] if c.startswith(".venv/bin/fm2uav") else c.split()[1]
            for c in cmds] == ["examples/make_jacksboro_geotiff.py", "app", "run"]


def _workspace(path: Path) -> Path:
    """A folder laid out as the guide's reader has it after ``make run`` (``.venv``: the
    environment running the tests, ``examples/``: the repository's, ``out/``: made by
    ``make run``), so the commands write into it and never into the checkout's ``out/``."""
    (path / ".venv").symlink_to(Path(sys.prefix))
    (path / "examples").symlink_to(ROOT / "examples")
    (path / "out").mkdir()
    return path


@pytest.mark.slow
def test_the_guides_commands_run(tmp_path):
    make, app_cmd, run_cmd = _commands()
    ws = _workspace(tmp_path)
    env = {**os.environ, "BROWSER": "true", "COLUMNS": "200"}   # no browser window in tests
    subprocess.run(shlex.split(make), cwd=ws, check=True, env=env, timeout=120)
    assert (ws / "out" / "jacksboro.tif").is_file()
    # the app as the guide starts it, on a free port (the default one may be taken here)
    proc = subprocess.Popen([*shlex.split(app_cmd), "--port", "0"], cwd=ws, env=env,
                            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    try:
        line = proc.stdout.readline()
        url = re.search(r"http://127\.0\.0\.1:\d+/", line).group(0)
        session = json.load(urllib.request.urlopen(url + "api/session", timeout=30))
        assert session["mission"]["world"]["dem"] == str(ws / "out" / "jacksboro.tif")
        assert session["mission_path"] == str(ws / "out" / "app" / "mission.yaml")
        # what the page sends on "Save mission": the page's document, default path
        doc = {**session["mission"], "name": "from the guide",
               "world": {**session["mission"]["world"], "cell_size": 300},
               "start": {"lon": -84.36016, "lat": 36.53435, "agl": 300},
               "goal": {"lon": -84.12133, "lat": 36.65048, "agl": 300},
               "planner": {"agl": 300}, "outputs": {"formats": ["plan", "wpl", "json"]}}
        req = urllib.request.Request(url + "api/mission/save", method="POST",
                                     data=json.dumps({"mission": doc}).encode(),
                                     headers={"Content-Type": "application/json"})
        saved = json.load(urllib.request.urlopen(req, timeout=30))
        assert saved["path"] == session["mission_path"]
    finally:
        proc.send_signal(signal.SIGINT)                     # Ctrl-C, as the guide says
        assert proc.wait(timeout=20) == 0
    res = subprocess.run([*shlex.split(run_cmd), "--quiet"], cwd=ws, env=env,
                         capture_output=True, text=True, timeout=300)
    assert res.returncode == 0, res.stderr
    assert json.loads((ws / "out" / "from-app" / "mission.plan").read_text())["fileType"] \
        == "Plan"
