"""`lonlat_line_lengths`: the WGS84 length of written lines, equal to pyproj's own measure."""

from __future__ import annotations

import numpy as np
import pytest
from pyproj import Geod

from fm2uav.world.line_length import lonlat_line_lengths

GEOD = Geod(ellps="WGS84")


def _lines(rng, n, cols):
    out = []
    for _ in range(n):
        m = int(rng.integers(1, 30))
        lon = 8.5 + np.cumsum(rng.normal(0, 2e-4, m))
        lat = 47.4 + np.cumsum(rng.normal(0, 2e-4, m))
        pts = [lon, lat] + ([500 + np.cumsum(rng.normal(0, 3.0, m))] if cols == 3 else [])
        out.append(np.column_stack(pts))
    return out


def test_equals_geod_line_length_line_by_line_and_batch_independent():
    lines = _lines(np.random.default_rng(0), 60, 2)
    got = lonlat_line_lengths(lines)
    want = [GEOD.line_length(a[:, 0], a[:, 1]) if len(a) > 1 else 0.0 for a in lines]
    np.testing.assert_allclose(got, want, rtol=0, atol=1e-9)
    # each line alone gives the same number (the batch's joins count for nobody)
    alone = np.concatenate([lonlat_line_lengths([a]) for a in lines])
    np.testing.assert_allclose(got, alone, rtol=0, atol=1e-9)
    assert got[[len(a) == 1 for a in lines]].tolist() == [0.0] * sum(len(a) == 1 for a in lines)


def test_altitude_combines_with_the_geodesic_segment_by_segment():
    lines = _lines(np.random.default_rng(1), 30, 3)
    got = lonlat_line_lengths(lines)
    for a, g in zip(lines, got):
        _, _, d = GEOD.inv(a[:-1, 0], a[:-1, 1], a[1:, 0], a[1:, 1])
        assert g == pytest.approx(float(np.sum(np.hypot(d, np.diff(a[:, 2])))), abs=1e-9)
    # a vertical line: only its altitude change
    assert lonlat_line_lengths([[[8.5, 47.4, 0.0], [8.5, 47.4, 120.0]]])[0] == 120.0


def test_edges():
    assert lonlat_line_lengths([]).shape == (0,)
    assert lonlat_line_lengths([[[1.0, 2.0]]]).tolist() == [0.0]
    with pytest.raises(ValueError, match="same columns"):
        lonlat_line_lengths([[[0, 0], [0, 1]], [[0, 0, 0], [0, 0, 1]]])
