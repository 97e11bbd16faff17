"""eikonal.velocity.normalise_distance in place (overwrite=True), and normalised_distance
(the map and its scale in one array, on the threads asked for): the same values."""

from __future__ import annotations

import numpy as np
import pytest

from fm2uav import InputError
from fm2uav.eikonal import _edt
from fm2uav.eikonal.velocity import (distance_map, distance_scale, normalise_distance,
                                     normalised_distance, velocity_map)


def test_normalise_in_place_gives_the_same_values():
    rng = np.random.default_rng(5)
    d = rng.random((6, 5, 4)) * 40.0
    expect = normalise_distance(d)
    work = d.copy()
    out = normalise_distance(work, overwrite=True)
    assert out is work
    np.testing.assert_array_equal(out, expect)
    ints = np.arange(4)  # not float64: a new array, the input untouched
    assert normalise_distance(ints, overwrite=True) is not ints and ints[3] == 3


def _maps():
    rng = np.random.default_rng(8)
    occ2 = rng.random((40, 31)) < 0.04
    occ3 = rng.random((17, 15, 9)) < 0.03
    return [(occ2, 1.0), (occ3, (15.0, 15.0, 10.0)), (np.zeros((9, 7), bool), 2.0),
            (np.ones((4, 5, 3), bool), 1.0)]


@pytest.mark.parametrize("k", range(4))
@pytest.mark.parametrize("method, walls", [("edt", False), ("edt", True), ("fmm", False),
                                           ("fmm", True)])
def test_normalised_distance_is_normalise_of_distance_map(k, method, walls):
    occ, h = _maps()[k]
    if method == "fmm" and occ.all():
        pytest.skip("a map of obstacles only has no boundary to march from (refused before)")
    d = distance_map(occ, spacing=h, method=method, walls=walls)
    W, scale = normalised_distance(occ, spacing=h, method=method, walls=walls)
    np.testing.assert_array_equal(W, normalise_distance(d))
    assert scale == distance_scale(d) or (np.isnan(scale) and np.isnan(distance_scale(d)))
    assert W.shape == occ.shape


@pytest.mark.parametrize("k", range(4))
def test_distance_and_velocity_maps_do_not_depend_on_the_threads(k, monkeypatch):
    occ, h = _maps()[k]
    one = velocity_map(occ, spacing=h, saturation_distance=20.0, exponent=0.7, threads=1)
    dist1 = distance_map(occ, spacing=h, threads=1)
    monkeypatch.setattr(_edt, "EDT_PARALLEL_MIN_NODES", 0)  # the big grids' path
    np.testing.assert_array_equal(
        velocity_map(occ, spacing=h, saturation_distance=20.0, exponent=0.7, threads=2), one)
    np.testing.assert_array_equal(distance_map(occ, spacing=h, threads=2), dist1)
    monkeypatch.setenv("FM2UAV_THREADS", "2")
    np.testing.assert_array_equal(distance_map(occ, spacing=h), dist1)


def test_bad_thread_counts_are_refused():
    occ = np.eye(5, dtype=bool)
    for bad in (0, -1, 1.5):
        with pytest.raises(InputError, match="threads"):
            distance_map(occ, threads=bad)
