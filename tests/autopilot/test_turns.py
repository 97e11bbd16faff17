"""Fixed-wing waypoint spacing: free waypoints that make a leg too short to turn onto are
dropped where the merged leg stays safe; waypoints that must stay get a small acceptance
radius so the firmware never skips them."""

from __future__ import annotations

import numpy as np

from fm2uav import World
from fm2uav.autopilot.firmware.ardupilot import PLANE_NAV
from fm2uav.autopilot.turns import MIN_ACCEPTANCE, fit_turns, leg_needs

NAV = PLANE_NAV.with_airframe(cruise=20.0)


def _dense(corners, z=100.0, step=2.0):
    pts = []
    for a, b in zip(corners[:-1], corners[1:]):
        a, b = np.asarray(a, float), np.asarray(b, float)
        n = max(int(np.hypot(*(b - a)) / step), 1)
        pts += [a + (b - a) * t for t in np.arange(n) / n]
    pts.append(np.asarray(corners[-1], float))
    p = np.asarray(pts)
    return np.column_stack([p, np.full(len(p), z)])


def _world():
    return World.from_heightmap(np.zeros((200, 200)), 10.0, 30)


def _kept(flown, corners):
    return np.array([int(np.argmin(np.hypot(*(flown[:, :2] - c).T))) for c in corners])


def test_a_free_waypoint_on_a_jog_is_dropped():
    corners = [(100, 100), (800, 100), (812, 112), (1500, 112)]  # a 17 m jog in the route
    flown = _dense(corners)
    idx = _kept(flown, corners)
    L, need, gap = leg_needs(flown[idx, :2], NAV)
    assert L[1] < need[1]
    out, acc, rep = fit_turns(idx, flown, _world(), required=np.full(len(flown), -np.inf),
                              keep=[], nav=NAV, tolerance=5.0)
    assert rep["removed"] >= 1 and len(out) < len(idx)
    assert not acc.any()
    L, need, gap = leg_needs(flown[out, :2], NAV)
    assert np.all(L[1:] >= need[1:] - 1e-6) and np.all(gap > 0)


def test_waypoints_that_must_stay_get_a_small_acceptance_radius_instead():
    corners = [(100, 100), (800, 100), (800, 110), (1500, 110)]  # band end and next start
    flown = _dense(corners)
    idx = _kept(flown, corners)
    out, acc, rep = fit_turns(idx, flown, _world(), required=np.full(len(flown), -np.inf),
                              keep=idx[1:3], nav=NAV, tolerance=5.0)
    np.testing.assert_array_equal(out, idx)
    assert rep["acceptance_set"] == 2 and acc[1] == acc[2] == MIN_ACCEPTANCE
    _, _, gap = leg_needs(flown[out, :2], NAV, acceptance=acc)
    assert np.all(gap[1:] > 0)  # no waypoint is reached before it is flown to


def test_a_merge_that_would_cut_below_the_floor_is_not_made():
    corners = [(100, 100), (800, 100), (812, 112), (1500, 112)]
    flown = _dense(corners, z=100.0)
    idx = _kept(flown, corners)
    w = _world()
    req = np.full(len(flown), 99.0)  # the legs must keep 99 m over the ground...
    flown[idx[1] + 1:idx[2], 2] = 140.0  # ...and the jog climbs: a straight cut would not
    req[idx[1] + 1:idx[2]] = 139.0
    out, _, rep = fit_turns(idx, flown, w, required=req, keep=[], nav=NAV, tolerance=5.0)
    np.testing.assert_array_equal(out, idx)
    assert rep["removed"] == 0
