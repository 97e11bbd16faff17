"""Mission exports: QGC .plan, MAVLink WPL 110 (loaded by pymavlink), GeoJSON, KML."""

import io
import json

import numpy as np
import pytest
from pymavlink import mavwp

from fm2uav.io import (
    EXPORT_FILES,
    Anchor,
    ExportOptions,
    export_writers,
    from_lonlat,
    ground_height,
    mission_waypoints,
    read_geojson_path,
    read_kml_path,
    read_plan,
    read_wpl,
    to_lonlat,
    validate_plan,
)
from fm2uav.io.thin import segment_distances

ANCHOR = Anchor(lon=8.545594, lat=47.3977419, alt=488.0)


def _write_all(plan, tmp_path, **opts):
    writers, wps = export_writers(plan, list(EXPORT_FILES), ExportOptions(anchor=ANCHOR, **opts))
    for name, write in writers.items():
        with open(tmp_path / name, "w") as fh:
            write(fh)
    return wps


def test_waypoints_are_few_and_within_tolerance(hill_tff):
    wps = mission_waypoints(hill_tff.path, hill_tff.world, tolerance=2.0, anchor=ANCHOR)
    assert 3 <= len(wps) <= 40 < len(hill_tff.path)
    p, k = hill_tff.path, wps.indices
    for a, b in zip(k[:-1], k[1:]):
        if b - a > 1:
            assert segment_distances(p[a + 1 : b], p[a], p[b]).max() <= 2.0 + 1e-9


def test_terrain_following_uses_frame_10_with_heights_above_ground(hill_tff):
    wps = mission_waypoints(hill_tff.path, hill_tff.world, anchor=ANCHOR, terrain_following=True)
    assert wps.frame == 10
    ground = ground_height(hill_tff.world, wps.points_m)
    np.testing.assert_allclose(wps.alt, wps.points_m[:, 2] - ground, atol=1e-9)
    np.testing.assert_allclose(wps.alt_amsl, wps.points_m[:, 2] + ANCHOR.alt, atol=1e-9)
    # home: ground under the start, above mean sea level
    home_ground = ground_height(hill_tff.world, hill_tff.path[:1])[0]
    assert wps.home[2] == pytest.approx(home_ground + ANCHOR.alt)
    assert wps.home[:2] == pytest.approx((wps.lat[0], wps.lon[0]), abs=1e-12)


def test_relative_frame_altitudes_are_above_home(hill_plan):
    wps = mission_waypoints(hill_plan.path, hill_plan.world, anchor=ANCHOR)
    assert wps.frame == 3
    home_ground = ground_height(hill_plan.world, hill_plan.path[:1])[0]
    np.testing.assert_allclose(wps.alt, wps.points_m[:, 2] - home_ground, atol=1e-9)
    forced = mission_waypoints(hill_plan.path, hill_plan.world, anchor=ANCHOR, frame="terrain")
    assert forced.frame == 10


def test_export_writers_pick_the_frame_from_the_plan(hill_plan, hill_tff, tmp_path):
    assert export_writers(hill_plan, ["plan"])[1].frame == 3
    assert export_writers(hill_tff, ["plan"])[1].frame == 10
    with pytest.raises(ValueError, match="unknown export format 'pdf'"):
        export_writers(hill_plan, ["pdf"])


def test_wpl_loads_in_pymavlink_and_round_trips(hill_tff, tmp_path):
    wps = _write_all(hill_tff, tmp_path)
    text = (tmp_path / "mission.waypoints").read_text()
    lines = text.splitlines()
    assert lines[0] == "QGC WPL 110"
    assert all(len(ln.split("\t")) == 12 for ln in lines[1:])
    loader = mavwp.MAVWPLoader()
    n = loader.load(str(tmp_path / "mission.waypoints"))
    assert n == 1 + 1 + len(wps)  # home + takeoff + waypoints
    home = loader.wp(0)
    assert (home.frame, home.command, home.current) == (0, 16, 1)
    assert (home.x, home.y) == pytest.approx(wps.home[:2], abs=1e-7)
    assert home.z == pytest.approx(wps.home[2], abs=1e-3)
    takeoff = loader.wp(1)
    assert (takeoff.command, takeoff.frame) == (22, 10)
    items = [loader.wp(i) for i in range(2, n)]
    assert [w.seq for w in items] == list(range(2, n))
    assert {w.command for w in items} == {16} and {w.frame for w in items} == {10}
    np.testing.assert_allclose([w.x for w in items], wps.lat, atol=1e-7, rtol=0)
    np.testing.assert_allclose([w.y for w in items], wps.lon, atol=1e-7, rtol=0)
    np.testing.assert_allclose([w.z for w in items], wps.alt, atol=1e-3)
    ours = read_wpl(tmp_path / "mission.waypoints")
    np.testing.assert_allclose(ours["lat"][1:], wps.lat, atol=1e-9, rtol=0)
    # back to world metres through the anchor: the waypoints themselves
    back = from_lonlat(np.column_stack([ours["lon"][1:], ours["lat"][1:]]), hill_tff.world,
                       anchor=ANCHOR)
    np.testing.assert_allclose(back, wps.points_m[:, :2], atol=1e-3)


