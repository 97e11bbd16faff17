"""Mission exports: the files of a built mission, QGC .plan structure and checker, WPL 110
(loaded by pymavlink), GeoJSON/KML round trips (the mission content itself:
tests/autopilot/test_build.py; its waypoints: tests/autopilot/test_waypoints.py)."""

import io
import json

import numpy as np
import pytest
from pymavlink import mavwp

from fm2uav.autopilot import ExportOptions
from fm2uav.io import (
    EXPORT_FILES,
    export_mission,
    export_writers,
    from_lonlat,
    read_geojson_path,
    read_kml_path,
    read_plan,
    read_wpl,
    to_lonlat,
    validate_plan,
)

from ..autopilot.mission_cases import ANCHOR, hill_free, hill_tff


def _write_all(plan, tmp_path, **opts):
    mission, files = export_mission(plan, list(EXPORT_FILES), ExportOptions(anchor=ANCHOR, **opts))
    for name, f in files.items():
        (tmp_path / name).parent.mkdir(parents=True, exist_ok=True)  # terrain/*.DAT
        with open(tmp_path / name, "wb" if f.binary else "w") as fh:
            f.write(fh)
    return mission


def test_export_writers_pick_the_frame_from_the_plan_and_firmware():
    assert export_writers(hill_free(), ["plan"])[1].frame == 3
    assert export_writers(hill_tff(), ["plan"])[1].frame == 0
    assert export_writers(hill_tff(), ["plan"], ExportOptions(firmware="ardupilot"))[1].frame == 10
    with pytest.raises(ValueError, match="unknown|not a known format 'pdf'|'pdf'"):
        export_writers(hill_free(), ["pdf"])


def test_wpl_loads_in_pymavlink_and_round_trips(tmp_path):
    m = _write_all(hill_tff(), tmp_path, firmware="ardupilot")
    wps = m.waypoints
    loader = mavwp.MAVWPLoader()
    n = loader.load(str(tmp_path / "mission.waypoints"))
    assert n == 1 + len(m.items)
    home = loader.wp(0)
    assert (home.frame, home.command, home.current) == (0, 16, 1)
    assert (home.x, home.y) == pytest.approx(wps.home[:2], abs=1e-7)
    assert home.z == pytest.approx(wps.home[2], abs=1e-3)
    takeoff = loader.wp(1)
    assert (takeoff.command, takeoff.frame) == (22, 3)  # ArduPilot: takeoff above home
    route = [loader.wp(i) for i in range(2, n) if loader.wp(i).command == 16]
    assert {w.frame for w in route} == {10}
    np.testing.assert_allclose([w.x for w in route], wps.lat[1:], atol=1e-7, rtol=0)
    np.testing.assert_allclose([w.y for w in route], wps.lon[1:], atol=1e-7, rtol=0)
    np.testing.assert_allclose([w.z for w in route], wps.alt[1:], atol=1e-3)
    ours = read_wpl(tmp_path / "mission.waypoints")
    route_ours = ours["command"] == 16
    back = from_lonlat(hill_tff().world,
                       np.column_stack([ours["lon"][route_ours], ours["lat"][route_ours]]), anchor=ANCHOR)
    np.testing.assert_allclose(back, wps.points_m[1:, :2], atol=1e-3)


def test_plan_has_qgroundcontrol_structure_and_round_trips(tmp_path):
    m = _write_all(hill_free(), tmp_path, cruise_speed=12.0, vehicle="fixed_wing",
                   firmware="ardupilot")
    raw = (tmp_path / "mission.plan").read_text()

    def no_nan(name):
        raise AssertionError(f"{name} is not JSON (QGC writes null)")

    doc = json.loads(raw, parse_constant=no_nan)
    assert validate_plan(doc) == []
    mission = doc["mission"]
    assert (doc["fileType"], doc["version"], mission["version"]) == ("Plan", 1, 2)
    assert (mission["firmwareType"], mission["vehicleType"], mission["cruiseSpeed"]) == (3, 1, 12.0)
    assert mission["plannedHomePosition"] == pytest.approx(list(m.home))
    assert mission["globalPlanAltitudeMode"] == 1
    items = mission["items"]
    assert [it["doJumpId"] for it in items] == list(range(1, len(items) + 1))
    assert items[0]["command"] == 22 and items[-1]["command"] == 20
    pos = [it for it in items if it["frame"] != 2]
    assert {it["frame"] for it in pos} == {3} and {it["AltitudeMode"] for it in pos} == {1}
    assert all(len(it["params"]) == 7 for it in items)
    back = read_plan(tmp_path / "mission.plan")
    route = back["command"] == 16
    np.testing.assert_allclose(back["lat"][route], m.waypoints.lat[1:], atol=1e-7, rtol=0)
    np.testing.assert_allclose(back["alt"][route], m.waypoints.alt[1:], atol=1e-9)


