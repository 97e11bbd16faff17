"""Fixed-wing waypoints the firmware's navigation can follow: no leg too short to turn onto.

A fixed-wing does not stop at a waypoint: it counts a waypoint as reached some
distance before it and turns onto the next leg with its turn radius
(:class:`~fm2uav.autopilot.firmware.navigation.FixedWingNav`: ArduPlane's
``min(WP_RADIUS, L1) · Δψ/90°`` before the waypoint, radius ``V² / (g tan φ)``). A
leg shorter than the turn onto it plus the next waypoint's turn distance is
flown with an overshoot; a waypoint the aircraft is already within the turn
distance of when it reaches the previous one is never flown to at all
(:mod:`fm2uav.autopilot.firmware.flight_rules`, ``fw-skipped-waypoint``).

:func:`fit_turns` removes the free waypoints (not a via point, band end or hold)
that make such legs, as long as the merged leg stays within ``max(tolerance,
turn radius)`` of the planned path and keeps the floor and the zones
(:class:`~fm2uav.autopilot.legs.LegCheck`). Where a waypoint must stay, it gets a
small acceptance radius (``NAV_WAYPOINT`` param2; ArduPlane then reaches it within
that radius or when it crosses the line through it, never skipping it).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from .firmware.flight_rules import END_TURN_DEG, turn_angles
from .firmware.navigation import FixedWingNav
from .legs import LegCheck

__all__ = ["leg_needs", "fit_turns", "MIN_ACCEPTANCE"]

#: Smallest acceptance radius written for a waypoint that must stay [m].
MIN_ACCEPTANCE = 5.0


def leg_needs(xy: np.ndarray, nav: FixedWingNav, speed: float | None = None,
              acceptance: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """For each leg of a waypoint polyline: ``(length, needed, gap)`` [m].

    ``needed`` is the turn onto the leg plus the next waypoint's turn distance;
    ``gap`` is how far the aircraft still is from the leg's end waypoint when it
    reaches its start (the next waypoint is skipped if ``gap`` <= its turn distance).
    The first leg starts straight (no turn). The last waypoint is reached with the
    turn distance of a 90° turn: ArduPlane assumes 90° where the mission has no next
    leg to turn onto (``Plane::setup_turn_angle``: the end of the mission, an RTL).
    """
    n = len(xy)
    acc_r = np.zeros(n) if acceptance is None else np.asarray(acceptance, dtype=float)
    ang = turn_angles(xy)
    if n >= 2:
        ang[-1] = END_TURN_DEG
    d = np.diff(xy, axis=0)
    L = np.hypot(d[:, 0], d[:, 1])
    acc = np.array([nav.turn_distance(ang[k], speed, acc_r[k]) for k in range(n)])
    need = np.array([nav.turn_on_distance(ang[k], speed) + acc[k + 1] for k in range(n - 1)])
    gap = np.full(n - 1, np.inf)
    for k in range(1, n - 1):
        u = d[k - 1] / max(L[k - 1], 1e-9)
        at = xy[k] - u * min(acc[k], L[k - 1])
        gap[k] = float(np.hypot(*(xy[k + 1] - at))) - acc[k + 1]
    return L, need, gap


def _deviation(flown: np.ndarray, a: int, b: int) -> float:
    """Largest horizontal distance of the dense points a..b from the segment a-b [m]."""
    p = flown[a:b + 1, :2]
    s = flown[b, :2] - flown[a, :2]
    n2 = float(s @ s)
    if n2 < 1e-12:
        return float(np.hypot(*(p - flown[a, :2]).T).max())
    t = np.clip(((p - flown[a, :2]) @ s) / n2, 0.0, 1.0)
    q = flown[a, :2] + t[:, None] * s
    return float(np.hypot(*(p - q).T).max())


def fit_turns(
    indices: Any,
    flown: Any,
    world: Any,
    *,
    required: Any,
    keep: Any,
    nav: FixedWingNav,
    tolerance: float,
    terrain_frame: bool = False,
) -> tuple[np.ndarray, np.ndarray, dict[str, Any]]:
    """Remove the free waypoints that make legs too short to turn onto (module docstring).

    Parameters
    ----------
    indices : array_like of int
        Kept dense indices (sorted; first and last are the start and the goal).
    flown : array_like, shape (N, 3)
        The dense path at its flown altitude [m].
    world : World
    required : array_like, shape (N,)
        The floor above the surface at each dense point [m] (``-inf``: none).
    keep : array_like of int
        Dense indices that must stay waypoints (vias, band ends, holds).
    nav : FixedWingNav
        The firmware's navigation with the airframe's numbers (cruise speed).
    tolerance : float
        Douglas–Peucker tolerance [m]; a merged leg may deviate ``max(tolerance, R)``.
    terrain_frame : bool
        Legs follow the terrain (frame 10).

    Returns
    -------
    indices : ndarray of int
    acceptance : ndarray, shape (len(indices),)
        Acceptance radius of each kept waypoint [m] (0: the firmware's own).
    report : dict
        ``removed``, ``acceptance_set``, ``turn_radius_m``, ``turn_distance_90_m``,
        ``shortest_leg_m``.
    """
    p = np.asarray(flown, dtype=float)
    idx = [int(i) for i in np.asarray(indices, dtype=int)]
    forced = {idx[0], idx[-1]} | {int(i) for i in np.asarray(keep, dtype=int).ravel()}
    legs = (LegCheck(world, p, np.asarray(required, dtype=float), terrain_frame=terrain_frame)
            if getattr(world, "ndim", 3) == 3 else None)
    r_turn = nav.turn_radius()
    allow = max(float(tolerance), r_turn)
    removed = 0
    while len(idx) > 3:
        xy = p[idx, :2]
        L, need, gap = leg_needs(xy, nav)
        bad = [k for k in range(1, len(idx) - 1) if L[k] < need[k] - 1e-6 or gap[k] <= 1e-6]
        if not bad:
            break
        done = False
        for k in sorted(bad, key=lambda k: L[k]):
            for j in (k + 1, k):  # drop the leg's end first: the turn moves to the next point
                if idx[j] in forced or j in (0, len(idx) - 1):
                    continue
                a, b = idx[j - 1], idx[j + 1]
                if _deviation(p, a, b) > allow:
                    continue
                if legs is not None:
                    low, _, hits = legs.check(a, b)
                    if low < -1e-6 or hits:
                        continue
                del idx[j]
                removed += 1
                done = True
                break
            if done:
                break
        if not done:
            break
    xy = p[idx, :2]
    acc = np.zeros(len(idx))
    if len(idx) > 2:
        L, need, gap = leg_needs(xy, nav)
        for k in range(1, len(idx) - 1):
            if gap[k] <= 1e-6 or L[k] < need[k] - 1e-6:
                # a leg between waypoints that must stay is too short to turn onto (or
                # the aircraft reaches k+1 by radius before it turns onto it): shrink both
                r = max(MIN_ACCEPTANCE, min(255.0, np.floor(L[k] / 3.0)))
                acc[k] = acc[k] or r
                acc[k + 1] = acc[k + 1] or r
        if acc.any():
            _, _, gap = leg_needs(xy, nav, acceptance=acc)
    d = np.diff(xy, axis=0)
    report = {"removed": removed, "acceptance_set": int(np.count_nonzero(acc)),
              "turn_radius_m": round(r_turn, 1),
              "turn_distance_90_m": round(nav.turn_distance(90.0), 1),
              "shortest_leg_m": round(float(np.hypot(d[:, 0], d[:, 1]).min()), 1)
              if len(d) else None}
    return np.asarray(idx, dtype=np.int64), acc, report
