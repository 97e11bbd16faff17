"""Geometric profiles and the geometric verdict (vehicles/geometric.py): exact checks."""

from __future__ import annotations

import math

import numpy as np
import pytest

from fm2uav.vehicles import climb_angle_profile, curvature_profile, geometric_check, get_airframe


def _circle(r: float, turns: float = 0.75, n: int = 600, z_slope: float = 0.0) -> np.ndarray:
    th = np.linspace(0.0, 2 * np.pi * turns, n)
    return np.column_stack([r * np.cos(th), r * np.sin(th), z_slope * r * th])


@pytest.mark.parametrize("r", [5.0, 30.0, 200.0])
def test_curvature_of_circle_is_exact(r):
    s, k = curvature_profile(_circle(r, n=2000), window=0.3 * r)
    inner = (s > 0.5 * r) & (s < s[-1] - 0.5 * r)
    np.testing.assert_allclose(k[inner], 1.0 / r, rtol=2e-3)


def test_curvature_zero_on_straight_and_climb_angle():
    p = np.column_stack([np.linspace(0, 100, 51), np.zeros(51), np.linspace(0, 100 * np.tan(0.2), 51)])
    _, k = curvature_profile(p)
    assert np.all(k < 1e-9)
    _, g = climb_angle_profile(p)
    np.testing.assert_allclose(g, 0.2, atol=1e-12)


def test_geometric_check_circle_tighter_than_r():
    af = get_airframe("disco")
    R = af.turn_radius()
    tight = geometric_check(_circle(0.5 * R), af)
    assert not tight.feasible
    assert tight.violations[0]["kind"] == "turn"
    assert tight.min_radius == pytest.approx(0.5 * R, rel=1e-2)
    wide = geometric_check(_circle(3 * R), af)
    assert wide.feasible and "R_min" in wide.reason


def test_geometric_check_climb_limit():
    af = get_airframe("disco")  # climb 30 deg, descent 25 deg
    for ang, ok in ((math.radians(20), True), (math.radians(35), False), (math.radians(-28), False)):
        p = np.column_stack([np.linspace(0, 100, 21), np.zeros(21), np.linspace(0, 100 * math.tan(ang), 21)])
        res = geometric_check(p, af)
        assert res.feasible is ok
        if not ok:
            assert res.violations[0]["kind"] == ("climb" if ang > 0 else "descent")
    # a multirotor is never geometrically infeasible
    assert geometric_check(_circle(1.0), "arducopter").feasible
