"""The world as a map in lon/lat: a shaded-relief image and the obstacle footprints.

What the reports' map (a Leaflet image overlay) and the matplotlib figures (lon/lat
axes) draw under a route, computed from the world itself, so it works offline and
for every world — a DEM, building footprints, a built-in scenario placed by its
anchor:

* :func:`lonlat_image` samples the ground of the world on a grid regular in
  longitude and in Web-Mercator y (``rows="mercator"``: a Leaflet image overlay
  placed by its corners is then exact) or in latitude (``rows="linear"``: an
  ``imshow`` on lon/lat axes), and shades it (:func:`fm2uav.viz.terrain.shaded_relief`,
  the app's colours). Filled DEM nodata (unknown ground) is hatched in orange;
  outside the world the image is transparent.
* :func:`obstacle_footprints` finds what stands on the ground — buildings, the
  blocks of a built-in city, the obstacles of a 2D map — as polygons in world
  metres with their height above the ground (no-fly zones are not obstacles
  here: the map draws them from ``World.zones``).

Drawing only: no planning, every number from the world.
"""

from __future__ import annotations

import base64
import io
import math
from dataclasses import dataclass
from typing import Any

import numpy as np

__all__ = ["LonLatImage", "Footprint", "lonlat_box", "lonlat_image", "obstacle_footprints",
           "footprints_lonlat", "mercator_y", "FILLED_RGB"]

#: Colour of the hatch over filled DEM nodata (unknown ground), as on plan.png.
FILLED_RGB = (255, 127, 14)
#: Nodes of the coarse lon/lat → world grid interpolated to the pixels.
_COARSE = 33


def mercator_y(lat: Any) -> np.ndarray:
    """Web-Mercator y (unit sphere) of latitudes [deg]."""
    phi = np.radians(np.asarray(lat, dtype=float))
    return np.log(np.tan(np.pi / 4 + phi / 2))


def _lat_of_mercator(y: np.ndarray) -> np.ndarray:
    return np.degrees(2 * np.arctan(np.exp(y)) - np.pi / 2)


def lonlat_box(world: Any, anchor: Any = None) -> tuple[float, float, float, float]:
    """(W, S, E, N) [deg] of the world's x/y rectangle (edges densified, 65 points each)."""
    from ..world.geo import to_lonlat

    b = np.asarray(world.bounds, dtype=float)
    t = np.linspace(0.0, 1.0, 65)
    x0, x1, y0, y1 = b[0, 0], b[0, 1], b[1, 0], b[1, 1]
    x = np.concatenate([x0 + (x1 - x0) * t, np.full(65, x1), x1 - (x1 - x0) * t, np.full(65, x0)])
    y = np.concatenate([np.full(65, y0), y0 + (y1 - y0) * t, np.full(65, y1), y1 - (y1 - y0) * t])
    ll = np.asarray(to_lonlat(world, np.column_stack([x, y]), anchor=anchor), dtype=float)
    return (float(ll[:, 0].min()), float(ll[:, 1].min()), float(ll[:, 0].max()),
            float(ll[:, 1].max()))


@dataclass(frozen=True)
class LonLatImage:
    """An RGBA image of the world's ground placed in lon/lat.

    Attributes
    ----------
    rgba : ndarray (rows, cols, 4) uint8
        Row 0 is the northern edge; alpha 0 outside the world.
    bounds : (W, S, E, N)
        Lon/lat [deg] of the image's outer edges.
    rows : {"mercator", "linear"}
        Rows regular in Web-Mercator y or in latitude.
    pixel_m : float
        Ground size of a pixel [m] (about).
    kind : {"terrain", "flat"}
        Shaded relief of a terrain, or the flat ground of a world without one.
    filled : bool
        Whether some of it is hatched as filled DEM nodata (unknown ground).
    elev : ndarray (rows, cols) or None
        The ground height drawn [m, world z], NaN outside the world (contours).
    lon, lat : ndarray
        Pixel-centre longitudes (cols,) and latitudes (rows,) [deg].
    """

    rgba: np.ndarray
    bounds: tuple[float, float, float, float]
    rows: str
    pixel_m: float
    kind: str
    filled: bool = False
    elev: np.ndarray | None = None
    lon: np.ndarray | None = None
    lat: np.ndarray | None = None

    def png(self) -> bytes:
        """The image as PNG bytes."""
        from PIL import Image

        buf = io.BytesIO()
        Image.fromarray(self.rgba, "RGBA").save(buf, format="PNG", compress_level=6)
        return buf.getvalue()

    def data_uri(self) -> str:
        """``data:image/png;base64,...`` of :meth:`png` (for a self-contained page)."""
        return "data:image/png;base64," + base64.b64encode(self.png()).decode("ascii")

    def extent(self) -> tuple[float, float, float, float]:
        """``(W, E, S, N)``: matplotlib ``imshow(extent=...)`` of a ``rows="linear"`` image."""
        w, s, e, n = self.bounds
        return (w, e, s, n)


