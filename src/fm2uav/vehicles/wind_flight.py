"""A path flown in a wind: the check of predicted times against a simulated flight.

The vehicle is a point in the horizontal plane holding an airspeed and steering its
heading ``ψ`` (degrees from north) with a bounded turn rate; the wind carries it:
``ṗ = V (sin ψ, cos ψ) + w(p)``. Guidance: a carrot ``lookahead`` metres ahead along
the path from the vehicle's projection on it; the commanded heading is the one whose
ground velocity points at the carrot (the wind-triangle crab,
``V n = g u − w``), reached at no more than ``max_turn_rate``. The commanded airspeed is
the planned one at the projection (``W × airspeed``), approached with a first-order
lag ``tau``. Integration: fixed step, semi-implicit Euler. The flight ends when the
projection reaches the path's end (or at the time limit).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..errors import InputError
from ..geometry import arc_length

__all__ = ["WindFlight", "fly_in_wind"]


@dataclass(frozen=True, eq=False)
class WindFlight:
    """A simulated flight along a path in a wind.

    Attributes
    ----------
    t : ndarray (K,)
        Time [s].
    position : ndarray (K, 2)
        Flown horizontal positions [m].
    progress : ndarray (K,)
        Arc length of the projection on the path [m].
    reached : bool
        The end of the path was reached before the time limit.
    time_s : float
        Time at which the end was reached [s] (``inf`` if not).
    max_separation : float
        Largest distance from the path [m].
    """

    t: np.ndarray
    position: np.ndarray
    progress: np.ndarray
    reached: bool
    time_s: float
    max_separation: float


def _project(path: np.ndarray, s: np.ndarray, p: np.ndarray, k0: int, window: int
             ) -> tuple[float, int, float]:
    """Arc length of the projection of ``p`` on segments ``k0 .. k0 + window``."""
    hi = min(len(path) - 1, k0 + window)
    a = path[k0:hi]
    b = path[k0 + 1:hi + 1]
    d = b - a
    L2 = np.maximum(np.sum(d * d, axis=1), 1e-12)
    f = np.clip(np.sum((p - a) * d, axis=1) / L2, 0.0, 1.0)
    q = a + f[:, None] * d
    dist = np.hypot(*(q - p).T)
    j = int(np.argmin(dist))
    return float(s[k0 + j] + f[j] * math.sqrt(L2[j])), k0 + j, float(dist[j])


def fly_in_wind(path: Any, airspeed: Any, wind: Any, *, dt: float = 0.1,
                lookahead: float | None = None, max_turn_rate_deg: float = 45.0,
                tau: float = 1.0, time_limit: float | None = None) -> WindFlight:
    """Fly ``path`` at the planned ``airspeed`` in ``wind`` (module docstring).

    Parameters
    ----------
    path : array_like, shape (N, 2|3)
        Planned path [m] (the horizontal part is flown).
    airspeed : float or array_like, shape (N,)
        Commanded airspeed at each path point [m/s] (``W × airspeed`` of a plan).
    wind : WindField
        The wind the vehicle meets (:class:`fm2uav.world.wind.WindField`).
    dt : float
        Integration step [s].
    lookahead : float, optional
        Carrot distance [m]; default ``2 × max airspeed × 1 s``, at least 10 m.
    max_turn_rate_deg : float
        Largest turn rate [deg/s].
    tau : float
        Time constant of the airspeed response [s].
    time_limit : float, optional
        Default ``5 × length / min airspeed + 60`` s.

    Raises
    ------
    InputError
        A bad path or airspeed.
    """
    p = np.asarray(path, dtype=float)
    if p.ndim != 2 or p.shape[1] not in (2, 3) or len(p) < 2:
        raise InputError(f"path must be an (N >= 2, 2|3) array, got shape {p.shape}")
    xy = p[:, :2]
    s = arc_length(xy)
    length = float(s[-1])
    va = np.broadcast_to(np.asarray(airspeed, dtype=float), (len(p),))
    if not np.all(np.isfinite(va)) or np.any(va <= 0):
        raise InputError("airspeeds along the path must be finite and > 0 m/s")
    la = lookahead if lookahead is not None else max(2.0 * float(va.max()), 10.0)
    limit = time_limit if time_limit is not None else 5.0 * length / float(va.min()) + 60.0
    rate = math.radians(max_turn_rate_deg)
    pos = xy[0].copy()
    d0 = xy[1] - xy[0]
    w0 = wind.at(pos[None, :])[0]
    psi = math.atan2(*(_crab(d0, w0, va[0])))
    v = float(va[0])
    k = 0
    ts, ps, prog = [0.0], [pos.copy()], [0.0]
    sep = 0.0
    t = 0.0
    reached = False
    while t < limit:
        sp, k, dist = _project(xy, s, pos, k, 20)
        sep = max(sep, dist)
        if sp >= length - 1e-6 or np.hypot(*(xy[-1] - pos)) < 0.5 * v * dt + 1e-9:
            reached = True
            break
        target = min(sp + la, length)
        j = min(int(np.searchsorted(s, target, side="right")) - 1, len(s) - 2)
        f = (target - s[j]) / max(s[j + 1] - s[j], 1e-12)
        carrot = xy[j] + f * (xy[j + 1] - xy[j])
        w = wind.at(pos[None, :])[0]
        v_cmd = float(np.interp(sp, s, va))
        v += (v_cmd - v) * min(dt / tau, 1.0)
        want = math.atan2(*(_crab(carrot - pos, w, v)))
        err = (want - psi + math.pi) % (2 * math.pi) - math.pi
        psi += max(-rate * dt, min(rate * dt, err))
        vel = v * np.array([math.sin(psi), math.cos(psi)]) + w
        pos = pos + vel * dt
        t += dt
        ts.append(t)
        ps.append(pos.copy())
        prog.append(sp)
    # the end is crossed within the last step: interpolate the arrival on the distance left
    t_end = t if reached else math.inf
    return WindFlight(np.array(ts), np.array(ps), np.array(prog), reached, t_end, sep)


def _crab(direction: np.ndarray, w: np.ndarray, v: float) -> tuple[float, float]:
    """``(east, north)`` of the air heading that makes good ``direction`` in wind ``w``
    (straight into the wind component when it is stronger than the airspeed)."""
    n = float(np.hypot(*direction))
    u = direction / n if n > 0 else np.array([0.0, 1.0])
    wt = float(u @ w)
    lam = v * v - float(w @ w) + wt * wt
    g = wt + math.sqrt(lam) if lam > 0 else 0.0
    air = g * u - w
    return float(air[0]), float(air[1])
