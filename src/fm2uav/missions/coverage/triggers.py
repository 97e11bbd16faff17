"""Camera triggering of a coverage flight: where each band starts and ends on the path.

A coverage mission photographs the bands only: the camera is switched on
(``DO_SET_CAM_TRIGG_DIST`` with the distance between photos) where the FM² path
enters a band and off (distance 0) where it leaves it, as QGroundControl's
survey does. :func:`band_indices` finds those points on the dense path;
:func:`camera_plan` adds the trigger distance and the camera figures:

* with a :class:`~fm2uav.missions.coverage.camera.Camera`: ground sample
  distance ``GSD = sensor_width · AGL / (focal · image_width)``, footprint,
  the side overlap the band spacing D gives (``1 − D / footprint_across``) and
  the trigger distance ``footprint_along · (1 − front_overlap)``;
* without one: the trigger distance given, else D (square photos with equal
  front and side overlap).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ...errors import InputError
from .camera import Camera

__all__ = ["CameraPlan", "band_indices", "camera_plan", "photo_positions"]


@dataclass(frozen=True)
class CameraPlan:
    """Camera triggering of a coverage mission.

    Attributes
    ----------
    trigger_distance : float
        Distance between photos along a band [m].
    bands : tuple of (int, int)
        Dense-path indices where each band starts and ends, flight order.
    info : dict
        Figures for the summary (GSD, footprint, overlaps, how far the path's
        band ends are from the bands' [m]).
    """

    trigger_distance: float
    bands: tuple[tuple[int, int], ...]
    info: dict[str, Any] = field(default_factory=dict)


def band_indices(zigzag: Any, path: Any) -> tuple[list[tuple[int, int]], float]:
    """Indices of the path points nearest to each band's start and end, in order.

    The search runs forward along the path (band ``k`` after band ``k − 1``), so
    a band end is never matched to a later pass over the same place.

    Returns
    -------
    bands : list of (int, int)
        ``(start index, end index)`` per band, increasing.
    mismatch : float
        Largest horizontal distance [m] between a band end and its path point.

    Raises
    ------
    InputError
        The path does not pass the bands in order (not this zigzag's path).
    """
    p = np.asarray(path, dtype=float)[:, :2]
    out: list[tuple[int, int]] = []
    worst = 0.0
    lo = 0
    half = float(zigzag.spacing) / 2.0
    for k, seg in enumerate(zigzag.bands()):
        a, b = np.asarray(seg.coords, dtype=float)[[0, -1]]
        idx = []
        for q in (a, b):
            d = np.hypot(p[lo:, 0] - q[0], p[lo:, 1] - q[1])
            near = np.flatnonzero(d < half)
            if near.size:  # the first pass near q: stop at the end of that run
                run_end = near[0] + 1
                while run_end < len(d) and d[run_end] < half:
                    run_end += 1
                j = near[0] + int(np.argmin(d[near[0]:run_end]))
            else:
                j = int(np.argmin(d))
            worst = max(worst, float(d[j]))
            idx.append(lo + j)
            lo = lo + j + 1 if lo + j + 1 < len(p) else lo + j
        if idx[1] <= idx[0]:  # a band shorter than the path's step (a sliver of the area)
            if idx[1] - 1 > (out[-1][1] if out else -1):
                idx[0] = idx[1] - 1
            elif idx[0] + 1 < len(p):
                idx[1] = idx[0] + 1
            else:
                raise InputError(f"band {k + 1}: the path does not fly it forward (start index "
                                 f"{idx[0]}, end {idx[1]}); is it this zigzag's path?")
            lo = min(idx[1] + 1, len(p) - 1)
        out.append((idx[0], idx[1]))
    return out, worst


def camera_plan(
    coverage: Any,
    *,
    camera: Camera | None = None,
    front_overlap: float = 0.0,
    trigger_distance: float | None = None,
) -> CameraPlan:
    """The camera triggering of a :class:`~fm2uav.missions.coverage.CoveragePlan`.

    Parameters
    ----------
    coverage : CoveragePlan
    camera : Camera, optional
        The camera (GSD, footprint, trigger distance from ``front_overlap``).
    front_overlap : float, optional
        Share of overlap between successive photos, in [0, 1).
    trigger_distance : float, optional
        Distance between photos [m]; overrides the camera's. Without either, D.
    """
    agl = float(coverage.level.agl)
    d = float(coverage.zigzag.spacing)
    info: dict[str, Any] = {"agl_m": agl, "band_spacing_m": d}
    if camera is not None:
        gsd = camera.gsd(agl)
        across, along = camera.footprint(agl)
        side = 1.0 - d / across
        trig = camera.trigger_distance(agl, front_overlap)
        info.update(gsd_cm_per_px=round(100 * gsd, 4), footprint_across_m=round(across, 3),
                    footprint_along_m=round(along, 3), side_overlap=round(side, 4),
                    front_overlap=float(front_overlap),
                    trigger_distance_source="camera footprint along the track x (1 - front "
                    "overlap)")
        if side < 0:
            info["warning"] = (f"the band spacing D = {d:g} m is wider than the camera "
                               f"footprint ({across:.1f} m at {agl:g} m AGL): gaps between bands")
    else:
        trig = d
        info["trigger_distance_source"] = ("band spacing D (no camera given: square photos, "
                                           "front overlap = side overlap)")
    if trigger_distance is not None:
        trig = float(trigger_distance)
        info["trigger_distance_source"] = "given (--trigger-distance)"
    trig = round(float(trig), 3)  # mm: what a mission item needs
    if not (math.isfinite(trig) and trig > 0):
        raise InputError(f"trigger distance must be > 0 m, got {trig!r}")
    bands, worst = band_indices(coverage.zigzag, coverage.path)
    info["band_end_mismatch_m"] = round(worst, 3)
    return CameraPlan(trigger_distance=float(trig), bands=tuple(bands), info=info)


def photo_positions(path: Any, shots: CameraPlan) -> tuple[np.ndarray, np.ndarray]:
    """Where the camera fires along the flown path, and the heading there.

    The mission switches distance triggering on at each band's start with
    "trigger once now" (``DO_SET_CAM_TRIGG_DIST`` param3 = 1) and off at its end,
    so a photo is taken at the band's start and then every ``trigger_distance``
    metres of ground track until the band's end.

    Parameters
    ----------
    path : ndarray, shape (N, 3)
        The flown path [m].
    shots : CameraPlan

    Returns
    -------
    points : ndarray, shape (k, 3)
        Photo positions [m].
    headings : ndarray, shape (k,)
        Direction of flight there [rad, counter-clockwise from +x].

    Examples
    --------
    >>> path = np.array([[0.0, 0, 50], [100, 0, 50], [100, 30, 50], [0, 30, 50]])
    >>> pts, hdg = photo_positions(path, CameraPlan(40.0, ((0, 1), (2, 3))))
    >>> pts[:, :2].tolist()
    [[0.0, 0.0], [40.0, 0.0], [80.0, 0.0], [100.0, 30.0], [60.0, 30.0], [20.0, 30.0]]
    >>> np.degrees(hdg).round().tolist()
    [0.0, 0.0, 0.0, 180.0, 180.0, 180.0]
    """
    p = np.asarray(path, dtype=float)
    pts: list[np.ndarray] = []
    hdg: list[np.ndarray] = []
    for a, b in shots.bands:
        seg = p[a:b + 1]
        if len(seg) < 2:
            continue
        step = np.linalg.norm(np.diff(seg[:, :2], axis=0), axis=1)
        s = np.concatenate([[0.0], np.cumsum(step)])
        at = np.arange(0.0, s[-1] + 1e-9, shots.trigger_distance)
        k = np.clip(np.searchsorted(s, at, side="right") - 1, 0, len(step) - 1)
        u = np.where(step[k] > 0, (at - s[k]) / np.where(step[k] > 0, step[k], 1.0), 0.0)
        pts.append(seg[k] + u[:, None] * (seg[k + 1] - seg[k]))
        d = seg[k + 1] - seg[k]
        hdg.append(np.arctan2(d[:, 1], d[:, 0]))
    if not pts:
        return np.zeros((0, 3)), np.zeros(0)
    return np.vstack(pts), np.concatenate(hdg)
