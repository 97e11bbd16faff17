"""Straight legs between waypoints, checked against the world: ground, roofs, no-fly zones.

Douglas–Peucker (:mod:`fm2uav.autopilot.thin`) bounds the distance to the dense
path, not the height above the ground: a 5 m tolerance still lets a long leg cut
a ridge. :func:`refine_legs` checks every straight leg against the ground/roof
surface and the no-fly zones of the world, sampled finer than the DEM, and keeps
more waypoints where a leg would dip below the floor the dense path keeps
(``min_agl`` / ``agl - tolerance``) or enter a zone.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ..errors import InputError
from ..geometry import arc_length

__all__ = ["LegCheck", "refine_legs"]


def _leg_heights(world: Any, a: np.ndarray, b: np.ndarray, step: float,
                 terrain_frame: bool, agl_a: float, agl_b: float
                 ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Samples of the straight leg a-b every <= step m: (points, t, height above surface)."""
    L = float(np.hypot(*(b[:2] - a[:2])))
    n = max(int(np.ceil(L / step)), 1)
    t = np.arange(n + 1) / n
    pts = a + t[:, None] * (b - a)
    surf = np.asarray(world.surface_height(pts[:, 0], pts[:, 1]), dtype=float)
    if terrain_frame:
        # the autopilot holds the AGL interpolated between the waypoints' AGLs
        h = agl_a + t * (agl_b - agl_a)
        pts[:, 2] = np.asarray(world.ground_height(pts[:, 0], pts[:, 1]), dtype=float) + h
        return pts, t, pts[:, 2] - surf
    return pts, t, pts[:, 2] - surf


class LegCheck:
    """Straight legs between points of a dense flown path, checked against its floor and
    the world's zones (:func:`refine_legs`; the fixed-wing turn fitting re-checks the
    legs it merges, :mod:`fm2uav.autopilot.turns`).

    Parameters
    ----------
    world : World
    flown : ndarray, shape (N, 3)
        The dense path at its flown altitude (world z) [m].
    required : ndarray, shape (N,)
        Lowest admissible height above the surface at each dense point [m].
    step : float, optional
        Leg sampling [m] (default a quarter of
        :func:`~fm2uav.world.ground_model.sampling_step`).
    terrain_frame : bool
        The autopilot follows the terrain between waypoints (frame 10).
    """

    def __init__(self, world: Any, flown: np.ndarray, required: np.ndarray, *,
                 step: float | None = None, terrain_frame: bool = False) -> None:
        from ..world.ground_model import sampling_step

        self.world, self.p, self.req = world, flown, required
        self.step = 0.25 * sampling_step(world) if step is None else float(step)
        self.terrain_frame = terrain_frame
        ground = np.asarray(world.ground_height(flown[:, 0], flown[:, 1]), dtype=float)
        self.own_agl = flown[:, 2] - ground
        self.cum = arc_length(flown[:, :2])  # horizontal distance along the path

    def check(self, a: int, b: int) -> tuple[float, int, list[Any]]:
        """``(lowest margin above the floor [m], dense index where it is lowest, zone hits)``
        of the straight leg from dense point ``a`` to ``b``."""
        from ..world.zones import zone_violations

        p, req = self.p, self.req
        pts, t, h = _leg_heights(self.world, p[a], p[b], self.step, self.terrain_frame,
                                 self.own_agl[a], self.own_agl[b])
        # dense point under each sample, by horizontal arc length
        span = self.cum[b] - self.cum[a]
        k = a + np.searchsorted(self.cum[a:b + 1], self.cum[a] + t * span, side="left")
        k = np.clip(k, a, b)
        floor = np.minimum(req[k], req[np.clip(k - 1, a, b)])
        margin = h - floor
        inner = (k > 0) & (k < len(p) - 1)
        margin = np.where(inner, margin, np.inf)
        low = float(margin.min()) if len(margin) else np.inf
        worst = int(k[int(np.argmin(margin))]) if len(margin) else a
        hits = (zone_violations(self.world, pts if self.terrain_frame else np.array([p[a], p[b]]),
                                step=self.step) if getattr(self.world, "zones", ()) else [])
        return low, worst, hits


def refine_legs(
    indices: Any,
    flown: Any,
    world: Any,
    *,
    required: Any,
    step: float | None = None,
    terrain_frame: bool = False,
) -> tuple[np.ndarray, dict[str, Any]]:
    """Add waypoints where a straight leg would pass too low or through a no-fly zone.

    Every leg between consecutive kept points is sampled every ``step`` metres
    (default a quarter of :func:`~fm2uav.world.ground_model.sampling_step`, i.e. at most
    1/16 of a source-DEM pixel);
    where the leg's height above the surface (:meth:`World.surface_height`)
    falls below the ``required`` height of the dense path it replaces, or the
    leg enters a zone's kept-out air (:func:`fm2uav.world.zones.zone_violations`),
    the dense point where it is worst is kept too, and both halves are checked
    again. A leg of two neighbouring dense points is never split.

    Parameters
    ----------
    indices : array_like of int
        Kept indices (sorted, first and last included), e.g. from
        :func:`~fm2uav.autopilot.thin.thin_indices`.
    flown : array_like, shape (N, 3)
        The dense path at its flown altitude (world z) [m].
    world : World
    required : array_like, shape (N,)
        Lowest admissible height above the surface [m] at each dense point
        (``-inf``: no floor, e.g. the take-off and landing points).
    step : float, optional
        Leg sampling [m].
    terrain_frame : bool
        The autopilot follows the terrain between waypoints (MAVLink frame
        10): the height along a leg is the waypoints' AGL interpolated, above
        the ground, instead of a straight line in altitude.

    Returns
    -------
    indices : ndarray of int
        The kept indices with the added ones.
    report : dict
        ``added`` (count), ``lowest_margin_m`` (smallest leg height minus its
        floor), ``zone_splits``, ``unresolved`` (legs of neighbouring points that
        still fail; 0 normally).
    """
    p = np.asarray(flown, dtype=float)
    req = np.asarray(required, dtype=float)
    if p.ndim != 2 or p.shape[1] != 3 or req.shape != (len(p),):
        raise InputError(f"flown must be (N, 3) and required (N,), got {p.shape} and {req.shape}")
    legs = LegCheck(world, p, req, step=step, terrain_frame=terrain_frame)
    keep = set(int(i) for i in np.asarray(indices, dtype=int))
    keep |= {0, len(p) - 1}
    stack = [(a, b) for a, b in zip(sorted(keep)[:-1], sorted(keep)[1:])]
    added = zone_splits = unresolved = 0
    worst_margin = np.inf
    while stack:
        a, b = stack.pop()
        low, worst, hits = legs.check(a, b)
        if low >= -1e-6 and not hits:
            worst_margin = min(worst_margin, low)
            continue
        if b - a < 2:
            unresolved += 1
            worst_margin = min(worst_margin, low)
            continue
        if low < -1e-6:
            split = worst
        else:
            zone_splits += 1
            hx, hy = hits[0].point[:2]
            d = np.hypot(p[a + 1:b, 0] - hx, p[a + 1:b, 1] - hy)
            split = a + 1 + int(np.argmin(d))
        split = min(max(split, a + 1), b - 1)
        keep.add(split)
        added += 1
        stack.extend([(a, split), (split, b)])
    step = legs.step
    report = {"added": added, "zone_splits": zone_splits, "unresolved": unresolved,
              "lowest_margin_m": None if not np.isfinite(worst_margin)
              else round(float(worst_margin), 3), "step_m": round(float(step), 3)}
    return np.array(sorted(keep), dtype=np.int64), report
