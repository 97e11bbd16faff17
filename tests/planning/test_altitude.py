"""The final altitude profile (planning/altitude.py) on array terrains."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from fm2uav.errors import InputError, PlanningError
from fm2uav.planning import FlightLevel
from fm2uav.planning.altitude import envelope_above, envelope_below, resample_route, solve_profile


def _terrain(seed: int, n: int = 800, ds: float = 5.0, rough: float = 60.0):
    rng = np.random.default_rng(seed)
    s = np.arange(n) * ds
    g = np.zeros(n)
    for k in range(1, 8):
        g += rough / k * np.sin(2 * np.pi * k * s / (n * ds) * rng.uniform(1, 6) + rng.uniform(0, 6))
    return s, g + 300.0


def _slopes_ok(s, z, lim, tol=1e-6):
    dz = np.diff(z) / np.maximum(np.diff(s), 1e-12)
    up, down = math.tan(math.radians(lim.max_climb)), math.tan(math.radians(lim.max_descent))
    return np.all(dz <= up + tol) and np.all(dz >= -down - tol)


def test_envelopes_are_the_tightest_slope_limited_bounds():
    s = np.linspace(0, 100, 101)
    rng = np.random.default_rng(3)
    lower = rng.normal(0, 10, 101)
    z = envelope_above(s, lower, 0.5, 0.3)
    lim = FlightLevel(agl=10, max_climb=math.degrees(math.atan(0.5)),
                        max_descent=math.degrees(math.atan(0.3)))
    assert np.all(z >= lower - 1e-12) and _slopes_ok(s, z, lim)
    # tight: every point is the cone of some bound point
    for i in range(101):
        cone = lower - np.where(np.arange(101) > i, 0.5, 0.3) * np.abs(s - s[i])
        assert z[i] == pytest.approx(cone.max())
    u = envelope_below(s, -lower, 0.5, 0.3)
    assert np.all(u <= -lower + 1e-12) and _slopes_ok(s, u, lim)



def _sweeps_python(s, bound, pick, forward, backward):
    """The envelopes' two passes as the Python loop they were before being compiled."""
    d = np.diff(np.asarray(s, dtype=float))
    z = np.array(bound, dtype=float)
    for i in range(1, len(z)):
        z[i] = pick(z[i], z[i - 1] + forward * d[i - 1])
    for i in range(len(z) - 2, -1, -1):
        z[i] = pick(z[i], z[i + 1] + backward * d[i])
    return z


@pytest.mark.parametrize("seed", range(12))
def test_compiled_envelopes_equal_the_python_passes_bit_for_bit(seed):
    """Random bounds with -inf / +inf / NaN entries, repeated arc lengths and ties: the
    compiled sweeps give exactly the Python loop's values (min/max as the builtins)."""
    rng = np.random.default_rng(seed)
    n = int(rng.integers(1, 400))
    s = np.cumsum(rng.choice([0.0, 0.25, 1.0, rng.uniform(0, 3)], size=n))
    bound = np.round(rng.normal(300, 40, n), int(rng.integers(0, 3)))
    for value in (-np.inf, np.inf, np.nan):
        bound[rng.random(n) < 0.05] = value
    up, down = rng.uniform(0.05, 2.0, 2)
    for got, want in (
        (envelope_above(s, bound, up, down), _sweeps_python(s, bound, max, -down, -up)),
        (envelope_below(s, bound, up, down), _sweeps_python(s, bound, min, up, down)),
    ):
        assert np.array_equal(got, want, equal_nan=True)
        assert np.array_equal(np.signbit(got), np.signbit(want))


@settings(max_examples=25, derandomize=True, deadline=None)
@given(seed=st.integers(0, 10_000), agl=st.sampled_from([60.0, 100.0, 120.0, 150.0]),
       climb=st.sampled_from([20.0, 30.0, 45.0, 60.0]))
def test_cruise_never_below_floor_and_slopes_hold(seed, agl, climb):
    s, g = _terrain(seed)
    lim = FlightLevel(agl=agl, tolerance=2.0, max_climb=climb, max_descent=climb)
    out = solve_profile(s, g, g, lim, z_start=g[0] + 20, z_goal=g[-1] + 20,
                        ground_start=g[0], ground_goal=g[-1])
    z, phase = out["z"], out["phase"]
    assert _slopes_ok(s, z, lim)
    cruise = phase == "cruise"
    assert cruise.sum() > len(s) // 2
    assert np.all(z[cruise] - g[cruise] >= agl - 2.0 - 1e-9)
    # the climb-out never gets closer to the ground than the start did
    assert np.all(z - g >= 20.0 - 1e-9)


