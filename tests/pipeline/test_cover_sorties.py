"""Coverage missions by battery: the sorties in the summary, --bands wind."""

from __future__ import annotations

import json

import pytest
from shapely.geometry import box
from typer.testing import CliRunner

from fm2uav.cli import app
from fm2uav.errors import InputError
from fm2uav.pipeline.cover import across_wind_angle, sortie_rows
from fm2uav.world.wind import WindField

runner = CliRunner()


@pytest.mark.parametrize("frm, angle", [(0.0, 0.0), (90.0, 90.0), (45.0, 135.0),
                                        (200.0, 160.0)])
def test_bands_across_the_wind(frm, angle):
    # from the north (blowing south, along -y): bands along x, angle 0
    got = across_wind_angle(WindField.constant(6.0, frm), None, box(0, 0, 100, 100))
    assert got == pytest.approx(angle)


def test_bands_wind_needs_a_wind():
    with pytest.raises(InputError, match="needs a wind"):
        across_wind_angle(None, None, box(0, 0, 1, 1))
    with pytest.raises(InputError, match="calm"):
        across_wind_angle(WindField.constant(0.0, 0.0), None, box(0, 0, 1, 1))


def test_sortie_rows_say_the_count_and_the_baseline():
    s = {"count": 2, "even_split_count": None, "usable_wh": 24.0, "sorties": [
        {"from_waypoint": 0, "to_waypoint": 5, "energy_wh": 23.5, "time_s": 360.0,
         "resume_lon_lat_alt": [-3.75, 40.33, 100.0]},
        {"from_waypoint": 5, "to_waypoint": 9, "energy_wh": 20.0, "time_s": 300.0,
         "resume_lon_lat_alt": [-3.74, 40.34, 100.0]}]}
    rows = sortie_rows(s)
    assert rows["sorties"].startswith("2 (one battery each, 24.0 Wh usable")
    assert "one leg alone is too long" in rows["sorties"]
    assert rows["sortie 2"].startswith("legs 5→9, 20.0 Wh, 5.0 min, resume at 40.340000, -3.740000")
    s["sorties"][1].update(resume_item=9, files=["sortie-02.csv", "sortie-02.plan",
                                                     "sortie-02.waypoints"])
    s["ways"] = {"kind": "return field"}
    rows = sortie_rows(s)
    assert rows["sortie 2"].endswith("(item 9); sortie-02.plan / sortie-02.waypoints")
    assert rows["sorties: ways out and home"] == "return field"
    assert sortie_rows(None) == {}


def test_cover_splits_a_long_survey_with_the_bands_across_the_wind(tmp_path):
    out = tmp_path / "c"
    res = runner.invoke(app, ["cover", "--area", "S3", "--spacing", "80", "--agl", "100",
                              "--battery", "40", "--wind", "6@200", "--bands", "wind",
                              "--out", str(out), "--json"])
    assert res.exit_code == 0, res.output
    s = json.loads((out / "summary.json").read_text())
    assert s["angle_deg"] == pytest.approx(160.0, abs=1e-6)          # across 6 m/s from 200°
    sorties = s["sorties"]
    assert sorties["count"] >= 2
    assert sorties["even_split_count"] is None or sorties["count"] < sorties["even_split_count"]
    assert all(x["energy_wh"] <= sorties["usable_wh"] + 1e-9 for x in sorties["sorties"])
    # the sorties fly the whole survey: their survey parts add up to the route's energy
    # (the mission's energy minus its take-off, way home and landing)
    route = sum(x["survey_wh"] for x in sorties["sorties"])
    assert 0.6 * s["autopilot"]["energy"]["energy_wh"] < route < s["autopilot"]["energy"][
        "energy_wh"]
    # one mission per sortie, in every format of the whole mission, listed in the summary
    for k, x in enumerate(sorties["sorties"], 1):
        names = {f"sortie-{k:02d}.{e}" for e in ("plan", "waypoints", "csv", "kml", "kmz",
                                                 "geojson")}
        assert set(x["files"]) == names and all((out / n).is_file() for n in names)
        assert json.loads((out / f"sortie-{k:02d}.plan").read_text())["mission"]["items"]
    assert not (out / f"sortie-{sorties['count'] + 1:02d}.plan").exists()
    assert sorties["ways"]["kind"] == "return field"
    assert str(out / "sortie-01.waypoints") in json.loads(res.output)["files"]
    bad = runner.invoke(app, ["cover", "--area", "S3", "--spacing", "80", "--bands", "wind",
                              "--out", str(tmp_path / "d")])
    assert bad.exit_code == 2 and "needs a wind" in bad.output


def test_the_printed_point_of_no_return_names_its_budget_and_model():
    from fm2uav.pipeline.rows import energy_rows, returns_rows

    base = {"worst": {}, "destinations": [], "firmware": None}
    reached = {"computed": True, "budget": "energy", "reached": True, "distance_m": 2500.0,
               "after_waypoint": 4, "t_mission_s": 300.0, "passed_before_end": True,
               "model": "energy model arducopter (class default) along the route and the FM² "
                        "ways back, battery 74 Wh; no endurance given"}
    rows = returns_rows({"returns": {**base, "point_of_no_return": reached}})
    assert rows["point of no return (battery binds; FM² ways back)"] == (
        "2.50 km along the route (after waypoint 4, 5.0 min) — BEFORE the route's end")
    assert rows["point of no return: model"].startswith("energy model arducopter")
    none = {"computed": True, "budget": "energy", "reached": False, "smallest_margin_wh": 3.25}
    rows = returns_rows({"returns": {**base, "point_of_no_return": none}})
    assert rows["point of no return (battery binds; FM² ways back)"] == (
        "none on the route (smallest margin 3.2 Wh)")
    # without returns the energy summary's straight one is the only one, and says its model
    e = {"energy_wh": 10.0, "time_s": 600.0, "battery_wh": 74.0, "usable_wh": 59.2,
         "reserve": 0.2, "ok": True, "model": "arducopter", "model_kind": "multirotor",
         "hover_or_cruise_power_w": 300.0, "model_source": "airframe.power",
         "no_return_waypoint": 7, "no_return_note": "the last waypoint ..."}
    assert "point of no return (battery, straight returns)" in energy_rows(e)
    e.pop("no_return_waypoint")
    assert not any("no return" in k for k in energy_rows(e))
