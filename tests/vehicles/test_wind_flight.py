"""A path flown in a wind: the wind triangle's times, the crab, the turn-rate limit."""

from __future__ import annotations

import math

import numpy as np
import pytest

from fm2uav.errors import InputError
from fm2uav.vehicles.wind_flight import fly_in_wind
from fm2uav.world.wind import WindField

LINE = np.column_stack([np.linspace(0, 2000, 81), np.zeros(81)])


@pytest.mark.parametrize("frm, ground", [(0.0, math.sqrt(144 - 25)),   # crosswind from north
                                         (90.0, 7.0), (270.0, 17.0)])   # head, tail
def test_straight_line_time_is_the_wind_triangle(frm, ground):
    f = fly_in_wind(LINE, 12.0, WindField.constant(5.0, frm), dt=0.05)
    assert f.reached and f.max_separation < 1.0
    assert f.time_s == pytest.approx(2000.0 / ground, rel=0.01)


def test_a_turn_rate_limit_overshoots_a_corner():
    corner = np.vstack([LINE[:41], np.column_stack([np.full(40, 1000.0),
                                                    np.linspace(25, 1000, 40)])])
    calm = WindField.constant(0.0, 0.0)
    quick = fly_in_wind(corner, 15.0, calm, max_turn_rate_deg=90.0)
    slow = fly_in_wind(corner, 15.0, calm, max_turn_rate_deg=5.0)
    assert quick.reached and slow.reached
    assert slow.max_separation > 3 * quick.max_separation


def test_bad_inputs():
    with pytest.raises(InputError, match="path must be"):
        fly_in_wind([[0, 0]], 10.0, WindField.constant(0, 0))
    with pytest.raises(InputError, match="airspeeds"):
        fly_in_wind(LINE, 0.0, WindField.constant(0, 0))
