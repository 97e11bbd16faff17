"""Each UAV's track: the final altitude profile's heights with the simulated timing (issue 25).

Measured independently: the fissure's ground is its node heights interpolated bilinearly
here (scipy), not through fm2uav's ground model.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy import ndimage

from fm2uav.missions.formation import profile_tracks


def _ground(world, x, y):
    return ndimage.map_coordinates(world.terrain, [(np.asarray(x) - world.origin[0]) /
                                                   world.spacing[0],
                                                   (np.asarray(y) - world.origin[1]) /
                                                   world.spacing[1]], order=1, mode="nearest")


def test_tracks_hold_the_level_over_the_continuous_ground(fissure_level):
    r = fissure_level
    assert len(r.tracks) == r.n_uav
    for i, tr in enumerate(r.tracks):
        assert tr.name == r.names[i] and tr.profile is not None
        assert np.all(np.diff(tr.times) > 0)
        assert len(tr.profile.required) == len(tr.path) == len(tr.profile.phase)
        # the common-time table is a subset of the track: same points at the same times
        k = np.searchsorted(tr.times, r.times)
        assert np.allclose(tr.times[k], r.times)
        assert np.allclose(tr.path[k], r.positions[:, i])
        # the cruise holds the request over the ground between the grid's nodes
        cruise = tr.profile.phase == "cruise"
        h = tr.path[cruise, 2] - _ground(r.world, tr.path[cruise, 0], tr.path[cruise, 1])
        assert h.min() >= 105.0 - 2.0 - 1e-6
        assert np.median(h) == pytest.approx(105.0, abs=0.5)
        # the straight pieces between track points stay above the floor too
        mid = 0.5 * (tr.path[1:] + tr.path[:-1])
        hm = mid[:, 2] - _ground(r.world, mid[:, 0], mid[:, 1])
        both = cruise[1:] & cruise[:-1]
        assert hm[both].min() >= 105.0 - 2.0 - 0.05


def test_tracks_keep_the_timing_of_the_flight(fissure_level):
    r = fissure_level
    for i, tr in enumerate(r.tracks):
        assert tr.times[0] == r.times[0] and tr.times[-1] == r.times[-1]
        # horizontal positions at any time agree with the simulated trajectory (but in the
        # first and last moving pieces, which a vertical take-off / landing leg shares)
        s = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(r.positions[:, i, :2],
                                                                 axis=0).T))])
        moving = np.flatnonzero(np.diff(s) > 1e-9)
        t = np.linspace(r.times[moving[0] + 1], r.times[moving[-1]], 997)
        for axis in (0, 1):
            a = np.interp(t, tr.times, tr.path[:, axis])
            b = np.interp(t, r.times, r.positions[:, i, axis])
            assert np.max(np.abs(a - b)) < 1e-6


def test_without_a_level_the_track_is_the_simulation(fissure_free):
    r = fissure_free
    for i, tr in enumerate(r.tracks):
        assert tr.profile is None
        assert np.array_equal(tr.path, r.positions[:, i]) and np.array_equal(tr.times, r.times)


def test_profile_tracks_on_a_straight_line(fissure):
    """A hand-made two-UAV flight: the track gets the profile's samples in between, with
    times proportional to the distance along each straight piece; a hold stays put."""
    from fm2uav import FlightLevel

    w = fissure.world
    y = 600.0
    xs = np.array([150.0, 150.0, 400.0, 650.0])
    g = _ground(w, xs, np.full(4, y))
    pos = np.column_stack([xs, np.full(4, y), g + 100.0])[:, None, :]
    pos = np.concatenate([pos, pos + [0.0, 100.0, 0.0]], axis=1)
    t = np.array([0.0, 5.0, 30.0, 55.0])
    out, tracks = profile_tracks(w, t, pos, ("a", "b"), (FlightLevel(agl=100.0), None))
    tr = tracks[0]
    assert np.array_equal(tracks[1].path, pos[:, 1])
    assert np.array_equal(out[:, 1], pos[:, 1])
    assert len(tr.path) > 100  # the profile's samples every quarter cell
    piece = (tr.times > 5.0) & (tr.times < 30.0)
    speed = np.diff(tr.path[piece, 0]) / np.diff(tr.times[piece])
    assert speed == pytest.approx(10.0)  # 250 m in 25 s
    assert np.array_equal(tr.path[:2, :2], pos[:2, 0, :2])  # the hold
