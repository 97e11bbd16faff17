"""Complete, firmware-correct missions: frames, takeoff/end, WPL NaN yaw, AMSL = DEM + AGL,
speed changes, camera triggers, via points, endurance, geofences, KMZ, .plan round trips."""

from __future__ import annotations

import io
import json
import math
import zipfile

import numpy as np
import pytest
from pymavlink import mavwp

from fm2uav.errors import InputError, MissionError
from fm2uav.autopilot import (
    CameraPlan,
    ExportOptions,
    FenceCircle,
    FencePolygon,
    build_mission,
    fences_from_world,
    speed_commands,
    start_holds,
)
from fm2uav.autopilot.items import END_COMMANDS, TAKEOFF_COMMANDS
from fm2uav.autopilot.validate import validate_mission
from fm2uav.io import (
    export_mission,
    from_lonlat,
    read_kml_path,
    read_plan,
    read_wpl,
    to_lonlat,
    validate_plan,
)
from fm2uav.missions.route import plan_route

from .mission_cases import ANCHOR, UTM, bilinear_ground, hill, hill_free, hill_tff

FIRMWARES = ("px4", "ardupilot", "generic")
VEHICLES = ("multirotor", "fixed_wing", "vtol")
ENDS = ("auto", "rtl", "land", "loiter")
_POSITION = {16, 17, 19, 21, 22, 31, 84, 85}


def _opts(**kw) -> ExportOptions:
    return ExportOptions(anchor=ANCHOR, **kw)


def _write(files, tmp_path):
    for name, f in files.items():
        (tmp_path / name).parent.mkdir(parents=True, exist_ok=True)  # terrain/*.DAT
        with open(tmp_path / name, "wb" if f.binary else "w") as fh:
            f.write(fh)


def _can_fly(firmware, vehicle, end):
    """PX4 fixed-wing / VTOL need a landing: a loiter end is refused."""
    return not (end == "loiter" and firmware in ("px4", "generic") and vehicle != "multirotor")


# ---------------------------------------------------------------- frames
@pytest.mark.parametrize("vehicle", VEHICLES)
@pytest.mark.parametrize("firmware", FIRMWARES)
def test_px4_never_gets_terrain_frame_and_ardupilot_does(firmware, vehicle):
    m, _ = export_mission(hill_tff(), ["plan"], _opts(firmware=firmware, vehicle=vehicle))
    frames = {it.frame for it in m.items if it.has_position}
    if firmware == "ardupilot":
        assert m.frame == "terrain" and 10 in frames
        takeoff = m.items[0]
        assert takeoff.command in TAKEOFF_COMMANDS and takeoff.frame == 3  # issue #20142
    else:
        assert m.frame == "amsl" and 10 not in frames and frames <= {0, 3}
    assert {it.frame for it in m.items if not it.has_position} <= {2}


def test_terrain_frame_altitudes_are_heights_above_the_ground_under_each_item():
    """Frame 10 (ArduPilot): param 7 is the height above the terrain under the item, measured
    here independently (the item's lon/lat back to metres, scipy's bilinear ground)."""
    p = hill_tff()
    m, _ = export_mission(p, ["plan"], _opts(firmware="ardupilot"))
    terrain = [it for it in m.items if it.has_position and it.frame == 10]
    assert len(terrain) >= 3
    ll = np.array([[it.lon, it.lat] for it in terrain])
    ground = bilinear_ground(p.world, ll)
    for it, g in zip(terrain, ground):
        assert it.alt == pytest.approx(it.alt_amsl - g, abs=0.05)
        assert 0.0 <= it.alt < it.alt_amsl - 100.0  # heights, not altitudes of the hill's z


def test_an_ardupilot_terrain_mission_lands_on_a_glide_slope_above_home():
    """The fixed-wing landing pattern of a terrain-frame mission is written above home
    (frame 3): a glide in the terrain frame would follow the ground down to the touchdown."""
    opt = _opts(firmware="ardupilot", vehicle="fixed_wing", end="land")
    m, _ = export_mission(hill_tff(), ["plan"], opt)
    start = next(i for i, it in enumerate(m.items) if it.command == 189)  # DO_LAND_START
    # the approach loiter after DO_LAND_START (a climb-out may loiter to altitude too)
    loiter = next(it for it in m.items[start:] if it.command == 31)
    land = next(it for it in m.items[start:] if it.command == 21)
    assert m.frame == "terrain" and loiter.frame == land.frame == 3
    home = m.home[2]
    assert land.alt == pytest.approx(land.alt_amsl - home, abs=1e-6)
    assert loiter.alt - land.alt == pytest.approx(opt.land_approach_agl, abs=1e-6)


def test_px4_terrain_frame_on_request_is_refused_naming_the_option():
    with pytest.raises(MissionError, match=r"px4 would reject.*terrain-frame.*outputs.frame"):
        export_mission(hill_tff(), ["plan"], _opts(firmware="px4", frame="terrain"))


