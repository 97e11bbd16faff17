"""descend_stopped: one whole march, each start descends the field a stopped march leaves."""

from __future__ import annotations

import numpy as np
import pytest

from fm2uav.errors import InputError, PlanningError, PointError, UnreachableError
from fm2uav.eikonal.fmm import fast_marching
from fm2uav.planning.geodesic import descend, descend_stopped, drop_ties


@pytest.mark.parametrize("shape,order", [((60, 50), 1), ((60, 50), 2), ((30, 25, 12), 2)])
def test_each_start_equals_the_descent_of_a_march_stopped_there(shape, order):
    rng = np.random.default_rng(len(shape) * 10 + order)
    V = rng.uniform(0.8, 1.0, shape)  # smooth enough for a source ball
    V[rng.random(shape) < 0.15] = 0.0
    g = tuple(n // 2 for n in shape)
    V[tuple(slice(c - 5, c + 6) for c in g)] = rng.uniform(0.8, 1.0, (11,) * len(shape))
    T = fast_marching(V, [g], order=order)
    ball = fast_marching(V, [g], order=order, stop_at=[g])
    assert np.isfinite(ball).sum() > 1  # the source ball is there
    fin = np.argwhere(np.isfinite(T))
    starts = fin[rng.choice(len(fin), 30, replace=False)] + rng.uniform(-0.4, 0.4, (30, len(shape)))
    starts = np.clip(starts, 0, np.asarray(shape) - 1)
    got = descend_stopped(T, list(starts), np.asarray(g, float), frozen=ball, threads=2)
    same = 0
    for s, r in zip(starts, got):
        sn = tuple(np.floor(s + 0.5).astype(int))
        Ts = drop_ties(fast_marching(V, [g], order=order, stop_at=[sn]), sn)
        if sn == g:
            continue
        want = descend(Ts, s, np.asarray(g, float))
        assert isinstance(r, np.ndarray)
        assert np.array_equal(r, want)
        same += 1
    assert same >= 25


def test_the_whole_field_would_give_other_paths():
    # the stopped field matters: descending the whole march differs for some start
    rng = np.random.default_rng(1)
    V = rng.uniform(0.2, 1.0, (50, 40))
    V[rng.random((50, 40)) < 0.2] = 0.0
    g = (25, 20)
    V[g] = 1.0
    T = fast_marching(V, [g])
    ball = fast_marching(V, [g], stop_at=[g])
    fin = np.argwhere(np.isfinite(T) & (T > 0))[::7].astype(float)
    got = descend_stopped(T, list(fin), np.asarray(g, float), frozen=ball)
    whole = [descend(T, s, np.asarray(g, float)) for s in fin]
    assert any(a.shape != b.shape or not np.array_equal(a, b) for a, b in zip(got, whole))


def test_drop_ties_keeps_the_node_and_drops_its_equals():
    T = np.array([[0.0, 1.0, 2.0], [1.0, 1.5, 2.0], [2.0, 2.0, np.inf]])
    out = drop_ties(T.copy(), (0, 2))
    assert out[0, 2] == 2.0
    assert np.isinf(out[1, 2]) and np.isinf(out[2, 0]) and np.isinf(out[2, 1])
    assert out[1, 1] == 1.5 and out[0, 1] == 1.0
    same = drop_ties(T.copy(), (1, 1))  # no tie: unchanged
    assert np.array_equal(same, T)


def test_failures_are_returned_per_start():
    V = np.ones((20, 20))
    V[10, :] = 0.0  # a wall: the upper half is cut off
    g = (3, 3)
    T = fast_marching(V, [g])
    ball = fast_marching(V, [g], stop_at=[g])
    got = descend_stopped(T, [(5.0, 5.0), (15.0, 5.0), (10.0, 4.0), (30.0, 1.0), (1.0,)],
                          (3.0, 3.0), frozen=ball, blocked=V == 0)
    assert isinstance(got[0], np.ndarray)
    assert isinstance(got[1], UnreachableError)
    assert isinstance(got[2], PointError)
    assert isinstance(got[3], PlanningError)
    assert isinstance(got[4], InputError)
    seen = []
    descend_stopped(T, [(5.0, 5.0), (15.0, 5.0), (6.0, 8.0)], (3.0, 3.0), frozen=ball,
                    on_done=lambda pos, res: seen.extend(pos))
    assert sorted(seen) == [0, 1, 2]
    with pytest.raises(InputError, match="threads"):
        descend_stopped(T, [(5.0, 5.0)], (3.0, 3.0), frozen=ball, threads=0)
    with pytest.raises(InputError, match="frozen"):
        descend_stopped(T, [(5.0, 5.0)], (3.0, 3.0), frozen=ball[:5])
