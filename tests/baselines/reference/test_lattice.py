"""Lattice reference planners: free-space accuracy, curvature bound, obstacles, errors."""

import math

import numpy as np
import pytest

from fm2uav import World
from fm2uav.geometry import menger_curvature, resample_path
from fm2uav.baselines.reference import build_primitives, dubins_length, lattice_headings, reference_path
from fm2uav.baselines.reference.primitives import biarc
from fm2uav.errors import InputError, PointError, UnreachableError

XI = 5.0  # metres = cells on a 1 m grid (the city default: 10 m on 2 m nodes)


@pytest.fixture(scope="module")
def free_world():
    return World(np.zeros((90, 90), bool), spacing=1.0)


def test_headings():
    h = lattice_headings(1)
    assert np.allclose(np.degrees(h), np.arange(0, 360, 45))
    assert len(lattice_headings(2)) == 16
    assert len(lattice_headings(4)) == 48


def test_biarc_joins_poses_exactly():
    rng = np.random.default_rng(3)
    for _ in range(50):
        t0, t1 = rng.uniform(-math.pi, math.pi, 2)
        dx, dy = rng.integers(-4, 5, 2)
        if dx == dy == 0:
            continue
        phi1, L1, k1, phi2, L2, k2, ok = biarc(t0, float(dx), float(dy), t1, 1.0)
        if not ok:
            continue
        # integrate the two arcs and land on the end pose
        def arc(x, y, h, k, L):
            if abs(k) < 1e-12:
                return x + L * math.cos(h), y + L * math.sin(h), h
            return x + (math.sin(h + k * L) - math.sin(h)) / k, y - (math.cos(h + k * L) - math.cos(h)) / k, h + k * L
        x, y, h = arc(0.0, 0.0, t0, float(k1), float(L1))
        x, y, h = arc(x, y, h, float(k2), float(L2))
        assert (x, y) == pytest.approx((dx, dy), abs=1e-9)
        assert math.remainder(h - t1, 2 * math.pi) == pytest.approx(0.0, abs=1e-9)


def test_dubins_primitives_respect_curvature():
    P = build_primitives("dubins", XI)
    pts = np.stack([P.pt_x, P.pt_y], 1)
    for p in range(0, P.count, 7):
        a, b = P.pt_ptr[p], P.pt_ptr[p + 1]
        seg = np.vstack([[0.0, 0.0], pts[a:b]])
        if len(seg) >= 3:
            assert menger_curvature(seg).max() <= 1.0 / XI * 1.05


@pytest.mark.parametrize(
    "start,goal",
    [
        ((10, 10, 0.0), (70, 40, 0.0)),
        ((10, 10, math.pi / 2), (60, 70, 0.0)),
        ((20, 20, 0.0), (30, 60, math.pi)),
        ((70, 15, math.atan2(1, 2)), (20, 70, math.pi / 2)),
        ((45, 45, 0.0), (45, 30, math.pi)),
    ],
)
def test_dubins_free_space_within_2_percent(free_world, start, goal):
    ref = reference_path(free_world, start[:2], goal[:2], model="dubins", xi=XI,
                         start_heading=start[2], goal_heading=goal[2])
    exact = dubins_length(start, goal, XI)
    assert ref.cost >= exact * (1 - 1e-9)          # every lattice path is a real Dubins-feasible curve
    assert ref.cost <= exact * 1.02                # and within 2 % of the optimum
    assert ref.length == pytest.approx(ref.cost, rel=2e-3)  # polyline of the samples
    k = menger_curvature(resample_path(ref.path, 0.5))
    assert k.max() <= 1.0 / XI * 1.1


@pytest.mark.slow
def test_free_headings_give_straight_line(free_world):
    for model in ("dubins", "elastica", "rs"):
        ref = reference_path(free_world, (10, 10), (70, 40), model=model, xi=XI)
        assert ref.cost == pytest.approx(math.hypot(60, 30), rel=1e-9)


def test_model_costs_are_ordered(free_world):
    kw = dict(xi=XI, start_heading=math.pi / 2, goal_heading=0.0)
    d = reference_path(free_world, (10, 10), (60, 50), model="dubins", **kw)
    e = reference_path(free_world, (10, 10), (60, 50), model="elastica", **kw)
    r = reference_path(free_world, (10, 10), (60, 50), model="rs", **kw)
    # sqrt(1 + x²) <= 1 + x²: the RS optimum is no dearer than the elastica one,
    # and both exceed the length of their path
    assert r.cost <= e.cost + 1e-9
    assert e.cost > e.length and r.cost > r.length
    assert d.cost == pytest.approx(d.length, rel=2e-3)


def test_goes_through_the_gap_and_avoids_obstacles():
    occ = np.zeros((80, 60), bool)
    occ[38:42, :] = True
    occ[38:42, 40:48] = False  # one gap, 8 m wide
    w = World(occ, spacing=1.0)
    for model in ("dubins", "elastica", "rs"):
        ref = reference_path(w, (10, 10), (70, 10), model=model, xi=XI)
        cells = np.floor(w.to_index(ref.path) + 0.5).astype(int)
        assert not occ[cells[:, 0], cells[:, 1]].any()
        crossing = ref.path[(ref.path[:, 0] > 38) & (ref.path[:, 0] < 41)]
        assert len(crossing) and np.all((crossing[:, 1] > 39) & (crossing[:, 1] < 48))
        assert np.allclose(ref.path[0], (10, 10)) and np.allclose(ref.path[-1], (70, 10))


def test_errors():
    occ = np.zeros((40, 30), bool)
    occ[20, :] = True
    w = World(occ, spacing=1.0)
    with pytest.raises(UnreachableError):
        reference_path(w, (5, 5), (35, 5), model="dubins", xi=XI)
    with pytest.raises(PointError):
        reference_path(w, (20, 5), (35, 5))
    with pytest.raises(PointError):
        reference_path(w, (5, 5), (95, 5))
    with pytest.raises(InputError):
        reference_path(w, (5, 5), (10, 5), model="bike")
    with pytest.raises(InputError):
        reference_path(World(np.zeros((4, 4, 4), bool), spacing=1.0), (1, 1, 1), (2, 2, 2))
    with pytest.raises(InputError):
        reference_path(World(np.zeros((10, 10), bool), spacing=(1.0, 2.0)), (1, 1), (5, 5))
