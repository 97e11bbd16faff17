"""velocity_map / distance_map: exact tiny cases, options, FMM vs EDT, errors."""

import numpy as np
import pytest

from fm2uav import InputError, distance_map, velocity_map
from fm2uav.eikonal.velocity import normalise_distance, shape_velocity


def strip(n, obstacles=()):
    occ = np.zeros((n, 1), bool)
    for i in obstacles:
        occ[i, 0] = True
    return occ


def test_single_obstacle_strip_is_linear_ramp():
    W = velocity_map(strip(5, [0]))
    np.testing.assert_allclose(W[:, 0], [0.0, 0.25, 0.5, 0.75, 1.0])


def test_spacing_scales_distance_but_not_normalised_map():
    d = distance_map(strip(5, [0]), spacing=2.5)
    np.testing.assert_allclose(d[:, 0], [0.0, 2.5, 5.0, 7.5, 10.0])
    np.testing.assert_allclose(velocity_map(strip(5, [0]), spacing=2.5)[:, 0], [0, 0.25, 0.5, 0.75, 1])


def test_saturation_and_exponent_exact():
    # W0 = [0, .25, .5, .75, 1]; saturation 0.5 -> [0, .5, 1, 1, 1]; exponent 2 -> squares
    W = velocity_map(strip(5, [0]), saturation=0.5, exponent=2.0)
    np.testing.assert_allclose(W[:, 0], [0.0, 0.25, 1.0, 1.0, 1.0])


def test_walls_treat_border_as_obstacle():
    # ghost obstacle layers one spacing outside every border: on a 5 x 7 map the
    # distance of node (i, j) is min(i + 1, 5 - i, j + 1, 7 - j) spacings
    d = distance_map(np.zeros((5, 7), bool), spacing=2.0, walls=True)
    i, j = np.meshgrid(np.arange(5), np.arange(7), indexing="ij")
    expected = 2.0 * np.minimum.reduce([i + 1, 5 - i, j + 1, 7 - j])
    np.testing.assert_allclose(d, expected)
    W = velocity_map(np.zeros((5, 7), bool), walls=True)
    np.testing.assert_allclose(W, expected / expected.max())


def test_no_obstacle_gives_full_speed_everywhere():
    W = velocity_map(np.zeros((4, 3), bool))
    np.testing.assert_array_equal(W, np.ones((4, 3)))


def test_obstacles_are_zero_and_free_cells_positive():
    rng = np.random.default_rng(3)
    occ = rng.random((20, 15, 6)) < 0.2
    W = velocity_map(occ, spacing=(1.0, 2.0, 0.5))
    assert np.all(W[occ] == 0)
    assert np.all(W[~occ] > 0)
    assert W.max() == pytest.approx(1.0)


def test_anisotropic_edt_matches_brute_force():
    rng = np.random.default_rng(7)
    occ = rng.random((9, 7, 5)) < 0.1
    h = np.array([1.0, 2.0, 0.5])
    d = distance_map(occ, spacing=h)
    obst = np.argwhere(occ) * h
    nodes = np.argwhere(np.ones_like(occ)) * h
    brute = np.min(np.linalg.norm(nodes[:, None, :] - obst[None, :, :], axis=2), axis=1)
    np.testing.assert_allclose(d.reshape(-1), brute, atol=1e-12)


@pytest.mark.parametrize("order", [1, 2])
def test_fmm_method_close_to_exact_distance(order):
    # A disc obstacle in a 2D map: FMM from the obstacle nodes vs the exact EDT.
    # Both measure distance to the nearest obstacle node; the FMM error is the
    # scheme's discretisation error, a fraction of a cell per cell travelled
    # (bounded here by 1.5 cells over a 60-cell map at order 1, 0.6 at order 2).
    n, h = 61, 0.5
    x = np.arange(n) * h
    X, Y = np.meshgrid(x, x, indexing="ij")
    occ = (X - 10) ** 2 + (Y - 12) ** 2 <= 4.0**2
    exact = distance_map(occ, spacing=h, method="edt")
    approx = distance_map(occ, spacing=h, method="fmm", order=order)
    err = np.abs(approx - exact)
    assert np.all(approx[occ] == 0)
    assert err.max() <= (1.5 if order == 1 else 0.6) * h
    assert err.mean() <= 0.5 * h


def test_normalise_handles_all_inf():
    np.testing.assert_array_equal(normalise_distance(np.full((2, 2), np.inf)), np.ones((2, 2)))


def test_shape_velocity_does_not_modify_input():
    W = np.linspace(0, 1, 5)
    before = W.copy()
    shape_velocity(W, saturation=0.5, exponent=3.0)
    shape_velocity(W)
    np.testing.assert_array_equal(W, before)


@pytest.mark.parametrize(
    "kwargs, phrase",
    [
        ({"saturation": 0.0}, "saturation must be in (0, 1]"),
        ({"saturation": 1.5}, "saturation must be in (0, 1]"),
        ({"exponent": 0.0}, "exponent must be > 0"),
        ({"exponent": float("nan")}, "exponent must be > 0"),
        ({"method": "bfs"}, "method must be 'edt' or 'fmm'"),
        ({"spacing": -1.0}, "spacing must be finite and > 0"),
    ],
)
def test_bad_parameters_raise_input_error(kwargs, phrase):
    with pytest.raises(InputError) as exc:
        velocity_map(strip(5, [0]), **kwargs)
    assert phrase in str(exc.value)


def test_non_bool_occupancy_is_rejected_with_hint():
    with pytest.raises(InputError, match="occupancy > 0"):
        velocity_map(np.zeros((3, 3), int))


def test_saturation_distance_in_metres():
    # d = [0, 2.5, 5, 7.5, 10] m; d_sat = 5 m -> W = min(d / 5, 1) = [0, .5, 1, 1, 1];
    # exponent 2 squares it; the same margin on a map twice as large gives the same W
    occ = strip(5, [0])
    W = velocity_map(occ, spacing=2.5, saturation_distance=5.0, exponent=2.0)
    np.testing.assert_allclose(W[:, 0], [0.0, 0.25, 1.0, 1.0, 1.0])
    W9 = velocity_map(strip(9, [0]), spacing=2.5, saturation_distance=5.0)
    np.testing.assert_allclose(W9[:3, 0], [0.0, 0.5, 1.0])
    assert np.all(W9[2:, 0] == 1.0)
    # beyond the largest distance W never reaches 1: W = d / d_sat
    far = velocity_map(occ, spacing=2.5, saturation_distance=20.0)
    np.testing.assert_allclose(far[:, 0], [0.0, 0.125, 0.25, 0.375, 0.5])
    # it overrides the share-of-the-largest saturation
    np.testing.assert_allclose(velocity_map(occ, spacing=2.5, saturation=0.1,
                                            saturation_distance=5.0)[:, 0], [0, .5, 1, 1, 1])
    with pytest.raises(InputError, match="saturation_distance"):
        velocity_map(occ, saturation_distance=0.0)
    with pytest.raises(InputError, match="max_distance"):
        shape_velocity(np.ones(3), saturation_distance=1.0)