def test_terrain_plan_uses_terrain_altitude_mode():
    mission, files = export_mission(hill_tff(), ["plan"],
                                    ExportOptions(anchor=ANCHOR, firmware="ardupilot"))
    buf = io.StringIO()
    files["mission.plan"].write(buf)
    doc = json.loads(buf.getvalue())
    route = [it for it in doc["mission"]["items"] if it["command"] == 16]
    assert {it["frame"] for it in route} == {10} and {it["AltitudeMode"] for it in route} == {4}
    assert doc["mission"]["globalPlanAltitudeMode"] == 0  # mixed: takeoff above home


@pytest.mark.parametrize(
    "mutate, problem",
    [
        (lambda d: d.pop("fileType"), "missing key 'fileType'"),
        (lambda d: d.update(version=2), "top.version must be 1"),
        (lambda d: d["rallyPoints"].pop("points"), "missing key 'points'"),
        (lambda d: d["geoFence"].update(polygons=[{"inclusion": True, "polygon": [[1, 2]]}]),
         ">= 3 [lat, lon] points"),
        (lambda d: d["mission"].pop("plannedHomePosition"), "plannedHomePosition"),
        (lambda d: d["mission"].pop("firmwareType"), "firmwareType"),
        (lambda d: d["mission"].update(items=[]), "at least one item"),
        (lambda d: d["mission"]["items"][0].update(autoContinue=1), "autoContinue: expected bool"),
        (lambda d: d["mission"]["items"][0]["params"].pop(), "7 values"),
        (lambda d: next(it for it in d["mission"]["items"] if it["command"] == 16)["params"]
         .__setitem__(4, 123.0), "valid latitude"),
        (lambda d: d["mission"]["items"][1].update(type="Mystery"), "'SimpleItem' or 'ComplexItem'"),
        (lambda d: d["mission"]["items"][1].update(type="ComplexItem"), "complexItemType"),
        (lambda d: d["mission"].update(plannedHomePosition=[1, 2]), "[lat, lon, alt]"),
    ],
)
def test_plan_checker_names_the_problem(mutate, problem):
    _, files = export_mission(hill_free(), ["plan"], ExportOptions(anchor=ANCHOR))
    buf = io.StringIO()
    files["mission.plan"].write(buf)
    doc = json.loads(buf.getvalue())
    mutate(doc)
    problems = validate_plan(doc)
    assert problems and any(problem in p for p in problems), problems


def test_geojson_and_kml_round_trip_coordinates(tmp_path):
    p = hill_tff()
    m = _write_all(p, tmp_path)
    geo = to_lonlat(p.world, p.path, anchor=ANCHOR)
    for reader, file in ((read_geojson_path, "path.geojson"), (read_kml_path, "path.kml"),
                         (read_kml_path, "path.kmz")):
        got = reader(tmp_path / file)
        assert got.shape == geo.shape
        np.testing.assert_allclose(got[:, :2], geo[:, :2], atol=1e-7, rtol=0)
        np.testing.assert_allclose(got[:, 2], geo[:, 2], atol=1e-3)
        np.testing.assert_allclose(from_lonlat(p.world, got, anchor=ANCHOR), p.path, atol=0.02)
        wp = reader(tmp_path / file, name="waypoints")
        np.testing.assert_allclose(wp[:, 1], m.waypoints.lat, atol=1e-7, rtol=0)
        np.testing.assert_allclose(wp[:, 2], m.waypoints.alt_amsl, atol=1e-3)
    doc = json.loads((tmp_path / "path.geojson").read_text())
    names = [f["properties"]["name"] for f in doc["features"]]
    assert names == ["path", "waypoints", "start", "goal"]
    assert doc["features"][0]["properties"]["frame"] == 0
    # RFC 7946 order: longitude first
    assert doc["features"][2]["geometry"]["coordinates"][0] == pytest.approx(geo[0, 0], abs=1e-8)
