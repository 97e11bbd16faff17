"""The leader's path as the formation's guide: partial goals, headings, grey levels.

Thesis ch. 6 step 5c: the leader's partial goal is the point ``leader_speed ·
cycle`` further along its FM² path; the followers' partial goals follow the
leader's pose there with eqs 6.1 / 6.2, their lateral offsets shrunk (and the
column stretched) by the grey level ``B`` (:func:`grey_levels`). Followers at a
flight level put their goal at that level over the terrain, the others at the
leader's height.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ...geometry import arc_length, at_arc_length
from ...planning import FlightLevel
from .local import StaticMaps
from .metrics import path_heading
from .shapes import FormationShape, slot_offsets, slot_positions

__all__ = ["grey_levels", "LeaderGuide"]


def grey_levels(
    maps: StaticMaps,
    shape: FormationShape,
    leader_goal: np.ndarray,
    heading: np.ndarray,
    dist: float,
    reference: float,
    *,
    mode: str = "goal",
    followers: np.ndarray | None = None,
    candidates: int = 41,
) -> np.ndarray:
    """Grey level ``B`` in [0, 1] of every follower (the shrink factor of eqs 6.1/6.2).

    The thesis deforms the formation in the leader's horizontal plane only
    ("the distances are only modified in the plane x–y"), so the grey level is
    measured there: the horizontal clearance ``c`` (distance to the terrain in
    the same height layer, :func:`~fm2uav.missions.formation.local.horizontal_clearance`)
    at the leader's height, saturated at ``reference``: ``B = min(1, c / reference)``
    — the grey level of a saturated ``W``. Followers on a flight level then
    take their height from the terrain under their deformed slot.

    Parameters
    ----------
    maps : StaticMaps
    shape : FormationShape
    leader_goal : ndarray, shape (3,)
        The leader's pose (position [m]) the slots follow.
    heading : ndarray, shape (2,)
        The leader's unit direction in the x–y plane.
    dist : float
        Safety distance [m].
    reference : float
        Clearance [m] at which ``B = 1`` (default of the mission: ``2·dist``,
        the nominal lateral offset).
    mode : {"goal", "follower"}
        ``"goal"`` (default): the largest ``B`` (of ``candidates`` values)
        whose deformed partial goal has ``c >= B·reference`` — a self-consistent
        grey level *of the partial goal* (thesis step 5c); it depends on the
        leader's pose only, so it cannot oscillate. ``"follower"``: the literal
        wording of eqs 6.1/6.2, ``c`` at the follower's current position
        ``followers`` (n, 3) [m] (taken at the leader's height).

    Returns
    -------
    ndarray, shape (n_followers,)
    """
    n = shape.n_followers
    z = float(leader_goal[2])
    if mode == "follower":
        pts = np.array(followers, dtype=float)
        pts[:, 2] = z
        return np.clip(maps.horizontal_clearance_at(pts) / reference, 0.0, 1.0)
    B = np.linspace(1.0, 0.0, candidates)
    grey = np.repeat(B[:, None], n, axis=1)                   # (m, n)
    xy = clip_xy(maps, slot_positions(leader_goal[:2], heading, slot_offsets(shape, grey), dist))
    pts = np.concatenate([xy, np.full(xy.shape[:-1] + (1,), z)], axis=-1)
    c = maps.horizontal_clearance_at(pts)                     # (m, n)
    ok = c >= grey * reference - 1e-9
    return B[np.argmax(ok, axis=0)]                           # largest consistent B


def clip_xy(maps: StaticMaps, xy: np.ndarray) -> np.ndarray:
    """``xy`` (..., 2) [m] clipped into the map's horizontal bounds."""
    lo = maps.origin[:2]
    hi = lo + (maps.shape[:2] - 1) * maps.spacing[:2]
    return np.clip(xy, lo, hi)


class LeaderGuide:
    """Partial goals of every UAV along the leader's FM² path.

    Parameters
    ----------
    path : ndarray, shape (N, 3)
        The leader's FM² path [m].
    maps : StaticMaps
    shape : FormationShape
    dist : float
        Safety distance [m] (also the half window of the heading).
    reference : float
        Horizontal clearance [m] at which the grey level is 1.
    grey : {"goal", "follower"}
        Where the grey level is measured (:func:`grey_levels`).
    follower_levels : sequence of FlightLevel or None
        Each follower's flight level (None: the leader's height).
    """

    def __init__(self, path: np.ndarray, maps: StaticMaps, shape: FormationShape,
                 dist: float, reference: float, grey: str,
                 follower_levels: Sequence[FlightLevel | None]) -> None:
        self.path = path
        self.s = arc_length(path)
        self.length = float(self.s[-1])
        self.maps, self.shape, self.dist = maps, shape, dist
        self.reference, self.grey = reference, grey
        self.follower_levels = tuple(follower_levels)

    def point(self, s: float) -> np.ndarray:
        """The leader's path point at arc length ``s`` [m] (linear)."""
        return at_arc_length(self.path, self.s, s)

    def heading(self, s: float, previous: np.ndarray) -> np.ndarray:
        """Unit horizontal direction of the path at ``s``; ``previous`` where it has none."""
        hd = path_heading(self.path, self.s, s, self.dist)
        return previous if not np.all(np.isfinite(hd)) else hd

    def _goal_z(self, leader_z: float, xy: np.ndarray) -> np.ndarray:
        z = np.empty(xy.shape[:-1])
        for j, lv in enumerate(self.follower_levels):
            z[..., j] = leader_z if lv is None else self.maps.level_z(lv.agl, xy[..., j, :])
        return z

    def follower_goals(self, leader_goal: np.ndarray, heading: np.ndarray,
                       current: np.ndarray | None) -> tuple[np.ndarray, np.ndarray]:
        """Followers' partial goals (n, 3) [m] and grey levels (n,) for a leader pose.

        ``current`` (n, 3): the followers' positions (for ``grey="follower"``);
        None measures at the goals (used for the default starts).
        """
        B = grey_levels(self.maps, self.shape, leader_goal, heading, self.dist, self.reference,
                        mode=self.grey if current is not None else "goal", followers=current)
        xy = clip_xy(self.maps, slot_positions(leader_goal[:2], heading,
                                               slot_offsets(self.shape, B), self.dist))
        z = self._goal_z(float(leader_goal[2]), xy[None])[0]
        return np.concatenate([xy, z[:, None]], axis=1), B

    def progress(self, p: np.ndarray, s_ref: float, s_goal: float) -> float:
        """Arc length of the leader's projection ``p`` on its path, never decreasing.

        Searched between ``s_ref`` and ``s_goal`` widened by their gap, and
        clamped to ``[s_ref, s_goal]``.
        """
        path, s_arr = self.path, self.s
        lo = int(np.searchsorted(s_arr, s_ref - (s_goal - s_ref), side="left"))
        hi = int(np.searchsorted(s_arr, s_goal + (s_goal - s_ref), side="right"))
        lo, hi = max(lo - 1, 0), min(hi + 1, len(s_arr) - 1)
        a, b = path[lo:hi], path[lo + 1:hi + 1]
        if len(a) == 0:
            return s_ref
        d = b - a
        dd = (d * d).sum(axis=1)
        t = np.clip(((p - a) * d).sum(axis=1) / np.where(dd > 0, dd, 1.0), 0.0, 1.0)
        q = a + t[:, None] * d
        k = int(np.argmin(((q - p) ** 2).sum(axis=1)))
        s = s_arr[lo + k] + t[k] * np.sqrt(dd[k])
        return float(max(s_ref, min(s, s_goal)))
