"""Airframes (vehicles/airframes.py): turn radius and rate, presets, validation."""

from __future__ import annotations

import math

import pytest

from fm2uav.errors import InputError
from fm2uav.vehicles import AIRFRAMES, FixedWing, Multirotor, get_airframe
from fm2uav.vehicles.airframes import G


def test_turn_radius_and_rate_formulas():
    af = FixedWing("t", 20.0, 10.0, 30.0, math.radians(45), math.radians(20), math.radians(20))
    assert af.turn_radius() == pytest.approx(400.0 / G)
    assert af.max_turn_rate() == pytest.approx(G / 20.0)
    assert af.turn_radius(10.0) == pytest.approx(100.0 / G)
    # R * rate = V
    assert af.turn_radius() * af.max_turn_rate() == pytest.approx(20.0)
    mr = Multirotor("m", 10.0, 2.5, 2.0, 1.0)
    assert mr.turn_radius() == pytest.approx(40.0)


def test_presets_documented_numbers():
    d = get_airframe("disco")
    assert (d.cruise_speed, d.min_speed, d.max_speed) == (14.0, 12.0, 17.0)
    assert math.degrees(d.max_bank) == pytest.approx(55.0)
    assert d.turn_radius() == pytest.approx(14.0**2 / (G * math.tan(math.radians(55))))
    assert get_airframe("ArduCopter").max_accel == 2.5
    assert all(a.source for a in AIRFRAMES.values())
    assert get_airframe(d) is d


@pytest.mark.parametrize(
    "kwargs",
    [
        dict(cruise_speed=-1.0),
        dict(cruise_speed=float("nan")),
        dict(min_speed=0.0),
        dict(max_bank=math.radians(95)),
        dict(cruise_speed=40.0),  # above max
    ],
)
def test_fixed_wing_rejects_bad_numbers(kwargs):
    base = dict(name="x", cruise_speed=14.0, min_speed=12.0, max_speed=17.0,
                max_bank=0.9, max_climb=0.3, max_descent=0.3)
    base.update(kwargs)
    with pytest.raises(InputError):
        FixedWing(**base)


def test_unknown_airframe_lists_presets():
    with pytest.raises(InputError, match="disco"):
        get_airframe("concorde")
