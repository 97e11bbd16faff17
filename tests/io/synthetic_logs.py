"""Flight logs made from a known power model: a MAVLink telemetry log (.tlog) written
with pymavlink (:func:`fm2uav.io.flightlog.write_power_tlog`) and an ArduPilot DataFlash
log (.bin) written byte by byte as its format describes (FMT messages first), for the
power-fit tests."""

from __future__ import annotations

import struct
from pathlib import Path

import numpy as np


def flight_states(kind: str, seed: int = 0) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(t, airspeed, climb)`` of a 12-minute flight: hover, speed steps, climbs, descents."""
    rng = np.random.default_rng(seed)
    t = np.arange(0.0, 720.0, 0.5)
    if kind == "multirotor":
        speeds = [0, 2, 4, 6, 8, 10, 12, 14, 5, 0, 9, 3]
        climbs = [0, 2.5, 0, -1.5, 0, 1.0, 0, -0.8, 2.0, -1.2, 0, 0]
    else:
        speeds = [12, 13, 14, 15, 16, 17, 18, 20, 14, 13, 16, 19]
        climbs = [0, 2.0, 0, -1.5, 0, 1.0, 0, -0.5, 3.0, -1.0, 0, 0]
    k = (t // 60).astype(int)
    air = np.array(speeds, float)[k] + 0.3 * rng.standard_normal(len(t)).cumsum() * 0.05
    air = np.abs(air) if kind == "multirotor" else np.maximum(air, 11.0)
    climb = np.array(climbs, float)[k]
    return t, air, climb


def write_tlog(path: Path, t, power, airspeed, climb, *, volts: float = 14.8,
               armed_from: float = 0.0) -> Path:
    """A .tlog of HEARTBEAT, SYS_STATUS (volts x current in mV / cA) and VFR_HUD at ``t``
    (:func:`fm2uav.io.flightlog.write_power_tlog`)."""
    from fm2uav.io.flightlog import write_power_tlog
    from fm2uav.vehicles.calibration import PowerSamples

    t = np.asarray(t, float)
    s = PowerSamples(t, np.asarray(power, float), np.asarray(airspeed, float),
                     np.asarray(climb, float), np.asarray(airspeed, float))
    return write_power_tlog(path, s, volts=volts, armed_from=armed_from)


def write_bin(path: Path, t, power, airspeed, climb, *, volts: float = 22.2) -> Path:
    """A DataFlash .bin with FMT, BAT (Volt, Curr), ARSP (Airspeed) and GPS (GMS, GWk, Spd, VZ)."""
    head = b"\xa3\x95"
    fmts = {"BAT": (129, "QBff", "TimeUS,Instance,Volt,Curr"),
            "ARSP": (130, "QBf", "TimeUS,I,Airspeed"),
            "GPS": (131, "QBIHff", "TimeUS,I,GMS,GWk,Spd,VZ")}
    size = {"Q": 8, "B": 1, "f": 4, "I": 4, "H": 2}
    with open(path, "wb") as f:
        f.write(head + bytes([128]) + struct.pack("<BB4s16s64s", 128, 89, b"FMT", b"BBnNZ",
                                                  b"Type,Length,Name,Format,Columns"))
        for name, (mid, fmt, cols) in fmts.items():
            length = 3 + sum(size[c] for c in fmt)
            f.write(head + bytes([128]) + struct.pack("<BB4s16s64s", mid, length, name.encode(),
                                                      fmt.encode(), cols.encode()))
        for ti, p, a, c in zip(t, power, airspeed, climb):
            us = int(ti * 1e6) + 1_000_000
            f.write(head + bytes([131]) + struct.pack("<QBIHff", us, 0, 300_000_000 + us // 1000,
                                                      2400, float(a), float(-c)))
            f.write(head + bytes([130]) + struct.pack("<QBf", us + 1000, 0, float(a)))
            f.write(head + bytes([129]) + struct.pack("<QBff", us + 2000, 0, volts,
                                                      float(p / volts)))
    return path


#: The topics :func:`write_ulg` logs, as PX4 defines their fields (a subset, in order).
ULOG_FORMATS = {
    "battery_status": "uint64_t timestamp;float voltage_v;float current_a;uint8_t connected;",
    "vehicle_local_position": "uint64_t timestamp;float vx;float vy;float vz;",
    "airspeed_validated": "uint64_t timestamp;float calibrated_airspeed_m_s;"
                          "float true_airspeed_m_s;",
    "vehicle_status": "uint64_t timestamp;uint8_t arming_state;",
}


def _ulog_message(kind: str, payload: bytes) -> bytes:
    """A ULog message: ``uint16 msg_size`` (payload bytes), ``uint8 msg_type``, payload."""
    return struct.pack("<HB", len(payload), ord(kind)) + payload


def write_ulg(path: Path, t, power, airspeed, climb, *, volts: float = 16.8,
              groundspeed=None, armed_from: float | None = None, airspeed_topic: bool = True,
              current=None) -> Path:
    """A PX4 ULog (.ulg) written byte by byte as the ULog spec describes
    (docs.px4.io, "ULog File Format"): the 16-byte header (magic ``ULog\\x01\\x12\\x35``,
    version 1, start time), the flag bits, one format message per topic, an info message,
    the subscriptions (``A``: multi_id, msg_id, name) and the data (``D``: msg_id, the
    fields packed little-endian), all timestamps in microseconds.

    ``battery_status`` carries ``volts`` and ``power / volts`` (``current``: the currents
    as given, e.g. −1 for PX4's unknown), ``vehicle_local_position`` the ground speed north
    and ``vz = −climb``, ``airspeed_validated`` the true airspeed (left out with
    ``airspeed_topic=False``), ``vehicle_status`` armed (2) from ``armed_from`` (standby,
    1, before; no such topic with None).
    """
    t = np.asarray(t, float)
    gs = np.asarray(airspeed if groundspeed is None else groundspeed, float)
    amps = np.asarray(power, float) / volts if current is None else np.asarray(current, float)
    topics = {k: v for k, v in ULOG_FORMATS.items()
              if (airspeed_topic or k != "airspeed_validated")
              and (armed_from is not None or k != "vehicle_status")}
    ids = {name: k for k, name in enumerate(topics)}
    out = bytearray(b"ULog\x01\x12\x35" + bytes([1]) + struct.pack("<Q", 0))
    out += _ulog_message("B", bytes(16) + struct.pack("<3Q", 0, 0, 0))
    for name, fields in topics.items():
        out += _ulog_message("F", f"{name}:{fields}".encode())
    key, value = b"char[9] sys_name", b"PX4 tests"
    out += _ulog_message("I", bytes([len(key)]) + key + value)
    for name, k in ids.items():
        out += _ulog_message("A", struct.pack("<BH", 0, k) + name.encode())

    def data(name: str, fmt: str, *values) -> None:
        out.extend(_ulog_message("D", struct.pack("<H", ids[name]) + struct.pack(fmt, *values)))

    for ti, a, g, c, i in zip(t, airspeed, gs, climb, amps):
        us = int(round(ti * 1e6)) + 1_000_000
        if "vehicle_status" in ids:
            data("vehicle_status", "<QB", us, 2 if ti >= armed_from else 1)
        data("vehicle_local_position", "<Qfff", us + 1000, float(g), 0.0, float(-c))
        if "airspeed_validated" in ids:
            data("airspeed_validated", "<Qff", us + 2000, float(a), float(a))
        data("battery_status", "<QffB", us + 3000, volts, float(i), 1)
    Path(path).write_bytes(bytes(out))
    return Path(path)
