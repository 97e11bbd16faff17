"""Airframes, geometric profiles and admissible speed: exact and analytic checks."""

from __future__ import annotations

import math

import numpy as np
import pytest

from fm2uav.errors import InputError
from fm2uav.vehicles import (
    AIRFRAMES,
    FixedWing,
    Multirotor,
    admissible_speed_from_w,
    climb_angle_profile,
    curvature_profile,
    geometric_check,
    get_airframe,
    speed_profile,
    turn_speed_limit,
)
from fm2uav.vehicles.airframes import G


def _circle(r: float, turns: float = 0.75, n: int = 600, z_slope: float = 0.0) -> np.ndarray:
    th = np.linspace(0.0, 2 * np.pi * turns, n)
    return np.column_stack([r * np.cos(th), r * np.sin(th), z_slope * r * th])


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
