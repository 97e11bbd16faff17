"""The exact distance transform as it was written first (issue 27's baseline): plain Python,
one line at a time, each pass over the whole grid, the square root by numpy afterwards.

:mod:`fm2uav.eikonal._edt` reorders the work (lines gathered in blocks, the binary pass
in two sweeps, the root and the division inside the passes) and must give these bytes.
"""

from __future__ import annotations

import numpy as np


def edt_line(f: np.ndarray, w2: float) -> np.ndarray:
    """Felzenszwalb & Huttenlocher's 1D squared transform of ``f`` (inf = no sample)."""
    n = len(f)
    v = np.zeros(n, dtype=np.int64)
    z = np.zeros(n + 1)
    out = np.empty(n)
    k = -1
    for q in range(n):
        fq = float(f[q])
        if fq == np.inf:
            continue
        if k < 0:
            k = 0
            v[0] = q
            z[0], z[1] = -np.inf, np.inf
            continue
        while True:
            p = int(v[k])
            s = ((fq + w2 * q * q) - (float(f[p]) + w2 * p * p)) / (2.0 * w2 * (q - p))
            if s <= z[k] and k > 0:
                k -= 1
            else:
                break
        if s <= z[k]:
            v[0] = q
            z[0], z[1] = -np.inf, np.inf
            continue
        k += 1
        v[k] = q
        z[k] = s
        z[k + 1] = np.inf
    if k < 0:
        out[:] = np.inf
        return out
    k = 0
    for q in range(n):
        while z[k + 1] < q:
            k += 1
        d = q - int(v[k])
        out[q] = w2 * d * d + float(f[v[k]])
    return out


def squared_edt(occ: np.ndarray, hx: float, hy: float, hz: float) -> np.ndarray:
    """Squared distance [m²] of every node of the 3D ``occ`` to its nearest True node."""
    nx, ny, nz = occ.shape
    d = np.where(occ, 0.0, np.inf)
    for i in range(nx):
        for j in range(ny):
            d[i, j, :] = edt_line(d[i, j, :], hz * hz)
    if ny > 1:
        for i in range(nx):
            for k in range(nz):
                d[i, :, k] = edt_line(d[i, :, k], hy * hy)
    if nx > 1:
        for j in range(ny):
            for k in range(nz):
                d[:, j, k] = edt_line(d[:, j, k], hx * hx)
    return d