def test_relative_frame_for_plans_without_a_flight_level():
    m, _ = export_mission(hill_free(), ["plan"], _opts(firmware="px4"))
    assert m.frame == "relative" and m.waypoints.frame == 3
    home = m.home[2]
    for it in m.items:
        if it.has_position:
            assert it.alt == pytest.approx(it.alt_amsl - home, abs=1e-6)


@pytest.mark.parametrize("crs", [None, UTM])
def test_amsl_altitudes_are_dem_ground_plus_agl_at_every_waypoint(crs):
    p = hill_tff(crs)
    anchor = None if crs else ANCHOR
    m, _ = export_mission(p, ["plan"], ExportOptions(anchor=anchor, firmware="px4"))
    wps = [it for it in m.items if it.command == 16]
    lonlat = np.array([[it.lon, it.lat] for it in wps])
    ground = bilinear_ground(p.world, lonlat, anchor)
    agl = np.array([it.agl for it in wps])
    alt = np.array([it.alt for it in wps])
    assert {it.frame for it in wps} == {0}
    np.testing.assert_allclose(alt, ground + agl, atol=1.0)
    # cruise waypoints carry the requested 60 m: exactly (FM²'s grid level, a cell low, is
    # snapped to it) or within the final profile's 2 m tolerance (Plan.profile)
    tol = 1e-9 if getattr(p, "profile", None) is None else 2.0
    assert np.median(agl) == pytest.approx(60.0, abs=tol)
    assert agl[1:-1].min() >= 60.0 - tol


def test_terrain_frame_altitude_is_the_requested_agl():
    m, _ = export_mission(hill_tff(), ["wpl"], _opts(firmware="ardupilot"))
    terrain = [it for it in m.items if it.frame == 10]
    assert terrain and {round(it.alt, 9) for it in terrain if it.command == 16} == {60.0}


def test_home_is_the_dem_ground_under_the_start_with_its_source():
    p = hill_tff(UTM)
    m, _ = export_mission(p, ["plan"], ExportOptions(firmware="px4"))
    lonlat = to_lonlat(p.world, p.path[:1])[:, :2]
    assert m.home[2] == pytest.approx(float(bilinear_ground(p.world, lonlat, None)[0]), abs=1e-6)
    s = m.summary()
    assert "DEM ground" in s["home"]["source"] and s["crs"] == UTM
    assert not any("synthetic" in w for w in s["warnings"])


def test_synthetic_world_warns_that_its_relief_is_not_the_real_terrain():
    m, _ = export_mission(hill_tff(), ["plan"], _opts())
    assert "not the real terrain" in m.summary()["home"]["source"]
    assert any("synthetic world" in w and "lon 8.54559" in w for w in m.warnings)


# ---------------------------------------------------------------- takeoff / end
@pytest.mark.parametrize("end", ENDS)
@pytest.mark.parametrize("vehicle", VEHICLES)
@pytest.mark.parametrize("firmware", FIRMWARES)
def test_every_mission_starts_with_a_takeoff_and_ends_on_the_ground_or_holding(
        firmware, vehicle, end, tmp_path):
    opts = _opts(firmware=firmware, vehicle=vehicle, end=end)
    if not _can_fly(firmware, vehicle, end):
        with pytest.raises(MissionError, match="need a landing"):
            export_mission(hill_tff(), ["plan"], opts)
        return
    m, files = export_mission(hill_tff(), ["plan", "wpl"], opts)
    _write(files, tmp_path)
    for cmds in (read_plan(tmp_path / "mission.plan")["command"],
                 read_wpl(tmp_path / "mission.waypoints")["command"]):
        assert cmds[0] == (84 if vehicle == "vtol" else 22)
        assert cmds[-1] in END_COMMANDS
    assert validate_mission(m.items, firmware, vehicle=vehicle, home_alt=m.home[2]) == []
    if end == "auto":
        assert m.end == ("rtl" if vehicle == "fixed_wing" else "land")


def test_px4_fixed_wing_rtl_adds_a_landing_pattern_at_home():
    m, _ = export_mission(hill_tff(), ["plan"], _opts(firmware="px4", vehicle="fixed_wing"))
    cmds = [it.command for it in m.items]
    assert cmds[-4:] == [20, 189, 31, 21]
    land, loiter = m.items[-1], m.items[-2]
    assert (land.lat, land.lon) == pytest.approx(m.home[:2], abs=1e-9)
    slope = math.degrees(math.atan2(loiter.alt_amsl - land.alt_amsl, 1.0))
    assert slope > 0 and m.summary()["landing"]["glide_slope_deg"] <= 5.0
    ardu, _ = export_mission(hill_tff(), ["plan"], _opts(firmware="ardupilot",
                                                          vehicle="fixed_wing"))
    assert [it.command for it in ardu.items][-1] == 20


