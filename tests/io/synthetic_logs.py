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