def _world_xy(world: Any, anchor: Any, lon: np.ndarray, lat: np.ndarray
              ) -> tuple[np.ndarray, np.ndarray]:
    """World x, y [m] of the pixel centres (lon (cols,), lat (rows,)): the exact transform
    on a coarse grid, interpolated bilinearly to the pixels (a smooth map; cm errors)."""
    from scipy.ndimage import map_coordinates

    from ..world.geo import from_lonlat

    cl = np.linspace(lon[0], lon[-1], _COARSE)
    ct = np.linspace(lat[0], lat[-1], _COARSE)
    L, T = np.meshgrid(cl, ct)
    xy = np.asarray(from_lonlat(world, np.column_stack([L.ravel(), T.ravel()]), anchor=anchor),
                    dtype=float)
    X, Y = xy[:, 0].reshape(L.shape), xy[:, 1].reshape(L.shape)
    # fractional coarse-grid index of every pixel centre (exact: both grids are regular in
    # lon, and the coarse one regular in lat, so map lat through its own linear index)
    ci = (lon - lon[0]) / max(lon[-1] - lon[0], 1e-300) * (_COARSE - 1)
    cj = (lat - lat[0]) / (lat[-1] - lat[0]) * (_COARSE - 1) if lat[-1] != lat[0] \
        else np.zeros_like(lat)
    J, I = np.meshgrid(cj, ci, indexing="ij")
    coords = np.array([J.ravel(), I.ravel()])
    x = map_coordinates(X, coords, order=1, mode="nearest").reshape(J.shape)
    y = map_coordinates(Y, coords, order=1, mode="nearest").reshape(J.shape)
    return x, y


def _size(world: Any, box: tuple[float, float, float, float], max_px: int, min_px: int
          ) -> tuple[int, int, float]:
    """(cols, rows, pixel [m]) of the image: about the world's cell, within min..max px."""
    w, s, e, n = box
    lat0 = math.radians(0.5 * (s + n))
    width_m = max((e - w) * 111_320.0 * math.cos(lat0), 1e-3)
    height_m = max((n - s) * 110_574.0, 1e-3)
    cell = float(min(world.spacing[:2]))
    long_px = max(width_m, height_m) / cell
    long_px = min(max(long_px, float(min_px)), float(max_px))
    pixel = max(width_m, height_m) / long_px
    return (max(2, int(round(width_m / pixel))), max(2, int(round(height_m / pixel))), pixel)


