"""docs/operator.md, *ArduPilot terrain files*: the command runs as written and writes what
the guide says it writes (the terrain folder, its parameters, the climb-out and speeds)."""

from __future__ import annotations

import re
import shlex
from pathlib import Path

import pytest

from .docs_run import _without, commands

ROOT = Path(__file__).resolve().parents[2]
DOC = (ROOT / "docs" / "operator.md").read_text()


def _section() -> str:
    return DOC.split("### ArduPilot terrain files", 1)[1].split("\n### ", 1)[0]


@pytest.mark.slow
def test_the_terrain_files_command_writes_what_the_guide_says(cli_once):
    text = _section()
    (command,) = commands(re.search(r"```bash\n(.*?)```", text, flags=re.S).group(1))
    args = shlex.split(command, comments=True)
    assert args[0] == ".venv/bin/fm2uav" and "--out" in args
    # the run the docs' run makes of the same command (cli_once: once per session)
    run = cli_once(_without(args[1:], "--out"))
    res, out = run.result, run.out
    assert res.exit_code == 0, res.output
    spacing = int(args[args.index("--terrain-spacing") + 1])
    dat = re.search(r"`terrain/(\w+\.DAT)`", text).group(1)
    assert sorted(p.name for p in (out / "terrain").iterdir()) == [dat, "terrain.param"]
    assert f"TERRAIN_SPACING {spacing}" in (out / "terrain" / "terrain.param").read_text()
    assert f"(`TERRAIN_SPACING {spacing}`)" in text
    rows = " ".join(res.output.split())
    assert "APM/terrain/" in rows and f"TERRAIN_SPACING={spacing}" in rows
    items = [line.split("\t") for line in (out / "mission.waypoints").read_text().splitlines()[1:]]
    assert "31" in [i[3] for i in items]  # the loiter climb-out
    lo, hi = (float(args[args.index(f) + 1]) for f in ("--min-speed", "--cruise-speed"))
    speeds = [(float(i[4]), float(i[5])) for i in items if i[3] == "178"]
    assert speeds and all(t == 0 and lo <= v <= hi for t, v in speeds)
    assert f"airspeeds from W between {lo:g} and {hi:g} m/s" in text
