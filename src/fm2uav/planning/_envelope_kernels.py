"""Compiled slope sweeps of the altitude envelopes (:func:`fm2uav.planning.altitude._sweeps`).

The two passes are sequential recurrences (each value depends on the previous one), so they
are loops; compiled, a profile of a few thousand samples takes microseconds instead of the
milliseconds of the Python loop (a mission's safe returns compute hundreds of profiles).
"""

from __future__ import annotations

import numpy as np

from .._numba import njit

__all__ = ["sweep_pair"]


@njit(cache=True)
def sweep_pair(z: np.ndarray, d: np.ndarray, upper: bool, forward: float,
               backward: float) -> None:
    """Sweep ``z`` in place: forward ``z_i = pick(z_i, z_(i-1) + forward * d_(i-1))``, then
    backward ``z_i = pick(z_i, z_(i+1) + backward * d_i)``; ``pick`` is ``max`` (``upper``
    False: the envelope above) or ``min`` — as Python's builtins: the candidate replaces
    ``z_i`` only when strictly larger (smaller), so a NaN candidate never does.

    Parameters
    ----------
    z : float64[N]
        Bounds [m], overwritten by the envelope.
    d : float64[N - 1]
        Steps of the arc length [m].
    upper : bool
        ``True``: ``min`` (the envelope below an upper bound).
    forward, backward : float
        Slopes [m/m] of the two passes.
    """
    n = z.shape[0]
    for i in range(1, n):
        v = z[i - 1] + forward * d[i - 1]
        if (v < z[i]) if upper else (v > z[i]):
            z[i] = v
    for i in range(n - 2, -1, -1):
        v = z[i + 1] + backward * d[i]
        if (v < z[i]) if upper else (v > z[i]):
            z[i] = v