def test_rtl_warns_that_the_straight_way_home_is_not_planned():
    m, _ = export_mission(hill_tff(), ["plan"], _opts(end="rtl"))
    assert any("straight line home" in w for w in m.warnings)
    assert m.summary()["landing"]["rtl_max_ground_above_home_m"] > 0  # the hill


# ---------------------------------------------------------------- file formats
@pytest.mark.parametrize("firmware", FIRMWARES)
def test_wpl_writes_nan_yaw_and_pymavlink_loads_it(firmware, tmp_path):
    m, files = export_mission(hill_tff(), ["wpl"], _opts(firmware=firmware, speed_changes=True))
    _write(files, tmp_path)
    lines = (tmp_path / "mission.waypoints").read_text().splitlines()
    assert lines[0] == "QGC WPL 110" and all(len(ln.split("\t")) == 12 for ln in lines[1:])
    loader = mavwp.MAVWPLoader()
    n = loader.load(str(tmp_path / "mission.waypoints"))
    assert n == 1 + len(m.items)
    home = loader.wp(0)
    assert (home.frame, home.command, home.current) == (0, 16, 1)
    assert (home.x, home.y, home.z) == pytest.approx(m.home, abs=1e-3)
    for k, it in enumerate(m.items, start=1):
        w = loader.wp(k)
        assert (w.seq, w.command, w.frame) == (k, it.command, it.frame)
        if it.command in (16, 21, 22, 84, 85):
            assert math.isnan(w.param4)  # never 0 = "turn north"
        if it.has_position:
            assert (w.x, w.y) == pytest.approx((it.lat, it.lon), abs=1e-7)
            assert w.z == pytest.approx(it.alt, abs=1e-3)


def test_plan_and_wpl_describe_the_same_items(tmp_path):
    m, files = export_mission(hill_tff(), ["plan", "wpl"], _opts(speed_changes=True))
    _write(files, tmp_path)
    doc = json.loads((tmp_path / "mission.plan").read_text(),
                     parse_constant=lambda c: pytest.fail(f"{c} in JSON (QGC writes null)"))
    assert validate_plan(doc) == []
    mission = doc["mission"]
    assert mission["plannedHomePosition"] == pytest.approx(list(m.home))
    assert (mission["firmwareType"], mission["vehicleType"]) == (12, 2)
    a, b = read_plan(tmp_path / "mission.plan"), read_wpl(tmp_path / "mission.waypoints")
    np.testing.assert_array_equal(a["command"], b["command"])
    np.testing.assert_array_equal(a["frame"], b["frame"])
    np.testing.assert_allclose(a["lat"], b["lat"], atol=1e-9)
    np.testing.assert_allclose(a["alt"], b["alt"], atol=1e-3)
    for it in mission["items"]:
        if it["command"] == 16:
            assert it["params"][3] is None and it["AltitudeMode"] == 2  # absolute (AMSL)
        if it["frame"] == 2:
            assert "AltitudeMode" not in it


def test_kmz_is_the_kml_zipped_and_reads_back(tmp_path):
    m, files = export_mission(hill_tff(), ["kml", "kmz", "geojson"], _opts())
    _write(files, tmp_path)
    with zipfile.ZipFile(tmp_path / "path.kmz") as z:
        assert z.namelist() == ["doc.kml"]
        assert z.read("doc.kml").decode() == (tmp_path / "path.kml").read_text()
    np.testing.assert_allclose(read_kml_path(tmp_path / "path.kmz", "waypoints")[:, 2],
                               m.waypoints.alt_amsl, atol=1e-3)
    props = json.loads((tmp_path / "path.geojson").read_text())["features"][0]["properties"]
    assert props["firmware"] == "px4" and props["frame_name"] == "amsl" and props["warnings"]


# ---------------------------------------------------------------- speeds
def test_speed_commands_quantise_down_slow_at_once_and_speed_up_with_hysteresis():
    legs = [9.7, 9.2, 8.9, 9.4, 9.9, 10.5, 12.0, 4.2, 4.9, 11.6]
    got = speed_commands(legs, current=None, step=1.0, hysteresis=2, floor=1.0, cap=12.0)
    # 9.4 / 9.9 are not 2 steps above 8; 10.5 is; 4.9 stays at 4; 11.6 is 7 steps above
    assert got == [(0, 9.0), (2, 8.0), (5, 10.0), (6, 12.0), (7, 4.0), (9, 11.0)]
    assert speed_commands([0.2], current=None, step=1.0, hysteresis=2, floor=1.0, cap=5) == \
        [(0, 1.0)]


