"""Flight time, the time back home and where the budget runs out."""

import numpy as np
import pytest

from fm2uav.errors import InputError
from fm2uav.vehicles.endurance import first_shortfall, flight_time, return_time


def test_return_time_is_the_legs_then_the_landing():
    path = [[0, 0, 100], [300, 0, 100], [300, 400, 160]]
    t, L = return_time(path, speed=5.0, climb_rate=2.0, descent_rate=1.5, landing_height=60.0)
    # 300 m at 5 m/s; 400 m at 5 m/s (80 s) vs 60 m climb at 2 m/s (30 s); land 60 m at 1.5
    assert t == pytest.approx(60.0 + 80.0 + 40.0)
    assert L == pytest.approx(300.0 + np.hypot(400, 60))
    ft = flight_time(np.asarray(path, float), 5.0, climb_rate=2.0, descent_rate=1.5,
                     final_descent=60.0)
    assert t == pytest.approx(ft.time_s)
    t2, _ = return_time([[0, 0], [50, 0]], speed=5.0, climb_rate=1, descent_rate=1)
    assert t2 == pytest.approx(10.0)
    with pytest.raises(InputError):
        return_time(np.zeros(3), speed=1, climb_rate=1, descent_rate=1)


def test_first_shortfall():
    assert first_shortfall([0, 10, 20], [5, 5, 5], 30.0) is None
    assert first_shortfall([0, 10, 20], [5, 15, 25], 30.0) == (2, 0.25)
    assert first_shortfall([0, 10], [40, 5], 30.0) == (0, 0.0)
    k, f = first_shortfall([0, 10, 20], [5, 5, np.inf], 30.0)
    assert (k, f) == (2, 1.0)  # no way back at the next sample: the whole interval is fine
