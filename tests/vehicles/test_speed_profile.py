"""Admissible speed from W and the turn limit (vehicles/speed_profile.py): exact checks."""

from __future__ import annotations

import math

import numpy as np
import pytest

from fm2uav.errors import InputError
from fm2uav.vehicles import admissible_speed_from_w, get_airframe, speed_profile, turn_speed_limit
from fm2uav.vehicles.airframes import G

from .test_geometric import _circle


def test_speed_from_w_and_turn_limit():
    af = get_airframe("disco")
    np.testing.assert_allclose(admissible_speed_from_w([0, 0.5, 1], af), [12.0, 14.5, 17.0])
    np.testing.assert_allclose(admissible_speed_from_w([0, 1], "arducopter"), [0.0, 10.0])
    # flying the curvature 1/R_min is allowed exactly at cruise speed
    assert turn_speed_limit([1 / af.turn_radius()], af)[0] == pytest.approx(af.cruise_speed)
    assert np.isinf(turn_speed_limit([0.0], af)[0])
    with pytest.raises(InputError):
        admissible_speed_from_w([0.5, 1.5], af)
    with pytest.raises(InputError):
        admissible_speed_from_w([np.nan], af)


def test_speed_profile_flags_over_speed_in_tight_turn():
    af = get_airframe("disco")
    R = af.turn_radius()
    path = _circle(0.5 * R)
    prof = speed_profile(path, af, w=np.ones(len(path)))
    assert prof.over, "cruise exceeds the admissible speed on a circle tighter than R"
    assert prof.v_admissible.min() == pytest.approx(math.sqrt(G * math.tan(af.max_bank) * 0.5 * R), rel=2e-2)
    straight = np.column_stack([np.linspace(0, 50, 11), np.zeros(11)])
    p2 = speed_profile(straight, af, w=np.full(11, 0.5))
    np.testing.assert_allclose(p2.v_admissible, 14.5)
    assert not p2.over
    with pytest.raises(InputError):
        speed_profile(straight, af, w=np.ones(3))