def test_plan_has_qgroundcontrol_structure_and_round_trips(hill_plan, tmp_path):
    wps = _write_all(hill_plan, tmp_path, cruise_speed=12.0, vehicle="fixed_wing")
    raw = (tmp_path / "mission.plan").read_text()

    def no_nan(name):
        raise AssertionError(f"{name} is not JSON (QGC writes null)")

    doc = json.loads(raw, parse_constant=no_nan)
    assert validate_plan(doc) == []
    m = doc["mission"]
    assert (doc["fileType"], doc["version"], m["version"]) == ("Plan", 1, 2)
    assert (m["firmwareType"], m["vehicleType"], m["cruiseSpeed"]) == (12, 1, 12.0)
    assert m["plannedHomePosition"] == pytest.approx(list(wps.home))
    assert m["globalPlanAltitudeMode"] == 1
    items = m["items"]
    assert [it["doJumpId"] for it in items] == list(range(1, len(items) + 1))
    assert items[0]["command"] == 22 and {it["command"] for it in items[1:]} == {16}
    assert {it["frame"] for it in items} == {3} and {it["AltitudeMode"] for it in items} == {1}
    assert all(len(it["params"]) == 7 and it["params"][3] is None for it in items)
    back = read_plan(tmp_path / "mission.plan")
    np.testing.assert_allclose(back["lat"][1:], wps.lat, atol=1e-7, rtol=0)
    np.testing.assert_allclose(back["lon"][1:], wps.lon, atol=1e-7, rtol=0)
    np.testing.assert_allclose(back["alt"][1:], wps.alt, atol=1e-9)


def test_terrain_plan_uses_terrain_altitude_mode(hill_tff):
    writers, wps = export_writers(hill_tff, ["plan"], ExportOptions(anchor=ANCHOR))
    buf = io.StringIO()
    writers["mission.plan"](buf)
    doc = json.loads(buf.getvalue())
    assert {it["frame"] for it in doc["mission"]["items"]} == {10}
    assert {it["AltitudeMode"] for it in doc["mission"]["items"]} == {4}
    assert doc["mission"]["globalPlanAltitudeMode"] == 4


@pytest.mark.parametrize(
    "mutate, problem",
    [
        (lambda d: d.pop("fileType"), "missing key 'fileType'"),
        (lambda d: d.update(version=2), "top.version must be 1"),
        (lambda d: d.pop("rallyPoints"), "missing key 'rallyPoints'"),
        (lambda d: d["mission"].pop("plannedHomePosition"), "plannedHomePosition"),
        (lambda d: d["mission"].pop("firmwareType"), "firmwareType"),
        (lambda d: d["mission"].update(items=[]), "at least one item"),
        (lambda d: d["mission"]["items"][0].update(autoContinue=1), "autoContinue: expected bool"),
        (lambda d: d["mission"]["items"][0]["params"].pop(), "7 values"),
        (lambda d: d["mission"]["items"][1]["params"].__setitem__(4, 123.0), "valid latitude"),
        (lambda d: d["mission"]["items"][1].update(type="ComplexItem"), "SimpleItem"),
        (lambda d: d["mission"].update(plannedHomePosition=[1, 2]), "[lat, lon, alt]"),
    ],
)
def test_plan_checker_names_the_problem(hill_plan, mutate, problem):
    writers, _ = export_writers(hill_plan, ["plan"])
    buf = io.StringIO()
    writers["mission.plan"](buf)
    doc = json.loads(buf.getvalue())
    mutate(doc)
    problems = validate_plan(doc)
    assert problems and any(problem in p for p in problems), problems


def test_geojson_and_kml_round_trip_coordinates(hill_tff, tmp_path):
    wps = _write_all(hill_tff, tmp_path)
    geo = to_lonlat(hill_tff.path, hill_tff.world, anchor=ANCHOR)
    for reader, file in ((read_geojson_path, "path.geojson"), (read_kml_path, "path.kml")):
        got = reader(tmp_path / file)
        assert got.shape == geo.shape
        np.testing.assert_allclose(got[:, :2], geo[:, :2], atol=1e-7, rtol=0)
        np.testing.assert_allclose(got[:, 2], geo[:, 2], atol=1e-3)
        np.testing.assert_allclose(from_lonlat(got, hill_tff.world, anchor=ANCHOR),
                                   hill_tff.path, atol=0.02)
        wp = reader(tmp_path / file, name="waypoints")
        np.testing.assert_allclose(wp[:, 1], wps.lat, atol=1e-7, rtol=0)
    doc = json.loads((tmp_path / "path.geojson").read_text())
    names = [f["properties"]["name"] for f in doc["features"]]
    assert names == ["path", "waypoints", "start", "goal"]
    assert doc["features"][0]["properties"]["frame"] == 10
    # RFC 7946 order: longitude first
    assert doc["features"][2]["geometry"]["coordinates"][0] == pytest.approx(geo[0, 0], abs=1e-8)
