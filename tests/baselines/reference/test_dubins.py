"""Exact Dubins length: closed-form cases and OMPL's DubinsStateSpace."""

import math

import numpy as np
import pytest

from fm2uav.baselines.reference import dubins_length
from fm2uav.errors import InputError


def test_straight_and_u_turn():
    assert dubins_length((0, 0, 0), (10, 0, 0), 2.0) == pytest.approx(10.0, abs=1e-12)
    # U-turn to the left onto the parallel line 2r away: half a circle
    assert dubins_length((0, 0, 0), (0, 4, math.pi), 2.0) == pytest.approx(2 * math.pi, abs=1e-9)
    # quarter circle
    assert dubins_length((0, 0, 0), (3, 3, math.pi / 2), 3.0) == pytest.approx(1.5 * math.pi, abs=1e-9)
    # same pose: zero
    assert dubins_length((1, 2, 0.3), (1, 2, 0.3), 1.0) == pytest.approx(0.0, abs=1e-9)


def test_scales_with_radius():
    a = dubins_length((0, 0, 0.2), (7, -3, 2.0), 1.5)
    b = dubins_length((0, 0, 0.2), (14, -6, 2.0), 3.0)
    assert b == pytest.approx(2 * a, rel=1e-12)


def test_matches_ompl():
    ob = pytest.importorskip("ompl.base")
    rng = np.random.default_rng(7)
    for radius in (0.5, 2.0, 5.0):
        space = ob.DubinsStateSpace(radius)
        a, b = space.allocState(), space.allocState()
        for _ in range(300):
            p = rng.uniform(-12, 12, 6)
            p[2], p[5] = rng.uniform(-math.pi, math.pi, 2)
            a.setX(p[0]); a.setY(p[1]); a.setYaw(p[2])  # noqa: E702
            b.setX(p[3]); b.setY(p[4]); b.setYaw(p[5])  # noqa: E702
            assert dubins_length(p[:3], p[3:], radius) == pytest.approx(space.distance(a, b), abs=1e-9)


def test_bad_input():
    with pytest.raises(InputError):
        dubins_length((0, 0), (1, 1, 0), 1.0)
    with pytest.raises(InputError):
        dubins_length((0, 0, 0), (1, 1, 0), 0.0)
