"""The power fit recovers the coefficients of the model a synthetic log was made from."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from fm2uav.errors import InputError
from fm2uav.io.flightlog import read_power_samples
from fm2uav.vehicles.calibration import PowerSamples, fit_power
from fm2uav.vehicles.power import POWER_MODELS

from ..io.synthetic_logs import flight_states, write_bin, write_tlog, write_ulg

QUAD = POWER_MODELS["arducopter"]
DISCO = POWER_MODELS["disco"]


def test_a_quad_tlog_is_fitted_back_to_its_coefficients(tmp_path):
    t, air, climb = flight_states("multirotor")
    p = QUAD.power(air, climb) + np.random.default_rng(1).normal(0.0, 1.0, len(t))
    log = write_tlog(tmp_path / "quad.tlog", t, p, air, climb)
    start = replace(QUAD, induced_factor=1.4, profile_power_w=20.0, drag_area_m2=0.08,
                    efficiency=0.6, descent_recovery=0.3)
    cal = fit_power(start, read_power_samples(log))
    np.testing.assert_allclose(cal.model.coefficients(), QUAD.coefficients(), rtol=0.02)
    assert cal.model.efficiency == pytest.approx(QUAD.efficiency, rel=0.01)
    assert cal.model.drag_area_m2 == pytest.approx(QUAD.drag_area_m2, rel=0.02)
    assert cal.rms_w < 1.3 and cal.r2 > 0.99
    assert "avionics_w" not in cal.free and cal.model.avionics_w == QUAD.avionics_w
    assert cal.summary()["samples"] == cal.samples > 1000


def test_a_plane_bin_is_fitted_back_exactly(tmp_path):
    t, air, climb = flight_states("fixed-wing")
    log = write_bin(tmp_path / "disco.bin", t, DISCO.power(air, climb), air, climb)
    start = replace(DISCO, cd0=0.05, k=0.05, efficiency=0.7, descent_recovery=0.5)
    cal = fit_power(start, read_power_samples(log))
    np.testing.assert_allclose(cal.model.coefficients(), DISCO.coefficients(), rtol=1e-3)
    assert (cal.model.cd0, cal.model.k) == pytest.approx((DISCO.cd0, DISCO.k), rel=1e-3)


def test_a_px4_plane_ulg_is_fitted_back_exactly(tmp_path):
    t, air, climb = flight_states("fixed-wing", seed=3)
    log = write_ulg(tmp_path / "disco.ulg", t, DISCO.power(air, climb), air, climb,
                    groundspeed=air + 2.0, armed_from=0.0)
    start = replace(DISCO, cd0=0.05, k=0.05, efficiency=0.7, descent_recovery=0.5)
    cal = fit_power(start, read_power_samples(log))
    np.testing.assert_allclose(cal.model.coefficients(), DISCO.coefficients(), rtol=1e-3)
    assert cal.samples > 1000 and cal.r2 > 0.999


def test_what_the_log_does_not_excite_is_held():
    t, air, _ = flight_states("multirotor")
    level = np.zeros_like(t)
    s = PowerSamples(t, QUAD.power(air, level), air, level, air)
    start = replace(QUAD, efficiency=0.6)
    cal = fit_power(start, s, fit=["induced_factor/efficiency", "drag_area_m2/efficiency",
                                   "profile_power_w/efficiency", "1/efficiency (climb)"])
    assert "1/efficiency (climb)" not in cal.free        # no climb in the log
    assert cal.coefficients["1/efficiency (climb)"] == pytest.approx(1 / 0.6)
    assert cal.r2 > 0.999


def test_refusals_name_the_problem():
    t, air, climb = flight_states("multirotor")
    s = PowerSamples(t[:5], QUAD.power(air[:5], climb[:5]), air[:5], climb[:5], air[:5])
    with pytest.raises(InputError, match="5 usable power samples"):
        fit_power(QUAD, s)
    with pytest.raises(InputError, match="unknown coefficient"):
        fit_power(QUAD, s, fit=["cd0/efficiency"])
    with pytest.raises(InputError, match="power has 2 values for 3 times"):
        PowerSamples(np.arange(3.0), np.ones(2), np.ones(3), np.ones(3), np.ones(3))
