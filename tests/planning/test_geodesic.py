"""Tests of the geodesic extraction ``fm2uav.planning.geodesic.descend``.

Pyramid: exact/analytic fields on tiny grids → obstacles (wall with a gap,
L-shaped corridor) → degenerate fields (plateaus, inconsistent T) → seeded
random fields → 3D → errors. ``check_path`` is the reusable "is this path
correct?" checker used by most tests.
"""

from __future__ import annotations

import numpy as np
import pytest

from fm2uav.eikonal.fmm import fast_marching
from fm2uav.errors import InputError, PlanningError, UnreachableError
from fm2uav.planning.geodesic import descend, nearest_node


# --------------------------------------------------------------------------- helpers
def check_path(path, T, start, goal, blocked=None, samples=16):
    """Assert the invariants every path from :func:`descend` must satisfy.

    * shape (N, ndim), finite, inside the grid;
    * ``path[0] == start`` and ``path[-1] == goal`` exactly;
    * no two consecutive points equal (no zero-length segments);
    * every vertex, and ``samples`` points along every segment, has a nearest
      node that is not blocked and has finite T.
    """
    T = np.asarray(T)
    ndim = T.ndim
    path = np.asarray(path)
    assert path.ndim == 2 and path.shape[1] == ndim
    assert np.all(np.isfinite(path))
    assert np.all(path >= 0) and np.all(path <= np.asarray(T.shape) - 1)
    assert np.array_equal(path[0], np.asarray(start, dtype=float))
    assert np.array_equal(path[-1], np.asarray(goal, dtype=float))
    if len(path) > 1:
        assert np.all(np.any(np.diff(path, axis=0) != 0, axis=1))
    free = np.isfinite(T)
    if blocked is not None:
        free &= ~np.asarray(blocked, dtype=bool)
    t = np.linspace(0.0, 1.0, samples + 1)[:, None, None]
    dense = (path[:-1][None] * (1 - t) + path[1:][None] * t).reshape(-1, ndim)
    dense = np.vstack([path, dense])
    nodes = np.clip(nearest_node(dense), 0, np.asarray(T.shape) - 1)
    ok = free[tuple(nodes.T)]
    assert ok.all(), f"path enters blocked/unreached cells at {dense[~ok][:3].tolist()}"


def path_length(path, spacing=1.0):
    """Physical length [m] of a polyline given in index coordinates."""
    p = np.asarray(path) * np.asarray(spacing, dtype=float)
    return float(np.linalg.norm(np.diff(p, axis=0), axis=1).sum())


def distance_to_line(points, a, b):
    """Distance of each point to the infinite line through a and b (same units)."""
    points, a, b = (np.asarray(x, dtype=float) for x in (points, a, b))
    u = (b - a) / np.linalg.norm(b - a)
    d = points - a
    return np.linalg.norm(d - np.outer(d @ u, u), axis=1)


def euclid(shape, source, spacing=1.0):
    """Exact distance field [m] from a node (the ideal constant-speed T)."""
    h = np.broadcast_to(np.asarray(spacing, dtype=float), (len(shape),))
    idx = np.indices(shape, dtype=float)
    return np.sqrt(sum(((idx[k] - source[k]) * h[k]) ** 2 for k in range(len(shape))))


# --------------------------------------------------------------------------- tiny exact cases
def test_axis_line_exact():
    """Along a grid axis the gradient is exactly axial: the path is the axis."""
    T = fast_marching(np.ones((11, 7)), [(10, 3)])
    path = descend(T, (0.0, 3.0), (10.0, 3.0))
    check_path(path, T, (0.0, 3.0), (10.0, 3.0))
    assert np.all(path[:, 1] == 3.0)
    assert np.all(np.diff(path[:, 0]) > 0)
    # steps of 0.5 cell, then the final jump of at most one cell to the goal
    assert np.allclose(np.diff(path[:-1, 0]), 0.5)
    assert 0 < path[-1, 0] - path[-2, 0] <= 1.0


def test_straight_line_on_exact_distance_field():
    """The descent itself adds little error: on an exact distance field the path
    stays within 0.07 cell of the straight line (one-sided differences at the
    grid corner and the cone tip are the only error sources)."""
    T = euclid((21, 21), (20, 13))
    for start in [(0.0, 0.0), (0.3, 17.6), (5.5, 2.25)]:
        path = descend(T, start, (20, 13))
        check_path(path, T, start, (20, 13))
        assert distance_to_line(path, start, (20, 13)).max() < 0.07
        exact = np.hypot(*np.subtract((20, 13), start))
        assert path_length(path) == pytest.approx(exact, rel=2e-3)


