"""Power models: momentum theory and the drag polar against their closed forms."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from fm2uav.errors import InputError
from fm2uav.vehicles.airframes import AIRFRAMES, G, FixedWing, Multirotor
from fm2uav.vehicles.power import (POWER_MODELS, FixedWingPower, MultirotorPower,
                                   get_power_model, induced_velocity, isa_density)

QUAD = POWER_MODELS["arducopter"]
DISCO = POWER_MODELS["disco"]


def test_induced_velocity_solves_the_momentum_equation():
    v, vz = np.meshgrid(np.linspace(0, 20, 21), np.linspace(-3, 5, 17))
    vi = induced_velocity(v, vz, 6.3)
    assert np.all(vi > 0)
    np.testing.assert_allclose(vi * np.sqrt(v ** 2 + (vz + vi) ** 2), 6.3 ** 2, rtol=1e-12)
    # axial climb: v_i = -Vz/2 + sqrt(Vz²/4 + v_h²)
    np.testing.assert_allclose(induced_velocity(0.0, 2.5, 6.3),
                               -1.25 + math.sqrt(1.25 ** 2 + 6.3 ** 2), rtol=1e-12)


def test_induced_velocity_is_the_same_bits_one_state_at_a_time_or_many():
    """A few states are bisected with Python floats, more in a compiled loop: each state's
    result is the same to the last bit either way (and in any batch it comes in)."""
    rng = np.random.default_rng(4)
    v, vz = rng.uniform(0.0, 25.0, 300), rng.uniform(-8.0, 8.0, 300)
    v[:40] = 0.0  # hover and axial climbs/descents
    many = induced_velocity(v, vz, 6.3)
    one = np.array([float(induced_velocity(a, c, 6.3)[()]) for a, c in zip(v, vz)])
    pairs = np.concatenate([induced_velocity(v[k:k + 2], vz[k:k + 2], 6.3)
                            for k in range(0, 300, 2)])
    assert np.array_equal(many, one) and np.array_equal(many, pairs)
    assert induced_velocity(v[:3], vz[:3], 6.3).shape == (3,)
    assert induced_velocity(np.zeros((2, 3)), 1.0, 6.3).shape == (2, 3)
    assert induced_velocity(0.0, 0.0, 6.3).shape == ()


def test_multirotor_hover_power_is_momentum_theory_by_hand():
    t = QUAD.mass_kg * G
    vh = math.sqrt(t / (2 * QUAD.air_density * QUAD.disk_area_m2))
    e = QUAD.efficiency
    want = QUAD.induced_factor * t * vh / e + QUAD.profile_power_w / e + QUAD.avionics_w
    assert QUAD.hover_power() == pytest.approx(want, rel=1e-12)
    assert 100 <= QUAD.hover_power() / QUAD.mass_kg <= 150  # W/kg of survey quads


def test_multirotor_power_curve_is_a_bucket_and_climbing_costs():
    v = np.linspace(0, QUAD.max_airspeed(), 200)
    p = QUAD.power(v, 0.0)
    k = int(np.argmin(p))
    assert 0 < k < len(v) - 1            # least power at a moderate speed, not in hover
    assert p[k] < 0.9 * p[0] and p[-1] > p[k]
    assert QUAD.power(0.0, 2.5) > QUAD.hover_power() > QUAD.power(0.0, -1.5)
    # parasite term: ½ ρ CdA V³ / η exactly between two speeds, the rest unchanged
    no_drag = replace(QUAD, drag_area_m2=0.0)
    diff = QUAD.power(12.0, 0.0) - no_drag.power(12.0, 0.0)
    assert diff == pytest.approx(0.5 * QUAD.air_density * QUAD.drag_area_m2 * 12 ** 3
                                 / QUAD.efficiency, rel=1e-12)


def test_multirotor_max_airspeed_balances_drag_with_the_tilt():
    v = QUAD.max_airspeed()
    drag = 0.5 * QUAD.air_density * QUAD.drag_area_m2 * v * v
    assert drag == pytest.approx(QUAD.mass_kg * G * math.tan(math.radians(30)), rel=1e-12)


def test_fixed_wing_least_power_speed_is_the_drag_polar_optimum():
    f = replace(DISCO, avionics_w=0.0)
    cl = math.sqrt(3 * f.cd0 / f.k)
    v_star = math.sqrt(2 * f.weight_n / (f.air_density * f.wing_area_m2 * cl))
    assert f.stall_free_min_power_speed() == pytest.approx(v_star, rel=1e-12)
    assert f.minimum_power_speed(3.0, 30.0) == pytest.approx(v_star, abs=0.02)
    # best range (least energy per metre): CL = sqrt(CD0 / k)
    v_range = math.sqrt(2 * f.weight_n / (f.air_density * f.wing_area_m2
                                          * math.sqrt(f.cd0 / f.k)))
    assert f.best_range_speed(3.0, 30.0) == pytest.approx(v_range, abs=0.02)


def test_fixed_wing_level_power_and_climb_by_hand():
    v = 14.0
    q = 0.5 * DISCO.air_density * v * v
    cl = DISCO.weight_n / (q * DISCO.wing_area_m2)
    drag = q * DISCO.wing_area_m2 * (DISCO.cd0 + DISCO.k * cl * cl)
    assert DISCO.power(v, 0.0) == pytest.approx(drag * v / DISCO.efficiency
                                                + DISCO.avionics_w, rel=1e-12)
    assert DISCO.power(v, 2.0) - DISCO.power(v, 0.0) == pytest.approx(
        DISCO.weight_n * 2.0 / DISCO.efficiency, rel=1e-12)
    # a steep glide: the motor gives nothing back, the avionics still draw
    assert DISCO.power(v, -10.0) == pytest.approx(DISCO.avionics_w)
    with pytest.raises(InputError, match="airspeeds > 0"):
        DISCO.power(0.0, 0.0)


@pytest.mark.parametrize("model", list(POWER_MODELS.values()), ids=list(POWER_MODELS))
def test_coefficients_round_trip(model):
    back = model.with_coefficients(model.coefficients())
    np.testing.assert_allclose(back.coefficients(), model.coefficients(), rtol=1e-12)


def test_every_electric_preset_has_a_model_of_its_kind():
    for name, af in AIRFRAMES.items():
        if name == "plane-jet":
            with pytest.raises(InputError, match="no power model for airframe 'plane-jet'"):
                get_power_model(name)
            continue
        m = get_power_model(name)
        assert isinstance(m, MultirotorPower) == isinstance(af, Multirotor)
        assert isinstance(m, FixedWingPower) == isinstance(af, FixedWing)
        assert m.source
        if isinstance(af, FixedWing):   # cruise endurance on 80 % of the pack: 20-90 min
            minutes = 0.8 * m.battery_wh / float(m.power(af.cruise_speed, 0.0)) * 60
            assert 20 < minutes < 90, (name, minutes)
    assert get_power_model(QUAD) is QUAD


def test_bad_parameters_say_which():
    with pytest.raises(InputError, match="efficiency must be finite and > 0 and <= 1"):
        replace(QUAD, efficiency=1.2)
    with pytest.raises(InputError, match="mass_kg must be a number"):
        replace(DISCO, mass_kg="heavy")
    with pytest.raises(InputError, match="climb coefficient"):
        QUAD.with_coefficients([1.5, 40, 0.05, 0.5, 0.5, 10])


def test_isa_density():
    assert isa_density(0.0) == pytest.approx(1.225)
    assert isa_density(2000.0) == pytest.approx(1.0066, abs=1e-3)
    with pytest.raises(InputError):
        isa_density(20000.0)