def test_speed_items_follow_w_and_never_exceed_it():
    """The speeds map the obstacle-distance W onto the airframe's range, floor + W (cap -
    floor), quantised down: never above what a leg allows, never below the floor."""
    p = hill_tff()
    opts = _opts(speed_changes=True, hover_speed=12.0)
    m, _ = export_mission(p, ["plan"], opts)
    idx = m.waypoints.indices
    legs = len(idx) - 1
    changes = [it for it in m.items if it.command == 178]
    assert 1 <= len(changes) <= legs
    assert {it.params[0] for it in changes} == {1.0}  # ground speed (multirotor)
    share = p.speed_share()
    current, k = None, 0
    for it in m.items:  # the speed in force when a waypoint is reached is its leg's
        if it.command == 178:
            current = it.params[1]
        elif it.command == 16:
            k += 1
            admissible = 1.0 + float(share[idx[k - 1]:idx[k] + 1].min()) * (12.0 - 1.0)
            assert 1.0 <= current <= admissible + 1e-9


def test_fixed_wing_speed_changes_need_a_minimum_speed():
    with pytest.raises(MissionError, match="min_speed"):
        export_mission(hill_tff(), ["plan"], _opts(vehicle="fixed_wing", speed_changes=True))
    m, _ = export_mission(hill_tff(), ["plan"], _opts(vehicle="fixed_wing", speed_changes=True,
                                                       min_speed=11.0, firmware="ardupilot"))
    speeds = [it.params[1] for it in m.items if it.command == 178]
    assert speeds and min(speeds) >= 11.0 and {it.params[0] for it in m.items
                                              if it.command == 178} == {0.0}


# ---------------------------------------------------------------- camera
def _two_band_path():
    """A lawnmower over the hill world at 60 m AGL: band 1 east, turn, band 2 west."""
    x = np.linspace(60.0, 340.0, 57)
    turn = np.linspace(-np.pi / 2, np.pi / 2, 17)[1:-1]
    xy = np.vstack([np.column_stack([x, np.full_like(x, 100.0)]),
                    np.column_stack([340 + 40 * np.cos(turn), 140 + 40 * np.sin(turn)]),
                    np.column_stack([x[::-1], np.full_like(x, 180.0)])])
    world = hill()
    z = world.ground_height(xy[:, 0], xy[:, 1]) + 60.0
    return np.column_stack([xy, z]), (0, 56), (71, 127)


@pytest.mark.parametrize("firmware", ["px4", "ardupilot"])
def test_camera_triggers_switch_on_at_each_band_start_and_off_at_its_end(firmware):
    path, b1, b2 = _two_band_path()
    cam = CameraPlan(trigger_distance=23.5, bands=(b1, b2), info={"gsd_cm_per_px": 2.7})
    m = build_mission(path, hill(), _opts(firmware=firmware), agl=60.0, camera=cam)
    trig = [(k, it) for k, it in enumerate(m.items) if it.command == 206]
    assert [it.params[0] for _, it in trig] == [23.5, 0.0, 23.5, 0.0]
    geo = to_lonlat(hill(), path, anchor=ANCHOR)
    ends = [b1[0], b1[1], b2[0], b2[1]]
    for (k, it), i in zip(trig, ends):
        prev = next(m.items[j] for j in range(k - 1, -1, -1) if m.items[j].has_position)
        assert (prev.lon, prev.lat) == pytest.approx(tuple(geo[i, :2]), abs=1e-9)
    on = [it for _, it in trig if it.params[0] > 0]
    assert all(it.params[2] == 1.0 for it in on)  # trigger once at the band start
    s = m.summary()["camera"]
    assert s["trigger_items"] == 4 and s["gsd_cm_per_px"] == 2.7


def test_a_camera_left_on_is_a_defect():
    path, b1, _ = _two_band_path()
    m = build_mission(path, hill(), _opts(), agl=60.0,
                      camera=CameraPlan(20.0, (b1,)))
    items = [it for it in m.items if not (it.command == 206 and it.params[0] == 0)]
    assert any(p.code == "trigger-on" for p in validate_mission(items, "px4",
                                                                home_alt=m.home[2]))


# ---------------------------------------------------------------- via points
def test_a_two_via_mission_reaches_each_via_in_order():
    world = hill()
    start, goal = (20.0, 20.0, 70.0), (380.0, 280.0, 70.0)
    via = [np.r_[350.0, 40.0, world.ground_height(350.0, 40.0) + 60.0],
           np.r_[60.0, 260.0, world.ground_height(60.0, 260.0) + 60.0]]
    route = plan_route(world, start, goal, via=via, level=_level(60.0))
    assert len(route.legs) == 3
    for k, v in enumerate(via):
        np.testing.assert_array_equal(route.plan.path[route.junctions[k + 1]], v)
    m, _ = export_mission(route.plan, ["plan"], _opts(), via=route.junctions[1:-1])
    geo = to_lonlat(world, np.array(via), anchor=ANCHOR)
    labelled = [(k, it) for k, it in enumerate(m.items) if it.label.startswith("via")]
    assert [it.label for _, it in labelled] == ["via 1", "via 2"]
    assert labelled[0][0] < labelled[1][0]
    for (_, it), g in zip(labelled, geo):
        assert (it.lon, it.lat) == pytest.approx(tuple(g[:2]), abs=1e-9)
    assert route.plan.length == pytest.approx(sum(lg.length for lg in route.legs))


