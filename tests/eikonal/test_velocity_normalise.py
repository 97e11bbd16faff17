"""eikonal.velocity.normalise_distance in place (overwrite=True): the same values."""

from __future__ import annotations

import numpy as np

from fm2uav.eikonal.velocity import normalise_distance


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
