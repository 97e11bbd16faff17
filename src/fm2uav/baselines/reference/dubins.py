"""Exact length of the shortest Dubins path in free space (Dubins 1957).

Used to validate the lattice reference (:mod:`.lattice`): the shortest
forward path of bounded curvature ``|κ| <= 1/ξ`` between two poses is one of
the six words LSL, RSR, LSR, RSL, RLR, LRL (arcs of radius ξ and straight
segments). Formulas of Shkel & Lumelsky (2001), in units of the radius.
"""

from __future__ import annotations

import math

import numpy as np

from ...errors import InputError

__all__ = ["dubins_length", "dubins_words"]

#: Tolerance on the existence tests (words with a zero-length straight part).
_EPS = 1e-10


def _mod2pi(a: float) -> float:
    return a % (2.0 * math.pi)


def dubins_words(d: float, alpha: float, beta: float) -> dict[str, float]:
    """Normalised lengths (in radii) of the six Dubins words.

    Parameters
    ----------
    d : float
        Distance between the two positions divided by the turning radius.
    alpha, beta : float
        Start and end headings relative to the direction start → goal [rad].

    Returns
    -------
    dict
        Word name → total length in turning radii (``inf`` where the word
        does not exist).
    """
    sa, ca = math.sin(alpha), math.cos(alpha)
    sb, cb = math.sin(beta), math.cos(beta)
    cab = math.cos(alpha - beta)
    out: dict[str, float] = {}

    # LSL
    p2 = 2 + d * d - 2 * cab + 2 * d * (sa - sb)
    if p2 >= -_EPS:
        p2 = max(p2, 0.0)
        tmp = math.atan2(cb - ca, d + sa - sb)
        out["LSL"] = _mod2pi(-alpha + tmp) + math.sqrt(p2) + _mod2pi(beta - tmp)
    # RSR
    p2 = 2 + d * d - 2 * cab + 2 * d * (sb - sa)
    if p2 >= -_EPS:
        p2 = max(p2, 0.0)
        tmp = math.atan2(ca - cb, d - sa + sb)
        out["RSR"] = _mod2pi(alpha - tmp) + math.sqrt(p2) + _mod2pi(-beta + tmp)
    # LSR
    p2 = -2 + d * d + 2 * cab + 2 * d * (sa + sb)
    if p2 >= -_EPS:
        p = math.sqrt(max(p2, 0.0))
        tmp = math.atan2(-ca - cb, d + sa + sb) - math.atan2(-2.0, p)
        out["LSR"] = _mod2pi(-alpha + tmp) + p + _mod2pi(-_mod2pi(beta) + tmp)
    # RSL
    p2 = d * d - 2 + 2 * cab - 2 * d * (sa + sb)
    if p2 >= -_EPS:
        p = math.sqrt(max(p2, 0.0))
        tmp = math.atan2(ca + cb, d - sa - sb) - math.atan2(2.0, p)
        out["RSL"] = _mod2pi(alpha - tmp) + p + _mod2pi(beta - tmp)
    # RLR
    tmp = (6.0 - d * d + 2 * cab + 2 * d * (sa - sb)) / 8.0
    if abs(tmp) <= 1 + _EPS:
        p = _mod2pi(2 * math.pi - math.acos(min(1.0, max(-1.0, tmp))))
        t = _mod2pi(alpha - math.atan2(ca - cb, d - sa + sb) + p / 2.0)
        out["RLR"] = t + p + _mod2pi(alpha - beta - t + p)
    # LRL
    tmp = (6.0 - d * d + 2 * cab + 2 * d * (-sa + sb)) / 8.0
    if abs(tmp) <= 1 + _EPS:
        p = _mod2pi(2 * math.pi - math.acos(min(1.0, max(-1.0, tmp))))
        t = _mod2pi(-alpha - math.atan2(ca - cb, d + sa - sb) + p / 2.0)
        out["LRL"] = t + p + _mod2pi(_mod2pi(beta) - alpha - t + p)
    return out


def dubins_length(start, goal, radius: float) -> float:
    """Length of the shortest Dubins path between two poses [m].

    Parameters
    ----------
    start, goal : sequence of 3 floats
        Poses ``(x [m], y [m], heading [rad])``.
    radius : float
        Minimum turning radius ξ [m] (curvature ``<= 1/ξ``).

    Returns
    -------
    float
        Path length [m].

    Examples
    --------
    >>> round(dubins_length((0, 0, 0), (10, 0, 0), 1.0), 9)
    10.0
    """
    s = np.asarray(start, dtype=float).reshape(-1)
    g = np.asarray(goal, dtype=float).reshape(-1)
    if s.size != 3 or g.size != 3 or not (np.all(np.isfinite(s)) and np.all(np.isfinite(g))):
        raise InputError("start and goal must be finite poses (x [m], y [m], heading [rad])")
    if not (np.isfinite(radius) and radius > 0):
        raise InputError(f"radius must be > 0 metres, got {radius!r}")
    dx, dy = g[0] - s[0], g[1] - s[1]
    d = math.hypot(dx, dy) / radius
    if d == 0.0 and abs(math.remainder(g[2] - s[2], 2 * math.pi)) < 1e-12:
        return 0.0
    phi = math.atan2(dy, dx) if d > 0 else 0.0
    words = dubins_words(d, _mod2pi(s[2] - phi), _mod2pi(g[2] - phi))
    return float(min(words.values())) * float(radius)
