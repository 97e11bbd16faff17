"""The firmware's straight-line return made safe: lowest return altitude per firmware model,
on worlds whose answer is known by hand (a 100 m wall between the route and home)."""

import numpy as np
import pytest

from fm2uav import World
from fm2uav.autopilot.build import ExportOptions, build_mission
from fm2uav.autopilot.firmware import PROFILES
from fm2uav.autopilot.items import CMD_DO_CHANGE_SPEED, MissionItem
from fm2uav.autopilot.rally import RallyPoint
from fm2uav.autopilot.returns import firmware_returns, leg_speeds, route_samples
from fm2uav.vehicles.endurance import flight_time


def wall_world():
    """80 x 40 columns of 10 m, flat at 0 m, a 100 m wall across x = 400..420 m."""
    h = np.zeros((80, 40))
    h[40:43, :] = 100.0
    return World.from_heightmap(h, 10.0, 30)


@pytest.fixture(scope="module")
def world():
    return wall_world()


def mission(world, path, **opt):
    return build_mission(np.asarray(path, float), world,
                         ExportOptions(tolerance=1.0, **{"frame": "relative", **opt}))


HIGH = [[700.0, 200.0, 150.0], [200.0, 200.0, 150.0], [200.0, 50.0, 150.0]]


def by(fr, label):
    return next(r for r in fr.results if r.model.label == label)


@pytest.mark.parametrize("firmware, vehicle, label, names", [
    ("ardupilot", "multirotor", "ArduCopter", {"RTL_ALT": 13000, "RTL_ALT_M": 130}),
    ("px4", "multirotor", "PX4 multicopter", {"RTL_RETURN_ALT": 130}),
    ("ardupilot", "fixed_wing", "ArduPlane", {"ALT_HOLD_RTL": 13000, "RTL_ALTITUDE": 130}),
])
def test_the_lowest_altitude_clears_the_wall_by_min_agl(world, firmware, vehicle, label, names):
    # home east of the wall (x = 700), the route crosses it at 150 m and flies west of it
    m = mission(world, HIGH, firmware=firmware, vehicle=vehicle,
                **({"end": "loiter"} if vehicle == "fixed_wing" else {}))
    fr = firmware_returns(m, min_agl=30.0)
    r = by(fr, label)
    assert r.feasible and r.altitude_m == 130.0  # wall 100 m + 30 m, home at 0 m
    params = {p.name: p.value for p in r.params}
    for k, v in names.items():
        assert params[k] == v
    assert r.summary["min_clearance_m"] == pytest.approx(30.0, abs=1e-6)
    assert r.summary["binding_line"]["surface_point_m"][2] == pytest.approx(100.0)
    assert fr.summary()["start_points"]["waypoints"] == len(m.waypoints)


def test_a_ceiling_below_the_needed_altitude_makes_it_infeasible(world):
    m = mission(world, HIGH, firmware="ardupilot")
    fr = firmware_returns(m, min_agl=30.0, max_agl=120.0)
    r = fr.results[0]
    assert not r.feasible and r.altitude_m is None and r.clearing_m == 130.0
    assert "ceiling" in r.reasons[0] and "ridge" in r.reasons[0]
    names = {p.name: p.value for p in r.params}
    # the clearing altitude is still written (a plain RTL does not hit the wall) and the
    # failsafes go to the mission's planned return
    assert names["RTL_ALT_M"] == 130 and names["FS_THR_ENABLE"] == 6
    assert names["BATT_FS_LOW_ACT"] == 6


def test_px4_mission_return_overrides_its_return_type(world):
    m = mission(world, HIGH, firmware="px4")
    r = firmware_returns(m, min_agl=30.0, max_agl=120.0).results[0]
    assert {p.name: p.value for p in r.params}["RTL_TYPE"] == 2  # not the checked 0


def test_a_plane_too_close_below_the_wall_cannot_climb_over_it_copter_can(world):
    # the route ends 20 m west of the wall at 60 m; home is east of it
    low = [[700.0, 200.0, 150.0], [380.0, 200.0, 150.0], [380.0, 150.0, 60.0],
           [380.0, 50.0, 60.0]]
    plane = firmware_returns(mission(world, low, firmware="ardupilot", vehicle="fixed_wing",
                                     end="loiter"), min_agl=30.0).results[0]
    assert not plane.feasible and "climb" in plane.reasons[0]
    copter = firmware_returns(mission(world, low, firmware="ardupilot"), min_agl=30.0)
    assert copter.feasible and copter.results[0].altitude_m == 130.0