def test_straight_line_constant_speed_fmm():
    """Constant speed, single source: straight to within the FMM's own error."""
    T = fast_marching(np.ones((21, 21)), [(20, 13)])
    path = descend(T, (0, 0), (20, 13))
    check_path(path, T, (0, 0), (20, 13))
    assert distance_to_line(path, (0, 0), (20, 13)).max() < 0.35
    assert path_length(path) == pytest.approx(np.hypot(20, 13), rel=5e-3)


def test_off_grid_start_and_goal_returned_exactly():
    T = fast_marching(np.ones((15, 12)), [(11, 9)])  # goal's nearest node
    start, goal = (1.37, 2.81), (10.6, 8.7)
    path = descend(T, start, goal)
    check_path(path, T, start, goal)
    assert path[0].tolist() == list(start) and path[-1].tolist() == list(goal)


def test_start_equals_goal_gives_single_point():
    T = fast_marching(np.ones((5, 5)), [(2, 2)])
    path = descend(T, (2.0, 2.0), (2.0, 2.0))
    assert path.shape == (1, 2) and path[0].tolist() == [2.0, 2.0]
    path = descend(T, (2.2, 1.9), (2.2, 1.9))
    assert path.shape == (1, 2) and path[0].tolist() == [2.2, 1.9]


def test_start_next_to_goal_is_one_segment():
    T = fast_marching(np.ones((5, 5)), [(2, 2)])
    path = descend(T, (2.8, 1.4), (2.1, 2.3))
    assert path.tolist() == [[2.8, 1.4], [2.1, 2.3]]


def test_single_node_grid():
    path = descend(np.zeros((1, 1)), (0, 0), (0, 0))
    assert path.tolist() == [[0.0, 0.0]]


def test_max_steps_zero_is_pure_discrete_descent():
    T = fast_marching(np.ones((12, 9)), [(10, 7)])
    path = descend(T, (0.4, 0.3), (10.2, 7.1), max_steps=0)
    check_path(path, T, (0.4, 0.3), (10.2, 7.1))
    inner = path[1:-1]
    assert len(inner) > 0 and np.all(inner == np.round(inner))  # nodes only
    node_T = T[tuple(inner.astype(int).T)]
    assert np.all(np.diff(node_T) < 0)  # strictly descending


def test_step_size_controls_resolution():
    T = euclid((31, 31), (30, 30))
    n_half = len(descend(T, (0, 0), (30, 30), step=0.5))
    n_quarter = len(descend(T, (0, 0), (30, 30), step=0.25))
    assert n_quarter == pytest.approx(2 * n_half, rel=0.1)


# --------------------------------------------------------------------------- spacing
def test_anisotropic_spacing_follows_physical_gradient():
    """A straight line in metres; using the index-space gradient instead would
    bend the path (T_i = hx^2 * i / T is not parallel to (i, j))."""
    h = (1.0, 2.5)
    shape, goal = (41, 17), (40, 16)
    ph = np.asarray(h)
    T = euclid(shape, goal, spacing=h)
    path = descend(T, (0, 0), goal, spacing=h)
    check_path(path, T, (0, 0), goal)
    # 0.24 m (0.1 cell of the 2.5 m axis), reached just before the goal in
    # the grid's corner, where node directions take the Fast Marching upwind
    # rule at the edge (was < 0.2 m with central / one-sided differences)
    assert distance_to_line(path * ph, (0, 0), np.multiply(goal, h)).max() < 0.27  # [m]
    steps = np.linalg.norm(np.diff(path[:-1] * ph, axis=0), axis=1)
    assert np.allclose(steps, 0.5 * min(h))  # physical step = step * min(spacing)

    T = fast_marching(np.ones(shape), [goal], spacing=h)
    path = descend(T, (0, 0), goal, spacing=h)
    check_path(path, T, (0, 0), goal)
    assert distance_to_line(path * ph, (0, 0), np.multiply(goal, h)).max() < 0.4 * max(h)
    assert path_length(path, h) == pytest.approx(np.hypot(40 * 1.0, 16 * 2.5), rel=5e-3)


def test_spacing_scale_invariance():
    """Multiplying spacing (and T) by a constant leaves the index path unchanged."""
    T = fast_marching(np.ones((20, 15)), [(18, 3)])
    a = descend(T, (1, 13), (18, 3), spacing=1.0)
    b = descend(T * 7.0, (1, 13), (18, 3), spacing=7.0)
    assert np.allclose(a, b)


