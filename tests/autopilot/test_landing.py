"""The fixed-wing landing pattern from the firmware's numbers: a loiter it flies, a glide the
sink limit holds, an approach at least two L1 distances long, DO_LAND_START first."""

from __future__ import annotations

import math

import numpy as np
import pytest

from fm2uav.autopilot import ExportOptions
from fm2uav.autopilot.firmware.ardupilot import PLANE_NAV
from fm2uav.autopilot.firmware.flight_rules import local_xy
from fm2uav.autopilot.landing import loiter_radius
from fm2uav.io import export_mission

from .mission_cases import ANCHOR, hill_tff


def test_loiter_radius_is_at_least_the_flyable_one():
    nav = PLANE_NAV.with_airframe(cruise=22.0)
    assert loiter_radius(10.0, nav) == math.ceil(1.2 * nav.turn_radius())
    assert loiter_radius(200.0, nav) == 200.0
    assert loiter_radius(10.0, None) == 10.0


@pytest.mark.parametrize("cruise", [12.0, 22.0])
def test_the_landing_pattern_fits_the_aircraft(cruise):
    opt = ExportOptions(anchor=ANCHOR, firmware="ardupilot", vehicle="fixed_wing", end="land",
                        cruise_speed=cruise, land_slope_deg=5.0, loiter_radius=20.0)
    m, _ = export_mission(hill_tff(), ["plan"], opt)
    k = next(i for i, it in enumerate(m.items) if it.command == 189)
    loiter, land = m.items[k + 1], m.items[k + 2]
    assert (loiter.command, land.command) == (31, 21) and land is m.items[-1]
    nav = PLANE_NAV.with_airframe(cruise=cruise)
    r = loiter.params[1]
    assert r >= 1.2 * nav.turn_radius() - 1e-6
    xy = local_xy([loiter, land], loiter.lat, loiter.lon)
    run = math.sqrt(float(np.hypot(*xy[1])) ** 2 - r * r)
    assert run >= 2 * nav.l1_distance() - 1.0
    slope = math.degrees(math.atan2(loiter.alt_amsl - land.alt_amsl, run))
    assert slope <= min(5.0, nav.max_glide_deg()) + 0.1
    assert m.info["landing"]["glide_slope_deg"] == pytest.approx(slope, abs=0.2)
