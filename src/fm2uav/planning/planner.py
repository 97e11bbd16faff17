"""The FM² planner: velocity map → arrival times from the goal → geodesic.

Thesis §2.2: (1) the binary map W0; (2) a wave from every obstacle gives the
velocity map W (distance to obstacles, rescaled to [0, 1], then shaped by the
saturation α and exponent β); (3) a wave from the goal over W gives the arrival
times T, stopped as soon as the start is reached; (4) gradient descent on T from
the start gives the path.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from scipy import ndimage

from ..world.clearance import clearance_profile
from ..eikonal.fmm import fast_marching
from ..eikonal.velocity import distance_map, normalise_distance, shape_velocity
from ..errors import InputError, PointError, UnreachableError
from ..world import World
from .flight_level import flight_level_speed
from .geodesic import descend

__all__ = ["Plan", "plan", "base_velocity"]


@dataclass(frozen=True, eq=False)
class Plan:
    """The result of :func:`plan`.

    Attributes
    ----------
    path : ndarray, shape (N, ndim)
        Path from start to goal in world coordinates [m]; ``path[0]`` is the
        start and ``path[-1]`` the goal, exactly.
    speed : ndarray, shape (N,)
        W interpolated (linearly) at each path point: the admissible speed as a
        share of the maximum, in [0, 1].
    length : float
        Path length [m].
    clearance : float
        Smallest distance from a path point to an obstacle node [m]
        (``inf`` on a map without obstacles).
    timings : dict of str to float
        Wall time of each stage [s]: ``velocity_map``, ``fast_marching``,
        ``geodesic``, ``metrics``, ``total``.
    W : ndarray
        The velocity map used (after saturation/exponent and any flight-level
        shaping), same shape as the world.
    T : ndarray
        Arrival times [s·(1/W)] of the wave from the goal; ``inf`` where not
        reached before the start was frozen.
    world : World
        The map planned on.
    params : dict
        The planner parameters (saturation, exponent, order, ...).
    """

    path: np.ndarray
    speed: np.ndarray
    length: float
    clearance: float
    timings: dict[str, float]
    W: np.ndarray = field(repr=False)
    T: np.ndarray = field(repr=False)
    world: World = field(repr=False)
    params: dict[str, Any] = field(default_factory=dict)

    @property
    def start(self) -> np.ndarray:
        """Start point [m]."""
        return self.path[0]

    @property
    def goal(self) -> np.ndarray:
        """Goal point [m]."""
        return self.path[-1]

    def lonlat(self) -> np.ndarray:
        """Path as WGS84 ``(lon [deg], lat [deg], alt [m])`` rows.

        Needs a geo-referenced world (``world.crs`` set, e.g. ``World.from_dem``);
        raises InputError otherwise. See :func:`fm2uav.world.geo.to_lonlat`.
        """
        from ..world.geo import to_lonlat

        return to_lonlat(self.world, self.path)

    def summary(self) -> dict[str, Any]:
        """Plain-Python summary (JSON-friendly) of the plan's numbers."""
        return {
            "start_m": [round(float(v), 3) for v in self.start],
            "goal_m": [round(float(v), 3) for v in self.goal],
            "points": int(len(self.path)),
            "length_m": round(float(self.length), 3),
            "clearance_m": float(self.clearance) if np.isfinite(self.clearance) else None,
            "min_speed": round(float(self.speed.min()), 6),
            "params": dict(self.params),
            "timings_s": {k: round(v, 6) for k, v in self.timings.items()},
        }


def base_velocity(world: World, *, method: str = "edt", walls: bool = False) -> np.ndarray:
    """Normalised velocity map of a world before shaping, cached on the world.

    ``d / max(d)`` with ``d`` the distance to the nearest obstacle; cached in
    ``world._cache`` because it depends only on the (immutable) occupancy, so
    sweeps over saturation/exponent pay the distance transform once.
    """
    key = ("base_velocity", method, bool(walls))
    cached = world._cache.get(key)
    if cached is None:
        dist = distance_map(world.occupancy, spacing=world.spacing, method=method, walls=walls)
        cached = normalise_distance(dist)
        cached.setflags(write=False)
        world._cache[key] = cached
    return cached


