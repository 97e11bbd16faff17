"""Mission-file keys of the energy figures: airframe.power, airframe.battery and wind:."""

from __future__ import annotations

import pytest

from fm2uav.io.mission import load_mission
from fm2uav.vehicles.power import get_power_model

OK_WORLD = "world: {scenario: open-field}\n"


def test_power_file_relative_to_the_mission_battery_and_wind(tmp_path):
    (tmp_path / "models").mkdir()
    (tmp_path / "models" / "quad.yaml").write_text("preset: arducopter\nmass_kg: 2.6\n")
    f = tmp_path / "m.yaml"
    f.write_text(OK_WORLD + "airframe: {power: models/quad.yaml, battery: 99.5}\n"
                 "wind: {speed: 7, from: 225}\n")
    o = load_mission(f).export_options()
    assert get_power_model(o.power).mass_kg == 2.6 and o.battery_wh == 99.5
    assert o.wind.kind == "constant" and o.wind.direction_deg == 225.0
    u, v = o.wind.at([[0.0, 0.0]])[0]
    assert u == pytest.approx(7 / 2 ** 0.5) and v == pytest.approx(7 / 2 ** 0.5)  # to the NE


def test_a_wind_profile_and_the_defaults(tmp_path):
    f = tmp_path / "m.yaml"
    f.write_text(OK_WORLD + "wind: {speed: 5, from: 0, ref_height: 10, exponent: 0.25}\n")
    w = load_mission(f).export_options().wind
    assert w.kind == "profile" and w.at([[0, 0]], agl=[160.0])[0][1] == pytest.approx(-10.0)
    f.write_text(OK_WORLD)
    o = load_mission(f).export_options()
    assert o.power is None and o.battery_wh is None and o.wind is None
