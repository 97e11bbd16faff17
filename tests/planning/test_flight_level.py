"""Flight-level shaping (Algorithm 2) and the terrain-following plans it gives."""

from __future__ import annotations

import numpy as np
import pytest

import fm2uav
from fm2uav import FlightLevel, World
from fm2uav.analysis import flight_level_deviation
from fm2uav.errors import InputError, PlanningError, PointError
from fm2uav.planning.flight_level import exponents_from_k, flight_layer, flight_level_speed


def _ramp_world():
    # 4 x 3 columns, ground top node at layer 0,1,2,1 along x, 8 layers of 1 m
    h = np.array([[0.0] * 3, [1.0] * 3, [2.0] * 3, [1.0] * 3])
    return World.from_heightmap(h, 1.0, 8)


def test_flight_layer_is_surface_plus_level():
    w = _ramp_world()
    np.testing.assert_array_equal(flight_layer(w, 2.0)[:, 0], [2, 3, 4, 3])
    # agl rounds to whole cells: 2.6 m -> 3 cells
    np.testing.assert_array_equal(flight_layer(w, 2.6)[:, 1], [3, 4, 5, 4])


def test_literal_mode_is_the_seeds_exponents_exactly():
    w = _ramp_world()
    rng = np.random.default_rng(0)
    W = rng.uniform(0.05, 1.0, w.shape)
    W[w.occupancy] = 0
    V = flight_level_speed(W, w, FlightLevel(agl=2.0, p1=0.5, p2=1.5, mode="literal"))
    layer = flight_layer(w, 2.0)
    k = np.arange(8)[None, None, :]
    on = k == layer[:, :, None]
    expect = np.where(on, W**0.5, W**1.5)
    expect[w.occupancy] = 0
    np.testing.assert_array_equal(V, expect)


def test_capped_mode_caps_columns_at_the_level_value():
    w = _ramp_world()
    # W grows with height: 0 on the ground, then k / 7
    W = np.broadcast_to(np.arange(8) / 7.0, w.shape).copy()
    W[w.occupancy] = 0
    V = flight_level_speed(W, w, FlightLevel(agl=2.0, p1=0.5, p2=1.5))
    col = V[0, 0]  # ground at layer 0, level at layer 2 (W = 2/7)
    wl = 2 / 7
    np.testing.assert_allclose(col, [0, (1 / 7) ** 1.5, wl**0.5] + [wl**1.5] * 5)
    # the level is the fastest node of every column
    layer = flight_layer(w, 2.0)
    np.testing.assert_array_equal(np.argmax(V, axis=2), layer)


def test_band_and_graded_band():
    w = _ramp_world()
    W = np.full(w.shape, 0.5)
    W[w.occupancy] = 0
    V = flight_level_speed(W, w, FlightLevel(agl=3.0, p1=0.5, p2=2.0, band=1.0))
    np.testing.assert_allclose(V[0, 0, 2:5], 0.5**0.5)
    np.testing.assert_allclose(V[0, 0, 5], 0.5**2.0)
    G = flight_level_speed(W, w, FlightLevel(agl=3.0, p1=0.5, p2=2.0, band=2.0, graded=True))
    # exponents 0.5 at the level, 1.25 one cell off, 2.0 at the band edge
    np.testing.assert_allclose(G[0, 0, 1:6], 0.5 ** np.array([2.0, 1.25, 0.5, 1.25, 2.0]))


@pytest.mark.parametrize("bad", [0.0, -1.0, np.nan, np.inf])
def test_nonpositive_exponents_are_rejected(bad):
    with pytest.raises(InputError, match="p1"):
        FlightLevel(agl=2.0, p1=bad, p2=1.5)
    with pytest.raises(InputError, match="p2"):
        FlightLevel(agl=2.0, p1=0.5, p2=bad)


def test_other_bad_inputs():
    w = _ramp_world()
    W = np.full(w.shape, 0.5)
    with pytest.raises(InputError, match="band"):
        FlightLevel(agl=2.0, band=-1)
    with pytest.raises(InputError, match="mode"):
        FlightLevel(agl=2.0, mode="nope")
    with pytest.raises(InputError, match="FlightLevel"):
        flight_level_speed(W, w, 2.0)
    with pytest.raises(InputError, match="shape"):
        flight_level_speed(W[:2], w, FlightLevel(agl=2.0))
    with pytest.raises(InputError, match="agl"):
        flight_layer(w, 0.2)
    with pytest.raises(PlanningError, match="leaves the map"):
        flight_layer(w, 6.0)  # layer 2 + 6 = 8 > top layer 7
    with pytest.raises(InputError):
        exponents_from_k(1.0)
    assert exponents_from_k(0.3) == (0.3, 0.7)


@pytest.fixture(scope="module")
def open_field():
    return fm2uav.scenarios.open_field()


@pytest.mark.parametrize("level,p1,p2", [(10, 0.5, 1.3), (5, 0.5, 1.5), (2, 0.5, 2.5)])
def test_open_field_follows_the_level(open_field, level, p1, p2):
    sc = open_field
    p = fm2uav.plan(sc.world, sc.start, sc.goal, level=FlightLevel(agl=level * 15.0, p1=p1, p2=p2))
    r = flight_level_deviation(sc.world, p.path, level * 15.0)
    assert r.within >= 0.8
    assert r.inside_terrain == 0
    assert r.transition_share < 0.3
    # also on the middle 60 % of the points, with the layer as the reference
    rl = flight_level_deviation(sc.world, p.path, level * 15.0, reference="layer")
    n = len(p.path)
    assert np.mean(np.abs(rl.deviation[n // 5 : 4 * n // 5]) <= 15.0) >= 0.8


def test_literal_mode_climbs_to_the_ceiling(open_field):
    # the measured reason for the capped default (docs/tff.md)
    sc = open_field
    p = fm2uav.plan(sc.world, sc.start, sc.goal,
                    level=FlightLevel(agl=150.0, p1=0.5, p2=1.3, mode="literal",
                                      heights="fm2"))
    r = flight_level_deviation(sc.world, p.path, 150.0)
    assert r.within < 0.2
    assert p.path[:, 2].max() >= 39 * 15.0 - 1e-6


def test_start_below_terrain_or_above_ceiling(open_field):
    sc = open_field
    with pytest.raises(PointError, match="inside an obstacle"):
        fm2uav.plan(sc.world, (300.0, 300.0, 30.0), sc.goal, level=FlightLevel(agl=150.0))
    with pytest.raises(PointError, match="outside the map"):
        fm2uav.plan(sc.world, (300.0, 300.0, 900.0), sc.goal, level=FlightLevel(agl=150.0))
    with pytest.raises(PlanningError, match="leaves the map"):
        fm2uav.plan(sc.world, sc.start, sc.goal, level=FlightLevel(agl=15.0 * 30))
