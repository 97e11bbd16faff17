"""Path profiles (analysis/profiles.py): exact geometric cases (helix, line, right angle)."""

from __future__ import annotations

import numpy as np
import pytest

from fm2uav.analysis import path_profiles
from fm2uav.errors import InputError
from fm2uav.geometry import menger_curvature


def test_helix_profiles_are_exact():
    # helix radius R, pitch angle g: horizontal curvature 1/R, climb g,
    # 3D curvature cos(g)^2 / R, turn per step ds*cos(g)/R
    R, g, ds = 200.0, np.radians(10.0), 5.0
    t = np.linspace(0, 2 * np.pi, 4000)
    h = R * t * np.tan(g)
    helix = np.stack([R * np.cos(t), R * np.sin(t), h], axis=1)
    pr = path_profiles(helix, ds=ds)
    np.testing.assert_allclose(pr.climb, g, atol=1e-3)
    np.testing.assert_allclose(pr.curvature_h[2:-2], 1 / R, rtol=2e-3)
    np.testing.assert_allclose(pr.curvature[2:-2], np.cos(g) ** 2 / R, rtol=2e-3)
    np.testing.assert_allclose(pr.turn[2:-2], ds * np.cos(g) / R, rtol=2e-3)
    s = pr.summary()
    assert s["min_turn_radius_m"] == pytest.approx(R, rel=5e-3)
    assert s["climb_max_deg"] == pytest.approx(10.0, abs=0.1)


def test_straight_line_and_right_angle():
    line = np.stack([np.linspace(0, 100, 11), np.zeros(11), np.linspace(0, 100, 11)], axis=1)
    pr = path_profiles(line, ds=10.0)
    assert np.allclose(pr.turn, 0) and np.allclose(pr.curvature, 0)
    np.testing.assert_allclose(np.degrees(pr.climb), 45.0)
    assert pr.summary()["min_turn_radius_m"] == np.inf
    corner = np.array([[0.0, 0, 0], [10, 0, 0], [10, 10, 0]])
    pr = path_profiles(corner, ds=10.0)
    np.testing.assert_allclose(np.degrees(pr.turn), [90.0])
    # circle through (0,0), (10,0), (10,10): radius 5 sqrt(2)
    np.testing.assert_allclose(menger_curvature(corner), [1 / (5 * np.sqrt(2))])
    with pytest.raises(InputError):
        path_profiles(np.zeros((1, 3)))