# --------------------------------------------------------------------------- obstacles
def wall_with_gap(n=40, gap=(28, 32)):
    blocked = np.zeros((n, n), dtype=bool)
    blocked[19:22, :] = True
    blocked[19:22, gap[0] : gap[1]] = False
    return blocked


def test_wall_with_gap_goes_through_gap():
    blocked = wall_with_gap()
    T = fast_marching(np.where(blocked, 0.0, 1.0), [(35, 5)])
    start, goal = (5.0, 5.0), (35.0, 5.0)
    path = descend(T, start, goal, blocked=blocked)
    check_path(path, T, start, goal, blocked)
    in_wall = (path[:, 0] > 18.5) & (path[:, 0] < 21.5)
    assert in_wall.any()
    assert np.all((path[in_wall, 1] > 27.5) & (path[in_wall, 1] < 31.5))
    # geodesic length ~ T(start) (speed 1); the FMM overestimates slightly
    assert path_length(path) == pytest.approx(T[5, 5], rel=0.03)
    assert path_length(path) <= T[5, 5] * 1.01


def test_blocked_only_via_mask():
    """Blocked nodes given only through ``blocked`` (T finite there) are still
    avoided: descend treats them as inf."""
    blocked = wall_with_gap()
    T = fast_marching(np.where(blocked, 0.0, 1.0), [(35, 5)])
    T_filled = np.where(np.isfinite(T), T, 1e3)  # pretend the wall was reached
    before = T_filled.copy()
    path = descend(T_filled, (5, 5), (35, 5), blocked=blocked)
    check_path(path, T, (5, 5), (35, 5), blocked)
    assert np.array_equal(T_filled, before)  # the caller's T is not modified


def test_l_shaped_corridor():
    blocked = np.ones((30, 30), dtype=bool)
    blocked[2:8, 2:28] = False  # vertical arm (along y) at x = 2..7
    blocked[2:28, 22:28] = False  # horizontal arm (along x) at y = 22..27
    T = fast_marching(np.where(blocked, 0.0, 1.0), [(26, 24)])
    start, goal = (4.5, 3.2), (26.0, 24.4)
    path = descend(T, start, goal, blocked=blocked)
    check_path(path, T, start, goal, blocked)
    # shortest path hugs the inner corner (7, 22) of the L
    corner_dist = np.hypot(path[:, 0] - 7, path[:, 1] - 22).min()
    assert corner_dist < 2.0
    assert path_length(path) <= T[nearest_node(start)[0], nearest_node(start)[1]] + 1.5


def test_no_corner_cutting_between_diagonal_obstacles():
    """Two obstacles touching at a corner form a wall for the discrete moves."""
    blocked = np.zeros((12, 12), dtype=bool)
    for i in range(12):  # anti-diagonal staircase with a gap at the end
        if i < 10:
            blocked[i, 11 - i] = True
    T = fast_marching(np.where(blocked, 0.0, 1.0), [(11, 11)], order=1)
    for max_steps in (None, 0):
        path = descend(T, (0.0, 0.0), (11.0, 11.0), blocked=blocked, max_steps=max_steps)
        check_path(path, T, (0.0, 0.0), (11.0, 11.0), blocked, samples=64)
        # must go around the end of the staircase (x >= 10 when crossing)
        assert np.max(path[:, 0]) >= 10


# --------------------------------------------------------------------------- degenerate fields
def test_plateaus_terminate_at_goal():
    """np.floor of a distance field: zero gradient almost everywhere."""
    for q in (1.0, 0.5):
        T = np.floor(euclid((25, 25), (20, 4)) / q) * q
        for start in [(0, 24), (1.3, 0.2), (24, 24)]:
            path = descend(T, start, (20, 4))
            check_path(path, T, start, (20, 4))
            assert path_length(path) < 1.5 * np.hypot(*np.subtract((20, 4), start)) + 2


def test_noisy_field_terminates():
    """A monotone but noisy field (FMM times plus small positive noise that keeps
    every node above its best neighbour) still ends at the goal."""
    rng = np.random.default_rng(3)
    T = fast_marching(np.ones((30, 30)), [(15, 15)], order=1)
    T = T + rng.uniform(0, 0.3, T.shape) * (T > 0)
    path = descend(T, (0, 0), (15, 15))
    check_path(path, T, (0, 0), (15, 15))


