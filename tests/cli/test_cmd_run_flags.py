"""``fm2uav run`` takes the airframe speed flags its errors name (issue 24 deliverable 4)."""

from __future__ import annotations

from pathlib import Path

import pytest
from typer.testing import CliRunner

from fm2uav.cli import app

ROOT = Path(__file__).resolve().parents[2]
runner = CliRunner()


@pytest.mark.slow  # two missions planned on the open field
def test_a_fixed_wing_mission_asks_for_min_speed_and_run_takes_it(tmp_path):
    mission = tmp_path / "plane.yaml"
    mission.write_text((ROOT / "examples" / "open_field_tff.yaml").read_text(encoding="utf-8"),
                       encoding="utf-8")
    args = ["run", str(mission), "--vehicle", "fixed_wing", "--speed-changes",
            "--cruise-speed", "18", "--out", str(tmp_path / "out")]
    res = runner.invoke(app, args)
    assert res.exit_code == 2, res.output
    assert "airframe.min_speed" in res.output and "--min-speed" in res.output
    res = runner.invoke(app, [*args, "--min-speed", "14", "--json"])
    assert res.exit_code == 0, res.output
    import json

    summary = json.loads(res.output)
    speeds = summary["autopilot"]["speed_changes"]["speeds_mps"]
    assert speeds and min(speeds) >= 14 and max(speeds) <= 18
