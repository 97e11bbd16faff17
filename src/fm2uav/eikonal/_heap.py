"""The binary min-heap of the compiled marches (numba): the two sifts, written once.

A heap of ``size`` entries lives in two arrays, ``key[i]`` (the priority, e.g. an
arrival time [s]) and ``item[i]`` (what it orders, e.g. a node index); slot 0 holds
the smallest key. An indexed heap also keeps ``pos[item] = slot`` up to date (so a
key can be lowered in place); a heap with lazy deletion passes an empty ``pos``.
Used by the source boxes of :mod:`._sources`; the lattice search of
:mod:`fm2uav.baselines.reference` takes the same steps on one interleaved array, and its
tests check it against these two.
"""

from __future__ import annotations

from numba import njit

__all__ = ["sift_up", "sift_down"]


@njit(cache=True, inline="always")
def _put(key, item, pos, p, t, c):
    """Slot ``p`` holds item ``c`` with key ``t`` (and ``pos[c] = p`` in an indexed heap)."""
    key[p] = t
    item[p] = c
    if pos.shape[0] > 0:
        pos[c] = p


@njit(cache=True, inline="always")
def sift_up(key, item, pos, p, t, c):
    """Place item ``c`` with key ``t`` at slot ``p`` or above it: parents with a larger
    key move down a level. Returns the slot of ``c``."""
    while p > 0:
        q = (p - 1) >> 1
        if key[q] <= t:
            break
        _put(key, item, pos, p, key[q], item[q])
        p = q
    _put(key, item, pos, p, t, c)
    return p


@njit(cache=True, inline="always")
def sift_down(key, item, pos, size, t, c):
    """Place item ``c`` with key ``t`` at the root of a heap of ``size`` entries or below
    it: the smaller child moves up a level. Returns the slot of ``c``."""
    p = 0
    while True:
        child = 2 * p + 1
        if child >= size:
            break
        if child + 1 < size and key[child + 1] < key[child]:
            child += 1
        if key[child] >= t:
            break
        _put(key, item, pos, p, key[child], item[child])
        p = child
    _put(key, item, pos, p, t, c)
    return p