def test_a_plane_taking_off_below_the_floor_keeps_its_own_height_not_min_agl(world):
    # the route starts 10 m above home and climbs out east of the wall: from there a plane
    # cannot be 30 m up at once, and need not be; it must not come closer to the ground
    climb = [[790.0, 200.0, 10.0], [640.0, 200.0, 20.0], [560.0, 200.0, 150.0],
             [200.0, 200.0, 150.0], [200.0, 50.0, 150.0]]
    plane = firmware_returns(mission(world, climb, firmware="ardupilot", vehicle="fixed_wing",
                                     end="loiter"), min_agl=30.0).results[0]
    assert plane.feasible and plane.altitude_m == 130.0, plane.reasons
    assert plane.summary["unsafe_lines"] == 0
    # but 10 m up right in front of the wall it cannot climb over it
    low = [[700.0, 200.0, 150.0], [380.0, 200.0, 150.0], [380.0, 150.0, 10.0]]
    plane = firmware_returns(mission(world, low, firmware="ardupilot", vehicle="fixed_wing",
                                     end="loiter"), min_agl=30.0).results[0]
    assert not plane.feasible and "climb" in plane.reasons[0]


def test_rally_points_compete_with_home_and_get_their_own_transit_altitude(world):
    m = mission(world, HIGH, firmware="ardupilot")
    # a rally point west of the wall: the lines from the west never cross the wall
    r = RallyPoint("rally 1", np.array([150.0, 120.0, 50.0]), 0.0, 50.0)
    fr = firmware_returns(m, rally=[r], min_agl=30.0)
    res = fr.results[0]
    assert res.feasible
    # a west point goes to the rally point, the east ones home
    assert res.summary["destinations"]["rally 1"] > 0 and res.summary["destinations"]["home"] > 0
    names = {p.name: p.value for p in res.params}
    assert names["RALLY_INCL_HOME"] == 1 and names["RALLY_LIMIT_KM"] == 0
    assert fr.rally_altitudes["rally 1"] >= 30.0
    # every line west of the wall to the rally point: only 30 m needed, but Copter flies at
    # max(rally altitude, RTL_ALT): both are checked
    assert res.summary["min_clearance_m"] >= 30.0 - 1e-6


def test_px4_measures_its_altitude_above_the_destination(world):
    m = mission(world, HIGH, firmware="px4")
    high = RallyPoint("rally 1", np.array([150.0, 120.0, 60.0]), 40.0, 20.0)  # ground 40 m
    w2 = world
    fr = firmware_returns(m, rally=[high], min_agl=30.0)
    res = fr.results[0]
    # lines to home need 130 m above home; lines to the rally point 30 m above ground 0
    # minus its 40 m ground: the parameter is the larger, 130 m
    assert res.altitude_m == 130.0
    assert fr.rally_altitudes == {"rally 1": 40.0}  # PX4: the rally point's own height
    assert w2 is world


def test_generic_checks_both_firmwares(world):
    m = mission(world, HIGH, firmware="generic")
    fr = firmware_returns(m, min_agl=30.0)
    assert [r.model.label for r in fr.results] == ["PX4 multicopter", "ArduCopter"]
    assert {p.name for p in fr.params} >= {"RTL_RETURN_ALT", "RTL_ALT", "RTL_ALT_M"}


def test_a_zone_on_the_line_is_a_reason(world):
    from shapely.geometry import box

    from fm2uav.world.zones import Zone, with_zones

    zw = with_zones(world, [Zone(box(500, 100, 560, 340), name="prison")])
    path = [[700.0, 350.0, 150.0], [200.0, 350.0, 150.0], [200.0, 250.0, 150.0]]
    r = firmware_returns(mission(zw, path, firmware="ardupilot"), min_agl=30.0).results[0]
    assert not r.feasible and "prison" in r.reasons[-1]


