"""Compiled one-pass column scan of a 3D occupancy grid (private; see World.surface_index)."""

from __future__ import annotations

import numpy as np

from .._numba import njit, prange


@njit(cache=True, error_model="numpy", parallel=True)
def _scan(occ, top, solid):
    nx, ny, nz = occ.shape
    for i in prange(nx):
        for j in range(ny):
            t = -1
            for k in range(nz - 1, -1, -1):
                if occ[i, j, k]:
                    t = k
                    break
            top[i, j] = t
            ok = True
            for k in range(t):
                if not occ[i, j, k]:
                    ok = False
                    break
            solid[i, j] = ok


def column_tops(occ: np.ndarray) -> tuple[np.ndarray, bool]:
    """Top obstacle layer of every column, and whether every column is solid below it.

    Parameters
    ----------
    occ : ndarray of bool, shape (nx, ny, nz)
        Occupancy, True = obstacle.

    Returns
    -------
    top : ndarray of int64, shape (nx, ny)
        Index of the topmost True node of each column, ``-1`` for a column without one.
    solid : bool
        True if every column is True from layer 0 up to ``top`` (a column world:
        terrain, extruded buildings), i.e. ``occ == (k <= top)``.

    One pass over the grid without temporaries (the numpy form, ``argmax`` over
    the reversed axis plus a comparison with ``k <= top``, allocates the grid's size
    twice: 1.4 GB on a 3000 x 3000 x 78 DEM world).
    """
    nx, ny, _ = occ.shape
    top = np.empty((nx, ny), dtype=np.int64)
    solid = np.empty((nx, ny), dtype=np.bool_)
    _scan(np.ascontiguousarray(occ), top, solid)
    return top, bool(solid.all())
