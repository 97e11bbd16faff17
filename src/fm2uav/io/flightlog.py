"""Flight logs read with pymavlink and pyulog: the power and the flight state for the power fit.

* **Telemetry logs** (``.tlog``, what a ground station records: each MAVLink message
  after an 8-byte timestamp): the power is ``SYS_STATUS.voltage_battery`` [mV] ×
  ``current_battery`` [cA] (``BATTERY_STATUS`` — the sum of its cell voltages —
  where ``SYS_STATUS`` has no current), the airspeed, ground speed and climb rate are
  ``VFR_HUD``'s; samples while the vehicle's ``HEARTBEAT`` says disarmed are dropped.
* **DataFlash logs** (``.bin``, written on board by ArduPilot): ``BAT`` (``CURR`` in
  older firmware) ``Volt`` × ``Curr``, the airspeed from ``ARSP.Airspeed`` (the ground
  speed where there is none), ground speed ``GPS.Spd`` and climb ``−GPS.VZ`` (GPS
  velocities are north-east-down).
* **PX4 logs** (``.ulg``, ULog written on board by PX4, read with pyulog): the power is
  ``battery_status`` ``voltage_v`` × ``current_a`` (samples with PX4's −1 "unknown
  current" dropped); the true airspeed is ``airspeed_validated.true_airspeed_m_s``
  (``airspeed.true_airspeed_m_s`` in logs without it, the ground speed where there is
  neither); ground speed ``hypot(vx, vy)`` and climb ``−vz`` of ``vehicle_local_position``
  (north-east-down); samples while ``vehicle_status.arming_state`` is not armed (2) are
  dropped. The first instance of each topic is read (``multi_id`` 0).

The speeds and climb are interpolated to the power samples' times (never beyond the
times they cover). Reading computes nothing else; the fit is
:func:`fm2uav.vehicles.calibration.fit_power`. :func:`write_power_tlog` writes such
samples as a telemetry log (what a ground station would have recorded), for tests and
examples.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from ..errors import InputError
from ..vehicles.calibration import PowerSamples

__all__ = ["read_power_samples", "write_power_tlog"]

_ARMED = 128  # MAV_MODE_FLAG_SAFETY_ARMED
_GCS = 6  # MAV_TYPE_GCS


def _messages(path: Path, types: list[str]) -> dict[str, list[Any]]:
    from pymavlink import mavutil

    try:
        conn = mavutil.mavlink_connection(str(path), dialect="ardupilotmega",
                                          robust_parsing=True)
    except Exception as exc:  # pymavlink raises many kinds on a foreign file
        raise InputError(f"{path}: not a MAVLink log pymavlink can read ({exc})") from None
    out: dict[str, list[Any]] = {t: [] for t in types}
    try:
        while True:
            m = conn.recv_match(type=types, blocking=False)
            if m is None:
                break
            if m.get_type() in out:
                out[m.get_type()].append(m)
    finally:
        conn.close()
    return out


def _interp(t: np.ndarray, ts: np.ndarray, vs: np.ndarray) -> np.ndarray:
    if len(ts) == 0:
        return np.full(len(t), np.nan)
    order = np.argsort(ts, kind="stable")
    ts, vs = ts[order], vs[order]
    v = np.interp(t, ts, vs)
    return np.where((t >= ts[0]) & (t <= ts[-1]), v, np.nan)


def _tlog(path: Path) -> PowerSamples:
    msgs = _messages(path, ["SYS_STATUS", "BATTERY_STATUS", "VFR_HUD", "HEARTBEAT"])
    sys_ = [m for m in msgs["SYS_STATUS"] if m.current_battery >= 0 and m.voltage_battery > 0]
    if sys_:
        tp = np.array([m._timestamp for m in sys_])
        power = np.array([m.voltage_battery * 1e-3 * m.current_battery * 1e-2 for m in sys_])
        which = "SYS_STATUS"
    else:
        bat = [m for m in msgs["BATTERY_STATUS"] if m.current_battery >= 0]
        cells = [sum(v for v in m.voltages if v != 65535) for m in bat]
        tp = np.array([m._timestamp for m, c in zip(bat, cells) if c > 0])
        power = np.array([c * 1e-3 * m.current_battery * 1e-2 for m, c in zip(bat, cells)
                          if c > 0])
        which = "BATTERY_STATUS"
    hud = msgs["VFR_HUD"]
    if not len(tp) or not hud:
        raise InputError(f"{path}: the telemetry log has no battery current (SYS_STATUS / "
                         "BATTERY_STATUS) or no VFR_HUD: it cannot calibrate a power model")
    th = np.array([m._timestamp for m in hud])
    air = _interp(tp, th, np.array([m.airspeed for m in hud], float))
    gs = _interp(tp, th, np.array([m.groundspeed for m in hud], float))
    climb = _interp(tp, th, np.array([m.climb for m in hud], float))
    beats = [m for m in msgs["HEARTBEAT"] if m.type != _GCS]
    if beats:
        tb = np.array([m._timestamp for m in beats])
        armed = np.array([bool(m.base_mode & _ARMED) for m in beats])
        k = np.searchsorted(tb, tp, side="right") - 1
        power = np.where((k >= 0) & armed[np.maximum(k, 0)], power, np.nan)
    return PowerSamples(tp - tp[0], power, air, climb, gs,
                        source=f"{path.name}: {which} x VFR_HUD")


def _bin(path: Path) -> PowerSamples:
    msgs = _messages(path, ["BAT", "CURR", "ARSP", "GPS"])
    bat = msgs["BAT"] or msgs["CURR"]
    bat = [m for m in bat if getattr(m, "Instance", 0) == 0]
    gps = [m for m in msgs["GPS"] if getattr(m, "I", 0) == 0]
    if not bat or not gps:
        raise InputError(f"{path}: the DataFlash log has no BAT/CURR or no GPS messages: it "
                         "cannot calibrate a power model")
    tp = np.array([m.TimeUS * 1e-6 for m in bat])
    power = np.array([m.Volt * m.Curr for m in bat], float)
    tg = np.array([m.TimeUS * 1e-6 for m in gps])
    gs = _interp(tp, tg, np.array([m.Spd for m in gps], float))
    climb = _interp(tp, tg, -np.array([m.VZ for m in gps], float))
    arsp = [m for m in msgs["ARSP"] if getattr(m, "I", 0) == 0]
    if arsp:
        air = _interp(tp, np.array([m.TimeUS * 1e-6 for m in arsp]),
                      np.array([m.Airspeed for m in arsp], float))
        which = "ARSP"
    else:
        air, which = gs, "GPS.Spd as airspeed"
    return PowerSamples(tp - tp[0], power, air, climb, gs,
                        source=f"{path.name}: {'BAT' if msgs['BAT'] else 'CURR'} x {which}, GPS")


_ULOG_TOPICS = ["battery_status", "vehicle_local_position", "airspeed_validated", "airspeed",
                "vehicle_status"]
_PX4_ARMED = 2  # vehicle_status.ARMING_STATE_ARMED


def _ulg(path: Path) -> PowerSamples:
    try:
        from pyulog import ULog
    except ImportError:  # pragma: no cover - a dependency of fm2uav
        raise InputError(f"{path}: reading a PX4 .ulg log needs the pyulog package "
                         "(pip install pyulog)") from None
    try:
        log = ULog(str(path), _ULOG_TOPICS)
    except Exception as exc:  # pyulog raises many kinds on a foreign or truncated file
        raise InputError(f"{path}: not a ULog file pyulog can read ({exc})") from None

    def topic(name: str, *fields: str) -> dict[str, np.ndarray] | None:
        for d in log.data_list:
            if d.name == name and d.multi_id == 0 and all(f in d.data for f in fields):
                return d.data
        return None

    bat = topic("battery_status", "timestamp", "voltage_v", "current_a")
    pos = topic("vehicle_local_position", "timestamp", "vx", "vy", "vz")
    if bat is None or pos is None:
        raise InputError(f"{path}: the PX4 log has no battery_status (voltage_v, current_a) or "
                         "no vehicle_local_position (vx, vy, vz): it cannot calibrate a power "
                         "model")
    volts = np.asarray(bat["voltage_v"], float)
    amps = np.asarray(bat["current_a"], float)
    good = (volts > 0) & (amps >= 0)
    tp = np.asarray(bat["timestamp"], float)[good] * 1e-6
    power = volts[good] * amps[good]
    if not len(tp):
        raise InputError(f"{path}: battery_status never measures the current (current_a is "
                         "-1, unknown, throughout): it cannot calibrate a power model")
    tl = np.asarray(pos["timestamp"], float) * 1e-6
    gs = _interp(tp, tl, np.hypot(np.asarray(pos["vx"], float), np.asarray(pos["vy"], float)))
    climb = _interp(tp, tl, -np.asarray(pos["vz"], float))
    which = "ground speed as airspeed"
    air = gs
    for name in ("airspeed_validated", "airspeed"):
        a = topic(name, "timestamp", "true_airspeed_m_s")
        if a is not None:
            air = _interp(tp, np.asarray(a["timestamp"], float) * 1e-6,
                          np.asarray(a["true_airspeed_m_s"], float))
            which = f"{name}.true_airspeed_m_s"
            break
    st = topic("vehicle_status", "timestamp", "arming_state")
    if st is not None:
        ts = np.asarray(st["timestamp"], float) * 1e-6
        armed = np.asarray(st["arming_state"]) == _PX4_ARMED
        k = np.searchsorted(ts, tp, side="right") - 1
        power = np.where((k >= 0) & armed[np.maximum(k, 0)], power, np.nan)
    return PowerSamples(tp - tp[0], power, air, climb, gs,
                        source=f"{path.name}: battery_status voltage_v x current_a, {which}, "
                               "vehicle_local_position")


def read_power_samples(path: str | Path) -> PowerSamples:
    """The power, airspeed and climb samples of an ArduPilot ``.tlog`` or ``.bin`` log or a
    PX4 ``.ulg`` log.

    Raises
    ------
    InputError
        A missing file, another extension, or a log without the messages needed
        (the message names them).
    """
    p = Path(path)
    if not p.is_file():
        raise InputError(f"flight log {p} not found (give an ArduPilot .bin or .tlog, or a PX4 "
                         ".ulg)")
    ext = p.suffix.lower()
    if ext == ".tlog":
        return _tlog(p)
    if ext in (".bin", ".log"):
        return _bin(p)
    if ext == ".ulg":
        return _ulg(p)
    raise InputError(f"flight log {p}: unknown kind {ext!r}; give an ArduPilot DataFlash "
                     "log (.bin), a telemetry log (.tlog) or a PX4 log (.ulg)")


def write_power_tlog(path: str | Path, samples: PowerSamples, *, volts: float = 14.8,
                     armed_from: float = 0.0) -> Path:
    """Write ``samples`` as a MAVLink 2 telemetry log (``.tlog``) with pymavlink.

    At each sample time: a ``HEARTBEAT`` of a quadrotor (armed from ``armed_from`` [s]),
    ``VFR_HUD`` (airspeed, ground speed, climb) and ``SYS_STATUS`` with the battery at
    ``volts`` and the current ``power / volts`` (in its mV and cA units, so rounded to
    them), each after its 8-byte big-endian microsecond timestamp.
    """
    import struct

    from pymavlink.dialects.v20 import ardupilotmega as mavlink

    mav = mavlink.MAVLink(None, srcSystem=1, srcComponent=1)
    t0 = 1.7e9
    p = Path(path)
    with open(p, "wb") as f:
        def put(ts: float, msg: Any) -> None:
            f.write(struct.pack(">Q", int((t0 + ts) * 1e6)) + msg.pack(mav))
        for ti, pw, a, g, c in zip(samples.t, samples.power, samples.airspeed,
                                   samples.groundspeed, samples.climb):
            armed = 128 if ti >= armed_from else 0
            put(ti, mavlink.MAVLink_heartbeat_message(2, 3, armed | 1, 4, 4, 3))
            put(ti + 0.01, mavlink.MAVLink_vfr_hud_message(float(a), float(g), 0, 50, 50.0,
                                                            float(c)))
            put(ti + 0.02, mavlink.MAVLink_sys_status_message(
                0, 0, 0, 0, int(round(volts * 1000)), int(round(pw / volts * 100)), 80,
                0, 0, 0, 0, 0, 0))
    return p
