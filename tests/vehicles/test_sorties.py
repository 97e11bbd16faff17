"""A survey split into sorties by battery: each fits with its way home, fewer than an even split."""

from __future__ import annotations

import numpy as np
import pytest

from fm2uav.errors import PlanningError
from fm2uav.vehicles.energy import fly_legs
from fm2uav.vehicles.power import POWER_MODELS
from fm2uav.vehicles.sorties import even_parts, even_split, split_sorties
from fm2uav.world.wind import WindField

QUAD = POWER_MODELS["arducopter"]
KW = dict(home=[0.0, 0.0, 0.0], battery_wh=74.0, reserve=0.2, speed=10.0, climb_rate=2.5,
          descent_rate=1.5)


def lawnmower(bands: int = 20, x0: float = 1000.0, length: float = 2000.0) -> np.ndarray:
    pts = []
    for k in range(bands):
        ys = (0.0, length) if k % 2 == 0 else (length, 0.0)
        pts += [[x0 + 100.0 * k, ys[0], 80.0], [x0 + 100.0 * k, ys[1], 80.0]]
    return np.array(pts)


def _dense_route(pts, a, b):
    """The route from point ``a`` to point ``b`` (3D), through the waypoints between."""
    seg = np.linalg.norm(np.diff(pts, axis=0), axis=1)
    s = np.concatenate([[0.0], np.cumsum(seg)])

    def at(q):
        k = int(np.argmin(np.linalg.norm(pts[:-1] - q, axis=1) + np.linalg.norm(pts[1:] - q, axis=1)
                          - seg))
        return k, s[k] + np.linalg.norm(q - pts[k])
    ka, sa = at(a)
    kb, sb = at(b)
    inner = [pts[k] for k in range(ka + 1, kb + 1) if sa < s[k] < sb]
    return np.array([a, *inner, b])


def test_every_sortie_is_an_independently_measured_flight_within_the_battery():
    pts = lawnmower()
    plan = split_sorties(pts, QUAD, **KW)
    assert len(plan.sorties) == 9 and plan.even_sorties == 18   # fewer than an even split
    for k, s in enumerate(plan.sorties):
        route = _dense_route(pts, s.resume, s.stop)
        top_a = [0.0, 0.0, s.resume[2]]
        top_b = [0.0, 0.0, s.stop[2]]
        flight = fly_legs(np.vstack([top_a, route, top_b]), QUAD, speed=10.0, climb_rate=2.5,
                          descent_rate=1.5, takeoff_climb=s.resume[2], final_descent=s.stop[2])
        assert s.energy_wh == pytest.approx(flight.energy_wh, rel=1e-9)
        assert s.time_s == pytest.approx(flight.time_s, rel=1e-9)
        assert s.energy_wh <= plan.usable_wh
        if k:
            np.testing.assert_allclose(s.resume, plan.sorties[k - 1].stop)  # resumes there
    np.testing.assert_allclose(plan.sorties[0].resume, pts[0])
    np.testing.assert_allclose(plan.sorties[-1].stop, pts[-1])
    s = plan.summary()
    assert s["count"] == 9 and s["sorties"][0]["from_waypoint"] == 0
    assert s["sorties"][-1]["to_waypoint"] == len(pts) - 1


def test_a_headwind_on_the_way_home_costs_sorties():
    pts = lawnmower()
    calm = split_sorties(pts, QUAD, **KW)
    windy = split_sorties(pts, QUAD, **KW, wind=WindField.constant(6.0, 90.0))
    assert len(windy.sorties) > len(calm.sorties)
    assert windy.even_sorties is None        # one 2 km leg and the way home: too much


def test_a_survey_out_of_reach_is_refused_and_a_short_one_is_one_sortie():
    with pytest.raises(PlanningError, match="cannot be split into sorties"):
        split_sorties(lawnmower(x0=20000.0), QUAD, **KW)
    one = split_sorties(lawnmower(bands=2), QUAD, **KW)
    assert len(one.sorties) == 1 and one.even_sorties == 1


def test_even_split_is_the_fewest_equal_parts():
    e = np.arange(11.0)            # 1 Wh a leg, 10 legs, no way out or home
    zero = np.zeros(11)
    assert even_split(e, zero, zero, 5.0) == 2
    assert even_split(e, zero, zero, 3.0) == 4      # 4 parts of 2-3 legs: 3 Wh each
    assert even_split(e, zero, zero, 0.5) is None
    assert even_parts(e, zero, zero, 3.0) == [2.0, 3.0, 3.0, 2.0]  # edges 0, 2, 5, 8, 10
    out, back = np.linspace(0.0, 1.0, 11), np.linspace(1.0, 0.0, 11)
    # out[a] + 3 legs + back[b]: 3 parts would need 4.6 Wh for the middle one
    assert even_parts(e, out, back, 4.0) == pytest.approx([2.8, 3.7, 3.7, 2.8])
    assert even_parts(e, zero, zero, 0.5) == []
