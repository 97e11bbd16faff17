"""Wind fields: the meteorological direction, the power-law profile, the gridded field."""

from __future__ import annotations

import math

import numpy as np
import pytest

from fm2uav.errors import InputError
from fm2uav.world import World
from fm2uav.world.wind import WindField, parse_wind_text


@pytest.mark.parametrize("frm, towards", [(0, (0, -1)), (90, (-1, 0)), (180, (0, 1)),
                                          (270, (1, 0)), (45, (-1, -1))])
def test_direction_is_where_the_wind_comes_from(frm, towards):
    uv = WindField.constant(10.0, frm).at([[0.0, 0.0]])[0]
    want = 10.0 * np.array(towards, float) / np.hypot(*towards)
    np.testing.assert_allclose(uv, want, atol=1e-12)


def test_profile_is_the_power_law_from_the_reference_height():
    f = WindField.profile(6.0, 270.0, ref_height=10.0, exponent=1 / 7)
    h = np.array([0.2, 1.0, 10.0, 50.0, 120.0])
    u = f.at(np.zeros((5, 3)), agl=h)[:, 0]
    np.testing.assert_allclose(u, 6.0 * (np.maximum(h, 1.0) / 10.0) ** (1 / 7), rtol=1e-12)
    assert f.max_speed() == pytest.approx(6.0 * 50 ** (1 / 7))


def test_grid_is_bilinear_exact_on_a_linear_field():
    x, y = np.linspace(0, 1000, 11), np.linspace(-500, 500, 6)
    X, Y = np.meshgrid(x, y, indexing="ij")
    f = WindField.grid(x, y, 2.0 + 0.003 * X - 0.001 * Y, 0.002 * Y, source="test")
    p = np.random.default_rng(0).uniform([0, -500], [1000, 500], (50, 2))
    uv = f.at(p)
    np.testing.assert_allclose(uv[:, 0], 2.0 + 0.003 * p[:, 0] - 0.001 * p[:, 1], atol=1e-12)
    np.testing.assert_allclose(uv[:, 1], 0.002 * p[:, 1], atol=1e-12)
    # outside the grid: the edge value (no extrapolation)
    assert f.at([[2000.0, 0.0]])[0, 0] == pytest.approx(2.0 + 3.0)


def test_on_nodes_shape_and_the_profile_over_the_ground():
    flat = World.from_heightmap(np.full((5, 4), 20.0), 10.0, 8)
    f = WindField.profile(5.0, 180.0, ref_height=10.0, exponent=0.25)
    nodes = f.on_nodes(flat)
    assert nodes.shape == flat.shape + (3,)
    assert np.all(nodes[..., 2] == 0) and np.all(nodes[..., 0] == pytest.approx(0.0))
    z = flat.origin[2] + flat.spacing[2] * np.arange(flat.shape[2])
    agl = np.maximum(z - 20.0, 1.0)
    np.testing.assert_allclose(nodes[0, 0, :, 1], 5.0 * (agl / 10.0) ** 0.25, rtol=1e-12)
    plane = World(np.zeros((6, 5), bool), spacing=2.0)
    assert WindField.constant(3.0, 270).on_nodes(plane).shape == (6, 5, 2)


def test_bad_winds_name_the_field_and_the_flag():
    with pytest.raises(InputError, match=r"wind direction .*--wind"):
        WindField.constant(5.0, 400.0)
    with pytest.raises(InputError, match=r"wind speed .*>= 0"):
        WindField.constant(-1.0, 0.0)
    with pytest.raises(InputError, match="u and v must have shape"):
        WindField.grid([0, 1], [0, 1, 2], np.zeros((2, 2)), np.zeros((2, 2)))
    with pytest.raises(InputError, match="missing"):
        WindField.grid([0, 1], [0, 1], np.full((2, 2), np.nan), np.zeros((2, 2)))
    with pytest.raises(InputError, match="SPEED@DIRECTION"):
        parse_wind_text("8 knots west")
    w = parse_wind_text(" 12.5@ 45 ")
    assert (w.speed, w.direction_deg) == (12.5, 45.0)
    assert w.describe() == "12.5 m/s from 45°" and not w.is_calm
    assert math.isclose(w.summary()["max_speed_mps"], 12.5)
