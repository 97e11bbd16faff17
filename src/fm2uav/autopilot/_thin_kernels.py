"""Compiled Douglas–Peucker splits (:func:`fm2uav.autopilot.thin.thin_indices`).

Without a point budget the points Douglas–Peucker keeps do not depend on the order in which
segments are split: a segment is split at its farthest interior point (the first one of
equal distances) exactly when that distance exceeds the tolerance. :func:`split_all` does
those splits with an explicit stack. Its distances are computed in its own floating-point
order, which may differ from numpy's (BLAS) by a few units in the last place; a segment
whose decision those few units could change — its largest distance within ``REL`` of the
tolerance, or its two largest within ``REL`` of each other — is not decided here but handed
back, and the caller decides it with numpy's own arithmetic. The result is therefore the
numpy implementation's, bit for bit.
"""

from __future__ import annotations

import math

import numpy as np

from .._numba import njit

__all__ = ["split_all", "REL"]

#: Relative margin [-] (of the segment's coordinate scale) within which a decision is left
#: to numpy: far above the few rounding errors by which the two arithmetics can differ.
REL = 1e-11


@njit(cache=True)
def split_all(p: np.ndarray, tol: float, keep: np.ndarray, todo: np.ndarray,
              n_todo: int, open_: np.ndarray) -> int:
    """Split the segments ``todo[:n_todo]`` (rows ``(i, j)`` of point indices) recursively.

    Parameters
    ----------
    p : float64[N, d]
        The points [m].
    tol : float
        The tolerance [m].
    keep : bool[N]
        Set True at every split point.
    todo : int64[N, 2]
        A stack (capacity N) holding the segments to split first; overwritten.
    n_todo : int
        How many rows of ``todo`` hold segments.
    open_ : int64[N, 2]
        Receives the segments left undecided (module docstring).

    Returns
    -------
    int
        The number of undecided segments written to ``open_``.
    """
    d = p.shape[1]
    n_open = 0
    while n_todo > 0:
        n_todo -= 1
        i = todo[n_todo, 0]
        j = todo[n_todo, 1]
        if j - i < 2:
            continue
        L2 = 0.0
        for c in range(d):
            L2 += (p[j, c] - p[i, c]) * (p[j, c] - p[i, c])
        best = -1.0
        second = -1.0
        k_best = -1
        scale = 0.0  # the largest coordinate: numpy's rounding is relative to it
        for c in range(d):
            scale = max(scale, abs(p[i, c]), abs(p[j, c]), abs(p[j, c] - p[i, c]))
        for k in range(i + 1, j):
            t = 0.0
            if L2 > 0.0:
                dot = 0.0
                for c in range(d):
                    dot += (p[k, c] - p[i, c]) * (p[j, c] - p[i, c])
                t = min(max(dot / L2, 0.0), 1.0)
            s2 = 0.0
            for c in range(d):
                x = p[k, c] - p[i, c]
                scale = max(scale, abs(p[k, c]), abs(x))
                r = x - t * (p[j, c] - p[i, c])
                s2 += r * r
            dist = math.sqrt(s2)
            if dist > best:
                second = best
                best = dist
                k_best = k
            elif dist > second:
                second = dist
        margin = REL * (scale + best + 1e-300)
        if abs(best - tol) <= margin or (best > tol and best - second <= margin):
            open_[n_open, 0] = i
            open_[n_open, 1] = j
            n_open += 1
            continue
        if best <= tol:
            continue
        keep[k_best] = True
        todo[n_todo, 0] = i
        todo[n_todo, 1] = k_best
        todo[n_todo + 1, 0] = k_best
        todo[n_todo + 1, 1] = j
        n_todo += 2
    return n_open
