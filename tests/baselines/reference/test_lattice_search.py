"""The compiled lattice search equals the state-by-state loop it replaced, tie for tie.

``_loop_search`` below is the search as it was before the padded, vectorised filter (the
same binary heap with lazy deletion, each primitive tested in turn), run as plain Python.
Both are run on seeded random maps and control sets — integer costs, so that many states
tie — and must return the same goal state, cost-to-come, parents and expansion count. The
kernel's heap (keys and state ids interleaved in one array) must pop what the two-array
heap of ``fm2uav.eikonal._heap`` pops, in the same order, ties included.
"""

from __future__ import annotations

import numpy as np
import pytest

from fm2uav.baselines.reference import _kernels, build_primitives
from fm2uav.eikonal import _heap
from fm2uav.eikonal._heap import sift_down, sift_up

_up, _down = sift_up.py_func, sift_down.py_func


def _loop_search(free, K, ptr, pdx, pdy, pend, pcost, cptr, cx, cy,
                 sources, goal_x, goal_y, goal_mask, heuristic_weight):
    """The former ``lattice_search``, line for line, in Python."""
    nx, ny = free.shape
    n_states = nx * ny * K
    cost = np.full(n_states, np.inf)
    parent = np.full(n_states, -1, np.int64)
    done = np.zeros(n_states, np.bool_)
    hk = np.empty(n_states * 64 + 16, np.float64)
    hv = np.empty(n_states * 64 + 16, np.int64)
    nopos = np.empty(0, np.int64)
    n = 0
    for s in sources:
        if cost[s] > 0.0:
            cost[s] = 0.0
            ix, iy = s // K // ny, (s // K) % ny
            _up(hk, hv, nopos, n, heuristic_weight * np.sqrt((ix - goal_x) ** 2 + (iy - goal_y) ** 2), s)
            n += 1
    n_expanded, goal_state = 0, -1
    while n > 0:
        s = hv[0]
        n -= 1
        if n > 0:
            _down(hk, hv, nopos, n, hk[n], hv[n])
        if done[s]:
            continue
        done[s] = True
        n_expanded += 1
        k, cell = s % K, s // K
        ix, iy = cell // ny, cell % ny
        if ix == goal_x and iy == goal_y and goal_mask[k]:
            goal_state = s
            break
        c0 = cost[s]
        for p in range(ptr[k], ptr[k + 1]):
            tx, ty = ix + pdx[p], iy + pdy[p]
            if tx < 0 or ty < 0 or tx >= nx or ty >= ny:
                continue
            t = (tx * ny + ty) * K + pend[p]
            if done[t]:
                continue
            nc = c0 + pcost[p]
            if nc >= cost[t]:
                continue
            ok = True
            for q in range(cptr[p], cptr[p + 1]):
                qx, qy = ix + cx[q], iy + cy[q]
                if qx < 0 or qy < 0 or qx >= nx or qy >= ny or not free[qx, qy]:
                    ok = False
                    break
            if not ok:
                continue
            cost[t] = nc
            parent[t] = p
            h = 0.0
            if heuristic_weight > 0.0:
                h = heuristic_weight * np.sqrt((tx - goal_x) ** 2 + (ty - goal_y) ** 2)
            _up(hk, hv, nopos, n, nc + h, t)
            n += 1
    return goal_state, cost, parent, n_expanded


def _random_set(rng, K):
    """A control set of ``K`` headings: per heading a few primitives to nearby nodes, sorted
    like ``build_primitives``'s, integer costs >= 1, swept cells = a few nodes on the way
    plus the start and end nodes."""
    ptr, dx, dy, end, cost, cptr, cx, cy = [0], [], [], [], [], [0], [], []
    for _k in range(K):
        rows = set()
        for _ in range(int(rng.integers(1, 7))):
            d = (int(rng.integers(-3, 4)), int(rng.integers(-3, 4)))
            if d != (0, 0):
                rows.add((d[0], d[1], int(rng.integers(0, K))))
        for ddx, ddy, j in sorted(rows):
            dx.append(ddx), dy.append(ddy), end.append(j)
            cost.append(float(rng.integers(1, 4)))
            way = {(0, 0), (ddx, ddy)}
            for f in rng.random(int(rng.integers(0, 3))):
                way.add((int(np.floor(f * ddx + 0.5)), int(np.floor(f * ddy + 0.5))))
            for x, y in sorted(way):
                cx.append(x), cy.append(y)
            cptr.append(len(cx))
        ptr.append(len(dx))
    a = lambda v, t=np.int64: np.asarray(v, t)  # noqa: E731
    return a(ptr), a(dx), a(dy), a(end), a(cost, np.float64), a(cptr), a(cx), a(cy)


