"""The OMPL RRT baseline (baselines/rrt.py): valid paths around walls, 3D, errors."""

from __future__ import annotations

import numpy as np
import pytest

from fm2uav import World
from fm2uav.baselines.rrt import RRTOptions, plan_rrt
from fm2uav.errors import InputError, PointError, UnreachableError


def _wall_world():
    occ = np.zeros((60, 40), bool)
    occ[28:32, 0:30] = True
    return World(occ, spacing=1.0)


@pytest.mark.parametrize("planner", ["rrt", "rrtconnect", "rrtstar"])
def test_rrt_paths_are_valid(planner):
    w = _wall_world()
    r = plan_rrt(w, (5.0, 5.0), (55.0, 5.0), planner=planner,
                 options=RRTOptions(time_limit=0.3 if planner == "rrtstar" else 5.0))
    np.testing.assert_allclose(r.path[0], [5, 5])
    np.testing.assert_allclose(r.path[-1], [55, 5])
    cells = w.to_cell(r.path)
    assert not any(w.occupancy[c] for c in cells)
    assert r.path[:, 1].max() > 29.0  # around the wall
    # a path from (5, 5) to (55, 5) through a point with y >= 29 is at least 2 x |(25, 24)|
    lower = 2.0 * np.hypot(25.0, 24.0)
    assert r.length >= lower - 1e-6 and r.raw_length >= lower - 1e-6
    assert r.length == pytest.approx(np.linalg.norm(np.diff(r.path, axis=0), axis=1).sum())
    if planner == "rrtstar":
        # asymptotically optimal: its own (unsmoothed) path is near the shortest one (~71.2 m
        # around the wall's corner cells; plain RRT's raw paths are 85-125 m here), and the
        # smoothing (shortcuts, then a B-spline) may lengthen it a little, never much
        assert r.raw_length <= 1.15 * 71.2
        assert r.length <= 1.1 * r.raw_length
    else:
        assert r.length <= r.raw_length + 1e-6  # shortcut smoothing only shortens
    assert np.max(np.linalg.norm(np.diff(r.path, axis=0), axis=1)) <= 0.5 + 1e-9
    assert r.clearance >= 0.0 and r.timings["total"] > 0
    assert len(r.tree) > 0


def test_rrt_3d_and_errors():
    occ = np.zeros((20, 20, 10), bool)
    occ[8:12, :, :8] = True
    w = World(occ, spacing=2.0)
    r = plan_rrt(w, (4.0, 20.0, 4.0), (34.0, 20.0, 4.0), planner="rrtconnect")
    assert r.path.shape[1] == 3
    assert r.path[:, 2].max() >= 15.0  # over the wall
    with pytest.raises(PointError):
        plan_rrt(w, (20.0, 20.0, 2.0), (34.0, 20.0, 4.0))
    with pytest.raises(InputError):
        plan_rrt(w, (4.0, 20.0, 4.0), (34.0, 20.0, 4.0), planner="prm")
    sealed = occ.copy()
    sealed[8:12, :, :] = True
    with pytest.raises(UnreachableError):
        plan_rrt(World(sealed, spacing=2.0), (4.0, 20.0, 4.0), (34.0, 20.0, 4.0),
                 options=RRTOptions(time_limit=0.2))