def _check_free(world: World, point: np.ndarray, what: str) -> tuple[int, ...]:
    # World.to_cell validates "inside the map" with a clear message and uses the
    # same nearest-node rule as the geodesic
    cell = world.to_cell(point, what=what)
    if world.occupancy[cell]:
        hint = ""
        if world.terrain is not None and world.ndim == 3:
            ground = float(world.terrain[cell[0], cell[1]])
            hint = f" (the ground there is at z = {ground:.1f} m; raise the {what} above it)"
        raise PointError(
            f"{what} {np.round(point, 3).tolist()} m is inside an obstacle (node {list(cell)})"
            f"{hint}; move the {what} to free space"
        )
    return cell


def _as_point(p: Any, ndim: int, what: str) -> np.ndarray:
    try:
        arr = np.asarray(p, dtype=float).reshape(-1)
    except (TypeError, ValueError):
        raise InputError(f"{what} must be {ndim} coordinates in metres, got {p!r}") from None
    if arr.size != ndim:
        raise InputError(
            f"{what} must have {ndim} coordinates (metres) for this {ndim}D world, got {arr.size}"
        )
    if not np.all(np.isfinite(arr)):
        raise InputError(f"{what} must be finite, got {arr.tolist()}")
    return arr


def plan(
    world: World,
    start: Any,
    goal: Any,
    *,
    saturation: float = 1.0,
    exponent: float = 1.0,
    order: int = 2,
    method: str = "edt",
    walls: bool = False,
    agl: float | None = None,
    p1: float = 0.5,
    p2: float = 1.5,
    agl_band: float = 0.0,
    agl_graded: bool = False,
    agl_mode: str = "capped",
    speed_map: np.ndarray | None = None,
    step: float = 0.5,
) -> Plan:
    """Plan a path from ``start`` to ``goal`` with Fast Marching Square.

    Parameters
    ----------
    world : World
        The map (occupancy True = obstacle).
    start, goal : sequence of float
        World coordinates [m].
    saturation : float, optional
        α in (0, 1]: ``W = min(W / α, 1)``. Default 1 (none).
    exponent : float, optional
        β > 0: ``W = W ** β``; < 1 lightens the map (smoother paths closer to
        obstacles), > 1 darkens it (paths further away). Default 1.
    order : {1, 2}, optional
        Order of both Fast Marching runs. Default 2.
    method : {"edt", "fmm"}, optional
        Distance to obstacles: exact transform or FMM from the obstacles as in
        the seeds. Default "edt".
    walls : bool, optional
        Treat the map border as an obstacle. Default False.
    agl : float, optional
        Impose a flight level this many metres above the ground (thesis
        Algorithm 2, see :mod:`fm2uav.planning.flight_level`). Default None.
    p1, p2 : float, optional
        Exponents on the flight-level cells and on all other cells (used with
        ``agl``). Defaults 0.5 and 1.5.
    agl_band : float, optional
        Half-width [m] of the clarified band around the level. Default 0 (the
        seeds' single layer).
    agl_graded : bool, optional
        Blend the exponent from p1 to p2 across the band. Default False.
    agl_mode : {"capped", "literal"}, optional
        How Algorithm 2 reads W (see :func:`~fm2uav.planning.flight_level.flight_level_speed`):
        "capped" (default) caps each column at W of its flight-level node so the
        level is the brightest cell; "literal" exponentiates W as is (climbs to
        the ceiling on open maps, kept for comparison; docs/tff.md).
    speed_map : ndarray, optional
        Use this velocity map instead of computing one (0 = impassable);
        saturation/exponent/method/walls are then ignored. This is the hook for
        extra shaping (flight levels, other UAVs).
    step : float, optional
        Geodesic step, in cells of the finest axis. Default 0.5.

    Returns
    -------
    Plan

    Raises
    ------
    fm2uav.PlanningError
        Start or goal outside the map or inside an obstacle.
    fm2uav.UnreachableError
        No free connection between start and goal.
    fm2uav.InputError
        Bad parameter values.

    Examples
    --------
    >>> import numpy as np
    >>> from fm2uav import World, plan
    >>> occ = np.zeros((40, 30), bool); occ[18:22, 0:20] = True
    >>> p = plan(World(occ, spacing=1.0), (5.0, 5.0), (35.0, 5.0))
    >>> bool(p.path[:, 1].max() > 20)   # goes around the wall
    True
    """
    t_all = time.perf_counter()
    if not isinstance(world, World):
        raise InputError(f"world must be a fm2uav.World, got {type(world).__name__}")
    start_m = _as_point(start, world.ndim, "start")
    goal_m = _as_point(goal, world.ndim, "goal")
    start_cell = _check_free(world, start_m, "start")
    goal_cell = _check_free(world, goal_m, "goal")

    t0 = time.perf_counter()
    if speed_map is None:
        # 0 on obstacles already (distance 0); the cached base map is read-only
        # and used as is when there is nothing to shape
        W = base_velocity(world, method=method, walls=walls)
        if saturation != 1.0 or exponent != 1.0:
            W = shape_velocity(W, saturation=saturation, exponent=exponent)
        if agl is not None:
            W = flight_level_speed(
                W, world, agl, p1, p2, band=agl_band, graded=agl_graded, mode=agl_mode
            )
    else:
        W = np.asarray(speed_map, dtype=float)
        if W.shape != world.shape:
            raise InputError(
                f"speed_map has shape {W.shape} but the world is {world.shape}; "
                "give one speed per node"
            )
    t1 = time.perf_counter()
    if W[start_cell] <= 0 or W[goal_cell] <= 0:
        which = "start" if W[start_cell] <= 0 else "goal"
        raise PointError(
            f"the velocity map is 0 at the {which} node; move the {which} away from obstacles"
        )
    T = fast_marching(W, [goal_cell], spacing=world.spacing, order=order, stop_at=[start_cell])
    t2 = time.perf_counter()
    if not np.isfinite(T[start_cell]):
        raise UnreachableError(
            f"the goal {np.round(goal_m, 3).tolist()} m cannot be reached from the start "
            f"{np.round(start_m, 3).tolist()} m: no free connection between them; move one "
            "of them into the other's free region or clear the separating obstacles"
        )
    # descend() never enters nodes with T = inf; obstacles have W = 0, hence
    # T = inf, unless a custom speed map gave them a speed: only then pass the
    # mask (it costs a copy of T, ~1 s on a 40M-node map).
    blocked = world.occupancy if np.isfinite(T[world.occupancy]).any() else None
    path_idx = descend(
        T,
        world.to_index(start_m),
        world.to_index(goal_m),
        spacing=world.spacing,
        blocked=blocked,
        step=step,
    )
    path = world.to_world(path_idx)
    t3 = time.perf_counter()
    speed = ndimage.map_coordinates(W, path_idx.T, order=1, mode="nearest")
    length = float(np.sum(np.linalg.norm(np.diff(path, axis=0), axis=1)))
    clearance = float(clearance_profile(world, path).min())
    t4 = time.perf_counter()
    timings = {
        "velocity_map": t1 - t0,
        "fast_marching": t2 - t1,
        "geodesic": t3 - t2,
        "metrics": t4 - t3,
        "total": t4 - t_all,
    }
    params = {
        "saturation": float(saturation),
        "exponent": float(exponent),
        "order": int(order),
        "method": method,
        "walls": bool(walls),
        "custom_speed_map": speed_map is not None,
    }
    if agl is not None and speed_map is None:
        params.update(agl=float(agl), p1=float(p1), p2=float(p2),
                      agl_band=float(agl_band), agl_graded=bool(agl_graded),
                      agl_mode=str(agl_mode))
    return Plan(
        path=path,
        speed=speed,
        length=length,
        clearance=clearance,
        timings=timings,
        W=W,
        T=T,
        world=world,
        params=params,
    )
