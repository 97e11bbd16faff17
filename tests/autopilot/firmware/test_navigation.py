"""The firmware navigation numbers: ArduPlane's and PX4's documented defaults, the L1/turn
formulas, the airframe laid over them, the generic merge."""

from __future__ import annotations

import math

import pytest

from fm2uav.autopilot.firmware import ARDUPILOT, GENERIC, PX4
from fm2uav.autopilot.firmware.ardupilot import PLANE_NAV
from fm2uav.autopilot.firmware.navigation import AirframeNav, FixedWingNav, merge_nav
from fm2uav.autopilot.firmware.px4 import FW_NAV
from fm2uav.errors import InputError


def test_arduplane_defaults_are_the_parameter_pages():
    # ArduPlane/config.h, Parameters.cpp, AP_L1_Control, AP_TECS defaults
    n = PLANE_NAV
    assert (n.acceptance_radius, n.loiter_radius, n.bank_limit_deg) == (90.0, 60.0, 45.0)
    assert (n.guidance_period, n.guidance_damping) == (17.0, 0.75)
    assert (n.climb_rate, n.sink_rate) == (5.0, 5.0)
    assert (n.airspeed_min, n.airspeed_cruise, n.airspeed_max) == (9.0, 12.0, 22.0)
    assert n.param("acceptance_radius") == "WP_RADIUS" and n.param("climb_rate") == "TECS_CLMB_MAX"
    assert ARDUPILOT.fixed_wing_nav is PLANE_NAV and PX4.fixed_wing_nav is FW_NAV
    assert (FW_NAV.acceptance_radius, FW_NAV.loiter_radius, FW_NAV.landing_slope_max_deg) == \
        (10.0, 80.0, 5.0)


def test_turn_radius_l1_distance_and_turn_distance_formulas():
    n = PLANE_NAV.with_airframe(cruise=22.0)
    assert n.turn_radius() == pytest.approx(22.0**2 / (9.80665 * math.tan(math.radians(45))))
    assert n.l1_distance() == pytest.approx(0.75 * 17 * 22 / math.pi)  # 89.3 m
    # AP_L1_Control::turn_distance: min(WP_RADIUS, L1) x angle / 90, full beyond 90 deg
    assert n.turn_distance(90) == pytest.approx(min(90.0, n.l1_distance()))
    assert n.turn_distance(45) == pytest.approx(min(90.0, n.l1_distance()) / 2)
    assert n.turn_distance(170) == n.turn_distance(90)
    assert n.turn_distance(30, radius=12.0) == 12.0  # param2 overrides
    slow = PLANE_NAV.with_airframe(cruise=12.0)
    assert slow.turn_distance(90) == pytest.approx(slow.l1_distance())  # L1 < WP_RADIUS
    # PX4: the larger of NAV_ACC_RAD and the guidance's switch distance, whatever the turn
    assert FW_NAV.turn_distance(10) == FW_NAV.turn_distance(90) == max(10.0, FW_NAV.l1_distance())
    r = n.turn_radius()
    assert n.turn_on_distance(90) == pytest.approx(r)
    assert n.turn_on_distance(60) == pytest.approx(r * math.tan(math.radians(30)))
    assert n.turn_on_distance(180) == pytest.approx(2 * r)
    assert n.climb_distance(100.0) == pytest.approx(100 * 22 / 5)
    assert n.max_glide_deg() == pytest.approx(math.degrees(math.asin(5 / 22)))
    assert FW_NAV.max_glide_deg(15.0) == 5.0  # FW_LND_ANG below the sink limit


def test_the_airframe_is_laid_over_the_defaults():
    n = PLANE_NAV.for_airframe(AirframeNav(cruise=25.0, bank_deg=30.0, climb_rate=3.0))
    assert (n.airspeed_min, n.airspeed_cruise, n.airspeed_max) == (9.0, 25.0, 25.0)
    assert (n.bank_limit_deg, n.climb_rate, n.sink_rate) == (30.0, 3.0, 5.0)
    assert PLANE_NAV.for_airframe(None) is PLANE_NAV
    with pytest.raises(InputError, match="AIRSPEED_MIN 15.*AIRSPEED_CRUISE 12"):
        PLANE_NAV.with_airframe(minimum=15.0)
    with pytest.raises(InputError, match="ROLL_LIMIT_DEG must be in"):
        PLANE_NAV.with_airframe(bank_deg=89.0)


def test_generic_flies_what_both_firmwares_fly():
    g = GENERIC.fixed_wing_nav
    assert g == merge_nav((FW_NAV, PLANE_NAV))
    assert g.acceptance_radius == 90.0 and g.loiter_radius == 80.0 and g.bank_limit_deg == 45.0
    assert (g.airspeed_min, g.airspeed_max) == (10.0, 20.0) and g.landing_slope_max_deg == 5.0
    assert g.turn_distance_rule == "switch"
    assert merge_nav(()) is None and merge_nav((PLANE_NAV,)) is PLANE_NAV
    assert isinstance(g, FixedWingNav)
    # DO_CHANGE_SPEED: both take airspeed on a plane, ground speed on a multirotor
    assert GENERIC.change_speed["fixed_wing"].speed_type == 0
    assert GENERIC.change_speed["fixed_wing"].ignored_outside
    assert GENERIC.change_speed["multirotor"].accepted == (1,)
    assert ARDUPILOT.change_speed["multirotor"].accepted == (0, 1)
