"""The buildings-without-a-DEM command of docs/operator.md (section 4) runs as written and
does what its comment says: on ``--ground-elevation`` z is an altitude above sea level and
the mission is AMSL on that ground; without it z is the height above the ground and the
mission is written relative to home, with a home altitude that is unknown."""

from __future__ import annotations

import contextlib
import json
import os
import shlex
from pathlib import Path

import pytest

from .docs_run import _without

ROOT = Path(__file__).resolve().parents[2]
DOC = ROOT / "docs" / "operator.md"


def _doc_command() -> list[str]:
    """The ``fm2uav plan --buildings ... --ground-elevation`` command of the guide."""
    text = DOC.read_text().replace("\\\n", " ")
    lines = [ln for ln in text.splitlines()
             if ln.startswith(".venv/bin/fm2uav plan --buildings") and "--ground-elevation" in ln]
    assert len(lines) == 1, lines
    return shlex.split(lines[0])[1:]


@contextlib.contextmanager
def _in_repository():
    """The guide's paths are relative to the repository."""
    old = os.getcwd()
    os.chdir(ROOT)
    try:
        yield
    finally:
        os.chdir(old)


def _read(out: Path) -> tuple[dict, dict]:
    return (json.loads((out / "summary.json").read_text()),
            json.loads((out / "mission.plan").read_text()))


def _run(args: list[str], out: Path) -> tuple[dict, dict]:
    from typer.testing import CliRunner

    from fm2uav.cli import app

    args = [*args[:args.index("--out")], "--out", str(out), "--quiet"]
    with _in_repository():
        res = CliRunner().invoke(app, args)
    assert res.exit_code == 0, res.output
    return _read(out)


@pytest.mark.slow
def test_buildings_alone_on_a_ground_elevation_and_without_one(tmp_path, cli_once):
    args = _doc_command()
    ground = float(args[args.index("--ground-elevation") + 1])
    # the command as written: the run the docs' run makes of it (cli_once, once per session)
    with _in_repository():
        run = cli_once(_without(args, "--out"))
    assert run.result.exit_code == 0, run.result.output
    s, plan = _read(run.out)
    wps = [it for it in plan["mission"]["items"] if it["command"] == 16]
    assert {it["frame"] for it in wps} == {0}
    assert s["autopilot"]["home"]["alt_amsl_m"] == ground
    agl = float(args[args.index("--agl") + 1])
    assert min(it["params"][6] for it in wps) >= ground + agl - 0.5
    # the same without the ground's altitude: z above the ground, relative to home
    i = args.index("--ground-elevation")
    rel = args[:i] + args[i + 2:]
    for flag in ("--start", "--goal"):
        k = rel.index(flag) + 1
        x, y, z = rel[k].split(",")
        rel[k] = f"{x},{y},{float(z) - ground:g}"
    s, plan = _run(rel, tmp_path / "relative")
    wps = [it for it in plan["mission"]["items"] if it["command"] == 16]
    assert {it["frame"] for it in wps} == {3}
    assert s["autopilot"]["home"]["alt_amsl_m"] is None
    assert min(it["params"][6] for it in wps) >= agl - 0.5
