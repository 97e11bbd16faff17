"""The shared path geometry (fm2uav/geometry.py): resampling keeps the ends and the step."""

from __future__ import annotations

import numpy as np

from fm2uav.geometry import resample_path


def test_resample_keeps_ends_and_step():
    p = np.array([[0.0, 0, 0], [10, 0, 0], [10, 5, 0]])
    q = resample_path(p, 4.0)
    np.testing.assert_allclose(q[0], p[0])
    np.testing.assert_allclose(q[-1], p[-1])
    np.testing.assert_allclose(np.linalg.norm(np.diff(q, axis=0), axis=1)[:2], 4.0)
    # the third point is 12 m along the polyline: (10, 2, 0)
    np.testing.assert_allclose(q[3], [10, 2, 0])


def test_path_lengths_are_path_length_bit_for_bit():
    from fm2uav.geometry import path_length, path_lengths

    rng = np.random.default_rng(4)
    for dim in (2, 3):
        paths = [rng.normal(0, 50, (n, dim)).cumsum(axis=0) for n in (1, 2, 7, 8, 9, 300, 1000)]
        paths.append(np.zeros((3, dim)))
        assert path_lengths(paths) == [path_length(p) for p in paths]
    assert path_lengths([]) == []
