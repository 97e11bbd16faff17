import math

import numpy as np
import pytest

from fm2uav import InputError
from fm2uav.missions.coverage import (
    FULL_BOUNDS_DEG,
    DESettings,
    ZigzagCost,
    differential_evolution,
    scipy_de,
    sweep,
)

from .helpers import random_polygon


def test_de_within_half_percent_of_brute_force_sweep():
    """Judged: DE's best cost within 0.5 % of a 0.1° sweep, on seeded random polygons."""
    rng = np.random.default_rng(2024)
    worst = -1.0
    for k in range(25):
        p = random_polygon(rng, holes=k % 3 == 0)
        d = float(rng.uniform(30, 150))
        f = ZigzagCost.of(p, d)
        de = differential_evolution(f, seed=k)
        sw = sweep(f, step_deg=0.1)
        assert 1.0 <= de.angle_deg <= 89.0
        assert de.cost == pytest.approx(f(de.angle_deg))
        worst = max(worst, (de.cost - sw.cost) / sw.cost)
    assert worst <= 0.005


def test_de_settings_and_determinism():
    p = [(0, 0), (500, 100), (600, 400), (200, 500), (-50, 300)]
    a = differential_evolution(p, 40.0, seed=5)
    b = differential_evolution(p, 40.0, seed=5)
    c = differential_evolution(p, 40.0, seed=6)
    assert a.evaluations == 20 + 30 * 20
    np.testing.assert_array_equal(a.evaluated_deg, b.evaluated_deg)
    assert not np.array_equal(a.evaluated_deg, c.evaluated_deg)
    assert np.all((a.evaluated_deg >= 1.0) & (a.evaluated_deg <= 89.0))
    st = a.stats()
    assert st["min_cost"] == pytest.approx(a.cost)
    assert st["min_cost"] <= st["median_cost"] <= st["max_cost"]
    assert st["min_cost"] <= st["mean_cost"] <= st["max_cost"]
    # the DE's population improves: final best no worse than the initial best
    assert a.cost <= a.evaluated_cost[:20].min()


def test_scipy_de_and_full_range_agree_with_sweep():
    rng = np.random.default_rng(9)
    p = random_polygon(rng)
    f = ZigzagCost.of(p, 60.0)
    sw = sweep(f, step_deg=0.1, bounds_deg=FULL_BOUNDS_DEG)
    full = differential_evolution(f, bounds_deg=FULL_BOUNDS_DEG, seed=1)
    assert full.cost <= sw.cost * 1.005
    assert np.all(sw.evaluated_deg < 180.0)
    sp = scipy_de(f, seed=1)
    assert sp.cost <= sweep(f, step_deg=0.1).cost * 1.005


def test_bad_options():
    p = [(0, 0), (100, 0), (100, 100)]
    with pytest.raises(InputError):
        differential_evolution(p, 10.0, settings=DESettings(population=3))
    with pytest.raises(InputError):
        differential_evolution(p, 10.0, bounds_deg=(50, 10))
    with pytest.raises(InputError):
        sweep(p, 10.0, step_deg=0)


def test_sweep_exact_on_rectangle():
    # a 400 x 100 rectangle: bands along x (α → 0) are cheapest in [1°, 89°]
    s = sweep([(0, 0), (400, 0), (400, 100), (0, 100)], 50.0, step_deg=1.0)
    assert s.angle_deg == pytest.approx(1.0)
    assert math.isclose(s.evaluated_deg[-1], 89.0)
