"""Auto-tuning of p1/p2 (analysis/tune.py): airframe limits and the trade-off it finds."""

from __future__ import annotations

import numpy as np
import pytest

import fm2uav
from fm2uav import FlightLevel
from fm2uav.analysis.tune import as_limits, tune
from fm2uav.errors import InputError
from fm2uav.vehicles import AirframeLimits, FixedWing


def test_limits_parsing():
    lim = AirframeLimits.from_degrees(20, 50)
    assert lim.max_climb == pytest.approx(np.radians(20)) and lim.min_turn_radius == 50.0
    assert as_limits({"max_climb": np.radians(20), "min_turn_radius": 50}) == lim
    assert as_limits(lim) is lim
    with pytest.raises(InputError):
        AirframeLimits(0, 50)
    with pytest.raises(InputError, match="90 degrees"):
        AirframeLimits(2.0, 50)  # radians, not degrees: 115 degrees
    with pytest.raises(InputError):
        AirframeLimits.from_degrees(95, 50)
    with pytest.raises(InputError):
        AirframeLimits(0.3, -1)
    with pytest.raises(InputError, match="missing"):
        as_limits({"max_climb": 0.3})
    with pytest.raises(InputError, match="AirframeLimits"):
        as_limits((20, 50))
    # an airframe: the smaller of climb and descent, its turn radius at cruise
    wing = FixedWing("w", 14.0, 12.0, 17.0, np.radians(55), np.radians(15), np.radians(12))
    lim = as_limits(wing)
    assert lim.max_climb_deg == pytest.approx(12.0)
    assert lim.min_turn_radius == pytest.approx(wing.turn_radius())
    assert as_limits("disco") == fm2uav.get_airframe("disco").limits()
    assert as_limits("arducopter").max_climb == pytest.approx(np.pi / 2)


@pytest.fixture(scope="module")
def open_field():
    return fm2uav.scenarios.open_field()


def test_tune_trade_off(open_field):
    sc = open_field
    grid = {"p1": [0.5], "p2": [0.6, 0.8, 1.3, 2.5]}
    lv = FlightLevel(agl=150.0)
    loose = tune(sc.world, sc.start, sc.goal, AirframeLimits.from_degrees(89.9, 0.0), lv, grid=grid)
    strict = tune(sc.world, sc.start, sc.goal, AirframeLimits.from_degrees(25.0, 200.0), lv,
                  grid=grid)
    assert len(loose.rows) == 4 and all(r["error"] is None for r in loose.rows)
    # with no limits the best is the closest follower; with tight limits a smoother one
    assert loose.best["deviation_m"] == min(r["deviation_m"] for r in loose.rows)
    assert strict.best is not None
    assert strict.best["climb_max_deg"] <= 25.0 and strict.best["min_turn_radius_m"] >= 200.0
    assert strict.best["p2"] < loose.best["p2"]
    assert strict.best["deviation_m"] >= loose.best["deviation_m"]
    # the Pareto front is non-dominated and contains both extremes
    front = strict.pareto
    assert loose.best in loose.pareto
    for a in front:
        for b in front:
            assert not (b["deviation_m"] < a["deviation_m"] and b["climb_max_deg"] < a["climb_max_deg"]
                        and b["min_turn_radius_m"] > a["min_turn_radius_m"])
    assert "| p1 | p2 |" in strict.table()
    with pytest.raises(InputError, match="p2 > p1"):
        tune(sc.world, sc.start, sc.goal, AirframeLimits.from_degrees(30, 10), lv,
             grid={"p1": [1.0], "p2": [0.5]})
    with pytest.raises(InputError, match="grid 'p1'"):
        tune(sc.world, sc.start, sc.goal, AirframeLimits.from_degrees(30, 10), lv,
             grid={"p1": [-1.0]})
