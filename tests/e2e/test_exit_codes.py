"""Refusals and their exit codes (issue 25 deliverable 7; docs/operator.md §7): bad input is 2,
a plan that cannot be made is 1, on every command and every way in (flags, mission files,
zone files). Each row: the command line, the code, a fragment of the one-line message.

The rows that only parse run in a fraction of a second; those that build a world or plan are
marked slow.
"""

from __future__ import annotations

import json

import pytest
from typer.testing import CliRunner

from fm2uav.cli import app

runner = CliRunner()
SLOW = pytest.mark.slow

# the open field (15 m cells, 1785 x 1335 m): start cell (20, 20) = (300, 300) m
START, GOAL = (300.0, 300.0), (1500.0, 1200.0)


def _box(cx: float, cy: float, r: float) -> list[list[float]]:
    return [[cx - r, cy - r], [cx + r, cy - r], [cx + r, cy + r], [cx - r, cy + r]]


def _walls(cx: float, cy: float, inner: float, outer: float) -> list[list[list[float]]]:
    """Four zones that close a square ring around (cx, cy): nothing gets in or out."""
    return [[[cx - outer, cy - outer], [cx + outer, cy - outer], [cx + outer, cy - inner],
             [cx - outer, cy - inner]],
            [[cx - outer, cy + inner], [cx + outer, cy + inner], [cx + outer, cy + outer],
             [cx - outer, cy + outer]],
            [[cx - outer, cy - outer], [cx - inner, cy - outer], [cx - inner, cy + outer],
             [cx - outer, cy + outer]],
            [[cx + inner, cy - outer], [cx + outer, cy - outer], [cx + outer, cy + outer],
             [cx + inner, cy + outer]]]


def _mission(tmp, name: str, zones: list | None = None) -> str:
    lines = ["version: 1", f"name: {name}", "world: {scenario: open-field}",
             "start: {cell: [20, 20, 20]}", "goal: {cell: [100, 80, 30]}",
             "planner: {agl: 150}", "outputs: {formats: [csv, json]}"]
    if zones is not None:
        lines.append("no_fly_zones: " + json.dumps([{"polygon": z} for z in zones]))
    path = tmp / f"{name}.yaml"
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return str(path)


def _zone_file(tmp) -> str:
    """A GeoJSON no-fly zone around the open field's start (in the map's metres: the
    scenario has no CRS)."""
    ring = _box(*START, 60.0)
    doc = {"type": "FeatureCollection", "features": [{
        "type": "Feature", "properties": {"name": "airfield"},
        "geometry": {"type": "Polygon", "coordinates": [ring + [ring[0]]]}}]}
    path = tmp / "zone.geojson"
    path.write_text(json.dumps(doc), encoding="utf-8")
    return str(path)


def _zigzag_csv(tmp) -> str:
    """A path no fixed-wing can follow (sharp turns every 20 m)."""
    rows = ["x_m,y_m,z_m"] + [f"{300 + 20 * k},{300 + 20 * (k % 2)},300" for k in range(30)]
    path = tmp / "zigzag.csv"
    path.write_text("\n".join(rows) + "\n", encoding="utf-8")
    return str(path)


ROWS = [
    # parsing (typer): bad flag, bad value, missing argument, unknown command
    (["plan", "--bogus"], 2, "No such option"),
    (["plan", "--order", "x"], 2, "--order"),
    (["cover", "--angle", "north"], 2, "--angle"),
    (["run"], 2, "Missing argument"),
    (["fly"], 2, "No such command"),
    # files
    (["run", "{tmp}/missing.yaml"], 2, "missing.yaml not found"),
    (["check", "{tmp}/missing.csv"], 2, "missing.csv not found"),

    # points: outside the map, inside the terrain, inside a no-fly zone (bad input, never 1)
    pytest.param(["plan", "--start", "-50,1,1"], 2, "outside", marks=SLOW),
    pytest.param(["plan", "--start", "300,300,1"], 2, "start", marks=SLOW),
    pytest.param(["plan", "--agl", "150", "--no-fly", "{zone}"], 2, "lies in", marks=SLOW),
    pytest.param(["run", "{in_zone}"], 2, "the start", marks=SLOW),
    pytest.param(["run", "{in_zone}", "--no-fly", "{zone}"], 2, "lies in", marks=SLOW),
    # planning failures: the goal walled in by zones (every way in is closed)
    pytest.param(["run", "{walled}"], 1, "goal", marks=SLOW),
    # the firmware/airframe cannot fly it as asked: bad input naming the flag
    pytest.param(["run", "{plain}", "--vehicle", "fixed_wing", "--speed-changes"], 2,
                 "--min-speed", marks=SLOW),
    # an infeasible path is a result (0), or a failure with --fail-infeasible (1)
    pytest.param(["check", "{zigzag}", "--airframe", "disco"], 0, "", marks=SLOW),
    pytest.param(["check", "{zigzag}", "--airframe", "disco", "--fail-infeasible"], 1, "",
                 marks=SLOW),
]


@pytest.fixture
def files(tmp_path):
    return {
        "tmp": str(tmp_path),
        "zone": _zone_file(tmp_path),
        "in_zone": _mission(tmp_path, "in_zone", [_box(*START, 60.0)]),
        "walled": _mission(tmp_path, "walled", _walls(*GOAL, 60.0, 120.0)),
        "plain": _mission(tmp_path, "plain"),
        "zigzag": _zigzag_csv(tmp_path),
    }


@pytest.mark.parametrize("args, code, fragment", ROWS)
def test_every_refusal_exits_with_its_documented_code(files, tmp_path, args, code, fragment):
    argv = [a.format(**files) for a in args]
    writes = argv[0] in ("plan", "run", "check")
    res = runner.invoke(app, argv + (["--out", str(tmp_path / "out")] if writes else []))
    assert res.exit_code == code, res.output
    assert "Traceback" not in res.output
    assert fragment in res.output
    if code == 2 and argv[0] != "check":
        errors = [line for line in res.output.splitlines() if line.startswith("error:")]
        assert len(errors) <= 1
        if code == 2 and writes:
            assert not (tmp_path / "out").exists()  # nothing written for a refusal
