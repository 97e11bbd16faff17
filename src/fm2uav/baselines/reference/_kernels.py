"""Compiled Dijkstra / A* over the (x, y, θ) lattice (numba).

State id ``s = (ix * ny + iy) * K + k``. The heap is a binary min-heap over
arrays with lazy deletion (stale entries are skipped when popped).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from ...eikonal._heap import sift_down, sift_up

__all__ = ["lattice_search"]


@njit(cache=True, inline="always")
def _push(hk, hv, nopos, n, key, val):
    """Add ``val`` with ``key`` to the heap of ``n`` entries; the new count."""
    sift_up(hk, hv, nopos, n, key, val)
    return n + 1


@njit(cache=True, inline="always")
def _pop(hk, hv, nopos, n):
    """The root ``(key, val)`` taken off the heap of ``n`` entries, and the new count."""
    key = hk[0]
    val = hv[0]
    n -= 1
    if n > 0:
        sift_down(hk, hv, nopos, n, hk[n], hv[n])
    return key, val, n


# long on purpose: one compiled search loop; helpers would add calls in the hot path
@njit(cache=True)
def lattice_search(
    free, K, ptr, pdx, pdy, pend, pcost, cptr, cx, cy,
    sources, goal_x, goal_y, goal_mask, heuristic_weight,
):
    """Cheapest lattice path from any source state to the goal node.

    Long by design (kernel): one compiled loop; splitting adds call overhead in the hot path.

    Parameters
    ----------
    free : bool[nx, ny]
        True where the node is free.
    K : int
        Number of headings.
    ptr, pdx, pdy, pend, pcost, cptr, cx, cy : arrays
        The control set (see ``Primitives``).
    sources : int64[:]
        Source state ids (cost 0).
    goal_x, goal_y : int
        Goal node.
    goal_mask : bool[K]
        Admissible goal headings.
    heuristic_weight : float
        0 → Dijkstra; > 0 → A* with ``weight * euclidean distance`` [cells]
        (admissible for weight <= min cost per unit length, i.e. 1).

    Returns
    -------
    goal_state : int
        Reached goal state id, or -1 if unreachable.
    cost : float64[nx*ny*K]
        Cost-to-come (inf where not settled/reached).
    parent : int64[nx*ny*K]
        Primitive index used to reach each state (-1 for sources / unreached).
    n_expanded : int
        States settled.
    """
    nx, ny = free.shape
    n_states = nx * ny * K
    cost = np.full(n_states, np.inf)
    parent = np.full(n_states, -1, np.int64)
    done = np.zeros(n_states, np.bool_)
    cap = 1 << 20
    hk = np.empty(cap, np.float64)
    hv = np.empty(cap, np.int64)
    nopos = np.empty(0, np.int64)  # no slot index: lazy deletion (stale entries skipped)
    n = 0
    for s in sources:
        if cost[s] > 0.0:
            cost[s] = 0.0
            ix = s // K // ny
            iy = (s // K) % ny
            h = heuristic_weight * np.sqrt((ix - goal_x) ** 2 + (iy - goal_y) ** 2)
            if n >= cap:
                cap *= 2
                hk = np.concatenate((hk, np.empty(cap - hk.size, np.float64)))
                hv = np.concatenate((hv, np.empty(cap - hv.size, np.int64)))
            n = _push(hk, hv, nopos, n, h, s)
    n_expanded = 0
    goal_state = -1
    while n > 0:
        key, s, n = _pop(hk, hv, nopos, n)
        if done[s]:
            continue
        done[s] = True
        n_expanded += 1
        k = s % K
        cell = s // K
        ix = cell // ny
        iy = cell % ny
        if ix == goal_x and iy == goal_y and goal_mask[k]:
            goal_state = s
            break
        c0 = cost[s]
        for p in range(ptr[k], ptr[k + 1]):
            tx = ix + pdx[p]
            ty = iy + pdy[p]
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
                qx = ix + cx[q]
                qy = iy + cy[q]
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
            if n >= cap:
                cap *= 2
                hk2 = np.empty(cap, np.float64)
                hv2 = np.empty(cap, np.int64)
                hk2[:n] = hk[:n]
                hv2[:n] = hv[:n]
                hk = hk2
                hv = hv2
            n = _push(hk, hv, nopos, n, nc + h, t)
    return goal_state, cost, parent, n_expanded