def lonlat_image(world: Any, anchor: Any = None, *, rows: str = "mercator",
                 max_px: int = 1400, min_px: int = 700) -> LonLatImage:
    """The world's ground as a shaded-relief image in lon/lat (see the module docstring).

    Parameters
    ----------
    world : World
        2D or 3D; its terrain (or flat ground) is drawn, obstacles are not
        (:func:`obstacle_footprints`).
    anchor : fm2uav.world.geo.Anchor, optional
        Placement of a world without CRS (default: the exports' default anchor).
    rows : {"mercator", "linear"}
        Rows regular in Web-Mercator y (web maps) or in latitude (lon/lat axes).
    max_px, min_px : int
        Pixels along the long side: about one per grid cell, within these bounds.

    Returns
    -------
    LonLatImage
    """
    from .terrain import shaded_relief

    if rows not in ("mercator", "linear"):
        raise ValueError(f"rows must be 'mercator' or 'linear', got {rows!r}")
    box = lonlat_box(world, anchor)
    w, s, e, n = box
    cols, nrows, pixel = _size(world, box, max_px, min_px)
    lon = w + (np.arange(cols) + 0.5) * (e - w) / cols
    if rows == "mercator":
        ys, yn = float(mercator_y(s)), float(mercator_y(n))
        lat = _lat_of_mercator(yn - (np.arange(nrows) + 0.5) * (yn - ys) / nrows)
    else:
        lat = n - (np.arange(nrows) + 0.5) * (n - s) / nrows
    x, y = _world_xy(world, anchor, lon, lat)
    b = np.asarray(world.bounds, dtype=float)
    tol = 1e-6 * float(max(world.spacing[:2]))
    inside = ((x >= b[0, 0] - tol) & (x <= b[0, 1] + tol) & (y >= b[1, 0] - tol)
              & (y <= b[1, 1] + tol))
    terrain = getattr(world, "terrain", None) if world.ndim == 3 else None
    elev = np.full(x.shape, np.nan)
    if terrain is not None:
        elev[inside] = _smooth_ground(world, x[inside], y[inside])
        limits = (float(np.min(terrain)), float(np.max(terrain)))
        kind = "terrain"
    else:
        elev[inside] = 0.0
        limits = (-1.0, 1.0)   # flat ground: the middle of the tint
        kind = "flat"
    rgba = shaded_relief(elev, pixel, limits)
    filled = False
    if terrain is not None and getattr(world, "filled", None) is not None \
            and np.asarray(world.filled).any():
        unknown = np.zeros(x.shape, bool)
        unknown[inside] = np.asarray(world.ground_filled(x[inside], y[inside]), dtype=bool)
        if unknown.any():
            filled = True
            jj, ii = np.indices(unknown.shape)
            stripe = ((ii + jj) // 3) % 3 == 0     # diagonal hatch, 1 px in 3 every 3 px
            tint = unknown & ~stripe
            rgba[tint, :3] = (0.6 * rgba[tint, :3] + 0.4 * np.array(FILLED_RGB)).astype(np.uint8)
            rgba[unknown & stripe, :3] = FILLED_RGB
    return LonLatImage(rgba=rgba, bounds=box, rows=rows, pixel_m=float(pixel), kind=kind,
                       filled=filled, elev=elev if kind == "terrain" else None, lon=lon,
                       lat=lat)


def _smooth_ground(world: Any, x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """The terrain at ``x, y`` [m] by a cubic spline through the nodes: for the picture only
    (the bilinear ground of the figures shows its cell facets when shaded); every number
    elsewhere uses :meth:`World.ground_height`."""
    from scipy.ndimage import map_coordinates

    t = np.asarray(world.terrain, dtype=float)
    fi = (x - float(world.origin[0])) / float(world.spacing[0])
    fj = (y - float(world.origin[1])) / float(world.spacing[1])
    if min(t.shape) < 4:
        return np.asarray(world.ground_height(x, y), dtype=float)
    return map_coordinates(t, np.array([fi, fj]), order=3, mode="nearest")


@dataclass(frozen=True)
class Footprint:
    """An obstacle standing on the ground: its outline in world metres and its height.

    Attributes
    ----------
    polygon : shapely Polygon
        Outline [m] (the union of its grid cells, simplified by a third of a cell).
    height_m : float or None
        Highest roof above the ground under it [m] (None on a 2D map).
    """

    polygon: Any
    height_m: float | None


def obstacle_footprints(world: Any, *, max_count: int = 20_000) -> list[Footprint]:
    """What stands on the ground of ``world``, as polygons with heights (largest first).

    3D worlds: the columns whose top obstacle node is more than half a vertical
    cell above the ground (:meth:`World.ground_height`) — buildings, blocks —
    ignoring the nodes the no-fly zones block; 2D worlds: the occupied cells
    (zones left out too). Each connected group of cells is one footprint; at
    most ``max_count`` are returned (the largest).
    """
    import rasterio.features
    from affine import Affine
    from scipy import ndimage
    from shapely.geometry import shape

    from ..world.zones import terrain_surface_index, zone_voxels

    dx, dy = (float(v) for v in world.spacing[:2])
    x0, y0 = (float(v) for v in world.origin[:2])
    nx, ny = world.shape[:2]
    if world.ndim == 3:
        top = np.asarray(terrain_surface_index(world))
        dz, z0 = float(world.spacing[2]), float(world.origin[2])
        roof = np.where(top >= 0, z0 + top * dz, -np.inf)
        X = x0 + np.arange(nx)[:, None] * dx + 0 * np.arange(ny)[None, :]
        Y = y0 + np.arange(ny)[None, :] * dy + 0 * np.arange(nx)[:, None]
        ground = (np.asarray(world.ground_height(X, Y), dtype=float)
                  if getattr(world, "terrain", None) is not None else np.full((nx, ny), z0))
        height = roof - ground
        raised = height > 0.5 * dz
    else:
        zmask = zone_voxels(world)
        raised = np.asarray(world.occupancy, dtype=bool)
        if zmask is not None:
            raised = raised & ~zmask
        height = None
    if not raised.any():
        return []
    labels, count = ndimage.label(raised)
    # rows = y, cols = x; pixel (col i, row j) covers the cell of node (i, j)
    transform = Affine(dx, 0.0, x0 - dx / 2, 0.0, dy, y0 - dy / 2)
    tops = (ndimage.maximum(height, labels, index=np.arange(1, count + 1))
            if height is not None else None)
    out: list[Footprint] = []
    for geom, value in rasterio.features.shapes(labels.T.astype(np.int32), mask=raised.T,
                                                transform=transform, connectivity=4):
        k = int(value)
        poly = shape(geom).simplify(min(dx, dy) / 3, preserve_topology=True)
        if poly.is_empty:
            continue
        h = None if tops is None else round(float(tops[k - 1]), 1)
        out.append(Footprint(polygon=poly, height_m=h))
    out.sort(key=lambda f: -f.polygon.area)
    return out[:max_count]


def footprints_lonlat(world: Any, footprints: list[Footprint], anchor: Any = None
                      ) -> list[tuple[list[np.ndarray], float | None]]:
    """Each footprint's rings (exterior first, then holes) as ``(n, 2)`` lon/lat arrays, with
    its height; one transform call for all of them."""
    from ..world.geo import to_lonlat

    rings: list[np.ndarray] = []
    owner: list[int] = []
    for k, f in enumerate(footprints):
        for r in [f.polygon.exterior, *f.polygon.interiors]:
            rings.append(np.asarray(r.coords, dtype=float)[:, :2])
            owner.append(k)
    if not rings:
        return []
    ll = np.asarray(to_lonlat(world, np.concatenate(rings), anchor=anchor), dtype=float)[:, :2]
    out: list[tuple[list[np.ndarray], float | None]] = [([], f.height_m) for f in footprints]
    i = 0
    for k, r in zip(owner, rings):
        out[k][0].append(ll[i:i + len(r)])
        i += len(r)
    return out
