"""The march's layouts and shortcuts (issue 27, deliverable 2) give the same times, bit
for bit, as the march before them.

* **Interleaved layout** (``_kernels._buffers``): a 2D map without a plateau marches with
  ``T`` and ``1 / speed^2`` interleaved in one array (``unit = 2``), a uniform one in two
  separate arrays; a 3D map too, unless it has a plateau mask (then separate arrays);
  ``march(..., interleave=...)`` forces either.
* **Far neighbours while popping**: a far node next to the node just frozen has no other
  frozen neighbour, so the kernel takes the one-axis solution along that node's axis
  instead of the full update; the full update gives the same number.
* **The start box**: the seeding and the expansion of the nodes frozen on entry scan only
  the span of the start box (``st[_BEGIN]``, ``st[_END]``).

The digests pin the times of the kernel before these changes (commit 03b9820, computed
with it): a deliberate change of rounding must update them and say so.
"""

from __future__ import annotations

import hashlib
import math

import numpy as np
import pytest

from fm2uav.eikonal import _kernels, fast_marching

from .layout_cases import cases, fm2_field, free_near

INF = math.inf

#: sha256 (first 20 hex digits) of the arrival times of each case of ``layout_cases``,
#: computed with the march of commit 03b9820 (separate arrays, full updates, whole-grid
#: scans), renewed once for a deliberate change of rounding: since 7 December 2026 the
#: update solves its quadratic in ``T - tau_1`` (``_kernels._combine``, ``_solve_iso``),
#: without the cancellation of terms of size ``T^2``; the times moved by at most 3.2e-13
#: relative (2d fm2 o2 anisotropic; order 1 equal spacings 2D at most 1.2e-15).
BEFORE = {
    "2d fm2 o1": "a23f2f3fec640bbfbeb3",
    "2d fm2 o1 anisotropic": "b085341ac356966eafcc",
    "2d fm2 o2": "ba2b01754c1906622d79",
    "2d fm2 o2 anisotropic": "ca1065661a7dc20ee4d6",
    "2d fm2 o1 stop_at": "c710edbbc07e03c0eefc",
    "2d fm2 o1 70 sources": "328a09510b69d0f6f2ed",
    "2d fm2 o2 70 sources": "8d8547a064b7ef17291a",
    "2d uniform o1": "96002ac4f79f7c8c547a",
    "3d fm2 o1": "4fd1f176e8e9619bb6ed",
    "3d fm2 o2": "0c2c7c10945c04e45fd7",
}
CASES = cases()


def _digest(T):
    return hashlib.sha256(np.ascontiguousarray(T).tobytes()).hexdigest()[:20]


def test_the_cases_are_those_of_the_digests():
    assert sorted(CASES) == sorted(BEFORE)


@pytest.mark.parametrize("name", sorted(BEFORE))
def test_times_are_those_of_the_march_before_the_changes(name):
    v, src, opts = CASES[name]
    T = fast_marching(v, src, threads=1, **opts)
    assert np.isfinite(T).sum() > 0.5 * T.size * (0.01 if "stop_at" in name else 1.0)
    assert _digest(T) == BEFORE[name]


@pytest.fixture
def layouts(monkeypatch):
    """Records the layout of every march: 'interleaved' or 'separate'."""
    used = []
    original = _kernels._buffers

    def spy(*args, **kw):
        out = original(*args, **kw)
        used.append("interleaved" if out[4] == 2 else "separate")
        return out

    monkeypatch.setattr(_kernels, "_buffers", spy)
    return used


def test_a_map_without_plateau_marches_interleaved_a_uniform_one_separate(layouts):
    v = fm2_field((40, 36), 3)
    fast_marching(v, [free_near(v, (0.5, 0.5))], order=1)
    u = np.ones((40, 36))
    fast_marching(u, [(20, 18)], order=1)
    w = fm2_field((12, 10, 9), 3)
    fast_marching(w, [free_near(w, (0.5, 0.5, 0.5))], order=1)
    fast_marching(np.ones((12, 10, 9)), [(6, 5, 4)], order=1)
    # a 3D map saturated on most nodes keeps its plateau mask (separate arrays)
    sat = np.minimum(1.0, 3.0 * w)
    fast_marching(sat, [free_near(sat, (0.5, 0.5, 0.5))], order=1)
    assert layouts == ["interleaved", "separate", "interleaved", "separate", "separate"]