def _problem(rng, K, shape, prims, heuristic):
    free = rng.random(shape) > rng.uniform(0.0, 0.35)
    ny = shape[1]
    sx, sy = (int(v) for v in rng.integers(0, shape))
    gx, gy = (int(v) for v in rng.integers(0, shape))
    heads = rng.choice(K, size=int(rng.integers(1, K + 1)), replace=False)
    sources = ((sx * ny + sy) * K + np.append(heads, heads[:1])).astype(np.int64)  # one twice
    goal_mask = rng.random(K) < 0.5
    goal_mask[int(rng.integers(0, K))] = True
    return (free, K, *prims, sources, gx, gy, goal_mask, heuristic)


def _same(args):
    want = _loop_search(*args)
    got = _kernels.lattice_search(*args)
    assert got[0] == want[0] and got[3] == want[3]
    np.testing.assert_array_equal(got[1], want[1])
    np.testing.assert_array_equal(got[2], want[2])
    return want


@pytest.mark.parametrize("heuristic", [0.0, 0.5])
def test_random_lattices_with_ties_give_the_same_search(heuristic):
    rng = np.random.default_rng(20261203)
    ties = reached = 0
    for _case in range(40):
        K = int(rng.integers(1, 9))
        shape = (int(rng.integers(1, 14)), int(rng.integers(1, 14)))
        want = _same(_problem(rng, K, shape, _random_set(rng, K), heuristic))
        c = want[1][np.isfinite(want[1])]
        reached += c.size
        ties += c.size - np.unique(c).size
    assert ties > reached // 4  # the integer costs make many states tie


@pytest.mark.parametrize("model", ["dubins", "elastica", "rs"])
def test_real_control_sets_give_the_same_search(model):
    prims = build_primitives(model, 2.0, max_int=1, radius=2.5)
    cs = (prims.ptr, prims.dx, prims.dy, prims.end, prims.cost, prims.cell_ptr,
          prims.cell_x, prims.cell_y)
    rng = np.random.default_rng(7)
    for heuristic in (0.0, 1.0):
        for _case in range(3):
            _same(_problem(rng, len(prims.headings), (16, 12), cs, heuristic))


def test_a_source_in_an_obstacle_is_expanded_like_any_other():
    rng = np.random.default_rng(3)
    K = 4
    args = list(_problem(rng, K, (9, 9), _random_set(rng, K), 0.0))
    free = np.ones((9, 9), bool)
    free[2, 2] = False
    args[0] = free
    args[10] = np.array([(2 * 9 + 2) * K + 1], np.int64)
    _same(tuple(args))


def test_the_interleaved_heap_pops_like_the_two_array_heap():
    rng = np.random.default_rng(11)
    push, pop = _heap.push_pairs.py_func, _heap.pop_pairs.py_func
    size = 4000
    hk, hv, nopos = np.empty(size), np.empty(size, np.int64), np.empty(0, np.int64)
    hh = np.empty(2 * size)
    n = m = 0
    got, want = [], []
    for i in range(3000):  # pushes and pops mixed, few distinct keys: many ties
        if n > 0 and rng.random() < 0.4:
            want.append((hk[0], hv[0]))
            n -= 1
            if n > 0:
                _down(hk, hv, nopos, n, hk[n], hv[n])
            key, val, m = pop(hh, m)
            got.append((key, int(val)))
        else:
            key = float(rng.integers(0, 6))
            _up(hk, hv, nopos, n, key, i)
            n += 1
            m = push(hh, m, key, float(i))
    assert got == want and m == n
    assert len(set(want)) == len(want) and len({k for k, _ in want}) < len(want) // 100


def test_a_primitive_must_sweep_its_end_node():
    ptr = np.array([0, 1], np.int64)
    one = np.array([1], np.int64)
    with pytest.raises(ValueError, match="end node"):
        _kernels.lattice_search(
            np.ones((4, 4), bool), 1, ptr, one, one * 0, one * 0, np.ones(1),
            np.array([0, 1], np.int64), one * 0, one * 0, np.array([0], np.int64), 3, 3,
            np.ones(1, bool), 0.0)
