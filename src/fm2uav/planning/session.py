"""A planning session that keeps its maps and re-plans in a changing world.

The seeds re-plan when the environment changes (the coverage paper re-plans in
0.36 s; the formation chapter every control cycle). :class:`Planner` keeps the
velocity map W and the arrival times T of the wave from the goal (marched as far
as the starts asked for so far), so

* a re-plan from the vehicle's current position is only the descent of T
  (and, if the vehicle moved further from the goal than any start so far, the
  continuation of the march up to it);
* after obstacles or no-fly zones are added or removed, W is rebuilt and T is
  re-marched only where the change can reach (:func:`fm2uav.eikonal.restart.remarch`:
  every node the wave froze before meeting the change keeps its time).

The saving of the second case depends on how far the change is from the goal
and on how far W changes: with a relative saturation (``Shaping.saturation``) a
new obstacle that changes the map's largest obstacle distance rescales W
everywhere, and the re-march is a full one; ``Shaping.saturation_distance`` (m)
keeps the change local.
"""

from __future__ import annotations

import time
from dataclasses import replace
from typing import Any

import numpy as np

from .. import _validate
from ..eikonal.fmm import fast_marching
from ..eikonal.restart import remarch, unaffected
from ..errors import InputError, PointError
from ..world import World
from ..world.zones import Zone, check_points_allowed, with_zones
from .params import FlightLevel, PlanOptions, Shaping
from .planner import Plan, _check_free, _check_objects, plan_velocity, trace_plan

__all__ = ["Planner"]


