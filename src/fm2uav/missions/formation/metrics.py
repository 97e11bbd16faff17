"""Formation-shape error over time: how far the followers are from their nominal slots."""

from __future__ import annotations

import numpy as np

from ...geometry import arc_length, at_arc_length
from .shapes import FormationShape, slot_positions

__all__ = ["path_heading", "formation_error"]


def path_heading(
    path: np.ndarray, s_arr: np.ndarray, s: np.ndarray | float, half_window: float
) -> np.ndarray:
    """Unit horizontal direction of a path at arc length(s) ``s`` [m].

    The chord from ``s - half_window`` to ``s + half_window`` (clamped to the
    path), so small wiggles do not swing the formation. Where the chord has no
    horizontal extent (vertical climb, single point) the result is NaN.

    Returns
    -------
    ndarray, shape (..., 2)
    """
    s = np.asarray(s, dtype=float)
    L = float(s_arr[-1])
    a = at_arc_length(path, s_arr, np.clip(s - half_window, 0.0, L))
    b = at_arc_length(path, s_arr, np.clip(s + half_window, 0.0, L))
    d = (b - a)[..., :2]
    n = np.linalg.norm(d, axis=-1, keepdims=True)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(n > 1e-9, d / n, np.nan)


def formation_error(
    leader_path: np.ndarray,
    positions: np.ndarray,
    shape: FormationShape,
    dist: float,
    *,
    half_window: float | None = None,
) -> np.ndarray:
    """Largest horizontal distance of a follower from its nominal slot [m].

    At each sample the leader's pose is its position and the direction of its
    planned path at the nearest path point; the nominal slots (grey level 1)
    follow with :func:`~fm2uav.missions.formation.shapes.slot_positions`.

    Parameters
    ----------
    leader_path : ndarray, shape (N, 3)
        The leader's global FM² path [m].
    positions : ndarray, shape (n_t, 1 + n_followers, 3)
        Leader first [m].
    shape : FormationShape
    dist : float
        Safety distance [m].
    half_window : float, optional
        Heading chord half-length [m]; default ``dist``.

    Returns
    -------
    ndarray, shape (n_t,)
        Shape error [m]; divide by ``2 * dist`` for a dimensionless value.
    """
    path = np.asarray(leader_path, dtype=float)
    pos = np.asarray(positions, dtype=float)
    s_arr = arc_length(path)
    leader = pos[:, 0, :]
    # nearest path vertex of each leader sample (the path is a few hundred points)
    d2 = ((leader[:, None, :] - path[None, :, :]) ** 2).sum(axis=-1)
    s = s_arr[np.argmin(d2, axis=1)]
    heading = path_heading(path, s_arr, s, dist if half_window is None else half_window)
    # forward-fill headings that are undefined (vertical chords)
    ok = np.all(np.isfinite(heading), axis=1)
    if not ok.any():
        heading = np.tile([1.0, 0.0], (len(s), 1))
    else:
        idx = np.where(ok, np.arange(len(s)), 0)
        np.maximum.accumulate(idx, out=idx)
        first = int(np.argmax(ok))
        idx[:first] = first
        heading = heading[idx]
    err = np.zeros(len(s))
    for t in range(len(s)):
        slots = slot_positions(leader[t, :2], heading[t], shape.offsets, dist)
        err[t] = np.linalg.norm(pos[t, 1:, :2] - slots, axis=1).max()
    return err