def test_median_follows_the_request_when_the_airframe_can():
    s, g = _terrain(7, rough=30.0)
    lim = FlightLevel(agl=120.0, max_climb=45.0, max_descent=45.0)
    out = solve_profile(s, g, g, lim, z_start=g[0] + 120, z_goal=g[-1] + 120,
                        ground_start=g[0], ground_goal=g[-1])
    h = (out["z"] - g)[out["phase"] == "cruise"]
    assert abs(np.median(h) - 120.0) < 5.0 and h.min() >= 118.0


def test_ceiling_is_hard_and_forces_the_floor():
    # a 30 m spike on a plain: following it would leave the ceiling beside it;
    # the profile dips towards the floor over the spike instead
    s = np.arange(0, 2000.0, 1.0)
    g = np.where(np.abs(s - 1000) <= 5, 30.0, 0.0)
    lim = FlightLevel(agl=100.0, tolerance=20.0, max_agl=110.0, max_climb=45.0,
                        max_descent=45.0)
    out = solve_profile(s, g, g, lim, z_start=100, z_goal=100, ground_start=0,
                        ground_goal=0)
    h = out["z"] - g
    assert h.max() <= 110.0 + 1e-9
    assert h[out["phase"] == "cruise"].min() >= 80.0 - 1e-9
    assert h[1000] < 100.0  # the target (130 m) was given up for the ceiling


def test_infeasible_ceiling_names_max_agl():
    s = np.arange(0, 1000.0, 5.0)
    g = np.where(np.abs(s - 500) < 20, 0.0, 300.0)  # 300 m deep slot, 40 m wide
    lim = FlightLevel(agl=100.0, max_agl=110.0, max_climb=10.0, max_descent=10.0)
    with pytest.raises(PlanningError, match="max_agl"):
        solve_profile(s, g, g, lim, z_start=400, z_goal=400, ground_start=300,
                      ground_goal=300)


def test_vertical_climb_at_a_low_start_next_to_a_hill():
    s = np.arange(0, 1000.0, 5.0)
    g = np.where(s > 50, 200.0, 0.0)  # a 200 m cliff 50 m from the start
    lim = FlightLevel(agl=50.0, min_agl=30.0, max_climb=30.0, max_descent=30.0)
    out = solve_profile(s, g, g, lim, z_start=2.0, z_goal=250.0, ground_start=0.0,
                        ground_goal=200.0)
    z = out["z"]
    assert out["z_start_eff"] > 2.0
    assert np.all(z[1:] - g[1:] >= 30.0 - 1e-9)
    assert _slopes_ok(s, z, lim)


def test_request_outside_the_limits_is_refused_in_one_line():
    with pytest.raises(InputError, match=r"max_agl") as e:
        FlightLevel(agl=150.0, max_agl=120.0)
    assert "\n" not in str(e.value)
    with pytest.raises(InputError, match="min_agl"):
        FlightLevel(agl=20.0, min_agl=30.0)


def test_resample_route_keeps_ends_and_spacing():
    path = np.array([[0, 0, 5], [0, 0, 50], [30, 40, 50], [30, 40, 10.0]])
    xy, s = resample_route(path, 4.0)
    assert xy[0].tolist() == [0, 0] and xy[-1].tolist() == [30, 40]
    assert s[-1] == pytest.approx(50.0) and np.max(np.diff(s)) <= 4.0 + 1e-9


def test_the_cruise_floor_is_agl_minus_tolerance_or_min_agl_whichever_is_higher():
    from fm2uav.planning.altitude import floor_agl

    assert floor_agl(FlightLevel(agl=120.0)) == pytest.approx(118.0)  # tolerance 2 m
    assert floor_agl(FlightLevel(agl=120.0, tolerance=10.0, min_agl=50.0)) == 110.0
    assert floor_agl(FlightLevel(agl=120.0, tolerance=30.0, min_agl=100.0)) == 100.0


def test_a_zone_floor_above_a_zone_ceiling_is_no_flyable_profile():
    """A no-fly zone's lower bound is part of the floor: over a stretch where it lies above
    another zone's upper bound, no profile exists (not a profile through the zone)."""
    s = np.arange(0, 2000.0, 5.0)
    g = np.zeros_like(s)
    lo = np.where(np.abs(s - 1000) < 100, 300.0, -np.inf)
    up = np.where(np.abs(s - 1000) < 100, 200.0, np.inf)
    lim = FlightLevel(agl=100.0, max_climb=30.0, max_descent=30.0)
    with pytest.raises(PlanningError, match="no flyable profile"):
        solve_profile(s, g, g, lim, z_start=100, z_goal=100, ground_start=0, ground_goal=0,
                      extra_lower=lo, extra_upper=up)
    ok = solve_profile(s, g, g, lim, z_start=100, z_goal=100, ground_start=0, ground_goal=0,
                       extra_lower=np.where(np.abs(s - 1000) < 100, 150.0, -np.inf))
    assert ok["z"][np.abs(s - 1000) < 100].min() >= 150.0 - 1e-9
