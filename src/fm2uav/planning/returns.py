"""Return fields: one FM² wave from home (or a rally point) gives the safe way back from everywhere.

FM² plans by descending the arrival times ``T`` of a wave started at the goal. Started
at a *return destination* instead — home, or a rally point — and marched over the
whole map on the mission's own velocity map ``W`` (the same world, obstacles,
no-fly zones, saturation and flight level the route was planned on), the same wave
answers "how do I get back from here?" for every point at once: the descent of
``T`` from any point is the FM² path home, planned like the route itself, and its
heights come from the same final altitude profile (terrain following at the
requested height, limits, zone floors/ceilings: :func:`fm2uav.planning.altitude.final_profile`).

:class:`ReturnField` holds one such wave: one march per destination, then one
cheap descent per point asked (:meth:`ReturnField.paths`; the descents of many
points are :func:`descend_many`, the single swap point for a batched many-routes
descent). Times, speeds and energy are the airframe's business
(:mod:`fm2uav.autopilot.safe_return`); this module returns paths in metres.

A regional plan (:mod:`fm2uav.planning.regional`) has no world-sized ``W``: its
return field cannot be marched (:class:`~fm2uav.errors.InputError`).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .._validate import point as as_point
from ..eikonal.fmm import fast_marching
from ..errors import InputError, PlanningError, UnreachableError
from ..geometry import path_length
from .altitude import AltitudeProfile, final_profile
from .geodesic import descend_batch
from .params import FlightLevel

__all__ = ["ReturnPath", "ReturnField", "descend_many", "return_fields"]


@dataclass(frozen=True, eq=False)
class ReturnPath:
    """The FM² way back from one point.

    Attributes
    ----------
    path : ndarray, shape (N, ndim)
        From the point (``path[0]``, exactly) to the destination (``path[-1]``) [m];
        3D heights from the final altitude profile when the field has a flight level.
    destination : str
        Name of the field's destination (``"home"``, ``"rally 1"``, ...).
    length : float
        Length of ``path`` [m] (3D on a 3D world).
    profile : AltitudeProfile or None
        The heights' profile (floors of each point in ``profile.required``).
    """

    path: np.ndarray
    destination: str
    length: float
    profile: AltitudeProfile | None = field(default=None, repr=False)


def descend_many(T: np.ndarray, starts: Sequence[Any], goal: Any, *, spacing: Any,
                 step: float = 0.5, blocked: Any = None) -> list[np.ndarray]:
    """Descents of one arrival-time field from many starts, in index coordinates.

    Each start gets the descent of ``T`` to ``goal`` (``T``'s source;
    :func:`fm2uav.planning.geodesic.descend_batch`: the field checked once); a start on
    the goal's node gets the straight two-point path. The one place that runs many
    descents of one wave: a batched many-routes descent (issue 27) replaces it without
    changing its callers.

    Parameters
    ----------
    T : ndarray
        Arrival times of a wave from ``goal``'s nearest node.
    starts : sequence of array_like
        Start points in index coordinates [cells].
    goal : array_like
        The source in index coordinates [cells].
    spacing, step, blocked
        As :func:`~fm2uav.planning.geodesic.descend`.

    Returns
    -------
    list of ndarray
        One (N, ndim) path per start, in index coordinates.
    """
    g = np.asarray(goal, dtype=float)
    gn = np.floor(g + 0.5)
    pts = [np.asarray(s, dtype=float) for s in starts]
    far = [k for k, s in enumerate(pts) if not np.array_equal(np.floor(s + 0.5), gn)]
    paths = descend_batch(T, [pts[k] for k in far], g, spacing=spacing, blocked=blocked,
                          step=step)
    out: list[np.ndarray] = [np.vstack([s, g]) for s in pts]
    for k, p in zip(far, paths):
        out[k] = p
    return out


class ReturnField:
    """One FM² wave from a return destination over a mission's velocity map.

    Parameters
    ----------
    world : World
        The map the mission was planned on (zones included).
    W : ndarray
        The mission's velocity map (``Plan.W``: shaping, zones, flight level).
    source : array_like
        The destination [m]: where the way back ends (home: the route's start,
        above the take-off point; a rally point: its approach point above the ground).
    name : str
        ``"home"``, ``"rally 1"``, ...
    level : FlightLevel, optional
        The mission's flight level: return paths get its final altitude profile.
    order : {1, 2}
        Fast Marching order (the plan's).
    step : float
        Geodesic step in cells (the plan's).

    Raises
    ------
    InputError
        ``W`` does not match the world, or the source is outside the map.
    PlanningError
        The source is in an obstacle or where ``W`` = 0.
    """

    def __init__(self, world: Any, W: Any, source: Any, *, name: str = "home",
                 level: FlightLevel | None = None, order: int = 2, step: float = 0.5) -> None:
        W = np.asarray(W)
        if W.shape != world.shape:
            raise InputError(f"the velocity map has shape {W.shape} but the world is "
                             f"{world.shape}: a return field needs the plan's full-grid W")
        self.world, self.W, self.name = world, W, str(name)
        self.level, self.order, self.step = level, int(order), float(step)
        self.source = as_point(source, world.ndim, f"{name} (return destination)")
        cell = world.to_cell(self.source, what=f"{name} (return destination)")
        if world.occupancy[cell] or W[cell] <= 0:
            raise PlanningError(f"the return destination {name} at "
                                f"{np.round(self.source, 1).tolist()} m lies in an obstacle or "
                                "a no-fly zone; move it to free air")
        self._cell = cell
        self._blocked: Any = None
        self.T = fast_marching(W, [cell], spacing=world.spacing, order=self.order)

    @classmethod
    def from_plan(cls, plan: Any, source: Any, name: str = "home") -> ReturnField:
        """The return field of ``source`` on a plan's (or route's) map, level and settings.

        Raises
        ------
        InputError
            A regional plan (no world-sized velocity map).
        """
        params = dict(getattr(plan, "params", {}) or {})
        if params.get("storage") == "regional" or np.shape(plan.W) != plan.world.shape:
            raise InputError("return fields need the plan's full velocity map; this plan is "
                             "regional (coarse-to-fine windows, planner.storage / --storage): "
                             "plan with storage full, or leave the returns out (--no-returns)")
        return cls(plan.world, plan.W, source, name=name, level=getattr(plan, "level", None),
                   order=int(params.get("order", 2)), step=float(params.get("step", 0.5)))

    # ------------------------------------------------------------------ queries
    def cost(self, points: Any) -> np.ndarray:
        """FM² arrival time of the wave at ``points`` [s·(1/W), nearest node]: the
        planner's own measure of how far home is (``inf`` where it cannot return)."""
        p = np.atleast_2d(np.asarray(points, dtype=float))
        idx = np.floor(self.world.to_index(p) + 0.5).astype(np.int64)
        idx = np.clip(idx, 0, np.asarray(self.world.shape) - 1)
        return self.T[tuple(idx.T)]

    def paths(self, starts: Any) -> list[ReturnPath]:
        """The FM² way back from each of ``starts`` [m] (:class:`ReturnPath`).

        Raises
        ------
        UnreachableError
            A start the wave never reached (cut off from the destination).
        PlanningError
            No altitude profile meets the flight level's limits along a way back.
        """
        pts = np.atleast_2d(np.asarray(starts, dtype=float))
        w = self.world
        cut = np.flatnonzero(~np.isfinite(self.cost(pts)))
        if len(cut):
            raise UnreachableError(
                f"no way back to {self.name} from {np.round(pts[cut[0]], 1).tolist()} m: the "
                "point is cut off from it on the mission's map")
        if self._blocked is None:  # obstacles need the mask only if W gave them a speed
            self._blocked = (w.occupancy if np.isfinite(self.T[w.occupancy]).any() else False)
        blocked = self._blocked if self._blocked is not False else None
        raw = descend_many(self.T, list(w.to_index(pts)), w.to_index(self.source),
                           spacing=w.spacing, step=self.step, blocked=blocked)
        return [self._finish(pts[k], w.to_world(q)) for k, q in enumerate(raw)]

    def path(self, start: Any) -> ReturnPath:
        """The FM² way back from one point (:meth:`paths`)."""
        return self.paths([start])[0]

    def _finish(self, start: np.ndarray, path: np.ndarray) -> ReturnPath:
        w = self.world
        path = np.asarray(path, dtype=float)
        path[0], path[-1] = start, self.source
        profile = None
        lev = self.level
        if lev is not None and lev.heights == "ground" and w.ndim == 3 and len(path) > 1:
            profile = final_profile(w, path, lev)
            path = profile.path
        if w.zones:
            from ..world.zones import zone_violations

            bad = zone_violations(w, path)
            if bad:  # the zones are obstacles of W: a bug, never a user error
                raise PlanningError(
                    f"the way back to {self.name} enters {bad[0].zone!r} at "
                    f"{np.round(bad[0].point, 1).tolist()} m; please report this")
        return ReturnPath(path=path, destination=self.name, length=path_length(path),
                          profile=profile)


def return_fields(plan: Any, sources: dict[str, Any]) -> dict[str, ReturnField]:
    """One :class:`ReturnField` per named destination [m] on a plan's map (one march each)."""
    return {name: ReturnField.from_plan(plan, p, name) for name, p in sources.items()}