def test_a_return_leg_ends_the_route_at_the_start():
    world = hill()
    route = plan_route(world, (20.0, 20.0, 70.0), (380.0, 280.0, 70.0), return_to_start=True,
                       level=_level(60.0))
    np.testing.assert_array_equal(route.plan.path[-1], route.plan.path[0])
    m, _ = export_mission(route.plan, ["plan"], _opts(end="land"), via=route.junctions[1:-1])
    assert (m.items[-1].lat, m.items[-1].lon) == pytest.approx(m.home[:2], abs=1e-9)


def _level(agl):
    from fm2uav import FlightLevel

    return FlightLevel(agl=agl)


def test_route_points_must_differ():
    with pytest.raises(InputError, match="same place"):
        plan_route(hill(), (20.0, 20.0, 70.0), (380.0, 280.0, 70.0),
                   via=[(20.0, 20.0, 70.0)])


# ---------------------------------------------------------------- endurance
def test_endurance_warning_says_how_far_the_vehicle_gets():
    ok, _ = export_mission(hill_tff(), ["plan"], _opts(endurance_s=3600.0))
    assert ok.summary()["flight"]["ok"] and ok.summary()["flight"]["warning"] is None
    t = ok.summary()["flight"]["flight_time_s"]
    short, _ = export_mission(hill_tff(), ["plan"], _opts(endurance_s=0.5 * t, reserve=0.2))
    f = short.summary()["flight"]
    assert not f["ok"] and f["usable_s"] == pytest.approx(0.4 * t, abs=0.2)
    assert 0 < f["reach_m"] < f["flight_distance_m"]
    assert any("endurance" in w and "km along" in w for w in short.warnings)


@pytest.mark.parametrize("vehicle, minutes", [("multirotor", 20.0), ("fixed_wing", 45.0),
                                              ("vtol", 45.0)])
def test_the_endurance_check_runs_by_default_and_says_where_the_reserve_is_reached(
        vehicle, minutes):
    """Issue 25: a 177-minute multirotor transit passed without a word. Without an
    endurance the airframe type's default is checked, the summary says so, and the warning
    names the point where the reserve is reached (checked here on the waypoint legs)."""
    slow = 0.2 if vehicle == "multirotor" else 1.0  # the hill is short: fly it slowly
    m, _ = export_mission(hill_tff(), ["plan"], _opts(vehicle=vehicle, hover_speed=slow,
                                                      cruise_speed=slow, min_speed=slow / 2,
                                                      end="land"))
    f = m.summary()["flight"]
    assert f["endurance_s"] == pytest.approx(60.0 * minutes)
    assert "default" in f["endurance_source"] and "--endurance" in f["endurance_source"]
    if f["flight_time_s"] <= 0.8 * 60.0 * minutes:
        assert f["ok"] and f["warning"] is None
        return
    assert not f["ok"]
    w = next(x for x in m.warnings if x.startswith("endurance"))
    assert "lon" in w and "--endurance" in w
    # the point is on the legs, as far along as the usable endurance lasts
    q = np.asarray(f["reserve_reached_at_m"])
    p = m.waypoints.points_m
    k = f["reach_waypoint"]
    # the warning names the same waypoint of the whole list (a fixed-wing climb-out
    # replaces the first ones: its count still starts at the list's first waypoint)
    assert f"(waypoint {k} of {len(p) - 1})" in w
    seg = p[k + 1] - p[k]
    t = float(np.dot(q - p[k], seg) / np.dot(seg, seg))
    assert 0.0 <= t <= 1.0 and np.allclose(p[k] + t * seg, q, atol=0.01)
    lon, lat, _ = to_lonlat(m.world, q, anchor=ANCHOR)
    assert f["reserve_reached_at_lonlat"] == pytest.approx([lon, lat], abs=1e-6)
    # --endurance overrides the default
    given, _ = export_mission(hill_tff(), ["plan"], _opts(vehicle=vehicle, hover_speed=slow,
                                                          cruise_speed=slow, min_speed=slow / 2,
                                                          end="land",
                                                          endurance_s=1e6))
    assert given.summary()["flight"]["ok"]
    assert given.summary()["flight"]["endurance_source"].startswith("given")


