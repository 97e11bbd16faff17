"""Admissible speed along a path: from the FM² velocity map W and from curvature.

Thesis §3.2/§3.3: the first potential W is "proportional to the maximum
permissible speed of the UAV in each point, having a value between 0 and 1,
where 0 corresponds to the stall speed and 1 to the maximum speed". So for a
fixed-wing ``v_W = v_min + W (v_max - v_min)``; a multirotor can hover, so
``v_W = W v_max``. The turn adds ``v_turn = sqrt(a_lat / κ)`` with
``a_lat = g tan φ_max`` (fixed-wing) or ``a_max`` (multirotor); the admissible
speed is ``min(v_W, v_turn)`` (capped at v_max). A fixed-wing flying at its
constant cruise speed is over the admissible speed where ``cruise > v_adm``:
that is where the thesis expects it to drift off the planned path.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..errors import InputError
from ..geometry import as_path3, runs
from .airframes import G, Airframe, FixedWing, get_airframe
from .geometric import curvature_profile, default_window

__all__ = ["admissible_speed_from_w", "turn_speed_limit", "SpeedProfile", "speed_profile"]


def admissible_speed_from_w(w: Any, airframe: Airframe | str) -> np.ndarray:
    """Speed [m/s] that W in [0, 1] allows: stall..max (fixed-wing), 0..max (multirotor).

    Raises
    ------
    InputError
        W not finite or outside [0, 1] (beyond a 1e-9 rounding slack).
    """
    af = get_airframe(airframe)
    arr = np.asarray(w, dtype=float)
    if not np.all(np.isfinite(arr)):
        raise InputError("W along the path has NaN/inf values; give the velocity map values in [0, 1]")
    if arr.size and (arr.min() < -1e-9 or arr.max() > 1 + 1e-9):
        raise InputError(
            f"W along the path must lie in [0, 1] (0 = stall, 1 = max speed), got "
            f"[{arr.min():.4g}, {arr.max():.4g}]"
        )
    arr = np.clip(arr, 0.0, 1.0)
    if isinstance(af, FixedWing):
        return af.min_speed + arr * (af.max_speed - af.min_speed)
    return arr * af.max_speed


def turn_speed_limit(kappa: Any, airframe: Airframe | str) -> np.ndarray:
    """Highest speed [m/s] at which curvature κ [1/m] can be flown (inf where κ = 0)."""
    af = get_airframe(airframe)
    k = np.asarray(kappa, dtype=float)
    a_lat = G * math.tan(af.max_bank) if isinstance(af, FixedWing) else af.max_accel
    with np.errstate(divide="ignore"):
        return np.where(k > 0, np.sqrt(a_lat / np.maximum(k, 1e-300)), np.inf)


@dataclass(frozen=True)
class SpeedProfile:
    """Admissible speed along a path (see :func:`speed_profile`).

    Attributes
    ----------
    s : ndarray
        Arc length [m].
    v_w : ndarray or None
        Speed allowed by W [m/s] (None without W).
    v_turn : ndarray
        Speed allowed by the curvature [m/s] (inf on straight stretches).
    v_admissible : ndarray
        ``min(v_w, v_turn, v_max)`` [m/s].
    cruise_speed : float
        Speed of the tracking simulation [m/s].
    over : list of dict
        Stretches where ``cruise_speed > v_admissible``: s_from, s_to [m].
    """

    s: np.ndarray = field(repr=False)
    v_w: np.ndarray | None = field(repr=False)
    v_turn: np.ndarray = field(repr=False)
    v_admissible: np.ndarray = field(repr=False)
    cruise_speed: float
    over: list[dict[str, Any]]

    def summary(self) -> dict[str, Any]:
        """JSON-friendly numbers."""
        return {
            "min_admissible_mps": round(float(self.v_admissible.min()), 3),
            "mean_admissible_mps": round(float(np.mean(self.v_admissible)), 3),
            "cruise_mps": self.cruise_speed,
            "over_admissible_m": round(sum(o["s_to_m"] - o["s_from_m"] for o in self.over), 2),
            "over_admissible_stretches": len(self.over),
        }


def speed_profile(
    path: Any,
    airframe: Airframe | str,
    w: Any = None,
    *,
    window: float | None = None,
) -> SpeedProfile:
    """Admissible-speed profile of a path for an airframe.

    Parameters
    ----------
    path : array (N, 2|3)
        Points [m].
    airframe : FixedWing, Multirotor or preset name
    w : array (N,), optional
        W at each path point (e.g. ``Plan.w``), in [0, 1].
    window : float, optional
        Curvature window [m] (see :mod:`.geometric`).
    """
    af = get_airframe(airframe)
    p = as_path3(path)
    if w is not None:
        w_arr = np.asarray(w, dtype=float).reshape(-1)
        raw = np.asarray(path, dtype=float)
        if w_arr.size != len(raw):
            raise InputError(f"W has {w_arr.size} values but the path has {len(raw)} points")
        # align with the deduplicated points of as_path3
        raw3 = raw if raw.shape[1] == 3 else np.column_stack([raw, np.zeros(len(raw))])
        keep = np.concatenate([[True], np.linalg.norm(np.diff(raw3, axis=0), axis=1) > 1e-9])
        v_w = admissible_speed_from_w(w_arr[keep], af)
    else:
        v_w = None
    h = default_window(p, af) if window is None else window
    s, kappa = curvature_profile(p, h)
    v_turn = turn_speed_limit(kappa, af)
    v_adm = np.minimum(v_turn, af.max_speed)
    if v_w is not None:
        v_adm = np.minimum(v_adm, v_w)
    cruise = af.cruise_speed
    over = [
        {"s_from_m": round(float(s[i]), 2), "s_to_m": round(float(s[j - 1]), 2)}
        for i, j in runs(cruise > v_adm + 1e-9)
    ]
    return SpeedProfile(s=s, v_w=v_w, v_turn=v_turn, v_admissible=v_adm, cruise_speed=cruise,
                        over=over)
