"""Compiled clearance search for column worlds (private; see clearance.py)."""

from __future__ import annotations

import math

import numpy as np
from numba import njit


@njit(cache=True, error_model="numpy")
def column_clearance(points, surf, hx, hy, hz, ox, oy, oz):
    """Distance from each point to the nearest obstacle node of a column world.

    In a column world every obstacle column ``(i, j)`` is solid from layer 0
    up to ``surf[i, j]`` (``-1``: no obstacle). The nearest node of column
    ``(i, j)`` to a point at height ``z`` is the layer closest to ``z`` within
    ``[0, surf]``, so the search is 2D: columns are visited in rings of growing
    Chebyshev radius until the ring's smallest horizontal distance exceeds the
    best distance found.

    Parameters
    ----------
    points : ndarray, shape (N, 3)
        World coordinates [m].
    surf : ndarray of int64, shape (nx, ny)
        Top obstacle layer per column.
    hx, hy, hz : float
        Spacing [m].
    ox, oy, oz : float
        Origin [m].

    Returns
    -------
    ndarray, shape (N,)
        Distance [m] (``inf`` if there is no obstacle).
    """
    nx, ny = surf.shape
    out = np.empty(points.shape[0])
    rmax = nx + ny
    for p in range(points.shape[0]):
        x = points[p, 0]
        y = points[p, 1]
        z = points[p, 2]
        ci = int(math.floor((x - ox) / hx + 0.5))
        cj = int(math.floor((y - oy) / hy + 0.5))
        kz = (z - oz) / hz
        best2 = np.inf
        for r in range(rmax + abs(ci) + abs(cj) + 1):
            # smallest horizontal distance of any column on ring r
            ring = (r - 0.5) * min(hx, hy)
            if r > 0 and ring > 0 and ring * ring >= best2:
                break
            for i in range(ci - r, ci + r + 1):
                if i < 0 or i >= nx:
                    continue
                on_edge_i = i == ci - r or i == ci + r
                step = 1 if on_edge_i else 2 * r
                j = cj - r
                while j <= cj + r:
                    if 0 <= j < ny:
                        top = surf[i, j]
                        if top >= 0:
                            k = min(max(int(math.floor(kz + 0.5)), 0), top)
                            dx = ox + i * hx - x
                            dy = oy + j * hy - y
                            dz = oz + k * hz - z
                            d2 = dx * dx + dy * dy + dz * dz
                            if d2 < best2:
                                best2 = d2
                    if step == 0:
                        break
                    j += step
        out[p] = math.sqrt(best2)
    return out
