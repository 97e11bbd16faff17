"""Speeds that mean what they say: always a cruise speed at the start, W mapped onto the
airframe's range (never below its minimum), the obstacle-distance W of a terrain-following
plan (not its flight-level shaping), the speed type of each firmware."""

from __future__ import annotations

import numpy as np
import pytest

from fm2uav.autopilot import ExportOptions
from fm2uav.autopilot.speeds import DEFAULT_MIN_SPEED, plan_speeds, w_leg_speeds
from fm2uav.errors import MissionError
from fm2uav.io import export_mission

from .mission_cases import ANCHOR, hill_free, hill_tff

IDX = np.array([0, 4, 9])
PTS = np.array([[0.0, 0, 50], [40, 0, 50], [90, 0, 50]])


def test_a_cruise_speed_is_always_commanded_first():
    sp = plan_speeds(indices=IDX, points=PTS, forward=14.0, floor=None, fixed_wing=True,
                     changes=False, step=1.0, hysteresis=2)
    assert sp.changes == [(0, 14.0)] and sp.source == "forward speed"
    np.testing.assert_array_equal(sp.commanded, [14.0, 14.0])


def test_w_is_mapped_onto_the_airframe_range_not_taken_as_a_share_of_the_cap():
    w = np.array([1.0, 1, 1, 1, 1, 0.2, 0.2, 0.2, 0.2, 0.2])
    legs = w_leg_speeds(w, IDX, 12.0, 22.0)
    np.testing.assert_allclose(legs, [22.0, 12 + 0.2 * 10])  # floor + W (cap - floor)
    sp = plan_speeds(indices=IDX, points=PTS, forward=22.0, floor=12.0, fixed_wing=True,
                     changes=True, step=1.0, hysteresis=2, w=w)
    assert sp.changes == [(0, 22.0), (1, 14.0)] and min(v for _, v in sp.changes) >= 12.0
    # a multirotor's floor defaults to 1 m/s, and W = 0.09 is 1 + 0.09 x 5 m/s, not 0.54
    w = np.full(10, 0.09)
    sp = plan_speeds(indices=IDX, points=PTS, forward=6.0, floor=None, fixed_wing=False,
                     changes=True, step=0.5, hysteresis=2, w=w)
    assert sp.changes == [(0, 1.0)] and DEFAULT_MIN_SPEED == 1.0
    w = np.full(10, 0.5)
    sp = plan_speeds(indices=IDX, points=PTS, forward=6.0, floor=None, fixed_wing=False,
                     changes=True, step=0.5, hysteresis=2, w=w)
    assert sp.changes == [(0, 3.5)]


def test_fixed_wing_speed_changes_need_a_minimum_and_a_consistent_range():
    with pytest.raises(MissionError, match="min_speed"):
        plan_speeds(indices=IDX, points=PTS, forward=22.0, floor=None, fixed_wing=True,
                    changes=True, step=1.0, hysteresis=2, w=np.ones(10))
    with pytest.raises(MissionError, match="above the forward speed"):
        plan_speeds(indices=IDX, points=PTS, forward=10.0, floor=12.0, fixed_wing=True,
                    changes=False, step=1.0, hysteresis=2)


def test_a_terrain_following_plan_is_slowed_by_its_obstacles_not_its_flight_level():
    p = hill_tff()
    assert p.speed_share().shape == p.w.shape
    assert float(p.speed_share().min()) > float(p.w.min())  # the level shaping darkens W
    free = hill_free()
    np.testing.assert_array_equal(free.speed_share(), free.w)  # no level: W is the speed share
    m, _ = export_mission(p, ["plan"], ExportOptions(anchor=ANCHOR, speed_changes=True,
                                                     hover_speed=8.0))
    share = p.speed_share()
    idx = m.waypoints.indices
    legs = 1.0 + np.array([share[a:b + 1].min() for a, b in zip(idx[:-1], idx[1:])]) * 7.0
    first = next(it for it in m.items if it.command == 178)
    assert first.params[1] == np.floor(legs[0] + 1e-9)  # quantised down to the 1 m/s step


def test_the_flight_level_a_plan_keeps_is_open_sky_full_speed():
    """The speed share of a terrain-following plan: the distance to the nearest obstacle
    over the flight level's AGL (saturated at 1), computed here with scipy's exact
    distance transform on the occupancy grid."""
    from scipy import ndimage

    p = hill_tff()
    occ = p.world.occupancy
    d = ndimage.distance_transform_edt(~occ, sampling=p.world.spacing)
    at = ndimage.map_coordinates(d, p.world.to_index(p.path).T, order=1, mode="nearest")
    expect = np.minimum(at / p.level.agl, 1.0)
    # (the map is saturated on the grid, then interpolated: up to a few % apart near d = agl)
    np.testing.assert_allclose(p.speed_share(), expect, atol=0.05)
    assert np.mean(p.speed_share() >= 0.99) > 0.3  # most of the cruise is at full speed


@pytest.mark.parametrize("firmware, vehicle, kind", [
    ("ardupilot", "fixed_wing", 0), ("ardupilot", "multirotor", 1), ("px4", "fixed_wing", 0),
    ("px4", "multirotor", 1), ("generic", "vtol", 0)])
def test_the_speed_type_is_the_firmwares_for_the_airframe(firmware, vehicle, kind):
    end = "land" if firmware != "ardupilot" and vehicle != "multirotor" else "auto"
    m, _ = export_mission(hill_tff(), ["plan"], ExportOptions(anchor=ANCHOR, firmware=firmware,
                                                              vehicle=vehicle, end=end))
    speeds = [it for it in m.items if it.command == 178]
    first_wp = next(i for i, it in enumerate(m.items) if it.command == 16)
    assert speeds and {it.params[0] for it in speeds} == {kind}
    assert m.items.index(speeds[0]) < first_wp
    assert m.info["speed_changes"]["speed_type"] == kind


def test_the_flight_time_is_flown_at_the_commanded_speeds():
    """The route time of the summary is the waypoint legs at the speed each DO_CHANGE_SPEED
    puts in force (issue 24: the estimate assumed the hover speed while 1 m/s was commanded)."""
    m, _ = export_mission(hill_tff(), ["plan"], ExportOptions(anchor=ANCHOR, speed_changes=True,
                                                              hover_speed=8.0))
    fl = m.info["flight"]
    v, legs, prev = None, [], None
    for it in m.items:
        if it.command == 178:
            v = it.params[1]
        elif it.command == 16:
            if prev is not None:
                legs.append((prev, it, v))
            prev = it
    pts = m.waypoints.points_m[1:]  # the first point is the take-off's
    t = 0.0
    for k, (_, _, speed) in enumerate(legs):
        d = pts[k + 1] - pts[k]
        t += max(float(np.hypot(d[0], d[1])) / speed,
                 d[2] / fl["climb_rate_mps"] if d[2] > 0 else -d[2] / fl["descent_rate_mps"])
    assert len(legs) == len(pts) - 1 and v < 8.0  # the obstacles slow it below the hover speed
    assert fl["route_s"] == pytest.approx(t, rel=0.05)
