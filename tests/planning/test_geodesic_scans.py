"""The descent's scans of a whole field (issue 27: compiled, no map-sized temporaries) answer
as the numpy expressions they replaced."""

from __future__ import annotations

import numpy as np
import pytest

from fm2uav import InputError
from fm2uav.planning.geodesic import descend, drop_ties, reaches_any


def _numpy_drop_ties(T, node):
    t = T[node]
    if np.isfinite(t):
        ties = T == t
        if np.count_nonzero(ties) > 1:
            T[ties] = np.inf
            T[node] = t
    return T


@pytest.mark.parametrize("seed", range(6))
def test_drop_ties_as_numpy(seed):
    rng = np.random.default_rng(seed)
    shape = (7, 9, 5) if seed % 2 else (11, 13)
    T = np.round(rng.random(shape) * 4) / 4  # many ties
    T[rng.random(shape) < 0.2] = np.inf
    for node in [(0,) * len(shape), tuple(s - 1 for s in shape), tuple(s // 2 for s in shape)]:
        a, b = T.copy(), T.copy()
        assert drop_ties(a, node) is a
        np.testing.assert_array_equal(a, _numpy_drop_ties(b, node))
        assert a[node] == T[node]
    lone = np.arange(20.0).reshape(4, 5)  # no tie: nothing changes
    np.testing.assert_array_equal(drop_ties(lone.copy(), (1, 1)), lone)
    one = (1,) * T.ndim
    view, ref = T.copy()[:, ::2], T.copy()[:, ::2]  # not contiguous: the numpy way
    assert not view.flags.c_contiguous
    np.testing.assert_array_equal(drop_ties(view, one), _numpy_drop_ties(ref, one))


@pytest.mark.parametrize("seed", range(6))
def test_reaches_any_as_numpy(seed):
    rng = np.random.default_rng(seed)
    T = np.full((8, 6, 4), np.inf)
    T[rng.random(T.shape) < 0.5] = 1.0
    mask = rng.random(T.shape) < 0.1 * seed
    assert reaches_any(T, mask) == bool(np.isfinite(T[mask]).any())
    mask[...] = ~np.isfinite(T)
    assert reaches_any(T, mask) is False
    mask[np.unravel_index(np.argmin(T), T.shape)] = True
    assert reaches_any(T, mask) is True
    assert reaches_any(T[:, ::2], mask[:, ::2]) == bool(np.isfinite(T[:, ::2][mask[:, ::2]]).any())


@pytest.mark.parametrize("bad", [np.nan, -np.inf])
def test_descend_names_the_first_bad_time(bad):
    g = np.array([4.0, 4.0])
    T = np.hypot(*np.meshgrid(np.arange(6.0) - 4, np.arange(7.0) - 4, indexing="ij"))
    T[5, 6] = bad
    T[5, 2] = np.nan  # after it in C order: not the one named
    with pytest.raises(InputError, match=r"found (nan|-inf) at index \[5, 2\]"):
        descend(T, (0.0, 0.0), tuple(g))
    T[5, 2] = 1.0
    with pytest.raises(InputError, match=r"at index \[5, 6\]"):
        descend(T, (0.0, 0.0), tuple(g))