class Planner:
    """FM² towards one goal, re-planned as the vehicle moves and the world changes.

    Parameters
    ----------
    world : World
        The map at the start of the session.
    goal : sequence of float
        Goal [m], world coordinates.
    shaping, level, options
        As in :func:`fm2uav.plan` (``options.speed_map`` is not allowed: the
        session builds W itself).

    Attributes
    ----------
    world : World
        The current map (base world + added obstacles and zones).
    last_update : dict
        What the last world change cost: ``seconds``, ``reused`` (share of the
        nodes whose arrival time was kept), ``full`` (True if it re-marched all).

    Examples
    --------
    >>> import numpy as np
    >>> from fm2uav import World
    >>> occ = np.zeros((60, 40), bool)
    >>> s = Planner(World(occ, spacing=1.0), goal=(55.0, 20.0))
    >>> p0 = s.plan((5.0, 20.0))
    >>> wall = np.zeros_like(occ); wall[30, 5:35] = True
    >>> s.add_obstacles(wall)
    >>> p1 = s.plan((10.0, 20.0))          # from the vehicle's new position
    >>> bool(p1.length > p0.length - 5.0)   # around the wall now
    True
    """

    def __init__(self, world: World, goal: Any, *, shaping: Shaping = Shaping(),
                 level: FlightLevel | None = None, options: PlanOptions = PlanOptions()) -> None:
        if not isinstance(world, World):
            raise InputError(f"world must be a fm2uav.World, got {type(world).__name__}")
        _check_objects(shaping, level, options)
        if options.speed_map is not None:
            raise InputError("Planner builds W itself: options.speed_map must be None "
                             "(use fm2uav.plan for a custom speed map)")
        self._shaping, self._level, self._options = shaping, level, options
        self._base = world
        self._extra = np.zeros(world.shape, dtype=bool)  # obstacles added in the session
        self._cleared = np.zeros(world.shape, dtype=bool)  # base obstacles removed
        self._zones: tuple[Zone, ...] = ()
        self.world = world
        self.goal = _validate.point(goal, world.ndim, "goal")
        if world.zones:
            check_points_allowed(world, {"goal": self.goal})
        self._goal_cell = _check_free(world, self.goal, "goal")
        t0 = time.perf_counter()
        self._W = plan_velocity(world, shaping, level, options)
        self._check_goal_speed()
        # arrival times from the goal, marched as far as the last start asked for
        # (inf beyond): later plans continue the march, world changes re-use it
        self._T = fast_marching(self._W, [self._goal_cell], spacing=world.spacing,
                                order=options.order, stop_at=[self._goal_cell])
        self._stop: list[tuple[int, ...]] = [self._goal_cell]
        self.last_update = {"seconds": time.perf_counter() - t0, "reused": 0.0, "full": True}

    # ------------------------------------------------------------------ planning
    def plan(self, start: Any) -> Plan:
        """The FM² path from ``start`` (e.g. the vehicle's current position) to the goal.

        Only the descent of the kept arrival times runs; ``Plan.timings`` has
        ``velocity_map`` and ``fast_marching`` = 0.

        Raises
        ------
        PointError
            Start outside the map, in an obstacle or a zone.
        UnreachableError
            The start is cut off from the goal in the current world.
        """
        t0 = time.perf_counter()
        start_m = _validate.point(start, self.world.ndim, "start")
        if self.world.zones:
            check_points_allowed(self.world, {"start": start_m})
        cell = _check_free(self.world, start_m, "start")
        if not np.isfinite(self._T[cell]):  # continue the march up to this start
            self._stop = [cell]
            self._T = remarch(self._W, [self._goal_cell], self._T,
                              np.zeros(self.world.shape, dtype=bool), spacing=self.world.spacing,
                              order=self._options.order, stop_at=self._stop)
        return trace_plan(self.world, self._W, self._T, start_m, self.goal, self._shaping,
                          self._level, self._options, (t0, t0, t0, t0))

    # ------------------------------------------------------------------ world changes
    def add_obstacles(self, mask: Any) -> None:
        """Block the nodes where ``mask`` is True (bool array of the world's shape)."""
        m = self._mask(mask, "add_obstacles")
        self._extra |= m
        self._cleared &= ~m
        self._rebuild()

    def remove_obstacles(self, mask: Any) -> None:
        """Free the nodes where ``mask`` is True (added ones and the base map's own)."""
        m = self._mask(mask, "remove_obstacles")
        self._extra &= ~m
        self._cleared |= m & self._base.occupancy
        self._rebuild()

    def add_zones(self, zones: Any) -> None:
        """Add no-fly zones / an operating area (:class:`fm2uav.world.zones.Zone`)."""
        zs = tuple(zones) if not isinstance(zones, Zone) else (zones,)
        bad = [z for z in zs if not isinstance(z, Zone)]
        if bad:
            raise InputError(f"add_zones takes fm2uav.world.zones.Zone objects, got "
                             f"{type(bad[0]).__name__}")
        self._zones = self._zones + zs
        self._rebuild()

    def remove_zones(self, names: Any) -> None:
        """Remove the session's zones with these names (``Zone.name``)."""
        wanted = {names} if isinstance(names, str) else set(names)
        known = {z.name for z in self._zones}
        missing = sorted(wanted - known)
        if missing:
            raise InputError(f"no zone named {missing[0]!r} in this session; its zones are "
                             f"{sorted(known) or 'none'}")
        self._zones = tuple(z for z in self._zones if z.name not in wanted)
        self._rebuild()

    # ------------------------------------------------------------------ internals
    def _mask(self, mask: Any, what: str) -> np.ndarray:
        m = np.asarray(mask)
        if m.dtype != bool or m.shape != self._base.shape:
            raise InputError(f"{what} takes a bool mask of the world's shape {self._base.shape}, "
                             f"got {m.dtype} {m.shape}")
        return m

    def _check_goal_speed(self) -> None:
        if self._W[self._goal_cell] <= 0:
            raise PointError("the velocity map is 0 at the goal node; move the goal away "
                             "from obstacles")

    def _local_velocity(self, world: World) -> np.ndarray | None:
        """W of ``world`` recomputed only around the occupancy change, or None.

        With a saturation distance ``d_sat`` (and no walls, EDT distances) W can
        change only within ``d_sat`` of the changed nodes (the inner box), and
        there it depends only on obstacles within ``d_sat`` (the outer box, one
        ``d_sat`` further): W of a sub-world cut to the outer box is exact on the
        inner box. Flight-level shaping is per column, so boxes keep full columns.
        """
        sh = self._shaping
        if sh.saturation_distance is None or sh.walls or sh.method != "edt":
            return None
        diff = world.occupancy != self.world.occupancy
        if not diff.any():
            return self._W
        idx = np.argwhere(diff)
        r = np.ceil(sh.saturation_distance / np.asarray(world.spacing)).astype(int) + 1
        if world.ndim == 3:
            r[2] = world.shape[2]  # whole columns
        shape = np.asarray(world.shape)
        lo_in, hi_in = np.maximum(idx.min(0) - r, 0), np.minimum(idx.max(0) + r + 1, shape)
        lo_out, hi_out = np.maximum(lo_in - r, 0), np.minimum(hi_in + r, shape)
        if np.prod(hi_out - lo_out) > 0.5 * world.occupancy.size:
            return None  # most of the map: the full computation is as cheap
        outer = tuple(slice(a, b) for a, b in zip(lo_out, hi_out))
        col = outer[:2]
        origin = tuple(np.asarray(world.origin) + lo_out * np.asarray(world.spacing))
        sub = replace(
            world, occupancy=world.occupancy[outer], origin=origin, zones=(),
            terrain=None if world.terrain is None else world.terrain[col],
            filled=None if world.filled is None else world.filled[col],
            ground=world.ground,
        )
        W_sub = plan_velocity(sub, sh, self._level, self._options)
        W = np.array(self._W, copy=True)
        inner = tuple(slice(a, b) for a, b in zip(lo_in, hi_in))
        inner_sub = tuple(slice(a - o, b - o) for a, b, o in zip(lo_in, hi_in, lo_out))
        W[inner] = W_sub[inner_sub]
        return W

    def _rebuild(self) -> None:
        t0 = time.perf_counter()
        occ = (self._base.occupancy & ~self._cleared) | self._extra
        world = replace(self._base, occupancy=occ)
        if self._zones:
            world = with_zones(world, self._zones)
        if world.occupancy[self._goal_cell]:
            raise PointError(f"the change blocks the goal {np.round(self.goal, 3).tolist()} m; "
                             "keep the goal free or start a new Planner")
        W = self._local_velocity(world)
        if W is None:
            W = plan_velocity(world, self._shaping, self._level, self._options)
        changed = W != self._W
        kept = float(np.count_nonzero(unaffected(self._T, changed)))
        self._T = remarch(W, [self._goal_cell], self._T, changed, spacing=world.spacing,
                          order=self._options.order, stop_at=self._stop)
        self.world, self._W = world, W
        self._check_goal_speed()
        self.last_update = {
            "seconds": time.perf_counter() - t0,
            "changed_nodes": int(changed.sum()),
            "reused": kept / changed.size,
            "full": kept == 0,
        }
