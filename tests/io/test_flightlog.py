"""Flight logs read with pymavlink: the power samples of a .tlog and a .bin."""

from __future__ import annotations

import numpy as np
import pytest

from fm2uav.errors import InputError
from fm2uav.io.flightlog import read_power_samples

from .synthetic_logs import write_bin, write_tlog


def test_tlog_power_is_volts_times_amps_while_armed(tmp_path):
    t = np.arange(0.0, 20.0, 0.5)
    p = 200.0 + t
    air, climb = 5.0 + 0 * t, 0.5 + 0 * t
    s = read_power_samples(write_tlog(tmp_path / "a.tlog", t, p, air, climb, armed_from=5.0))
    assert len(s) == len(t) and "SYS_STATUS" in s.source
    armed = t >= 5.0
    assert np.all(np.isnan(s.power[~armed]))
    # mV x cA quantisation: 14.8 V x 0.01 A
    np.testing.assert_allclose(s.power[armed], p[armed], atol=0.08)
    np.testing.assert_allclose(s.airspeed[:-1], 5.0)  # the last after the last VFR_HUD
    np.testing.assert_allclose(s.climb[:-1], 0.5)


def test_bin_climb_is_minus_the_gps_down_velocity(tmp_path):
    t = np.arange(0.0, 10.0, 0.5)
    s = read_power_samples(write_bin(tmp_path / "a.bin", t, 100 + 0 * t, 15 + 0 * t,
                                     2.0 + 0 * t))
    assert "BAT" in s.source and "ARSP" in s.source
    np.testing.assert_allclose(s.power, 100.0, rtol=1e-6)
    np.testing.assert_allclose(s.climb[:-1], 2.0)  # the last BAT is after the last GPS
    assert np.isnan(s.climb[-1])


def test_logs_that_cannot_calibrate_are_refused(tmp_path):
    with pytest.raises(InputError, match="not found"):
        read_power_samples(tmp_path / "none.tlog")
    (tmp_path / "x.ulg").write_bytes(b"ULog")
    with pytest.raises(InputError, match="unknown kind '.ulg'"):
        read_power_samples(tmp_path / "x.ulg")
    (tmp_path / "empty.tlog").write_bytes(b"")
    with pytest.raises(InputError, match="no battery current"):
        read_power_samples(tmp_path / "empty.tlog")
