"""Write out/flight.tlog: a telemetry log of a quadrotor's 12-minute test flight.

The power is that of the ``arducopter`` preset carrying a 400 g payload with a
draggier frame (``mass_kg`` 2.4, ``drag_area_m2`` 0.06) and 70 % efficient motors, so
that ``fm2uav calibrate out/flight.tlog --power arducopter`` has something to find: it
is flown level at 0–14 m/s, climbing at up to 2.5 m/s and descending at up to 1.5 m/s,
with 1 W of sensor noise (seeded).

    .venv/bin/python examples/make_flight_log.py
"""

from dataclasses import replace
from pathlib import Path

import numpy as np

from fm2uav.io.flightlog import write_power_tlog
from fm2uav.vehicles.calibration import PowerSamples
from fm2uav.vehicles.power import POWER_MODELS

true = replace(POWER_MODELS["arducopter"], mass_kg=2.4, drag_area_m2=0.06, efficiency=0.7)
rng = np.random.default_rng(0)
t = np.arange(0.0, 720.0, 0.5)
k = (t // 60).astype(int)
air = np.array([0, 2, 4, 6, 8, 10, 12, 14, 5, 0, 9, 3], float)[k]
climb = np.array([0, 2.5, 0, -1.5, 0, 1.0, 0, -0.8, 2.0, -1.2, 0, 0])[k]
power = true.power(air, climb) + rng.normal(0.0, 1.0, len(t))
out = Path("out")
out.mkdir(exist_ok=True)
write_power_tlog(out / "flight.tlog", PowerSamples(t, power, air, climb, air))
print(f"wrote {out / 'flight.tlog'}: {len(t)} samples, hover {true.hover_power():.0f} W")
