"""The binary min-heap of the compiled marches (numba): the two sifts, written once.

A heap of ``size`` entries lives in two arrays, ``key[i]`` (the priority, e.g. an
arrival time [s]) and ``item[i]`` (what it orders, e.g. a node index); slot 0 holds
the smallest key. An indexed heap also keeps ``pos[item] = slot`` up to date (so a
key can be lowered in place); a heap with lazy deletion passes an empty ``pos``.
Used by the source boxes of :mod:`._sources`. The same heap on one array of interleaved
``(key, item)`` pairs (:func:`push_pairs`, :func:`pop_pairs`: the same steps and
comparisons, so the same pops, ties included; a parent's and its children's keys and items
share cache lines) serves the lattice search of :mod:`fm2uav.baselines.reference`
(tests/baselines/reference/test_lattice_search.py checks the two layouts pop alike).
"""

from __future__ import annotations

from .._numba import njit

__all__ = ["sift_up", "sift_down", "push_pairs", "pop_pairs"]


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


@njit(cache=True, inline="always")
def _put_pair(h, p, t, c):
    """Slot ``p`` of the interleaved heap ``h`` holds item ``c`` with key ``t``."""
    h[2 * p] = t
    h[2 * p + 1] = c


@njit(cache=True, inline="always")
def push_pairs(h, n, key, val):
    """Add ``val`` with ``key`` to the heap of ``n`` entries in ``h``; the new count.

    The heap's slot ``i`` is ``h[2 i]`` (key) and ``h[2 i + 1]`` (the item, e.g. a state
    id, exact as a float below 2**53): a parent's key and its children's keys and items
    share cache lines. Same steps and comparisons as :func:`sift_up`, so the same order of
    pops, ties included."""
    p = n
    while p > 0:
        q = (p - 1) >> 1
        if h[2 * q] <= key:
            break
        _put_pair(h, p, h[2 * q], h[2 * q + 1])
        p = q
    _put_pair(h, p, key, val)
    return n + 1


@njit(cache=True, inline="always")
def pop_pairs(h, n):
    """The root ``(key, val)`` taken off the heap of ``n`` entries in ``h`` (see
    :func:`push_pairs`), and the new count; the steps of :func:`sift_down`."""
    key = h[0]
    val = h[1]
    n -= 1
    if n > 0:
        t = h[2 * n]
        c = h[2 * n + 1]
        p = 0
        while True:
            child = 2 * p + 1
            if child >= n:
                break
            if child + 1 < n and h[2 * child + 2] < h[2 * child]:
                child += 1
            if h[2 * child] >= t:
                break
            _put_pair(h, p, h[2 * child], h[2 * child + 1])
            p = child
        _put_pair(h, p, t, c)
    return key, val, n