def test_flight_time_is_the_slowest_of_horizontal_and_vertical_motion():
    from fm2uav.vehicles.endurance import check_endurance, flight_time

    pts = np.array([[0, 0, 10], [100, 0, 10], [100, 0, 60], [300, 0, 40.0]])
    ft = flight_time(pts, [10.0, 10.0, 5.0], climb_rate=2.5, descent_rate=1.5,
                     takeoff_climb=10.0, final_descent=40.0)
    np.testing.assert_allclose(ft.leg_time, [10.0, 20.0, 40.0])
    assert ft.time_s == pytest.approx(4.0 + 70.0 + 40.0 / 1.5)
    assert ft.distance_m == pytest.approx(10 + 100 + 50 + math.hypot(200, 20) + 40)
    rep = check_endurance(ft, endurance_s=50.0, reserve=0.2)  # 40 s usable: 4 + 10 + 20 + 6
    assert not rep.ok and rep.reach_waypoint == 2
    assert rep.reach_m == pytest.approx(10 + 100 + 50 + math.hypot(200, 20) * 6 / 40)


# ---------------------------------------------------------------- formation timing
def test_a_timed_trajectory_becomes_a_time_consistent_mission():
    world = hill()
    t = np.linspace(0.0, 100.0, 201)
    x = 20 + 3.0 * t + 20 * np.sin(t / 10)
    y = 20 + 2.0 * t
    z = world.ground_height(x, y) + 60.0
    path = np.column_stack([x, y, z])
    stop = np.flatnonzero(t >= 50)[0]  # stand still 15 s half way (like a follower waiting)
    path = np.vstack([path[:stop + 1], np.repeat(path[stop:stop + 1], 30, axis=0),
                      path[stop + 1:]])
    t2 = np.concatenate([t[:stop + 1], t[stop] + 0.5 * np.arange(1, 31), t[stop + 1:] + 15.0])
    opts = _opts(speed_step=0.1, tolerance=1.0, climb_rate=8.0, descent_rate=8.0)
    m = build_mission(path, world, opts, agl=60.0, times=t2, start_hold=4.0)
    timing = m.summary()["timing"]
    assert timing["planned_s"] == pytest.approx(115.0) and timing["start_hold_s"] == 4.0
    assert abs(timing["error_s"]) <= 0.02 * timing["planned_s"]
    # with the default multirotor descent rate (1.5 m/s) the hill makes it late, and says so
    slow = build_mission(path, world, _opts(speed_step=0.1, tolerance=1.0), agl=60.0, times=t2)
    assert slow.summary()["timing"]["error_s"] > 0.02 * 115.0
    holds = [it.params[0] for it in m.items if it.command == 16 and it.params[0] > 0]
    assert holds[0] == pytest.approx(4.0) and max(holds) >= 14.0


# ---------------------------------------------------------------- geofences
def test_geofences_are_written_as_qgc_does_and_checked(tmp_path):
    from shapely.geometry import Polygon

    world = hill()
    zone = Polygon([(100, 150), (200, 150), (200, 250), (100, 250)])  # NW, off the route
    area = Polygon([(0, -10), (400, -10), (400, 300), (0, 300)],
                   holes=[[(20, 250), (50, 250), (50, 280), (20, 280)]])
    fences, warn = fences_from_world(zone, world, anchor=ANCHOR)
    inc, _ = fences_from_world(area, world, anchor=ANCHOR, inclusion=True)
    circle, _ = fences_from_world(("circle", (60.0, 250.0), 15.0), world, anchor=ANCHOR)
    assert warn == [] and len(inc) == 2 and not inc[1].inclusion  # hole -> exclusion
    m, files = export_mission(hill_tff(), ["plan"], _opts(), fences=fences + inc + circle)
    _write(files, tmp_path)
    doc = json.loads((tmp_path / "mission.plan").read_text())
    gf = doc["geoFence"]
    assert gf["version"] == 2 and len(gf["polygons"]) == 3 and len(gf["circles"]) == 1
    poly = np.array(gf["polygons"][0]["polygon"])
    lon, lat = poly[:, 1], poly[:, 0]
    assert 0.5 * np.sum(lon * np.roll(lat, -1) - np.roll(lon, -1) * lat) < 0  # clockwise
    back = read_plan(tmp_path / "mission.plan")["fences"]
    assert [type(f).__name__ for f in back] == ["FencePolygon"] * 3 + ["FenceCircle"]
    # the mapping form of the safety engineer's zones works the same
    mapping = {"polygons": [{"inclusion": False, "polygon": [list(p) for p in fences[0].points]}]}
    m2, _ = export_mission(hill_tff(), ["plan"], _opts(), fences=mapping)
    assert m2.fences == [FencePolygon(fences[0].points, False, "polygon 1")]
    big = FenceCircle((m.items[2].lat, m.items[2].lon), 30.0, False, "no-fly")
    with pytest.raises(MissionError, match="inside the exclusion fence 'no-fly'"):
        export_mission(hill_tff(), ["plan"], _opts(), fences=[big])


# ---------------------------------------------------------------- validators
def _good():
    """An exported PX4 mission with speed items (so the rules of DO items are reached)."""
    m, _ = export_mission(hill_tff(), ["plan"], _opts(firmware="px4", speed_changes=True))
    assert any(it.command == 178 for it in m.items)
    return list(m.items), m.home[2]


