"""Autopilot waypoints from a dense path: Douglas–Peucker with forced points, the flown
(ground + AGL) profile, and the same altitudes written in every MAVLink frame."""

import numpy as np
import pytest

from fm2uav.autopilot.thin import segment_distances
from fm2uav.autopilot.waypoints import altitude_profile, mission_waypoints, thin_with_keep

from fm2uav.world.geo import to_lonlat

from .mission_cases import ANCHOR, bilinear_ground, hill_free, hill_tff


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
    """Each frame's altitude, turned back into metres above mean sea level as its autopilot
    reads it (10: + the ground under the waypoint, 0: as written, 3: + home), is the same
    flown altitude: the independent bilinear ground + the requested AGL on the flight level,
    the path's own height off it."""
    p = hill_tff()
    got = {f: mission_waypoints(p.path, p.world, anchor=ANCHOR, frame=f, agl=60.0)
           for f in ("terrain", "amsl", "relative")}
    assert {f: w.frame for f, w in got.items()} == {"terrain": 10, "amsl": 0, "relative": 3}
    # the flown profile of the dense path, measured here (scipy on the height map + anchor)
    lonlat_path = np.column_stack([*to_lonlat(p.world, p.path, anchor=ANCHOR)[:, :2].T])
    ground = bilinear_ground(p.world, lonlat_path)
    own = p.path[:, 2] + ANCHOR.alt - ground
    on_level = np.abs(own - 60.0) <= p.world.spacing[2] + 1e-9
    flown = ground + np.where(on_level, 60.0, own)
    home = bilinear_ground(p.world, to_lonlat(p.world, p.path[:1], anchor=ANCHOR))[0]
    for f, w in got.items():
        g = bilinear_ground(p.world, np.column_stack([w.lon, w.lat]))
        amsl = {"terrain": w.alt + g, "amsl": w.alt, "relative": w.alt + home}[f]
        np.testing.assert_allclose(amsl, flown[w.indices], atol=1e-6, err_msg=f)
        np.testing.assert_allclose(w.home[2], home, atol=1e-6)
    assert on_level.all() and np.ptp(own) > 0.5  # the request differs from the own heights
    # the same dense points, whichever frame thinned them, fly at the same altitude
    common = np.intersect1d(got["amsl"].indices, got["terrain"].indices)
    assert len(common) >= 2


def test_relative_frame_altitudes_are_above_home():
    p = hill_free()
    wps = mission_waypoints(p.path, p.world, anchor=ANCHOR)
    assert wps.frame == 3
    home_ground = p.world.ground_height(*p.path[0, :2])
    np.testing.assert_allclose(wps.alt, wps.points_m[:, 2] - home_ground, atol=1e-9)
    np.testing.assert_allclose(wps.points_m[:, 2], p.path[wps.indices, 2])  # no level: own z
