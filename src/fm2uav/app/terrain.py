"""The offline basemap of the app: the user's DEM(s) as hillshade tiles and contours.

Tiles are read with rio-tiler (any GDAL raster, any CRS, reprojected on the fly to
Web Mercator ``z/x/y`` tiles; several files as a mosaic); the colours are drawn by
:func:`fm2uav.viz.terrain.shaded_relief`, the contours by
:func:`fm2uav.viz.terrain.contour_lines`. The ground height under the cursor is
the DEM's value at that point (nearest pixel), as the file gives it.
"""

from __future__ import annotations

import math
import threading
from collections import OrderedDict
from collections.abc import Sequence
from typing import Any

import numpy as np

__all__ = ["Terrain"]

TILE = 256
#: Rendered tiles kept in memory per DEM (~40 kB each).
CACHED_TILES = 2048


class Terrain:
    """Readers of one or more DEM files (tiles of one map).

    Parameters
    ----------
    paths : sequence of str
        DEM files GDAL reads, with a CRS (checked before by the mission's world
        validation, so a bad file never reaches here).
    """

    def __init__(self, paths: Sequence[str]) -> None:
        from rio_tiler.io import Reader

        self.paths = [str(p) for p in paths]
        self._lock = threading.Lock()
        self._tiles: OrderedDict[tuple[int, int, int], bytes | None] = OrderedDict()
        lo, hi = math.inf, -math.inf
        boxes = []
        for p in self.paths:
            with Reader(p) as src:
                boxes.append(src.get_geographic_bounds(src.tms.rasterio_geographic_crs))
                stats = src.statistics(max_size=256)
                b = next(iter(stats.values()))
                lo, hi = min(lo, float(b.min)), max(hi, float(b.max))
        self.bounds = [min(b[0] for b in boxes), min(b[1] for b in boxes),
                       max(b[2] for b in boxes), max(b[3] for b in boxes)]
        self.range = (lo, hi) if hi > lo else (lo, lo + 1.0)

    def info(self) -> dict[str, Any]:
        """Bounds (lon/lat W, S, E, N) and elevation range [m] of the DEM(s)."""
        return {"bounds": [round(v, 7) for v in self.bounds],
                "elevation": [round(self.range[0], 1), round(self.range[1], 1)],
                "files": self.paths}

    def _tile(self, x: int, y: int, z: int, buffer: int) -> Any:
        from rio_tiler.errors import TileOutsideBounds
        from rio_tiler.io import Reader
        from rio_tiler.mosaic import mosaic_reader

        def read(path: str, *args: Any, **kw: Any) -> Any:
            with Reader(path) as src:
                return src.tile(*args, **kw)

        try:
            img, _ = mosaic_reader(self.paths, read, x, y, z, tilesize=TILE, buffer=buffer,
                                   indexes=1, threads=0, resampling_method="bilinear",
                                   reproject_method="bilinear")
        except Exception as exc:  # every asset outside the tile
            if type(exc).__name__ in ("EmptyMosaicError",) or isinstance(exc, TileOutsideBounds):
                return None
            raise
        return img

    def tile_png(self, x: int, y: int, z: int) -> bytes | None:
        """Shaded relief PNG of Web Mercator tile ``z/x/y`` (None outside the DEM); the
        last :data:`CACHED_TILES` are kept, so panning back costs nothing."""
        key = (z, x, y)
        with self._lock:
            if key in self._tiles:
                self._tiles.move_to_end(key)
                return self._tiles[key]
        png = self._render(x, y, z)
        with self._lock:
            self._tiles[key] = png
            while len(self._tiles) > CACHED_TILES:
                self._tiles.popitem(last=False)
        return png

    def _render(self, x: int, y: int, z: int) -> bytes | None:
        from rio_tiler.utils import render

        from ..viz.terrain import shaded_relief

        img = self._tile(x, y, z, buffer=1)
        if img is None:
            return None
        elev = np.asarray(img.array[0], dtype=float)
        mask = np.ma.getmaskarray(img.array[0])
        lat = math.degrees(math.atan(math.sinh(math.pi * (1 - 2 * (y + 0.5) / 2 ** z))))
        pixel = 2 * math.pi * 6378137.0 / 2 ** z / TILE * math.cos(math.radians(lat))
        rgba = shaded_relief(np.where(mask, np.nan, elev), pixel, self.range)[1:-1, 1:-1]
        return render(np.moveaxis(rgba[..., :3], -1, 0), mask=rgba[..., 3],
                      img_format="PNG")

    def height(self, lon: float, lat: float) -> float | None:
        """The DEM's elevation [m] at (lon, lat) (nearest pixel; None outside or nodata)."""
        from rio_tiler.errors import PointOutsideBounds
        from rio_tiler.io import Reader

        for p in self.paths:
            try:
                with Reader(p) as src:
                    pt = src.point(lon, lat, indexes=1)
            except PointOutsideBounds:
                continue
            if not np.ma.getmaskarray(pt.array)[0]:
                return round(float(pt.array[0]), 2)
        return None

    def contours(self, max_size: int = 700) -> dict[str, Any]:
        """Contour lines of the DEM(s) as a GeoJSON FeatureCollection in lon/lat."""
        from rio_tiler.io import Reader

        from ..viz.terrain import contour_interval, contour_lines

        step = contour_interval(*self.range)
        feats: list[dict[str, Any]] = []
        for p in self.paths:
            with Reader(p) as src:
                b = src.get_geographic_bounds(src.tms.rasterio_geographic_crs)
                img = src.part(b, dst_crs=src.tms.rasterio_geographic_crs, max_size=max_size,
                               indexes=1)
            elev = np.where(np.ma.getmaskarray(img.array[0]), np.nan,
                            np.asarray(img.array[0], dtype=float))
            feats += contour_lines(elev, img.transform, step)
        return {"type": "FeatureCollection", "features": feats, "interval": step}