def test_field_from_other_goal_raises_planning_error():
    T = fast_marching(np.ones((10, 10)), [(0, 0)])
    with pytest.raises(PlanningError, match="not computed from this goal"):
        descend(T, (9, 9), (9, 0))


def test_second_minimum_raises_stuck():
    """A field with another zero (two sources): descent from its basin gets stuck."""
    T = fast_marching(np.ones((10, 10)), [(0, 0), (9, 9)])
    with pytest.raises(PlanningError, match="stuck at node \\[0, 0\\]"):
        descend(T, (1.2, 2.4), (9, 9))
    path = descend(T, (7.0, 5.0), (9, 9))  # from the goal's basin it works
    check_path(path, T, (7.0, 5.0), (9, 9))


def test_inconsistent_blocked_mask_terminates_with_error():
    """T ignores the wall, the mask does not: the descent is driven into a dead
    end and must stop with an error, not loop."""
    blocked = np.zeros((20, 20), dtype=bool)
    blocked[10, 2:18] = True
    blocked[6:10, 2] = True
    blocked[6:10, 17] = True  # a cup open towards the start
    T = fast_marching(np.ones((20, 20)), [(18, 10)])
    with pytest.raises(PlanningError):
        descend(T, (3.0, 10.0), (18, 10), blocked=blocked)


# --------------------------------------------------------------------------- random fields
@pytest.mark.parametrize("seed", range(12))
def test_random_fields_2d(seed):
    rng = np.random.default_rng(seed)
    n = int(rng.integers(8, 40))
    m = int(rng.integers(8, 40))
    speed = rng.uniform(0.05, 1.0, (n, m))
    blocked = rng.random((n, m)) < rng.uniform(0.0, 0.35)
    speed[blocked] = 0.0
    free = np.argwhere(~blocked)
    goal_node = tuple(free[rng.integers(len(free))])
    h = tuple(rng.uniform(0.5, 3.0, 2))
    T = fast_marching(speed, [goal_node], spacing=h, order=int(rng.integers(1, 3)))
    reached = np.argwhere(np.isfinite(T))
    goal = np.asarray(goal_node) + rng.uniform(-0.49, 0.49, 2)
    goal = np.clip(goal, 0, np.array([n, m]) - 1)
    for _ in range(5):
        node = reached[rng.integers(len(reached))]
        start = np.clip(node + rng.uniform(-0.49, 0.49, 2), 0, np.array([n, m]) - 1)
        step = float(rng.choice([0.25, 0.5, 1.0]))
        path = descend(T, start, goal, spacing=h, blocked=blocked, step=step)
        check_path(path, T, start, goal, blocked)
        assert len(path) < 20 * (n + m) / step


@pytest.mark.parametrize("seed", range(4))
def test_random_fields_3d(seed):
    rng = np.random.default_rng(100 + seed)
    shape = tuple(int(s) for s in rng.integers(5, 16, 3))
    speed = rng.uniform(0.1, 1.0, shape)
    blocked = rng.random(shape) < 0.25
    speed[blocked] = 0.0
    free = np.argwhere(~blocked)
    goal = tuple(float(v) for v in free[rng.integers(len(free))])
    T = fast_marching(speed, [tuple(int(v) for v in goal)])
    reached = np.argwhere(np.isfinite(T))
    for _ in range(4):
        start = reached[rng.integers(len(reached))].astype(float)
        path = descend(T, start, goal, blocked=blocked)
        check_path(path, T, start, goal, blocked)


def test_travel_time_close_to_arrival_time():
    """On a smooth speed field the path's travel time matches T(start)."""
    n = 60
    x, y = np.meshgrid(np.arange(n), np.arange(n), indexing="ij")
    speed = 0.3 + 0.7 * np.exp(-((x - 30) ** 2 + (y - 20) ** 2) / 300.0)
    T = fast_marching(speed, [(55, 55)])
    path = descend(T, (3, 3), (55, 55), step=0.25)
    check_path(path, T, (3, 3), (55, 55))
    # travel time = sum of segment length / speed at the segment midpoint
    mid = 0.5 * (path[1:] + path[:-1])
    seg = np.linalg.norm(np.diff(path, axis=0), axis=1)
    v = speed[tuple(nearest_node(mid).T)]
    assert float(np.sum(seg / v)) == pytest.approx(T[3, 3], rel=0.03)


