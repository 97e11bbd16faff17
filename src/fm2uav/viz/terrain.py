"""Terrain for maps: shaded relief colours and contour lines of an elevation grid.

Pure array functions shared by the web app's basemap tiles and the reports:
:func:`shaded_relief` (hypsometric tint × Horn hillshade, RGBA) and
:func:`contour_lines` (GeoJSON lines through contourpy, the contour library
matplotlib uses).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

__all__ = ["shaded_relief", "contour_interval", "contour_lines", "hillshade"]

#: Hypsometric tint: (share of the elevation range, RGB 0..255).
_TINT = ((0.0, (112, 153, 89)), (0.25, (170, 190, 120)), (0.5, (222, 214, 163)),
         (0.75, (190, 160, 120)), (1.0, (245, 240, 235)))


def hillshade(elev: np.ndarray, pixel: float, azimuth: float = 315.0,
              altitude: float = 45.0) -> np.ndarray:
    """Horn's hillshade in [0, 1] of a grid (rows north → south) with square pixels [m].

    NaN cells take the shade 1 (the caller masks them).

    Examples
    --------
    >>> flat = np.zeros((4, 4))
    >>> float(hillshade(flat, 10.0)[1, 1])   # sin(45°)
    0.7071...
    """
    z = np.where(np.isfinite(elev), elev, np.nanmean(elev) if np.isfinite(elev).any() else 0.0)
    p = np.pad(z, 1, mode="edge")
    dzdx = ((p[:-2, 2:] + 2 * p[1:-1, 2:] + p[2:, 2:])
            - (p[:-2, :-2] + 2 * p[1:-1, :-2] + p[2:, :-2])) / (8 * pixel)
    dzdy = ((p[2:, :-2] + 2 * p[2:, 1:-1] + p[2:, 2:])
            - (p[:-2, :-2] + 2 * p[:-2, 1:-1] + p[:-2, 2:])) / (8 * pixel)
    slope = np.arctan(np.hypot(dzdx, dzdy))
    aspect = np.arctan2(dzdy, -dzdx)
    zen, az = math.radians(90.0 - altitude), math.radians(360.0 - azimuth + 90.0)
    shade = (math.cos(zen) * np.cos(slope)
             + math.sin(zen) * np.sin(slope) * np.cos(az - aspect))
    return np.clip(shade, 0.0, 1.0)


def shaded_relief(elev: np.ndarray, pixel: float, limits: tuple[float, float]) -> np.ndarray:
    """RGBA uint8 image of an elevation grid: tint by height within ``limits`` × hillshade.

    Parameters
    ----------
    elev : ndarray, shape (rows, cols)
        Elevations [m], rows north → south; NaN = no data (transparent).
    pixel : float
        Ground size of a pixel [m].
    limits : (float, float)
        Elevations of the tint's two ends [m] (the whole DEM's range, so tiles agree).
    """
    lo, hi = limits
    t = np.clip((np.nan_to_num(elev, nan=lo) - lo) / max(hi - lo, 1e-9), 0.0, 1.0)
    stops = np.array([s for s, _ in _TINT])
    rgb = np.stack([np.interp(t, stops, [c[k] for _, c in _TINT]) for k in range(3)], axis=-1)
    shade = hillshade(elev, pixel)
    light = 0.45 + 0.75 * shade[..., None]
    out = np.empty(elev.shape + (4,), dtype=np.uint8)
    out[..., :3] = np.clip(rgb * light, 0, 255).astype(np.uint8)
    out[..., 3] = np.where(np.isfinite(elev), 255, 0).astype(np.uint8)
    return out


def contour_interval(lo: float, hi: float, lines: int = 15) -> float:
    """A round contour interval [m] (1, 2, 5 × 10^k) giving about ``lines`` levels.

    Examples
    --------
    >>> contour_interval(100.0, 400.0)
    20.0
    """
    raw = max(hi - lo, 1e-6) / lines
    e = math.floor(math.log10(raw))
    for m in (1.0, 2.0, 5.0, 10.0):
        if m * 10 ** e >= raw:
            return float(m * 10 ** e)
    return float(10 ** (e + 1))  # pragma: no cover


def contour_lines(elev: np.ndarray, transform: Any, interval: float,
                  index_every: int = 5) -> list[dict[str, Any]]:
    """GeoJSON LineString features of the contours of a grid every ``interval`` metres.

    Parameters
    ----------
    elev : ndarray, shape (rows, cols)
        Elevations [m], NaN = no data.
    transform : affine.Affine
        Pixel (col, row) → map coordinates of the grid (e.g. lon/lat).
    interval : float
        Contour spacing [m].
    index_every : int
        Every n-th level is an index contour (``properties.index`` true).
    """
    import contourpy

    finite = np.isfinite(elev)
    if finite.sum() < 4:
        return []
    lo, hi = float(np.nanmin(elev)), float(np.nanmax(elev))
    gen = contourpy.contour_generator(z=np.ma.masked_invalid(elev), line_type="SeparateCode")
    feats = []
    for level in np.arange(math.floor(lo / interval + 1) * interval, hi, interval):
        segs, _codes = gen.lines(float(level))
        lines = []
        for seg in segs:
            if len(seg) < 2:
                continue
            col, row = seg[:, 0] + 0.5, seg[:, 1] + 0.5    # pixel centres
            x = transform.c + transform.a * col + transform.b * row
            y = transform.f + transform.d * col + transform.e * row
            lines.append([[round(float(a), 6), round(float(b), 6)] for a, b in zip(x, y)])
        if lines:
            feats.append({"type": "Feature", "properties": {
                "elevation": float(level),
                "index": bool(round(level / interval) % index_every == 0)},
                "geometry": {"type": "MultiLineString", "coordinates": lines}})
    return feats
