"""world._columns.column_tops: the one-pass surface index and solid-columns test."""

from __future__ import annotations

import numpy as np

from fm2uav.world._columns import column_tops


def test_column_tops_matches_numpy():
    rng = np.random.default_rng(3)
    occ = rng.random((9, 7, 11)) < 0.3
    top, solid = column_tops(occ)
    has = occ.any(axis=2)
    expect = np.where(has, 10 - np.argmax(occ[:, :, ::-1], axis=2), -1)
    np.testing.assert_array_equal(top, expect)
    k = np.arange(11)
    assert solid == bool(np.array_equal(occ, k[None, None, :] <= top[:, :, None]))
    assert column_tops(k[None, None, :] <= top[:, :, None])[1]
