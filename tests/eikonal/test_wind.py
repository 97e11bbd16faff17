"""The wind march's public API: fast_marching(wind=...), zermelo_march and its helpers."""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
import pytest

from fm2uav.errors import InputError
from fm2uav.eikonal import fast_marching
from fm2uav.eikonal.wind import (
    as_wind,
    ground_speed,
    heading,
    is_calm,
    wind_refused,
    zermelo_march,
    zermelo_time,
)

DOC = Path(__file__).resolve().parents[2] / "docs" / "eikonal.md"


# ---------------------------------------------------------------- closed forms
def test_zermelo_time_solves_its_defining_equation():
    rng = np.random.default_rng(0)
    d = rng.normal(size=(200, 3)) * 50
    V = rng.uniform(5, 20, size=200)
    w = rng.normal(size=(200, 3))
    w *= (rng.uniform(0, 0.95, size=200) * V / np.linalg.norm(w, axis=1))[:, None]
    t = zermelo_time(d, V, w)
    np.testing.assert_allclose(np.linalg.norm(d - w * t[:, None], axis=1), V * t, rtol=1e-12)
    assert np.all(t > 0)


def test_zermelo_time_edge_cases():
    assert zermelo_time([0.0, 0.0], 10.0, [3.0, 4.0]) == 0.0
    assert math.isinf(zermelo_time([1.0, 0.0], 5.0, [3.0, 4.0]))  # |w| = V: refused
    assert zermelo_time([3.0, 0.0], 2.0, [0.0, 0.0]) == 1.5


def test_ground_speed_and_heading_fly_the_track():
    rng = np.random.default_rng(1)
    t = rng.normal(size=(100, 2))
    t /= np.linalg.norm(t, axis=1)[:, None]
    V = rng.uniform(5, 20, size=100)
    w = rng.normal(size=(100, 2)) * 3
    w *= np.minimum(1.0, 0.9 * V / np.linalg.norm(w, axis=1))[:, None]
    g = ground_speed(t, V, w)
    n = heading(t, V, w)
    np.testing.assert_allclose(np.linalg.norm(n, axis=1), 1.0, rtol=1e-12)
    np.testing.assert_allclose(V[:, None] * n + w, g[:, None] * t, atol=1e-12)
    assert np.all(g > 0)
    # the time to fly 100 m along t equals zermelo_time
    np.testing.assert_allclose(100 / g, zermelo_time(100 * t, V, w), rtol=1e-12)
    assert math.isnan(ground_speed([1.0, 0.0], 2.0, [3.0, 0.0]))


# ---------------------------------------------------------------- validation
@pytest.mark.parametrize("wind, match", [
    ([1.0, 2.0, 3.0], "2 components"),
    (np.zeros((4, 5, 3)), r"shape \(4, 5, 2\)"),
    ([1.0, np.nan], "finite"),
    ("east", "numbers"),
])
def test_bad_wind_is_an_input_error(wind, match):
    with pytest.raises(InputError, match=match):
        fast_marching(np.ones((4, 5)), [(0, 0)], wind=wind)


def test_3d_wind_with_two_components_says_how_to_fix_it():
    with pytest.raises(InputError, match="append 0"):
        zermelo_march(np.ones((3, 3, 3)), [(1, 1, 1)], [1.0, 0.0])


def test_source_on_a_refused_node_is_an_input_error():
    speed = np.ones((5, 5))
    speed[2, 2] = 0.5
    with pytest.raises(InputError, match=r"source \[2, 2\] is refused: the wind there \(0\.6"):
        fast_marching(speed, [(2, 2)], wind=[0.6, 0.0])
    speed[2, 2] = 0.0
    with pytest.raises(InputError, match="speed 0"):
        fast_marching(speed, [(2, 2)], wind=[0.1, 0.0])


@pytest.mark.parametrize("order", [0, 3, True, 1.0])
def test_bad_order(order):
    with pytest.raises(InputError, match="order must be 1 or 2"):
        zermelo_march(np.ones((3, 3)), [(1, 1)], [0.1, 0.0], order=order)


