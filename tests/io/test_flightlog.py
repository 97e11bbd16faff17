"""Flight logs read with pymavlink and pyulog: the power samples of a .tlog, a .bin, a .ulg."""

from __future__ import annotations

import numpy as np
import pytest

from fm2uav.errors import InputError
from fm2uav.io.flightlog import read_power_samples

from .synthetic_logs import write_bin, write_tlog, write_ulg


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
    with pytest.raises(InputError, match="not a ULog file pyulog can read"):
        read_power_samples(tmp_path / "x.ulg")
    (tmp_path / "x.px4log").write_bytes(b"")
    with pytest.raises(InputError, match=r"unknown kind '.px4log'.*PX4 log \(.ulg\)"):
        read_power_samples(tmp_path / "x.px4log")
    (tmp_path / "empty.tlog").write_bytes(b"")
    with pytest.raises(InputError, match="no battery current"):
        read_power_samples(tmp_path / "empty.tlog")


def test_ulg_power_is_volts_times_amps_while_armed(tmp_path):
    t = np.arange(0.0, 20.0, 0.5)
    p = 200.0 + t
    air, gs, climb = 14.0 + 0 * t, 11.0 + 0 * t, 0.5 + 0 * t
    s = read_power_samples(write_ulg(tmp_path / "a.ulg", t, p, air, climb, groundspeed=gs,
                                     armed_from=5.0))
    assert len(s) == len(t)
    assert s.source == ("a.ulg: battery_status voltage_v x current_a, "
                        "airspeed_validated.true_airspeed_m_s, vehicle_local_position")
    armed = t >= 5.0
    assert np.all(np.isnan(s.power[~armed]))
    np.testing.assert_allclose(s.power[armed], p[armed], rtol=1e-6)   # float32 volts, amps
    np.testing.assert_allclose(s.t, t - t[0], atol=1e-9)
    # the last battery sample is after the last position and airspeed samples
    np.testing.assert_allclose(s.airspeed[:-1], 14.0)
    np.testing.assert_allclose(s.groundspeed[:-1], 11.0)
    np.testing.assert_allclose(s.climb[:-1], 0.5)                    # climb = -vz (NED)
    assert np.isnan(s.climb[-1])


def test_ulg_without_airspeed_or_arming_uses_the_ground_speed(tmp_path):
    t = np.arange(0.0, 10.0, 0.5)
    cur = np.where(t < 2.0, -1.0, 6.0)                       # PX4: -1 = current unknown
    s = read_power_samples(write_ulg(tmp_path / "b.ulg", t, 0 * t, 9.0 + 0 * t, -1.0 + 0 * t,
                                     airspeed_topic=False, current=cur, volts=20.0))
    assert "ground speed as airspeed" in s.source
    assert len(s) == int((t >= 2.0).sum())                   # unknown currents dropped
    np.testing.assert_allclose(s.power, 120.0, rtol=1e-6)
    np.testing.assert_allclose(s.airspeed[:-1], 9.0)
    np.testing.assert_allclose(s.climb[:-1], -1.0)
    never = write_ulg(tmp_path / "c.ulg", t, 0 * t, 9.0 + 0 * t, 0 * t, current=-1 + 0 * t)
    with pytest.raises(InputError, match="never measures the current"):
        read_power_samples(never)
