"""fm2uav calibrate: a synthetic flight log fitted back, its power.yaml used by plan --power."""

from __future__ import annotations

import json
from dataclasses import replace

import pytest
from typer.testing import CliRunner

from fm2uav.cli import app
from fm2uav.vehicles.power import POWER_MODELS, get_power_model

from ..io.synthetic_logs import flight_states, write_tlog, write_ulg

runner = CliRunner()


@pytest.mark.slow
def test_calibrate_writes_a_model_plan_uses(tmp_path):
    true = replace(POWER_MODELS["arducopter"], profile_power_w=50.0, drag_area_m2=0.06,
                   efficiency=0.7)
    t, air, climb = flight_states("multirotor")
    log = write_tlog(tmp_path / "flight.tlog", t, true.power(air, climb), air, climb)
    out = tmp_path / "cal"
    res = runner.invoke(app, ["calibrate", str(log), "--power", "arducopter", "--out", str(out),
                              "--json", "--report"])
    assert res.exit_code == 0, res.output
    page = (out / "report.html").read_text()
    assert "plotly" in page and "fitted model" in page and "R²" in page
    fit = json.loads((out / "calibration.json").read_text())
    assert fit["r2"] > 0.999 and fit["rms_w"] < 0.5
    model = get_power_model(out / "power.yaml")
    assert model.efficiency == pytest.approx(0.7, rel=0.01)
    assert model.hover_power() == pytest.approx(true.hover_power(), rel=0.005)
    res = runner.invoke(app, ["plan", "--export", "plan", "--power", str(out / "power.yaml"),
                              "--battery", "50", "--wind", "5@90", "--hover-speed", "10",
                              "--saturation-distance", "100", "--out",
                              str(tmp_path / "p"), "--json"])
    assert res.exit_code == 0, res.output
    e = json.loads((tmp_path / "p" / "summary.json").read_text())["autopilot"]["energy"]
    assert e["model_source"] == "airframe.power" and e["battery_wh"] == 50.0
    assert e["wind"]["from_deg"] == 90.0 and e["energy_wh"] > 0


def test_calibrate_reads_a_px4_ulg(tmp_path):
    true = replace(POWER_MODELS["crosswind"], efficiency=0.62)
    t, air, climb = flight_states("fixed-wing", seed=2)
    log = write_ulg(tmp_path / "log_1.ulg", t, true.power(air, climb), air, climb,
                    groundspeed=air - 3.0, armed_from=30.0)
    out = tmp_path / "cal"
    res = runner.invoke(app, ["calibrate", str(log), "--power", "crosswind", "--out", str(out),
                              "--json"])
    assert res.exit_code == 0, res.output
    fit = json.loads((out / "calibration.json").read_text())
    assert fit["r2"] > 0.999 and fit["samples"] < len(t) - 50     # disarmed minute dropped
    model = get_power_model(out / "power.yaml")
    assert model.efficiency == pytest.approx(0.62, rel=0.01)
    assert "log_1.ulg (log_1.ulg: battery_status" in model.source


@pytest.mark.parametrize("args, part", [
    (["--wind", "fast"], "wind must be SPEED@DIRECTION"),
    (["--wind", "5@400"], "wind direction must be"),
    (["--power", "zeppelin"], "no power model for airframe 'zeppelin'"),
    (["--battery", "-3"], "--battery must be > 0 Wh"),
])
def test_bad_energy_flags_exit_2_before_any_work(tmp_path, args, part):
    res = runner.invoke(app, ["plan", "--export", "plan", *args, "--out", str(tmp_path / "o")])
    assert res.exit_code == 2, res.output
    assert part in res.output and not (tmp_path / "o").exists()


def test_calibrate_refuses_a_log_it_cannot_use(tmp_path):
    (tmp_path / "x.tlog").write_bytes(b"")
    res = runner.invoke(app, ["calibrate", str(tmp_path / "x.tlog"), "--out", str(tmp_path / "o")])
    assert res.exit_code == 2 and "no battery current" in res.output