def test_is_calm_and_as_wind():
    assert is_calm(None if False else [0.0, 0.0], (3, 3))
    assert is_calm(np.zeros((3, 3, 2)), (3, 3))
    assert not is_calm([0.0, 1e-300], (3, 3))
    assert as_wind([1, 2], (3, 3)).dtype == float


# ---------------------------------------------------------------- dispatch
def test_no_wind_and_zero_wind_are_bit_identical_to_the_isotropic_march():
    rng = np.random.default_rng(2)
    for ndim in (2, 3):
        shape = (23, 17) if ndim == 2 else (9, 11, 7)
        speed = rng.uniform(0.5, 3.0, shape)
        speed[rng.random(shape) < 0.1] = 0.0
        src = tuple(n // 2 for n in shape)
        speed[src] = 1.0
        for order in (1, 2):
            ref = fast_marching(speed, [src], order=order)
            for wind in (None, np.zeros(ndim), np.zeros(shape + (ndim,)), [0] * ndim):
                T = fast_marching(speed, [src], order=order, wind=wind)
                assert T.tobytes() == ref.tobytes()


def test_fast_marching_with_wind_is_zermelo_march():
    speed = np.full((15, 12), 3.0)
    w = np.array([1.0, -0.5])
    T = fast_marching(speed, [(7, 6)], wind=w, spacing=(2.0, 1.5), order=1, stop_at=[(14, 0)])
    R = zermelo_march(speed, [(7, 6)], w, spacing=(2.0, 1.5), order=1, stop_at=[(14, 0)])
    assert T.tobytes() == R.times.tobytes()
    assert np.isinf(T).any()  # stopped early


# ---------------------------------------------------------------- result object
def test_refused_nodes_are_reported_and_impassable():
    speed = np.full((8, 8), 2.0)
    speed[4:, :3] = 1.0
    speed[0, 7] = 0.0
    w = [1.2, 0.0]
    res = zermelo_march(speed, [(0, 0)], w)
    expected = np.zeros((8, 8), dtype=bool)
    expected[4:, :3] = True
    np.testing.assert_array_equal(res.refused, expected)
    np.testing.assert_array_equal(wind_refused(speed, w), expected)
    assert np.all(np.isinf(res.times[res.refused])) and np.isinf(res.times[0, 7])
    assert np.isfinite(res.times[7, 7])  # reached around the refused block


def test_acute_limit_and_reopened():
    res = zermelo_march(np.ones((9, 9)), [(4, 4)], [0.5, 0.0])
    assert math.isclose(res.acute_limit, 1 / math.sqrt(2))
    assert res.reopened == 0 and res.pops == 81
    res = zermelo_march(np.ones((41, 41)), [(20, 20)], [0.0, 0.8])
    assert res.reopened > 0
    res = zermelo_march(np.ones((5, 5, 5)), [(2, 2, 2)], [0.5, 0.0, 0.0])
    assert math.isclose(res.acute_limit, 1 / math.sqrt(3))
    res = zermelo_march(np.ones((5, 5)), [(2, 2)], [0.1, 0.0], spacing=(1.0, 2.0))
    assert math.isclose(res.acute_limit, 1 / math.sqrt(5))  # angle (1, 0)-(1, 2)


def test_towards_is_the_time_home_in_a_constant_wind():
    # 600 m square, 5 m cells; nodes at least 60 m from home (measured: 0.46 % and
    # 0.015 at this size, 0.08 % and 0.003 at 2.5 m cells: second order)
    n, h, c = 121, 5.0, 60
    V, w = 15.0, np.array([-4.0, 7.0])
    res = zermelo_march(np.full((n, n), V), [(c, c)], w, spacing=h, towards=True, track=True)
    X, Y = np.meshgrid((np.arange(n) - c) * h, (np.arange(n) - c) * h, indexing="ij")
    home = zermelo_time(np.stack([-X, -Y], axis=-1), V, w)  # fly from x to the source
    far = np.hypot(X, Y) >= 60
    assert np.max(np.abs(res.times - home)[far] / home[far]) < 0.006
    # the track points home (in a constant wind the routes are straight)
    unit = -np.stack([X, Y], axis=-1)[far] / np.hypot(X, Y)[far][:, None]
    assert np.max(np.linalg.norm(res.track[far] - unit, axis=1)) < 0.02
    np.testing.assert_array_equal(res.track[c, c], [0.0, 0.0])
    # the opposite direction: the same times with the wind reversed
    away = zermelo_march(np.full((n, n), V), [(c, c)], -w, spacing=h, track=True)
    assert away.times.tobytes() == res.times.tobytes()
    np.testing.assert_array_equal(away.track, -res.track)


def test_track_is_unit_where_reached_and_zero_elsewhere():
    speed = np.ones((12, 10))
    speed[6, :] = 0.0
    res = zermelo_march(speed, [(2, 3)], [0.2, 0.3], track=True)
    norm = np.linalg.norm(res.track, axis=-1)
    reached = np.isfinite(res.times) & (res.times > 0)
    np.testing.assert_allclose(norm[reached], 1.0, rtol=1e-12)
    assert np.all(norm[~reached] == 0)
    assert zermelo_march(speed, [(2, 3)], [0.2, 0.3]).track is None


def _descend(res, start, speed_fn, wind_fn, h, step=0.25):
    """Fly from ``start`` (index) to the source along the track field (bilinear), summing
    the time of each step at the ground speed of the local airspeed and wind."""
    from scipy.interpolate import RegularGridInterpolator

    n = res.times.shape[0]
    axes = (np.arange(n) * h, np.arange(n) * h)
    tr = [RegularGridInterpolator(axes, res.track[..., i]) for i in range(2)]
    x = np.array(start, dtype=float) * h
    total = 0.0
    for _ in range(100000):
        t = np.array([tr[0](x)[0], tr[1](x)[0]])
        t /= np.linalg.norm(t)
        V, w = speed_fn(x), wind_fn(x)
        g = float(ground_speed(t, V, w))
        remaining = res.times[tuple(np.round(x / h).astype(int))]
        if remaining < 2 * step * h / g:
            return total + remaining
        total += step * h / g
        x = x + step * h * t
    raise AssertionError("the descent did not arrive")


def test_descent_along_the_track_flies_the_predicted_time():
    # spiral wind around the goal (inflow plus rotation): the time-optimal routes curve,
    # and flying the track field from a far node takes the time T says
    n, h = 81, 25.0
    c = (n // 2) * h
    X, Y = np.meshgrid(np.arange(n) * h - c, np.arange(n) * h - c, indexing="ij")

    def wind_fn(p):
        x, y = p[0] - c, p[1] - c
        return np.array([-0.004 * x - 0.006 * y, -0.004 * y + 0.006 * x])

    def speed_fn(p):
        return 12.0

    w = np.stack([-0.004 * X - 0.006 * Y, -0.004 * Y + 0.006 * X], axis=-1)
    res = zermelo_march(np.full((n, n), 12.0), [(n // 2, n // 2)], w, spacing=h, towards=True,
                        track=True)
    for start in [(2, 2), (78, 40), (40, 75), (10, 70)]:
        flown = _descend(res, start, speed_fn, wind_fn, h)
        # measured 0.8 - 1.6 % here, 0.5 - 0.8 % with cells half as large
        assert abs(flown / res.times[start] - 1) < 0.02, (start, flown, res.times[start])


def test_docs_example_runs():
    text = DOC.read_text()
    wind = text[text.index("## Wind"):]
    blocks = re.findall(r"```python\n(.*?)```", wind, flags=re.S)
    assert blocks
    for i, block in enumerate(blocks):
        exec(compile(block, f"docs/eikonal.md Wind block {i + 1}", "exec"), {})
