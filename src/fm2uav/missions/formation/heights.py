"""One truth per vehicle: every UAV's flown heights from the final altitude profile.

The cycles (:mod:`.cycles`) fly each UAV on FM²'s grid, whose flight layer sits up
to one vertical cell below the request and is blind to the ground between nodes.
A single plan fixes that with the final altitude profile
(:func:`fm2uav.planning.altitude.final_profile`: the route kept, its heights set
over the continuous ground under the airframe's slope limits); a formation does the
same per UAV once the flight is over, so that the trajectory files, the figures, the
missions and the summary all tell the one flight that will be flown (issue 25: the
``*_path.geojson`` files and the profile figure sat 10–20 m below the missions).

For a UAV with a flight level (``FlightLevel.heights == "ground"``):

* its horizontal route (the simulated positions) is profiled like a plan;
* its **track** is the route at the profile's samples merged with the simulated
  samples, each with a time: a simulated sample keeps its time, a profile sample
  between two simulated samples gets the time of its arc length along that
  straight piece (the UAV moves at constant speed between samples), samples of a
  hold stay where they are; a vertical take-off leg takes the first half of the
  first moving piece;
* the common-time table (``FormationResult.positions``) takes the profile's
  heights at its samples: it is a subset of the track.

UAVs without a level (followers at the leader's height) and ``heights="fm2"``
(the seeds' reproduction) keep the simulated heights; their track is the simulated
trajectory itself.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ...planning import FlightLevel
from ...planning.altitude import AltitudeProfile, final_profile

__all__ = ["Track", "profile_tracks"]


@dataclass(frozen=True, eq=False)
class Track:
    """One UAV's flown trajectory, the one every file of that UAV is written from.

    Attributes
    ----------
    name : str
    path : ndarray, shape (m, 3)
        Positions [m], straight between samples.
    times : ndarray, shape (m,)
        Time of each position [s], non-decreasing (equal only where the UAV stands
        still).
    profile : AltitudeProfile or None
        Its final altitude profile sampled at ``path`` (same length: floors per
        point, phases); None without a flight level.
    """

    name: str
    path: np.ndarray = field(repr=False)
    times: np.ndarray = field(repr=False)
    profile: AltitudeProfile | None = field(default=None, repr=False)


def _profiled(level: FlightLevel | None) -> bool:
    return level is not None and level.heights == "ground"


def profile_tracks(world: Any, times: Any, positions: Any, names: Any, levels: Any
                   ) -> tuple[np.ndarray, tuple[Track, ...]]:
    """Each UAV's final heights and track (see the module docstring).

    Parameters
    ----------
    world : World
    times : array_like, shape (n_t,)
        Sample times [s].
    positions : array_like, shape (n_t, n_uav, 3)
        Simulated positions [m].
    names : sequence of str
    levels : sequence of (FlightLevel or None)
        One per UAV.

    Returns
    -------
    positions : ndarray, shape (n_t, n_uav, 3)
        The simulated positions with each profiled UAV's final heights.
    tracks : tuple of Track
    """
    t = np.asarray(times, dtype=float)
    pos = np.array(positions, dtype=float, copy=True)
    tracks = []
    for i, name in enumerate(names):
        p = pos[:, i]
        s = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(p[:, :2], axis=0).T))])
        lv = levels[i] if i < len(levels) else None
        if not _profiled(lv) or s[-1] <= 1e-9:
            tracks.append(Track(str(name), p.copy(), t.copy()))
            continue
        prof = final_profile(world, p, lv)
        path, tt, z_at = _merge(p, t, s, prof)
        pos[:, i, 2] = z_at
        tracks.append(Track(str(name), path, tt, _track_profile(world, prof, path, tt, p, s)))
    return pos, tuple(tracks)


def _route_part(prof: AltitudeProfile) -> slice:
    """The profile's samples along the route (without the vertical end legs)."""
    k0 = 1 if abs(prof.vertical_start_m) > 1e-6 else 0
    k1 = len(prof.s) - (1 if abs(prof.vertical_goal_m) > 1e-6 else 0)
    return slice(k0, k1)


def _merge(p: np.ndarray, t: np.ndarray, s: np.ndarray, prof: AltitudeProfile
           ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The track (positions, times) and the profile's height at each simulated sample."""
    part = _route_part(prof)
    ps, pz, pxy = prof.s[part], prof.path[part, 2], prof.path[part, :2]
    z_at = np.interp(s, ps, pz)
    z_at[s <= 1e-9] = p[0, 2]  # the start itself (and holds on it) before any vertical leg
    z_at[s >= s[-1] - 1e-9] = p[-1, 2]
    moving = np.flatnonzero(np.diff(s) > 1e-9)
    first, last = (int(moving[0]), int(moving[-1])) if len(moving) else (0, len(s) - 2)
    up = abs(prof.vertical_start_m) > 1e-6
    down = abs(prof.vertical_goal_m) > 1e-6
    rows, tt = [np.column_stack([p[:1, :2], z_at[:1]])], [t[:1]]
    for k in range(len(s) - 1):
        a, b = s[k], s[k + 1]
        if b - a > 1e-9:
            # the vertical legs take a share of their piece's time: a climb before the
            # horizontal move, a descent after it
            v_up, v_down = up and k == first, down and k == last
            share = (t[k + 1] - t[k]) / (1 + int(v_up) + int(v_down))
            ta = t[k] + share * int(v_up)
            tb = ta + share
            if v_up:
                rows.append(np.array([[p[k, 0], p[k, 1], pz[0]]]))
                tt.append(np.array([ta]))
            inner = (ps > a + 1e-9) & (ps < b - 1e-9)
            if inner.any():
                f = (ps[inner] - a) / (b - a)
                rows.append(np.column_stack([pxy[inner], pz[inner]]))
                tt.append(ta + f * (tb - ta))
            if v_down:
                rows.append(np.array([[p[k + 1, 0], p[k + 1, 1], pz[-1]]]))
                tt.append(np.array([tb]))
        rows.append(np.column_stack([p[k + 1:k + 2, :2], z_at[k + 1:k + 2]]))
        tt.append(t[k + 1:k + 2])
    return np.concatenate(rows), np.concatenate(tt), z_at


def _track_profile(world: Any, prof: AltitudeProfile, path: np.ndarray, times: np.ndarray,
                   p: np.ndarray, s_sim: np.ndarray) -> AltitudeProfile:
    """The profile re-sampled at the track's points: arc length, surface, phase and floor
    (a simulated sample between two profile samples keeps the lower floor of the two, and
    the transition's phase when one of them is not cruise)."""
    from dataclasses import replace

    seg = np.hypot(*np.diff(path[:, :2], axis=0).T)
    s = np.concatenate([[0.0], np.cumsum(seg)])
    part = _route_part(prof)
    ps, req, ph = prof.s[part], prof.required[part], prof.phase[part]
    j = np.clip(np.searchsorted(ps, s, side="left"), 0, len(ps) - 1)
    i = np.clip(j - 1, 0, len(ps) - 1)
    exact = np.isclose(ps[j], s, rtol=0.0, atol=1e-9)
    required = np.where(exact, req[j], np.minimum(req[i], req[j]))
    # between a cruise and a climb-out / descent sample the point belongs to the transition
    phase = np.where(exact, ph[j], np.where(ph[i] == "cruise", ph[j], ph[i]))
    required[0] = required[-1] = -np.inf
    surface = np.asarray(world.surface_height(path[:, 0], path[:, 1]), dtype=float)
    return replace(prof, path=path, s=s, surface=surface, phase=phase.astype(str),
                   required=required.astype(float))
