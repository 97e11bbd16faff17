"""Final altitude profile of a terrain-following plan: the height above ground that holds.

FM² finds the *route*; its heights sit on the grid's flight layer, up to one
vertical cell off the request and blind to the ground between nodes. The
flown heights are therefore set afterwards, along the route, from the
continuous ground (:meth:`World.surface_height`: the DEM interpolated
bilinearly, roofs of buildings):

1. the route is resampled every ``ds`` metres of horizontal arc length (a
   quarter of the horizontal cell, at most a quarter of a source-DEM pixel, by
   default) and the surface is read at each sample and at 1/4, 1/2 and 3/4 of
   the chords to its neighbours. The flown height is linear along a chord, so
   what matters is how far the surface bulges above the straight line between
   its values at the two samples (a few centimetres, up to a metre at pixel
   kinks of a rough DEM): ``S_max`` is the surface at the sample raised by the
   larger bulge of its two chords, ``G_min`` the ground lowered by the larger
   dip;
2. per sample, three bounds [m, world z]:

   * target ``L_t = S_max + agl`` — where the profile wants to be;
   * floor ``L_h = S_max + max(agl - tolerance, min_agl)`` — never below;
   * ceiling ``U = G_min + max_agl`` with ``G_min`` the lowest *ground* (not
     roof) under the sample and its chords, and the world's top node;

   no-fly zones with a floor or ceiling add their own lower / upper bound where
   the route crosses their (buffered) footprint (over them or under them, on
   the side FM² chose);
3. the airframe limits ``-tan(max_descent) <= dz/ds <= tan(max_climb)`` are
   imposed by *slope envelopes*: ``up(L)`` is the lowest slope-limited profile
   that stays at or above ``L`` (a forward pass ``z_i = max(L_i, z_{i-1} -
   tan(descent) ds)`` and a backward pass ``z_i = max(z_i, z_{i+1} - tan(climb)
   ds)``: the upper envelope of ``L`` under the slope cones), ``down(U)`` the
   highest one at or below ``U``. The cruise profile is
   ``z_c = max(up(L_h), min(up(L_t), down(U)))``: it follows the target where
   the airframe can, dips no lower than the floor where the ceiling forces it
   and never crosses the ceiling; if ``up(L_h) > down(U)`` somewhere, no profile
   exists and a :class:`~fm2uav.errors.PlanningError` names the place and the
   fix (``planner.max_agl`` / ``--max-agl``);
4. **climb-out and descent**: from the start the profile is clipped to the
   cone ``z_start - tan(descent) s <= z <= z_start + tan(climb) s`` (and the
   mirror cone at the goal); the part before the profile first meets ``z_c`` is
   the climb-out, the part after it last leaves ``z_c`` the descent, the rest is
   the cruise. If the cone from the start would pass closer to the ground than
   ``min_agl`` (or, without ``min_agl``, than the start's own height, at most
   ``agl - tolerance``), or above the ceiling, the start gets a *vertical*
   climb/descent first, to the lowest height from which the cone clears
   (reported as ``vertical_start_m``; the same at the goal). The take-off and
   landing points themselves are exempt from ``min_agl``.

The result is a slope-limited polyline; the sampling is denser than the grid,
so between samples the ground can only rise by the curvature of the bilinear
surface over a quarter cell (a few centimetres on real DEMs), which the
tolerance absorbs. What the profile cannot see is what the surface model does
not hold: ground finer than the DEM, obstacles not in the world.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..errors import InputError, PlanningError, PointError
from ..geometry import arc_length
from .params import FlightLevel

__all__ = [
    "AltitudeProfile",
    "final_profile",
    "join_profiles",
    "floor_agl",
    "envelope_above",
    "envelope_below",
    "resample_route",
    "solve_profile",
    "height_figures",
]


def _tan(deg: float) -> float:
    """tan of a flight-path angle [deg]; 90 deg (vertical) is a very large slope."""
    return math.tan(math.radians(min(float(deg), 89.999)))


def floor_agl(level: FlightLevel) -> float:
    """Cruise floor above the surface [m]: ``max(agl - tolerance, min_agl)``."""
    f = level.agl - level.tolerance
    return f if level.min_agl is None else max(f, float(level.min_agl))


# ---------------------------------------------------------------------- envelopes
def _steps(s: np.ndarray) -> np.ndarray:
    s = np.asarray(s, dtype=float)
    if s.ndim != 1 or len(s) < 1 or np.any(np.diff(s) < 0) or not np.all(np.isfinite(s)):
        raise InputError("s must be a finite, non-decreasing 1D array of arc lengths [m]")
    return np.diff(s)


def _sweeps(s: Any, bound: Any, upper: bool, forward: float, backward: float) -> np.ndarray:
    """``bound`` swept forward then backward: ``z_i = pick(z_i, z_(i-1) + forward * ds)``,
    then ``z_i = pick(z_i, z_(i+1) + backward * ds)`` (``ds`` the steps of ``s`` [m];
    ``pick`` is ``min`` when ``upper``, else ``max``; compiled:
    :func:`._envelope_kernels.sweep_pair`)."""
    from ._envelope_kernels import sweep_pair

    d = _steps(s)
    z = np.array(bound, dtype=float)
    if z.shape != (len(d) + 1,):
        raise InputError(f"the bound has shape {z.shape}, the arc lengths {(len(d) + 1,)}")
    sweep_pair(z, d, bool(upper), float(forward), float(backward))
    return z


def envelope_above(s: Any, lower: Any, tan_climb: float, tan_descent: float) -> np.ndarray:
    """Lowest profile ``z >= lower`` with ``-tan_descent <= dz/ds <= tan_climb``.

    Parameters
    ----------
    s : array_like, shape (N,)
        Horizontal arc length [m], non-decreasing.
    lower : array_like, shape (N,)
        Lower bound [m] (``-inf`` allowed).
    tan_climb, tan_descent : float
        Largest rise / drop per metre (> 0).

    Returns
    -------
    ndarray, shape (N,)
        ``z_i = max_j (lower_j - c |s_i - s_j|)`` with ``c = tan_climb`` for
        ``j > i`` and ``tan_descent`` for ``j < i`` (two passes, O(N)).

    Examples
    --------
    >>> envelope_above([0, 1, 2, 3, 4], [0, 0, 10, 0, 0], 5.0, 2.0).tolist()
    [0.0, 5.0, 10.0, 8.0, 6.0]
    """
    return _sweeps(s, lower, False, -tan_descent, -tan_climb)


def envelope_below(s: Any, upper: Any, tan_climb: float, tan_descent: float) -> np.ndarray:
    """Highest profile ``z <= upper`` with ``-tan_descent <= dz/ds <= tan_climb``.

    The mirror of :func:`envelope_above` (``+inf`` allowed in ``upper``).

    Examples
    --------
    >>> envelope_below([0, 1, 2, 3, 4], [9, 9, 0, 9, 9], 2.0, 5.0).tolist()
    [9.0, 5.0, 0.0, 2.0, 4.0]
    """
    return _sweeps(s, upper, True, tan_climb, tan_descent)


# ---------------------------------------------------------------------- route
def resample_route(path: Any, ds: float) -> tuple[np.ndarray, np.ndarray]:
    """The horizontal route of a path, every ``ds`` metres of horizontal arc length.

    Parameters
    ----------
    path : array_like, shape (N, 2) or (N, 3)
        The planned path [m] (its z is ignored).
    ds : float
        Largest horizontal spacing of the samples [m] (> 0).

    Returns
    -------
    xy : ndarray, shape (M, 2)
        Samples, the first and last exactly the path's ends; ``M >= 2``
        (``M = 2`` when the route has no horizontal length).
    s : ndarray, shape (M,)
        Horizontal arc length of each sample [m].
    """
    p = np.asarray(path, dtype=float)
    if p.ndim != 2 or p.shape[1] not in (2, 3) or len(p) < 2 or not np.all(np.isfinite(p)):
        raise InputError(f"path must be a finite (N, 2|3) array with N >= 2, got {p.shape}")
    if not (np.isfinite(ds) and ds > 0):
        raise InputError(f"ds must be a spacing > 0 m, got {ds!r}")
    xy = p[:, :2]
    seg = np.linalg.norm(np.diff(xy, axis=0), axis=1)
    keep = np.concatenate([[True], seg > 1e-9])
    xy, cum = xy[keep], np.concatenate([[0.0], np.cumsum(seg[seg > 1e-9])])
    total = float(cum[-1])
    if len(xy) < 2 or total <= 0:
        return np.array([p[0, :2], p[-1, :2]]), np.array([0.0, 0.0])
    n = max(int(math.ceil(total / ds)), 1)
    s = np.linspace(0.0, total, n + 1)
    out = np.column_stack([np.interp(s, cum, xy[:, 0]), np.interp(s, cum, xy[:, 1])])
    out[0], out[-1] = p[0, :2], p[-1, :2]
    return out, s


def _window(values_at_samples: np.ndarray, values_at_mids: np.ndarray, fn: Callable) -> np.ndarray:
    """max/min of each sample and the chord midpoints on either side of it."""
    out = values_at_samples.copy()
    if len(values_at_mids):
        out[:-1] = fn(out[:-1], values_at_mids)
        out[1:] = fn(out[1:], values_at_mids)
    return out


# ---------------------------------------------------------------------- the profile
@dataclass(frozen=True)
class AltitudeProfile:
    """The flown profile along the route and how it was obtained.

    Attributes
    ----------
    path : ndarray, shape (M, 3)
        The flown path [m]: the start, an optional vertical leg, the route
        samples at their final heights, an optional vertical leg, the goal.
    s : ndarray, shape (M,)
        Horizontal arc length of each point [m] (vertical legs repeat it).
    surface : ndarray, shape (M,)
        Surface height (ground or roof) under each point [m].
    phase : ndarray of str, shape (M,)
        ``"climb-out"``, ``"cruise"`` or ``"descent"`` per point.
    required : ndarray, shape (M,)
        The floor the profile keeps at each point, as a height above the
        surface [m]: ``max(agl - tolerance, min_agl)`` on the cruise, the
        climb-out / descent floor elsewhere, ``-inf`` at the take-off and
        landing points (what the waypoint legs must keep too).
    level : FlightLevel
        The request (agl, tolerance, min/max_agl, climb/descent limits).
    vertical_start_m, vertical_goal_m : float
        Length of the vertical legs at the start / goal [m] (+ = climb at the
        start, descent at the goal).
    climb_out_m, descent_m : float
        Horizontal length of the climb-out / descent [m].
    lifted_m : float
        Largest amount the cruise sits above the target ``surface + agl`` because
        the airframe cannot follow the ground more tightly [m].
    """

    path: np.ndarray = field(repr=False)
    s: np.ndarray = field(repr=False)
    surface: np.ndarray = field(repr=False)
    phase: np.ndarray = field(repr=False)
    required: np.ndarray = field(repr=False)
    level: FlightLevel
    vertical_start_m: float = 0.0
    vertical_goal_m: float = 0.0
    climb_out_m: float = 0.0
    descent_m: float = 0.0
    lifted_m: float = 0.0

    @property
    def cruise(self) -> np.ndarray:
        """Bool mask of the cruise points."""
        return self.phase == "cruise"

    def summary(self) -> dict[str, Any]:
        """JSON-friendly description (method, limits, phases)."""
        lim = self.level
        return {
            "method": "route from FM², heights = continuous surface + agl under slope limits",
            "agl_m": lim.agl, "tolerance_m": lim.tolerance, "min_agl_m": lim.min_agl,
            "max_agl_m": lim.max_agl, "max_climb_deg": lim.max_climb,
            "max_descent_deg": lim.max_descent,
            "vertical_start_m": round(self.vertical_start_m, 3),
            "vertical_goal_m": round(self.vertical_goal_m, 3),
            "climb_out_m": round(self.climb_out_m, 3), "descent_m": round(self.descent_m, 3),
            "max_lift_above_target_m": round(self.lifted_m, 3),
        }


def _where(s: float, xy: np.ndarray | None, i: int) -> str:
    if xy is None:
        return f"at {s:.0f} m along the route"
    return f"at {s:.0f} m along the route (x = {xy[i, 0]:.1f}, y = {xy[i, 1]:.1f} m)"


def _cone_interval(z_end: float, ground_end: float, dist: np.ndarray, up: float, down: float,
                   where: str, lim: FlightLevel, smax: np.ndarray, lo_x: np.ndarray,
                   ceil: np.ndarray) -> tuple[float, float, float]:
    """Heights [m] at an end point from which its cone keeps the profile within floor and ceiling.

    The cone is ``z_end + up*dist`` (above) / ``z_end - down*dist`` (below), ``dist``
    the horizontal distance [m] of each sample from the end. Returns the lowest and
    highest admissible height and the height above the surface kept near it.
    """
    own = max(z_end - ground_end, 0.0)
    keep = lim.min_agl if lim.min_agl is not None else min(lim.agl - lim.tolerance, own)
    low = np.maximum(smax + keep, lo_x)
    need_lo = float(np.max(low - up * dist))
    need_hi = float(np.min(ceil + down * dist))
    if need_lo > need_hi + 1e-6:
        raise PlanningError(
            f"the {where} cannot be joined to the route within the altitude limits "
            f"(needs {need_lo:.1f} m, ceiling allows {need_hi:.1f} m); move the {where} or "
            "raise planner.max_agl (--max-agl)")
    return need_lo, need_hi, keep


def _phases(z: np.ndarray, cruise_z: np.ndarray, rel: np.ndarray, total: float) -> np.ndarray:
    """Phase of each sample: ``climb-out`` before the profile first meets the cruise, ``descent``
    after it last leaves it, ``cruise`` between (split at half way when it never meets it)."""
    m = len(z)
    on = np.abs(z - cruise_z) <= 1e-6
    phase = np.full(m, "cruise", dtype=object)
    if on.any():
        i0, i1 = int(np.argmax(on)), int(m - 1 - np.argmax(on[::-1]))
        phase[:i0] = "climb-out"
        phase[i1 + 1:] = "descent"
    else:  # the cones never let the profile reach the cruise: all transition
        half = int(np.searchsorted(rel, total / 2.0))
        phase[:half] = "climb-out"
        phase[half:] = "descent"
    return phase.astype(str)


def solve_profile(
    s: Any,
    surf_max: Any,
    ground_min: Any,
    level: FlightLevel,
    *,
    z_start: float,
    z_goal: float,
    ground_start: float,
    ground_goal: float,
    extra_lower: Any = None,
    extra_upper: Any = None,
    top: float = math.inf,
    xy: np.ndarray | None = None,
) -> dict[str, Any]:
    """The profile along sampled route positions (the array core of :func:`final_profile`).

    Parameters
    ----------
    s : array_like, shape (M,)
        Horizontal arc length of the samples [m].
    surf_max : array_like, shape (M,)
        Highest surface (ground or roof) under each sample and its chords [m]:
        the floor and the target are measured from it.
    ground_min : array_like, shape (M,)
        Lowest ground under each sample and its chords [m]: the ``max_agl``
        ceiling is measured from it.
    level : FlightLevel
        agl, tolerance, min_agl, max_agl, max_climb, max_descent.
    z_start, z_goal : float
        Heights of the start and goal [m].
    ground_start, ground_goal : float
        Surface under them [m].
    extra_lower, extra_upper : array_like, optional
        More bounds per sample (no-fly zones): ``-inf`` / ``+inf`` where none.
    top : float, optional
        Highest admissible altitude (the world's top node) [m].
    xy : ndarray, optional
        Sample positions, for error messages.

    Returns
    -------
    dict
        ``z`` (M,), ``cruise_z`` (M,), ``z_start_eff``, ``z_goal_eff``,
        ``phase`` (M,), ``required`` (M,: the floor above the surface kept at
        each sample), ``lifted_m``.

    Raises
    ------
    PlanningError
        No profile meets the floor, the ceiling and the slope limits.
    """
    s = np.asarray(s, dtype=float)
    smax = np.asarray(surf_max, dtype=float)
    gmin = np.asarray(ground_min, dtype=float)
    m = len(s)
    lim = level
    tc, td = _tan(lim.max_climb), _tan(lim.max_descent)
    lo_x = np.full(m, -np.inf) if extra_lower is None else np.asarray(extra_lower, dtype=float)
    up_x = np.full(m, np.inf) if extra_upper is None else np.asarray(extra_upper, dtype=float)
    target = np.maximum(smax + lim.agl, lo_x)
    floor = np.maximum(smax + floor_agl(lim), lo_x)
    ceil = np.minimum(np.minimum(gmin + (np.inf if lim.max_agl is None else float(lim.max_agl)), up_x), top)
    a = envelope_above(s, floor, tc, td)
    c = envelope_below(s, ceil, tc, td)
    bad = np.flatnonzero(a > c + 1e-6)
    if len(bad):
        i = int(bad[0])
        raise PlanningError(
            f"no flyable profile {_where(s[i], xy, i)}: keeping {floor_agl(lim):g} m above the "
            f"ground needs z >= {a[i]:.1f} m there, but the ceiling (planner.max_agl = "
            f"{lim.max_agl} m, no-fly zone floors, the map top) and the airframe's climb/descent "
            f"limits ({lim.max_climb:g}/{lim.max_descent:g} deg) allow at most {c[i]:.1f} m; "
            "raise planner.max_agl (--max-agl), lower planner.agl (--agl) or allow steeper climbs")
    cruise_z = np.maximum(a, np.minimum(envelope_above(s, target, tc, td), c))
    lifted = float(np.max(cruise_z - target)) if m else 0.0

    total = float(s[-1] - s[0])
    rel = s - s[0]
    bounds = (lim, smax, lo_x, ceil)
    # start cone: going forward z rises at most tc and drops at most td per metre
    lo_s, hi_s, keep_s = _cone_interval(z_start, ground_start, rel, tc, td, "start", *bounds)
    zs = min(max(z_start, lo_s), hi_s)
    lo_g, hi_g, keep_g = _cone_interval(z_goal, ground_goal, total - rel, td, tc, "goal", *bounds)
    # the goal's effective height must also be reachable from the start's
    lo_g, hi_g = max(lo_g, zs - td * total), min(hi_g, zs + tc * total)
    if lo_g > hi_g + 1e-6:
        raise PlanningError(
            f"start and goal are {total:.0f} m apart horizontally but need heights "
            f"{zs:.1f} m and {z_goal:.1f} m: more than the climb/descent limits "
            f"({lim.max_climb:g}/{lim.max_descent:g} deg) allow; move them or allow steeper climbs")
    zg = min(max(z_goal, lo_g), hi_g)
    lo = np.maximum(zs - td * rel, zg - tc * (total - rel))
    hi = np.minimum(zs + tc * rel, zg + td * (total - rel))
    z = np.minimum(np.maximum(cruise_z, lo), hi)
    phase = _phases(z, cruise_z, rel, total)
    required = np.where(phase == "cruise", floor_agl(lim),
                        np.where(phase == "climb-out", keep_s, keep_g)).astype(float)
    return {"z": z, "cruise_z": cruise_z, "z_start_eff": zs, "z_goal_eff": zg,
            "phase": phase, "required": required, "lifted_m": lifted}


def _check_ends_below_ceiling(world: Any, p: np.ndarray, level: FlightLevel) -> None:
    """Refuse a start / goal of path ``p`` higher above the ground than ``level.max_agl`` [m]."""
    for what, q in (("start", p[0]), ("goal", p[-1])):
        above = float(q[2] - world.ground_height(q[0], q[1]))
        if above > level.max_agl + 1e-6:
            raise PointError(
                f"the {what} is {above:.1f} m above the ground, above planner.max_agl = "
                f"{level.max_agl:g} m (CLI --max-agl); give the {what} at most "
                f"{level.max_agl:g} m above the ground (e.g. {what}: {{..., agl: "
                f"{min(level.agl, level.max_agl):g}}}) or raise --max-agl")


def _surface_envelope(world: Any, xy: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Surface at the route samples ``xy`` [m]; its upper and the ground's lower envelope.

    The chord between two samples is flown straight: it is read at 1/4, 1/2, 3/4, and
    the roof of every building footprint it meets counts (``World.buildings``).
    Returns the surface height at the samples, the highest surface and the lowest
    ground over each sample's two chords [m].
    """
    from ..world.ground import surface_and_ground

    fr = np.array([0.25, 0.5, 0.75])
    inner = (xy[:-1, None, :] + fr[None, :, None] * (xy[1:] - xy[:-1])[:, None, :]).reshape(-1, 2)
    n_ch = len(xy) - 1
    # samples and chord points in one read (the ground once: a reprojection per point)
    s_all, g_all = surface_and_ground(world, np.r_[xy[:, 0], inner[:, 0]],
                                      np.r_[xy[:, 1], inner[:, 1]])
    s_at, g_at = s_all[:len(xy)], g_all[:len(xy)]
    s_in, g_in = s_all[len(xy):], g_all[len(xy):]
    # z is linear along a chord, so only the surface's departure from its own chord
    # between two samples matters: bump (above the chord) for the floor, dip (below
    # it) for the ceiling; each sample takes the larger of its two chords
    if n_ch:
        lin_s = s_at[:-1, None] + fr[None, :] * (s_at[1:] - s_at[:-1])[:, None]
        lin_g = g_at[:-1, None] + fr[None, :] * (g_at[1:] - g_at[:-1])[:, None]
        bump = np.maximum((s_in.reshape(n_ch, 3) - lin_s).max(axis=1), 0.0)
        dip = np.maximum((lin_g - g_in.reshape(n_ch, 3)).max(axis=1), 0.0)
    else:
        bump = dip = np.zeros(0)
    smax = s_at + _window(np.zeros(len(xy)), bump, np.maximum)
    model = getattr(world, "buildings", None)
    if model is not None and n_ch:  # a roof a chord meets between its read points
        smax = np.maximum(smax, _window(np.full(len(xy), -np.inf),
                                        model.roof_along(xy[:-1], xy[1:]), np.maximum))
    gmin = g_at - _window(np.zeros(len(xy)), dip, np.maximum)
    return s_at, smax, gmin


def final_profile(world: Any, path: Any, level: FlightLevel, *, ds: float | None = None
                  ) -> AltitudeProfile:
    """The flown profile of an FM² path over a world (see the module docstring).

    Parameters
    ----------
    world : World
        3D world with :meth:`~fm2uav.World.surface_height` /
        :meth:`~fm2uav.World.ground_height` (and optional ``zones``).
    path : array_like, shape (N, 3)
        The FM² path [m]: its horizontal route is kept, its heights replaced
        (they only choose the side of zones with a floor/ceiling).
    level : FlightLevel
    ds : float, optional
        Sample spacing along the route [m]; default a quarter of the smallest
        horizontal cell.

    Returns
    -------
    AltitudeProfile

    Raises
    ------
    PlanningError
        No profile meets the limits (message names the fix).
    """
    from ..world.ground_model import sampling_step
    from ..world.zones import zone_bounds_along

    p = np.asarray(path, dtype=float)
    if p.ndim != 2 or p.shape[1] != 3:
        raise InputError(f"a final altitude profile needs a 3D path (N, 3), got {p.shape}")
    if ds is None:
        ds = sampling_step(world)
    if level.max_agl is not None:  # the take-off / landing points must be legal too
        _check_ends_below_ceiling(world, p, level)
    xy, s = resample_route(p, ds)
    s_at, smax, gmin = _surface_envelope(world, xy)
    # the FM² route's own height at each sample (chooses over/under a zone)
    cum = arc_length(p[:, :2])  # horizontal distance along the route
    z_route = np.interp(s, cum, p[:, 2]) if cum[-1] > 0 else np.full(len(s), p[0, 2])
    lo_x, up_x = zone_bounds_along(world, xy, z_route)
    top = float(world.bounds[2, 1])
    out = solve_profile(s, smax, gmin, level, z_start=float(p[0, 2]), z_goal=float(p[-1, 2]),
                        ground_start=float(s_at[0]), ground_goal=float(s_at[-1]),
                        extra_lower=lo_x, extra_upper=up_x, top=top, xy=xy)
    z = out["z"]
    rows = [np.column_stack([xy, z])]
    ss, ph, rq, sf = [s], [out["phase"]], [out["required"]], [s_at]
    vs = float(out["z_start_eff"] - p[0, 2])
    vg = float(out["z_goal_eff"] - p[-1, 2])
    if abs(vs) > 1e-6:
        rows.insert(0, p[:1])
        ss.insert(0, s[:1]); ph.insert(0, np.array(["climb-out"]))
        rq.insert(0, np.array([-np.inf])); sf.insert(0, s_at[:1])
    if abs(vg) > 1e-6:
        rows.append(p[-1:])
        ss.append(s[-1:]); ph.append(np.array(["descent"]))
        rq.append(np.array([-np.inf])); sf.append(s_at[-1:])
    flown = np.concatenate(rows)
    flown[0], flown[-1] = p[0], p[-1]
    required = np.concatenate(rq)
    required[0] = required[-1] = -np.inf
    phase = np.concatenate(ph)
    sss = np.concatenate(ss)
    co = phase == "climb-out"
    de = phase == "descent"
    return AltitudeProfile(
        path=flown, s=sss, surface=np.concatenate(sf), phase=phase, required=required,
        level=level, vertical_start_m=vs, vertical_goal_m=vg,
        climb_out_m=float(sss[co].max() - sss[0]) if co.any() else 0.0,
        descent_m=float(sss[-1] - sss[de].min()) if de.any() else 0.0,
        lifted_m=float(out["lifted_m"]),
    )


def join_profiles(profiles: Any) -> AltitudeProfile | None:
    """One profile of consecutive legs (a route through via points), or None.

    The legs' paths must join (each leg starts where the previous ended); the
    first point of every later leg is dropped, arc lengths are continued, the
    phases and floors kept per leg (a via point is a descent then a climb-out
    when its height differs from the cruise). Vertical legs, climb-out and
    descent lengths are those of the first / last leg; ``lifted_m`` the largest.
    """
    ps = [p for p in profiles]
    if not ps or any(p is None for p in ps):
        return None
    if len(ps) == 1:
        return ps[0]
    path = [ps[0].path]
    s = [ps[0].s]
    sf, ph, rq = [ps[0].surface], [ps[0].phase], [ps[0].required]
    off = float(ps[0].s[-1])
    for p in ps[1:]:
        path.append(p.path[1:])
        s.append(p.s[1:] - p.s[0] + off)
        sf.append(p.surface[1:])
        ph.append(p.phase[1:])
        rq.append(p.required[1:])
        off += float(p.s[-1] - p.s[0])
    first, last = ps[0], ps[-1]
    return AltitudeProfile(
        path=np.concatenate(path), s=np.concatenate(s), surface=np.concatenate(sf),
        phase=np.concatenate(ph), required=np.concatenate(rq), level=first.level,
        vertical_start_m=first.vertical_start_m, vertical_goal_m=last.vertical_goal_m,
        climb_out_m=first.climb_out_m, descent_m=last.descent_m,
        lifted_m=max(p.lifted_m for p in ps))


def height_figures(agl: Any, requested: float | None = None, *, band: float = 5.0,
                   points: Any = None, s: Any = None) -> dict[str, Any]:
    """Figures of a height-above-ground series: min, p5, median, max, share within ±band.

    Parameters
    ----------
    agl : array_like, shape (N,)
        Height above the ground/surface [m].
    requested : float, optional
        The requested height [m] (gives ``within_band``).
    band : float, optional
        Half-width [m] of the band around ``requested``. Default 5.
    points : array_like, shape (N, 3), optional
        The points, for ``lowest_point_m``.
    s : array_like, shape (N,), optional
        Arc length [m] of each point, for ``lowest_at_m``.

    Returns
    -------
    dict
        ``n``, ``min_m``, ``p5_m``, ``median_m``, ``max_m``, ``within_band``
        (share in [0, 1], or None), ``band_m``, and the lowest point.
    """
    h = np.asarray(agl, dtype=float).ravel()
    if len(h) == 0:
        return {"n": 0}
    i = int(np.argmin(h))
    out: dict[str, Any] = {
        "n": int(len(h)),
        "min_m": round(float(h[i]), 3),
        "p5_m": round(float(np.percentile(h, 5)), 3),
        "median_m": round(float(np.median(h)), 3),
        "max_m": round(float(np.max(h)), 3),
        "band_m": float(band),
        "within_band": (None if requested is None else
                        round(float(np.mean(np.abs(h - float(requested)) <= band)), 4)),
    }
    if points is not None:
        out["lowest_point_m"] = [round(float(v), 3) for v in np.asarray(points)[i]]
    if s is not None:
        out["lowest_at_m"] = round(float(np.asarray(s)[i]), 3)
    return out
