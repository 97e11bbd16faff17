"""Buildings as their true footprints, beside the (coarser, dilated) planning grid.

A world built from building footprints blocks every grid column whose cell
touches a footprint (:mod:`fm2uav.world.buildings`), so that a building smaller
than a cell still blocks FM². That grid is the planner's conservative view: a
footprint grows by up to a cell on each side, depending on where its edges fall
between the nodes (round Swiss-grid coordinates on a grid whose origin is the
footprints' corner put the edges on the nodes: the largest growth), and a roof
is known to one vertical cell below it. Measured against that grid, the clearance
of a path that keeps 6.4 m from a wall read 4.9 m, and the height over a roof read
up to one vertical cell too high.

:class:`BuildingModel` keeps the footprints themselves (shapely polygons in the
world's metres, reprojected once by :func:`fm2uav.world.vectors.read_vectors`)
with their roof altitudes, and answers the safety questions from them:

* :meth:`BuildingModel.roof_at` — the roof under a point (its footprint's edge
  included), ``-inf`` off the buildings; :meth:`World.surface_height` takes the
  higher of it and the ground;
* :meth:`BuildingModel.roof_along` — the highest roof a straight chord meets
  (the final altitude profile flies chords between its samples);
* :meth:`BuildingModel.distance` — the exact distance from points to the
  buildings as prisms (footprint extruded up to the roof): horizontal distance
  to the footprint beside the walls, height above the roof over it, their
  hypotenuse past a roof edge; negative inside a building (minus the depth
  below its roof).

Every answer is what an independent reader of the buildings file gets with
shapely and pyproj in the file's own CRS (``tests/world/test_building_model.py``,
``tests/e2e/test_acc_buildings_any_crs.py``).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
import shapely

__all__ = ["BuildingModel"]


@dataclass(frozen=True, eq=False)
class BuildingModel:
    """Building footprints with roof altitudes, in world metres.

    Attributes
    ----------
    footprints : tuple of shapely Polygon / MultiPolygon
        In the world's CRS [m].
    roofs : ndarray, shape (n,)
        Roof altitude of each footprint (world z [m]).
    description : str
        One line for summaries.
    """

    footprints: tuple[Any, ...]
    roofs: np.ndarray = field(repr=False)
    description: str = ""
    _tree: Any = field(default=None, init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        geoms = tuple(self.footprints)
        roofs = np.array(self.roofs, dtype=float, copy=True).ravel()
        if len(geoms) != len(roofs) or not np.all(np.isfinite(roofs)):
            raise ValueError(f"BuildingModel needs one finite roof per footprint, got "
                             f"{len(geoms)} footprints and {len(roofs)} roofs")
        roofs.setflags(write=False)
        object.__setattr__(self, "footprints", geoms)
        object.__setattr__(self, "roofs", roofs)
        object.__setattr__(self, "_tree", shapely.STRtree(np.asarray(geoms, dtype=object)))

    def __len__(self) -> int:
        return len(self.footprints)

    def roof_at(self, x: Any, y: Any) -> np.ndarray:
        """Highest roof [m] whose footprint (edge included) holds ``(x, y)``; ``-inf`` elsewhere."""
        xa, ya = np.broadcast_arrays(np.asarray(x, dtype=float), np.asarray(y, dtype=float))
        out = np.full(xa.size, -np.inf)
        if len(self.footprints) and xa.size:
            pts = shapely.points(xa.ravel(), ya.ravel())
            i, k = self._tree.query(pts, predicate="intersects")
            np.maximum.at(out, i, self.roofs[k])
        return out.reshape(xa.shape)

    def roof_along(self, a: Any, b: Any) -> np.ndarray:
        """Highest roof [m] a straight chord from ``a[i]`` to ``b[i]`` (x, y) meets; ``-inf``
        for chords that meet no footprint."""
        pa = np.atleast_2d(np.asarray(a, dtype=float))[:, :2]
        pb = np.atleast_2d(np.asarray(b, dtype=float))[:, :2]
        out = np.full(len(pa), -np.inf)
        if len(self.footprints) and len(pa):
            same = np.all(pa == pb, axis=1)
            geoms = np.empty(len(pa), dtype=object)
            if same.any():
                geoms[same] = shapely.points(pa[same])
            if (~same).any():
                geoms[~same] = shapely.linestrings(np.stack([pa[~same], pb[~same]], axis=1))
            i, k = self._tree.query(geoms, predicate="intersects")
            np.maximum.at(out, i, self.roofs[k])
        return out

    def distance(self, points: Any) -> np.ndarray:
        """Distance [m] from points ``(n, 3)`` to the nearest building prism.

        ``sqrt(d_h² + max(z - roof, 0)²)`` with ``d_h`` the horizontal distance to the
        footprint, minimised over the buildings; ``z - roof`` (negative) for a point
        inside a building below its roof; ``inf`` without buildings.
        """
        p = np.atleast_2d(np.asarray(points, dtype=float))
        n = len(p)
        out = np.full(n, np.inf)
        if not len(self.footprints) or not n:
            return out
        pts = shapely.points(p[:, 0], p[:, 1])
        # an upper bound: the prism of the horizontally nearest footprint
        i, k = self._tree.query_nearest(pts, all_matches=False)
        dh = shapely.distance(pts[i], np.asarray(self.footprints, dtype=object)[k])
        bound = np.full(n, np.inf)
        np.minimum.at(bound, i, np.hypot(dh, np.maximum(p[i, 2] - self.roofs[k], 0.0)))
        # every footprint within that bound horizontally is a candidate
        i, k = self._tree.query(pts, predicate="dwithin", distance=bound + 1e-9)
        geoms = np.asarray(self.footprints, dtype=object)[k]
        dh = shapely.distance(pts[i], geoms)
        dz = p[i, 2] - self.roofs[k]
        d = np.hypot(dh, np.maximum(dz, 0.0))
        inside = (dh <= 0.0) & (dz < 0.0)
        d = np.where(inside, dz, d)
        np.minimum.at(out, i, d)
        return out