def _codes(items, firmware="px4", vehicle="multirotor", home=None):
    return {p.code for p in validate_mission(items, firmware, vehicle=vehicle, home_alt=home)}


def test_validators_accept_our_missions_and_name_each_defect():
    from dataclasses import replace

    from fm2uav.autopilot import MissionItem

    items, home = _good()
    assert _codes(items, home=home) == set()
    wp = next(i for i, it in enumerate(items) if it.command == 16)
    terrain = list(items)
    terrain[wp] = replace(items[wp], frame=10)
    assert "px4-terrain-frame" in _codes(terrain)
    assert "px4-terrain-frame" not in _codes(terrain, "ardupilot")
    turns = list(items)
    turns[wp] = replace(items[wp], command=18)
    assert "px4-command" in _codes(turns) and "px4-command" not in _codes(turns, "ardupilot")
    assert "no-takeoff" in _codes(items[1:])
    assert "no-end" in _codes(items[:-1])
    nan = list(items)
    p = list(items[wp].params)
    p[4] = float("nan")
    nan[wp] = replace(items[wp], params=tuple(p))
    assert "latlon" in _codes(nan)
    zero = list(items)
    p = list(items[wp].params)
    p[4] = p[5] = 0.0
    zero[wp] = replace(items[wp], params=tuple(p))
    assert "latlon-zero" in _codes(zero)
    low = [replace(items[0], params=(*items[0].params[:6], home - 1.0))] + items[1:]
    assert "takeoff-alt" in _codes(low, home=home)
    rtl_do = [replace(it, frame=3) if it.command == 178 else it for it in items]
    assert "px4-frame" in _codes(rtl_do)  # every rule: tests/autopilot/test_validate.py
    assert "px4-landing-required" in _codes(items[:-1] + [MissionItem.do(20)], vehicle="fixed_wing")
    # ArduCopter keeps DO_LAND_START / DO_RETURN_PATH_START as markers (mode_auto.cpp
    # start_command: "case MAV_CMD_DO_RETURN_PATH_START: case MAV_CMD_DO_LAND_START: break;")
    # but has no NAV_LOITER_TO_ALT
    copter_markers = items[:-1] + [MissionItem.do(188), MissionItem.do(189), items[-1]]
    assert "ardupilot-command" not in _codes(copter_markers, "ardupilot")
    loiter_alt = [replace(it, command=31) if it.command == 16 else it for it in items]
    assert "ardupilot-command" in _codes(loiter_alt, "ardupilot")
    assert "px4-command" in _codes(copter_markers)  # PX4 has no DO_RETURN_PATH_START
    ardu, _ = export_mission(hill_tff(), ["plan"], _opts(firmware="ardupilot"))
    bad_takeoff = [replace(ardu.items[0], frame=10, params=(*ardu.items[0].params[:6], 60.0))]
    assert "ardupilot-terrain-takeoff" in _codes(bad_takeoff + ardu.items[1:], "ardupilot")


def test_px4_fixed_wing_landing_rules():
    from dataclasses import replace

    m, _ = export_mission(hill_tff(), ["plan"], _opts(vehicle="fixed_wing", end="land"))
    items = list(m.items)
    assert [it.command for it in items[-3:]] == [189, 31, 21]
    assert _codes(items, vehicle="fixed_wing", home=m.home[2]) == set()
    steep = items[:-2] + [replace(items[-2], params=(*items[-2].params[:6],
                                                      items[-2].alt + 400.0)), items[-1]]
    assert "px4-fw-glide-slope" in _codes(steep, vehicle="fixed_wing", home=m.home[2])
    twice = items[:-3] + [items[-3]] + items[-3:]
    assert "px4-land-start" in _codes(twice, vehicle="fixed_wing", home=m.home[2])
    from fm2uav.autopilot import MissionItem

    before_rtl = items[:-3] + [items[-3], MissionItem.do(20)] + items[-2:]
    assert "px4-land-before-rtl" in _codes(before_rtl, vehicle="fixed_wing", home=m.home[2])


def test_export_refuses_a_start_on_the_ground():
    world = hill()
    g = world.ground_height(20.0, 20.0)
    path = np.array([[20.0, 20.0, g + 0.1], [200.0, 20.0, g + 60.0], [380.0, 280.0, 200.0]])
    with pytest.raises(MissionError, match="start is 0.10 m above the ground"):
        build_mission(path, world, _opts())


def test_written_plans_read_back_item_for_item(tmp_path):
    m, files = export_mission(hill_tff(), ["plan"], _opts(vehicle="vtol", speed_changes=True,
                                                          min_speed=9.0))
    _write(files, tmp_path)
    back = read_plan(tmp_path / "mission.plan")
    assert [it.command for it in back["items"]] == [it.command for it in m.items]
    for a, b in zip(back["items"], m.items):
        np.testing.assert_allclose(a.params, b.params, atol=1e-9, equal_nan=True)


