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
