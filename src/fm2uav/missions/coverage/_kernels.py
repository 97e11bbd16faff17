"""Compiled kernels of the zigzag construction (numba).

The cost function is evaluated hundreds of times by the optimisers, so its two
steps live here and are shared by the cost (:mod:`.cost`) and the geometry
(:mod:`.bands`): no second implementation of the band rule exists.

Frame: for a steering angle α the band direction is ``u = (cos α, sin α)`` and
the sweep direction ``n = (-sin α, cos α)``; a point has along-band coordinate
``t = x cos α + y sin α`` and across coordinate ``s = -x sin α + y cos α`` [m].
"""

from __future__ import annotations

import math

import numpy as np

from ..._numba import njit

__all__ = ["strip_extents", "band_ends", "zigzag_cost"]


@njit(cache=True)
def _update(lo, hi, k, t):
    if t < lo[k]:
        lo[k] = t
    if t > hi[k]:
        hi[k] = t


@njit(cache=True)
def strip_extents(ax, ay, bx, by, angle, spacing):
    """Along-band extent of the area inside every visual-field strip.

    Parameters
    ----------
    ax, ay, bx, by : ndarray, shape (m,)
        Edges ``a -> b`` of the area's exterior ring [m].
    angle : float
        Steering angle α [rad].
    spacing : float
        Band spacing D [m].

    Returns
    -------
    smin : float
        Across coordinate of the tangent line [m] (band ``i`` lies at
        ``smin + (i + 1/2) D``).
    lo, hi : ndarray, shape (n,)
        Smallest / largest ``t`` [m] of the area within strip
        ``[smin + i D, smin + (i + 1) D]`` (exact: the extremes of a polygon
        clipped to a strip are vertices inside it or edge crossings with the
        strip's two boundary lines — the seeds' D/2 visual-field lines).
    """
    c = math.cos(angle)
    s = math.sin(angle)
    m = ax.size
    ta = ax * c + ay * s
    sa = -ax * s + ay * c
    tb = bx * c + by * s
    sb = -bx * s + by * c
    smin = sa.min()
    smax = sa.max()
    n = int(math.ceil((smax - smin) / spacing - 1e-9))
    if n < 1:
        n = 1
    lo = np.full(n, np.inf)
    hi = np.full(n, -np.inf)
    for e in range(m):
        k = int((sa[e] - smin) / spacing)
        if k > n - 1:
            k = n - 1
        _update(lo, hi, k, ta[e])
        s0 = min(sa[e], sb[e])
        s1 = max(sa[e], sb[e])
        if s1 <= s0:
            continue
        j0 = int(math.ceil((s0 - smin) / spacing))
        j1 = int(math.floor((s1 - smin) / spacing))
        for j in range(max(j0, 0), min(j1, n) + 1):
            sl = smin + j * spacing
            f = (sl - sa[e]) / (sb[e] - sa[e])
            t = ta[e] + f * (tb[e] - ta[e])
            if j >= 1:
                _update(lo, hi, j - 1, t)
            if j < n:
                _update(lo, hi, j, t)
    return smin, lo, hi


@njit(cache=True)
def band_ends(lo, hi):
    """Start and end ``t`` of every band in flight order [m].

    Band 0 is flown towards decreasing ``t`` (the seeds fly from the greatest
    x to the smallest), band 1 back, and so on. Two consecutive bands are
    joined by a semicircle, so their joined ends must lie on one perpendicular
    (the seeds' cut-point adjustment): the shorter band is extended to the
    longer one's cut point.
    """
    n = lo.size
    start = np.empty(n)
    end = np.empty(n)
    for i in range(n):
        even = i % 2 == 0
        a = hi[i] if even else lo[i]
        b = lo[i] if even else hi[i]
        if i > 0:
            a = max(hi[i], hi[i - 1]) if even else min(lo[i], lo[i - 1])
        if i < n - 1:
            b = min(lo[i], lo[i + 1]) if even else max(hi[i], hi[i + 1])
        start[i] = a
        end[i] = b
    return start, end


@njit(cache=True)
def zigzag_cost(ax, ay, bx, by, angle, spacing):
    """Cost C(α) = Σ (straight dᵢ + arc lᵢ) [m] of the zigzag (seeds eq. 5.4)."""
    smin, lo, hi = strip_extents(ax, ay, bx, by, angle, spacing)
    start, end = band_ends(lo, hi)
    total = 0.0
    for i in range(start.size):
        total += abs(end[i] - start[i])
    return total + (start.size - 1) * math.pi * spacing / 2.0
