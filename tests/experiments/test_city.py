"""Thesis ch. 3 reproduction (experiments/city.py): the trend of Tables 3.1/3.2."""

from __future__ import annotations

import numpy as np
import pytest

from fm2uav import World
from fm2uav.experiments.city import (
    THESIS_TABLE_3_1,
    city_table,
    horizontal_slice,
)


@pytest.fixture(scope="module")
def table():
    return [c.row() for c in city_table(seed=0, airframe="disco")]


@pytest.mark.parametrize("mission", ["low", "high"])
def test_lower_exponent_gives_smaller_clearance_and_separation(table, mission):
    rows = sorted((r for r in table if r["mission"] == mission), key=lambda r: -r["exponent"])
    assert [r["exponent"] for r in rows] == [1.0, 0.5, 0.25]
    safety = [r["safety_m"] for r in rows]
    sep = [r["separation_max_m"] for r in rows]
    assert safety[0] > safety[1] > safety[2] > 5.0
    assert sep[0] > sep[1] > sep[2]


def test_low_altitude_all_feasible_and_near_thesis_magnitudes(table):
    low = [r for r in table if r["mission"] == "low"]
    assert all(r["feasible"] for r in low)
    for r in low:
        thesis_safety, _ = THESIS_TABLE_3_1[r["exponent"]]
        assert 0.5 * thesis_safety < r["safety_m"] < 2.0 * thesis_safety
        assert r["separation_max_m"] < 5.0


def test_horizontal_slice():
    occ = np.zeros((4, 5, 6), bool)
    occ[1, 2, :3] = True
    w = World(occ, spacing=(1.0, 2.0, 10.0), origin=(0, 0, 5))
    s = horizontal_slice(w, 24.0)  # nearest layer k = 2 (z = 25)
    assert s.shape == (4, 5) and s.spacing == (1.0, 2.0)
    assert s.occupancy[1, 2] and s.occupancy.sum() == 1
    assert not horizontal_slice(w, 40.0).occupancy.any()