def test_unknown_export_format_names_the_flag():
    with pytest.raises(InputError, match="--format 'pdf'"):
        export_mission(hill_tff(), ["pdf"], _opts())
    m, files = export_mission(hill_tff(), ["waypoints", "qgc"], _opts())
    assert set(files) == {"mission.waypoints", "mission.plan"}
    buf = io.StringIO()
    files["mission.plan"].write(buf)
    assert json.loads(buf.getvalue())["groundStation"] == "fm2uav"


@pytest.mark.parametrize("firmware", ["px4", "ardupilot"])
def test_a_coverage_export_triggers_the_camera_at_the_band_ends(firmware):
    from fm2uav import FlightLevel
    from fm2uav.missions.coverage import Camera, plan_coverage
    from fm2uav.missions.coverage.triggers import camera_plan
    from fm2uav.scenarios.coverage import coverage_area, coverage_world

    world = coverage_world(0)
    cp = plan_coverage(world, coverage_area("S1"), 80.0, level=FlightLevel(agl=100.0),
                       angle=math.radians(37.134))
    cam = Camera(13.2e-3, 8.8e-3, 8.8e-3, 5472, 3648)
    plan_cam = camera_plan(cp, camera=cam, front_overlap=0.7)
    m, _ = export_mission(cp.plan, ["plan"], _opts(firmware=firmware), agl=100.0,
                          camera=plan_cam)
    bands = cp.zigzag.bands()
    trig = [k for k, it in enumerate(m.items) if it.command == 206]
    assert len(trig) == 2 * len(bands)
    ends = np.array([np.asarray(b.coords)[[0, -1]] for b in bands]).reshape(-1, 2)
    for n, k in enumerate(trig):
        it = m.items[k]
        assert it.params[0] == (plan_cam.trigger_distance if n % 2 == 0 else 0.0)
        prev = next(m.items[j] for j in range(k - 1, -1, -1) if m.items[j].has_position)
        xy = from_lonlat(world, [[prev.lon, prev.lat]], anchor=ANCHOR)[0]
        assert np.hypot(*(xy - ends[n])) < 5.0  # at the band's start / end (m)
    s = m.summary()["camera"]
    # GSD = sensor width x AGL / (focal x image width): 13.2 mm x 100 m / (8.8 mm x 5472 px)
    assert s["gsd_cm_per_px"] == pytest.approx(100 * 13.2 * 100 / (8.8 * 5472), abs=1e-3)
    assert s["side_overlap"] == pytest.approx(1 - 80.0 / 150.0, abs=1e-3)
    assert plan_cam.trigger_distance == pytest.approx(100.0 * 0.3)


def test_formation_missions_one_per_vehicle_leave_together_and_keep_their_timing(tmp_path):
    from types import SimpleNamespace

    from fm2uav.io import export_formation

    world = hill()
    t = np.linspace(0.0, 60.0, 121)
    tracks = []
    for k, (dy, agl) in enumerate(((0.0, 60.0), (40.0, 40.0), (-40.0, 80.0))):
        x, y = 60 + 4.0 * t, 150 + dy + 10 * np.sin(t / 8)
        tracks.append(np.column_stack([x, y, world.ground_height(x, y) + agl]))
    res = SimpleNamespace(times=t, positions=np.stack(tracks, axis=1),
                          names=("leader", "follower1", "follower2"), agl=(60.0, 40.0, 80.0),
                          world=world)
    opts = _opts(climb_rate=8.0, descent_rate=8.0, tolerance=1.0)
    missions, files = export_formation(res, ["plan", "wpl"], opts)
    assert set(files) == {f"{n}_mission.{e}" for n in res.names for e in ("plan", "waypoints")}
    climb = [60.0 / 8, 40.0 / 8, 80.0 / 8]
    for (name, m), c in zip(missions.items(), climb):
        s = m.summary()
        assert s["timing"]["start_hold_s"] == pytest.approx(max(climb) - c)
        assert abs(s["timing"]["error_s"]) <= 0.02 * 60.0
        assert m.items[0].command == 22 and m.items[-1].command in END_COMMANDS
        assert sum(it.command == 178 for it in m.items) >= 1
    _write(files, tmp_path)
    assert read_plan(tmp_path / "follower2_mission.plan")["command"][0] == 22


def test_start_holds_let_vehicles_armed_together_leave_together():
    from fm2uav import World

    flat = World.from_heightmap(np.zeros((5, 5)), 10.0, 10)  # ground at z = 0
    holds = start_holds([[0.0, 0.0, 25.0], [10.0, 10.0, 10.0]], flat, ExportOptions())
    np.testing.assert_allclose(holds, [0.0, 6.0])  # 2.5 m/s up: 10 s and 4 s of climb
