"""Static maps of a formation mission and the per-cycle local FM² re-plan.

Everything that does not change between cycles is computed once per mission
(and the terrain parts once per world, cached in ``World._cache``):

* the static velocity map ``W`` of the terrain (:func:`fm2uav.planning.shaped_velocity`,
  then the flight-level shaping of each UAV's :class:`~fm2uav.FlightLevel`);
* the terrain *clearance band*: nodes closer than ``clearance`` to the terrain
  are impassable (``W = 0``), which keeps every path point strictly above the
  ground surface, not only off the obstacle nodes (see :func:`local_path`);
* the horizontal clearance (distance to the terrain within the same height
  layer), whose saturated value is the grey level of the partial goals.

Each cycle, each UAV re-plans only inside a small window around its position
and its partial goal (thesis ch. 6 steps 5a–5e): the other UAVs enter its
binary map as obstacles, so its first potential becomes
``W_i = min(W_static, shape(d_uav / d_max))`` — exactly the FM² velocity map of
the terrain plus point obstacles at the other UAVs, since the distance to a
union is the minimum of the distances and the shaping is monotone — and nodes
within a safety radius of another UAV are impassable. Then ``T_i`` from the
partial goal (stopped at the UAV) and gradient descent give the path.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import ndimage

from ...eikonal.fmm import fast_marching
from ...eikonal.velocity import distance_map, shape_velocity
from ...planning import FlightLevel, Shaping, max_distance, shaped_velocity
from ...planning.flight_level import flight_layer, flight_level_speed
from ...planning.geodesic import descend, nearest_node
from ...world import World

__all__ = ["StaticMaps", "LocalPath", "local_path", "terrain_distance", "horizontal_clearance"]

#: Horizontal clearance of layers without any obstacle [m].
_FAR = 1e9


def terrain_distance(world: World) -> np.ndarray:
    """Exact distance [m] from every node to the nearest obstacle node, cached on the world."""
    key = ("formation", "terrain_distance")
    d = world._cache.get(key)
    if d is None:
        d = distance_map(world.occupancy, spacing=world.spacing, method="edt", walls=False)
        d.setflags(write=False)
        world._cache[key] = d
    return d


def horizontal_clearance(world: World) -> np.ndarray:
    """Distance [m] to the nearest obstacle node *in the same height layer*, cached.

    One Euclidean distance transform with a huge vertical sampling, so the
    nearest obstacle is always searched within the layer; layers without any
    obstacle get ``1e9`` m.
    """
    key = ("formation", "horizontal_clearance")
    d = world._cache.get(key)
    if d is None:
        occ = world.occupancy
        if not occ.any():
            d = np.full(occ.shape, _FAR)
        else:
            dx, dy, _ = world.spacing
            d = np.minimum(ndimage.distance_transform_edt(~occ, sampling=(dx, dy, _FAR)), _FAR)
        d.setflags(write=False)
        world._cache[key] = d
    return d


class StaticMaps:
    """The parts of every UAV's velocity map that stay fixed during a mission.

    Parameters
    ----------
    world : World
        3D map.
    shaping : Shaping
        FM² shaping of ``W`` (as in :func:`fm2uav.plan`); also applied to the
        distance to the other UAVs in :func:`local_path`.
    clearance : float
        Nodes closer than this to the terrain are impassable [m].
    """

    def __init__(self, world: World, shaping: Shaping, clearance: float) -> None:
        self.world = world
        self.shaping = shaping
        self.clearance = float(clearance)
        self.spacing = np.asarray(world.spacing, dtype=float)
        self.origin = np.asarray(world.origin, dtype=float)
        self.shape = np.asarray(world.shape, dtype=np.int64)
        self.half_diagonal = 0.5 * float(np.linalg.norm(self.spacing))
        self.allowed = terrain_distance(world) >= self.clearance
        # The normaliser of W (largest distance to an obstacle), for the UAV term.
        dmax = max_distance(world, shaping)
        if not (np.isfinite(dmax) and dmax > 0.0):
            dmax = float(np.linalg.norm((self.shape - 1) * self.spacing)) or 1.0
        self.dmax = dmax
        W0 = shaped_velocity(world, shaping)
        W0 = W0.copy() if not W0.flags.writeable else W0
        W0[world.occupancy] = 0.0
        self._W0 = W0
        self._W: dict[FlightLevel | None, np.ndarray] = {}
        self._layer: dict[float, np.ndarray] = {}
        self.hclear = horizontal_clearance(world)

    def speed(self, level: FlightLevel | None) -> np.ndarray:
        """Static ``W`` of a UAV flying at ``level`` (None: free), read-only.

        Flight-level shaping (:func:`fm2uav.planning.flight_level.flight_level_speed`)
        and the clearance band applied; cached per level.
        """
        W = self._W.get(level)
        if W is None:
            if level is None:
                W = self._W0.copy()
            else:
                W = np.array(flight_level_speed(self._W0, self.world, level), dtype=float)
            W[~self.allowed] = 0.0
            W.setflags(write=False)
            self._W[level] = W
        return W

    def level_z(self, agl: float, xy: np.ndarray) -> np.ndarray:
        """Height [m] of the flight level ``agl`` at points ``xy`` (..., 2) [m].

        The level's layer (:func:`fm2uav.planning.flight_level.flight_layer`)
        interpolated bilinearly between columns.
        """
        key = float(agl)
        layer = self._layer.get(key)
        if layer is None:
            layer = np.asarray(flight_layer(self.world, key), dtype=float)
            self._layer[key] = layer
        xy = np.asarray(xy, dtype=float)
        idx = (xy - self.origin[:2]) / self.spacing[:2]
        flat = idx.reshape(-1, 2).T
        k = ndimage.map_coordinates(layer, flat, order=1, mode="nearest")
        return (self.origin[2] + k * self.spacing[2]).reshape(xy.shape[:-1])

    def horizontal_clearance_at(self, points: np.ndarray) -> np.ndarray:
        """Horizontal clearance [m] (:func:`horizontal_clearance`) at points (..., 3), trilinear."""
        pts = np.asarray(points, dtype=float)
        idx = ((pts.reshape(-1, 3) - self.origin) / self.spacing).T
        out = ndimage.map_coordinates(self.hclear, idx, order=1, mode="nearest")
        return out.reshape(pts.shape[:-1])


@dataclass(frozen=True)
class LocalPath:
    """One UAV's re-plan of one cycle.

    Attributes
    ----------
    path : ndarray, shape (N, 3)
        From the UAV's position to the (possibly projected) goal [m].
    goal : ndarray, shape (3,)
        The goal actually planned to [m].
    projected : bool
        The requested partial goal was not reachable inside the window (in an
        obstacle, in the terrain clearance band, in another UAV's safety ball,
        or cut off) and was moved to the nearest reachable node.
    blocked : bool
        The UAV's own node was impassable: no path (``path`` is the position).
    """

    path: np.ndarray
    goal: np.ndarray
    projected: bool
    blocked: bool


def local_path(
    maps: StaticMaps,
    W_static: np.ndarray,
    start: np.ndarray,
    goal: np.ndarray,
    others: np.ndarray,
    radii: np.ndarray,
    *,
    margin: int = 6,
    order: int = 2,
    step: float = 0.5,
) -> LocalPath:
    """FM² from ``start`` to ``goal`` inside a window, other UAVs as obstacles.

    Parameters
    ----------
    maps : StaticMaps
    W_static : ndarray
        This UAV's static velocity map (``maps.speed(level)``), full size.
    start, goal : ndarray, shape (3,)
        World points [m]; ``goal`` is clipped into the map.
    others : ndarray, shape (k, 3)
        Positions of the other UAVs [m].
    radii : ndarray, shape (k,)
        Nodes closer than ``radii[k]`` to ``others[k]`` are impassable [m].
    margin : int
        Window padding around the bounding box of start and goal [cells].
    order : {1, 2}
        Fast Marching order.
    step : float
        Geodesic step [cells].

    Returns
    -------
    LocalPath
        Path points and segments never enter the cell of an impassable node
        (guarantee of :func:`fm2uav.planning.descend`).
    """
    h, org, shape = maps.spacing, maps.origin, maps.shape
    start = np.asarray(start, dtype=float)
    si = (start - org) / h
    gi = np.clip((np.asarray(goal, dtype=float) - org) / h, 0.0, shape - 1.0)
    sn = np.clip(nearest_node(si), 0, shape - 1)
    gn = nearest_node(gi)
    lo = np.maximum(np.minimum(sn, gn) - margin, 0)
    hi = np.minimum(np.maximum(sn, gn) + margin + 1, shape)
    win = tuple(slice(int(a), int(b)) for a, b in zip(lo, hi))
    W = np.array(W_static[win], dtype=float)
    if len(others):
        axes = [org[a] + (lo[a] + np.arange(hi[a] - lo[a])) * h[a] for a in range(3)]
        X, Y, Z = np.meshgrid(*axes, indexing="ij", sparse=True)
        d_min = np.full(W.shape, np.inf)
        ball = np.zeros(W.shape, dtype=bool)
        for p, r in zip(np.asarray(others, dtype=float), np.asarray(radii, dtype=float)):
            d = np.sqrt((X - p[0]) ** 2 + (Y - p[1]) ** 2 + (Z - p[2]) ** 2)
            np.minimum(d_min, d, out=d_min)
            ball |= d < r
        sh = maps.shaping
        W_uav = shape_velocity(np.minimum(d_min / maps.dmax, 1.0), saturation=sh.saturation,
                               exponent=sh.exponent, saturation_distance=sh.saturation_distance,
                               max_distance=maps.dmax)
        np.minimum(W, W_uav, out=W)
        W[ball] = 0.0
    free = W > 0.0
    s_loc = tuple(int(v) for v in sn - lo)
    if not free[s_loc]:
        return LocalPath(path=start[None, :].copy(), goal=start.copy(), projected=True,
                         blocked=True)
    labels, _ = ndimage.label(free)
    comp = labels == labels[s_loc]
    g_loc_node = gn - lo
    g_cont = gi - lo
    projected = False
    if not comp[tuple(int(v) for v in g_loc_node)]:
        nodes = np.argwhere(comp)
        k = int(np.argmin((((nodes - g_cont) * h) ** 2).sum(axis=1)))
        g_loc_node = nodes[k]
        g_cont = g_loc_node.astype(float)
        projected = True
    g_tuple = tuple(int(v) for v in g_loc_node)
    T = fast_marching(W, [g_tuple], spacing=tuple(h), order=order, stop_at=[s_loc])
    path_loc = descend(T, si - lo, g_cont, spacing=tuple(h), blocked=~free, step=step)
    path = org + (lo + path_loc) * h
    return LocalPath(path=path, goal=path[-1].copy(), projected=projected, blocked=False)