def _start_of(v, src, order, spacing=1.0):
    """The march's start of ``fast_marching(v, src)`` (its source ball on a box)."""
    from fm2uav.eikonal import fmm

    shape3 = v.shape + (1,) * (3 - v.ndim)
    h = fmm.as_spacing(spacing, v.ndim)
    h3 = h + (1.0,) * (3 - v.ndim)
    src3 = np.zeros((len(src), 3), dtype=np.int64)
    src3[:, : v.ndim] = src
    extent = max((n - 1) * hk for n, hk in zip(v.shape, h))
    radius = max(2.0 * max(h), 0.05 * extent)
    return fmm._source_start(fmm._as_speed(v), src3, shape3, h3, radius, 2.0 * max(h)), shape3, h3


def _march(v, start, shape3, h3, order, stops=None, **kw):
    stops = np.zeros((0, 3), dtype=np.int64) if stops is None else stops
    # the work buffer this thread's next march reuses, full of negative numbers: the
    # interleaved layout leaves the speeds beside the ghosts unset, and no scan may take
    # them for band nodes
    npad = int(np.prod([n + 2 for n in shape3[: 2 if shape3[2] == 1 else 3]]))
    _kernels._work_interleaved(npad).fill(-1.0)
    T, frozen = _kernels.march(np.ascontiguousarray(v, dtype=float).reshape(-1), start, shape3,
                               h3, order, stops, **kw)
    return T.copy(), frozen


@pytest.mark.parametrize("order", [1, 2])
@pytest.mark.parametrize("spacing", [1.0, "anisotropic"])
@pytest.mark.parametrize("field", ["fm2", "plateau", "uniform"])
@pytest.mark.parametrize("shape", [(61, 47), (23, 19, 17)])
def test_interleaved_and_separate_layouts_give_the_same_times(shape, field, spacing, order):
    v = fm2_field(shape, 5)
    if field == "plateau":  # a saturated W: the separate layout reads it from the mask
        # (3D: the walls' first layer slower, every other node at the plateau's speed;
        # 3 v saturates every free node of this small grid, the walls cover a fifth)
        slow = v[v > 0].min()
        v = np.minimum(1.0, 3.0 * v) if v.ndim == 2 else np.where(v == slow, slow, 1.0)
    elif field == "uniform":  # the separate layout reads no speed at all
        v = np.where(v > 0, 1.3, 0.0)
    if spacing == "anisotropic":
        spacing = (0.7, 1.1, 0.9)[: len(shape)]
    src = [free_near(v, (0.3, 0.6, 0.45)[: len(shape)])]
    start, shape3, h3 = _start_of(v, src, order, spacing)
    npad = int(np.prod([n + 2 for n in shape]))
    U, qp = _kernels._plateau(v.reshape(-1), np.empty(0), shape3, npad)
    assert (qp > 0, U.size > 1) == {"fm2": (False, False), "plateau": (True, True),
                                    "uniform": (True, False)}[field]
    far = free_near(v, (0.9, 0.2, 0.8)[: len(shape)])
    stops = np.array([[*far, 0][:3]], dtype=np.int64)
    for stop in (None, stops):
        a, fa = _march(v, start, shape3, h3, order, stop, interleave=True)
        b, fb = _march(v, start, shape3, h3, order, stop, interleave=False)
        np.testing.assert_array_equal(a, b)
        assert fa == fb > 100


