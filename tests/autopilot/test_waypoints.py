"""Autopilot waypoints from a dense path: Douglas–Peucker with forced points, the flown
(ground + AGL) profile, and the same altitudes written in every MAVLink frame."""

import numpy as np
import pytest

from fm2uav.autopilot.thin import segment_distances
from fm2uav.autopilot.waypoints import altitude_profile, mission_waypoints, thin_with_keep

from .mission_cases import ANCHOR, hill_free, hill_tff


def test_waypoints_are_few_and_within_tolerance():
    p = hill_tff()
    wps = mission_waypoints(p.path, p.world, tolerance=2.0, anchor=ANCHOR, frame="amsl", agl=60)
    assert 3 <= len(wps) <= 40 < len(p.path)
    flown, k = wps.points_m, wps.indices
    # the thinned legs stay within the tolerance of the flown (ground + AGL) profile
    dense = altitude_profile(p.path, p.world, agl=60.0)[0]
    for a, b in zip(k[:-1], k[1:]):
        if b - a > 1:
            assert segment_distances(dense[a + 1:b], dense[a], dense[b]).max() <= 2.0 + 1e-9
    np.testing.assert_array_equal(flown, dense[k])


def test_forced_points_are_kept_and_pieces_thinned_alone():
    line = np.column_stack([np.linspace(0, 100, 101), np.zeros(101), np.zeros(101)])
    assert thin_with_keep(line, 0.5).tolist() == [0, 100]
    assert thin_with_keep(line, 0.5, keep=[37, 80]).tolist() == [0, 37, 80, 100]
    with pytest.raises(ValueError, match="keep indices"):
        thin_with_keep(line, 0.5, keep=[101])


def test_frames_write_the_same_flown_altitude():
    p = hill_tff()
    got = {f: mission_waypoints(p.path, p.world, anchor=ANCHOR, frame=f, agl=60.0)
           for f in ("terrain", "amsl", "relative")}
    assert {f: w.frame for f, w in got.items()} == {"terrain": 10, "amsl": 0, "relative": 3}
    np.testing.assert_allclose(got["terrain"].alt, got["terrain"].agl)
    np.testing.assert_allclose(got["amsl"].alt, got["amsl"].alt_amsl)
    np.testing.assert_allclose(got["relative"].alt, got["relative"].alt_amsl - got["relative"].home[2])
    for f in ("amsl", "relative"):
        np.testing.assert_allclose(got[f].alt_amsl, got[f].ground_amsl + got[f].agl, atol=1e-9)


def test_relative_frame_altitudes_are_above_home():
    p = hill_free()
    wps = mission_waypoints(p.path, p.world, anchor=ANCHOR)
    assert wps.frame == 3
    home_ground = p.world.ground_height(*p.path[0, :2])
    np.testing.assert_allclose(wps.alt, wps.points_m[:, 2] - home_ground, atol=1e-9)
    np.testing.assert_allclose(wps.points_m[:, 2], p.path[wps.indices, 2])  # no level: own z
