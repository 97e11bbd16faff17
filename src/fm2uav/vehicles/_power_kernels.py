"""Compiled bisection of the rotor induced velocity (private; see power.induced_velocity)."""

from __future__ import annotations

import math

import numpy as np

from .._numba import njit


@njit(cache=True)
def bisect_induced(v, vz, vh, vh2, halvings, out):
    """Solve ``v_i · sqrt(V² + (Vz + v_i)²) = v_h²`` for each state, into ``out``.

    The same IEEE operations, in the same order, as ``power._bisect`` (bit for bit): each
    state is bisected on ``[0, v_h + |Vz|]`` ``halvings`` times on its own. The halvings are
    the outer loop and the states the inner one, without branches (a select), so that the
    compiler runs several states in one vector instruction.

    Parameters
    ----------
    v, vz : float64[n]
        Airspeed and climb rate [m/s] of each state (contiguous).
    vh, vh2 : float
        Hover induced velocity ``v_h`` [m/s] and its square [m²/s²] (Python's ``vh ** 2``).
    halvings : int
        Bisection steps.
    out : float64[n]
        The induced velocities [m/s].
    """
    n = v.size
    v2 = np.empty(n)
    lo = np.zeros(n)
    hi = np.empty(n)
    for i in range(n):
        v2[i] = v[i] * v[i]
        hi[i] = vh + abs(vz[i])
    for _ in range(halvings):
        for i in range(n):
            mid = 0.5 * (lo[i] + hi[i])
            s = vz[i] + mid
            below = mid * math.sqrt(v2[i] + s * s) < vh2
            lo[i] = mid if below else lo[i]
            hi[i] = hi[i] if below else mid
    for i in range(n):
        out[i] = 0.5 * (lo[i] + hi[i])