@pytest.mark.parametrize("order", [1, 2])
def test_interleaved_restart_from_band_nodes_gives_the_same_times(order):
    # a restart: every node of the grid in the start box, frozen and band nodes spread
    v = fm2_field((50, 43), 6)
    T0 = fast_marching(v, [free_near(v, (0.5, 0.5))], order=order).reshape(-1)
    rng = np.random.default_rng(6)
    state = np.where(np.isfinite(T0), _kernels.FROZEN, _kernels.FAR).astype(np.uint8)
    band = (rng.random(T0.size) < 0.3) & np.isfinite(T0)
    state[band] = _kernels.BAND
    T = np.where(state > 0, T0 * np.where(band, 1.2, 1.0), np.inf)
    start = _kernels.Start.whole(T, state, (50, 43, 1))
    a, _ = _march(v, start, (50, 43, 1), (1.0, 1.0, 1.0), order, interleave=True)
    b, _ = _march(v, start, (50, 43, 1), (1.0, 1.0, 1.0), order, interleave=False)
    np.testing.assert_array_equal(a, b)
    # the band nodes' raised times were marched again, from their frozen neighbours
    np.testing.assert_array_equal(np.isfinite(a), np.isfinite(T0))
    assert (a[band] <= T[band]).all() and (a[band] < T[band]).mean() > 0.9


@pytest.mark.parametrize("order", [1, 2])
@pytest.mark.parametrize("shape3", [(31, 27, 1), (13, 11, 9)])
def test_a_start_box_gives_the_times_of_the_same_start_on_the_whole_grid(shape3, order):
    # frozen and band nodes on the box's first and last nodes and inside it: the scans
    # of the box's span must reach both ends
    rng = np.random.default_rng(8)
    v = rng.uniform(0.5, 1.5, shape3)
    lo, box = (3, 4, 2 if shape3[2] > 1 else 0), (6, 5, 4 if shape3[2] > 1 else 1)
    Tb = np.full(box, np.inf)
    sb = np.zeros(box, dtype=np.uint8)
    Tb.flat[0], sb.flat[0] = 0.0, _kernels.FROZEN
    Tb.flat[-1], sb.flat[-1] = 0.5, _kernels.BAND
    Tb.flat[7], sb.flat[7] = 0.25, _kernels.BAND
    start = _kernels.Start(lo, box, Tb.reshape(-1), sb.reshape(-1))
    T = np.full(shape3, np.inf)
    s = np.zeros(shape3, dtype=np.uint8)
    inner = tuple(slice(a, a + n) for a, n in zip(lo, box))
    T[inner], s[inner] = Tb, sb
    whole = _kernels.Start.whole(T.reshape(-1), s.reshape(-1), shape3)
    h3 = (1.0, 1.0, 1.0)
    a, fa = _march(v.reshape(-1), start, shape3, h3, order)
    b, fb = _march(v.reshape(-1), whole, shape3, h3, order)
    np.testing.assert_array_equal(a, b)
    assert fa == fb == v.size - 1  # every node but the frozen one, the band ones too


@pytest.mark.parametrize("seed", range(5))
def test_far_neighbour_update_is_the_full_update_with_one_frozen_neighbour(seed):
    # what the kernel computes for a far neighbour of the node just frozen (time tc on
    # the axis of weight ih2) against the full update with the other axes empty
    rng = np.random.default_rng(seed)
    for _ in range(200):
        tc = float(rng.uniform(0.0, 100.0))
        q = float(rng.uniform(1e-4, 10.0))
        ih2 = float(rng.uniform(0.1, 10.0))
        hh = 1.0 / ih2
        assert _kernels._solve_iso(tc, INF, INF, q * hh) == tc + math.sqrt(q * hh)
        assert _kernels._solve_iso(INF, tc, INF, q * hh) == tc + math.sqrt(q * hh)
        assert _kernels._solve_iso(INF, INF, tc, q * hh) == tc + math.sqrt(q * hh)
        short = tc + math.sqrt(q / ih2)
        assert _kernels._combine(tc, ih2, INF, 0.0, INF, 0.0, q) == short
        assert _kernels._combine(INF, 0.0, tc, ih2, INF, 0.0, q) == short
        assert _kernels._combine(INF, 0.0, INF, 0.0, tc, ih2, q) == short
        # order 2: the axis term along the frozen node's axis, weight 9/4 ih2
        tau = float(rng.uniform(0.0, 100.0))
        assert (_kernels._combine(INF, 0.0, tau, 2.25 * ih2, INF, 0.0, q)
                == tau + math.sqrt(q / (2.25 * ih2)))
        assert (_kernels._combine(INF, 0.0, INF, 0.0, tau, 2.25 * ih2, q)
                == tau + math.sqrt(q / (2.25 * ih2)))
