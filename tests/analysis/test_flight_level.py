"""flight_level_deviation (analysis/flight_level.py): exact transitions and deviations."""

from __future__ import annotations

import numpy as np
import pytest

import fm2uav
from fm2uav.analysis import flight_level_deviation


def test_flight_level_deviation_exact():
    w = fm2uav.World.from_heightmap(np.full((10, 4), 10.0), 5.0, 12)
    # ideal z = 10 + 20 = 30; start stretch 2 points, end stretch 1 point
    path = np.array([[0, 5, 50.0], [5, 5, 40.0], [10, 5, 33.0], [15, 5, 28.0],
                     [20, 5, 36.0], [25, 5, 30.0], [30, 5, 45.0]])
    r = flight_level_deviation(w, path, agl=20.0)
    assert r.start_transition_m == pytest.approx(np.hypot(5, 10) + np.hypot(5, 7))
    assert r.end_transition_m == pytest.approx(np.hypot(5, 15))
    assert r.middle_points == 4
    assert r.within == pytest.approx(3 / 4)  # 3, 2, 6, 0 m vs tolerance 5 m
    assert r.within_all == pytest.approx(3 / 7)
    assert r.mean_dev_m == pytest.approx((3 + 2 + 6 + 0) / 4)
    assert r.max_dev_m == pytest.approx(6.0)
    assert r.inside_terrain == 0 and r.min_agl_m == pytest.approx(18.0)
    # layer reference: surface node k=2 (z=10) + round(20/5)=4 -> z = 30
    rl = flight_level_deviation(w, path, agl=20.0, reference="layer")
    np.testing.assert_allclose(rl.deviation, r.deviation)
    inside = path.copy()
    inside[3, 2] = 9.0
    assert flight_level_deviation(w, inside, agl=20.0).inside_terrain == 1