# --------------------------------------------------------------------------- 3D
def test_3d_straight_line():
    T = fast_marching(np.ones((30, 25, 20)), [(28, 22, 17)])
    start, goal = (1.0, 2.0, 0.0), (28.2, 22.1, 16.6)
    path = descend(T, start, goal)
    check_path(path, T, start, goal)
    assert distance_to_line(path[:-1], start, (28, 22, 17)).max() < 0.15

    E = euclid((30, 25, 20), (28, 22, 17))
    path = descend(E, start, goal)
    assert distance_to_line(path[:-1], start, (28, 22, 17)).max() < 0.05


def test_3d_slab_with_hole():
    shape = (30, 30, 20)
    blocked = np.zeros(shape, dtype=bool)
    blocked[14:16] = True
    blocked[14:16, 20:24, 12:16] = False  # the only way through
    T = fast_marching(np.where(blocked, 0.0, 1.0), [(27, 5, 3)])
    start, goal = (2.0, 5.0, 3.0), (27.0, 5.0, 3.0)
    path = descend(T, start, goal, blocked=blocked, spacing=(1.0, 1.0, 1.0))
    check_path(path, T, start, goal, blocked)
    crossing = path[(path[:, 0] > 13.5) & (path[:, 0] < 15.5)]
    assert len(crossing) > 0
    assert np.all((crossing[:, 1] > 19.5) & (crossing[:, 1] < 23.5))
    assert np.all((crossing[:, 2] > 11.5) & (crossing[:, 2] < 15.5))


def test_3d_single_layer_equals_2d():
    T2 = fast_marching(np.ones((15, 10)), [(12, 8)])
    T3 = fast_marching(np.ones((15, 10, 1)), [(12, 8, 0)])
    p2 = descend(T2, (1.5, 0.5), (12, 8))
    p3 = descend(T3, (1.5, 0.5, 0.0), (12, 8, 0))
    assert np.allclose(p3[:, :2], p2) and np.all(p3[:, 2] == 0)


# --------------------------------------------------------------------------- errors
def test_unreachable_start_raises():
    blocked = np.zeros((20, 20), dtype=bool)
    blocked[3:9, 3] = blocked[3:9, 8] = blocked[3, 3:9] = blocked[8, 3:9] = True  # a closed box
    T = fast_marching(np.where(blocked, 0.0, 1.0), [(15, 15)])
    with pytest.raises(UnreachableError, match="cannot reach the goal") as exc:
        descend(T, (5.2, 5.7), (15, 15), blocked=blocked)
    assert "[5, 6]" in str(exc.value)
    assert isinstance(exc.value, ValueError)


@pytest.mark.parametrize(
    "kwargs, start, goal, err, match",
    [
        ({}, (4.0, 1.0), (1, 1), PlanningError, "blocked node"),  # start in obstacle
        ({}, (1.0, 1.0), (4.0, 1.0), PlanningError, "blocked node"),  # goal in obstacle
        ({}, (-0.5, 1.0), (1, 1), PlanningError, "outside the grid"),
        ({}, (1.0, 9.5), (1, 1), PlanningError, "outside the grid"),
        ({}, (1.0, 1.0, 1.0), (1, 1), InputError, "2 coordinates"),
        ({}, (np.nan, 1.0), (1, 1), InputError, "finite"),
        ({"step": 0.0}, (1.0, 1.0), (1, 1), InputError, "step"),
        ({"step": 1.5}, (1.0, 1.0), (1, 1), InputError, "step"),
        ({"max_steps": -1}, (1.0, 1.0), (1, 1), InputError, "max_steps"),
        ({"spacing": (1.0, 0.0)}, (1.0, 1.0), (1, 1), InputError, "spacing"),
        ({"blocked": np.zeros((3, 3), bool)}, (1.0, 1.0), (1, 1), InputError, "shape"),
    ],
)
def test_bad_input(kwargs, start, goal, err, match):
    blocked = np.zeros((8, 8), dtype=bool)
    blocked[4, :6] = True
    T = fast_marching(np.where(blocked, 0.0, 1.0), [(1, 1)])
    kwargs = {"blocked": blocked, **kwargs}
    with pytest.raises(err, match=match):
        descend(T, start, goal, **kwargs)


def test_bad_field():
    with pytest.raises(InputError, match="2D or 3D"):
        descend(np.zeros(5), (0,), (0,))
    T = np.zeros((3, 3))
    T[1, 1] = np.nan
    with pytest.raises(InputError, match="nan"):
        descend(T, (0, 0), (0, 0))
    with pytest.raises(PlanningError, match="T = inf"):
        descend(np.full((3, 3), np.inf), (0, 0), (1, 1))