def test_leg_speeds_are_read_as_mavlink_flies_them():
    wp = lambda: MissionItem(16, 3, (0, 0, 0, 0, 1, 1, 10))  # noqa: E731
    sp = lambda v: MissionItem.do(CMD_DO_CHANGE_SPEED, 1, v, -1, 0)  # noqa: E731
    items = [MissionItem(22, 3, (0, 0, 0, 0, 1, 1, 10)), sp(3.0), wp(), wp(), sp(7.0), wp()]
    speeds, holds = leg_speeds(items, 4, 5.0)  # waypoint 0 is the takeoff point
    assert speeds.tolist() == [3.0, 3.0, 7.0] and holds.tolist() == [0, 0, 0, 0]


def test_route_samples_keep_the_missions_clock(world):
    m = mission(world, HIGH, firmware="px4", speed_changes=False)
    s = route_samples(m, step=7.0)
    wps = m.waypoints
    at = s.waypoint >= 0
    assert s.waypoint[at].tolist() == list(range(len(wps)))
    ft = flight_time(wps.points_m, m.options.forward_speed,
                     climb_rate=m.info["flight"]["climb_rate_mps"],
                     descent_rate=m.info["flight"]["descent_rate_mps"],
                     takeoff_climb=float(wps.agl[0]))
    assert np.allclose(s.time[at], ft.elapsed())
    assert np.all(np.diff(s.time) >= 0) and np.all(np.diff(s.distance) >= 0)
    one = route_samples(m, legs=[(0, 0.5)])
    assert one.time[0] == pytest.approx(0.5 * (ft.elapsed()[0] + ft.elapsed()[1]))


@pytest.mark.parametrize("vehicle", ["multirotor", "fixed_wing", "vtol"])
def test_route_samples_run_on_the_clock_of_the_summarys_flight_time(world, vehicle):
    """One clock: the safe returns time the route as the summary's flight time does — a
    fixed wing's climb-out (not a vertical take-off) and legs at airspeed (a plane does
    not wait for its altitude); it counted a vertical climb and a hovering vehicle's legs."""
    path = [[700.0, 200.0, 60.0], [200.0, 200.0, 150.0], [200.0, 50.0, 90.0],
            [600.0, 50.0, 90.0]]
    m = mission(world, path, firmware="ardupilot", vehicle=vehicle, end="land",
                cruise_speed=14.0, **({} if vehicle == "multirotor" else {"min_speed": 10.0}))
    f = m.info["flight"]
    s = route_samples(m, step=7.0)
    at = s.waypoint >= 0
    first = m.info.get("climb_out", {}).get("dropped_waypoints", 0)  # waypoints it replaces
    assert s.time[at][first] == pytest.approx(f["takeoff_s"], abs=0.06)
    assert s.time[-1] == pytest.approx(f["takeoff_s"] + f["route_s"], abs=0.11)
    assert s.time[-1] + f["end_s"] == pytest.approx(f["flight_time_s"], abs=0.16)
    assert np.all(np.diff(s.time) >= 0)
    if vehicle == "fixed_wing":  # the climb-out is not a vertical take-off at 150 m
        assert m.info["climb_out"]["mode"] in ("loiter", "straight")


def test_every_firmware_and_airframe_has_a_return_model():
    for name, prof in PROFILES.items():
        for v in ("multirotor", "fixed_wing", "vtol"):
            assert prof.returns[v], (name, v)
            for m in prof.returns[v]:
                assert m.altitude and m.sources


def test_on_a_2d_map_a_line_through_an_obstacle_is_not_safe():
    occ = np.zeros((60, 40), bool)
    occ[30, 5:35] = True  # a building of unknown height between the route and home
    w = World(occ, spacing=10.0)
    m = build_mission(np.array([[100.0, 200.0], [100.0, 380.0], [500.0, 380.0],
                                [500.0, 200.0]]), w, ExportOptions(firmware="ardupilot"))
    r = firmware_returns(m, min_agl=30.0).results[0]
    assert not r.feasible and "2D map" in r.reasons[-1]
    ok = firmware_returns(build_mission(np.array([[100.0, 200.0], [200.0, 200.0]]), w,
                                        ExportOptions(firmware="ardupilot")), min_agl=30.0)
    assert ok.feasible and ok.results[0].altitude_m == 30.0
