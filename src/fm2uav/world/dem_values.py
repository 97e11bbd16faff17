"""What the numbers of an elevation raster mean: kind, unit, undeclared nodata, plausibility.

A DEM comes as it comes: with its sea floor, kilometre pixels, NaN holes, a
nodata value nobody declared, in feet, or as something that is not elevation at
all. :func:`fm2uav.world.dem.read_dem` takes its pixels through these steps, in
this order (issue 25):

1. **Crop** to ``world.bbox`` (only that window is read).
2. **Nodata**: the file's own (nodata value, mask and alpha bands, NaN), the
   user's ``world.nodata_value``, and *sentinels* (:func:`find_sentinels`):
   values such as -9999, -32768, 32767 or ±3.4e38 that mark missing data in
   files that do not say so. A sentinel outside the Earth's elevations
   (:data:`EARTH_LOWEST` .. :data:`EARTH_HIGHEST`) can only be nodata; one inside
   (-9999 m is a plausible trench floor) is nodata only where it steps from its
   measured neighbours more than any terrain can (:func:`max_step`).
3. **Sea level**: ``ground = max(DEM, sea_level)``; the sea floor is real and is
   kept without it (with a warning naming ``world.sea_level`` / ``--sea-level``).
4. **Plausibility** (:func:`check_plausible`), judged by *slope*, not by
   absolute difference: a step between neighbouring pixels is impossible only
   when it exceeds :func:`max_step` of their distance (the highest vertical
   walls on Earth, ~1.3 km, plus 60° beyond): a 500 m rise over a 2 km pixel
   (14°) is a mountain, a 4000 m step over 30 m is a data error. Elevations
   outside the Earth's range are refused as another unit or undeclared nodata.
   Nothing that may be real is ever called an error or suggested for erasure.

Before any pixel is read, :func:`raster_problem` refuses rasters that are not
elevation: RGB or colour-indexed images, complex bands, and band units that are
not lengths; :func:`length_unit_factor` turns feet, centimetres, ... into metres.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from typing import Any

import numpy as np
from scipy import ndimage

from ..errors import WorldError

__all__ = [
    "EARTH_LOWEST",
    "EARTH_HIGHEST",
    "MAX_WALL",
    "MAX_SLOPE_DEG",
    "SENTINELS",
    "Sentinel",
    "max_step",
    "length_unit_factor",
    "raster_problem",
    "find_sentinels",
    "check_plausible",
    "pixel_sizes",
]

#: Lowest elevation on Earth [m], with a margin (Challenger Deep: -10 935 m).
EARTH_LOWEST = -11000.0
#: Highest elevation on Earth [m], with a margin (Everest: 8849 m).
EARTH_HIGHEST = 9000.0
#: Highest step between two points however close [m]: the highest vertical walls
#: (Mount Thor 1250 m, Great Trango 1340 m), rounded up.
MAX_WALL = 1500.0
#: Steepest slope sustained over kilometres beyond a wall [deg] (the Rupal face of
#: Nanga Parbat, ~50° over 4.6 km), rounded up.
MAX_SLOPE_DEG = 60.0

#: Values that mark missing data in rasters that do not declare it (compared on the
#: stored numbers). Float32's extremes and each integer type's extremes are added per
#: raster (:func:`find_sentinels`).
SENTINELS = (-9999.0, -99999.0, -32768.0, -32767.0, 32767.0, 65535.0, -65504.0, 65504.0,
             -3.4e38, 3.4e38, -1e38, 1e38, -1e20, 1e20)

#: Band units read as metres (lower case).
_UNITS = {"": 1.0, "m": 1.0, "metre": 1.0, "metres": 1.0, "meter": 1.0, "meters": 1.0,
          "metre above sea level": 1.0, "meters above sea level": 1.0, "m asl": 1.0,
          "m amsl": 1.0, "masl": 1.0, "m msl": 1.0, "elevation": 1.0, "height": 1.0,
          "ft": 0.3048, "foot": 0.3048, "feet": 0.3048, "international foot": 0.3048,
          "us survey foot": 0.3048006096, "us-ft": 0.3048006096,
          "us_survey_foot": 0.3048006096, "foot_us": 0.3048006096, "ftus": 0.3048006096,
          "cm": 0.01, "centimetre": 0.01, "centimetres": 0.01, "centimeter": 0.01,
          "centimeters": 0.01, "dm": 0.1, "decimetre": 0.1, "decimetres": 0.1,
          "decimeter": 0.1, "decimeters": 0.1, "mm": 0.001, "millimetre": 0.001,
          "millimetres": 0.001, "millimeter": 0.001, "millimeters": 0.001, "km": 1000.0,
          "kilometre": 1000.0, "kilometres": 1000.0, "kilometer": 1000.0,
          "kilometers": 1000.0}


def max_step(distance_m: Any) -> np.ndarray:
    """Largest elevation difference [m] terrain can have between points ``distance_m``
    [m] apart: :data:`MAX_WALL` + ``distance * tan(MAX_SLOPE_DEG)``.

    >>> float(max_step(2000.0)) > 500.0      # a 500 m rise over a 2 km pixel is terrain
    True
    >>> float(max_step(30.0)) < 3900.0       # a 3900 m step over 30 m is not
    True
    """
    return MAX_WALL + np.asarray(distance_m, dtype=float) * np.tan(np.radians(MAX_SLOPE_DEG))


def length_unit_factor(unit: str | None) -> float | None:
    """Metres per unit of a band's unit text (``""`` → 1), or None when it is no length.

    The whole text is looked up first, then its first word, then a unit in brackets, so
    that ``"m above mean sea level"``, ``"Meters (EGM2008)"``, ``"feet, NAVD88"`` or
    ``"elevation (m)"`` are read as the lengths they name.

    >>> length_unit_factor("m above mean sea level"), length_unit_factor("degC")
    (1.0, None)
    """
    u = " ".join((unit or "").strip().lower().replace("_", " ").split())
    if u in _UNITS:
        return _UNITS[u]
    if u.replace(" ", "_") in _UNITS:
        return _UNITS[u.replace(" ", "_")]
    import re

    first = re.split(r"[\s,;:()\[\]/]+", u, maxsplit=1)[0]
    if first in _UNITS and first not in ("elevation", "height"):
        return _UNITS[first]
    inner = re.search(r"[(\[]\s*([a-z _-]+?)\s*[)\]]", u)  # "elevation (m)", "height [ft]"
    return _UNITS.get(inner.group(1)) if inner else None


def raster_problem(ds: Any, path: Any) -> str | None:
    """Why an open rasterio dataset is not an elevation raster (one line), or None.

    RGB/RGBA images, colour-indexed (palette) bands, complex bands and band
    units that are not lengths are refused; the message names the file and
    ``world.dem`` / ``--dem``.
    """
    from rasterio.enums import ColorInterp

    name = f"the DEM {path}"
    fix = "; give a DEM (one band of elevations in metres or feet) with world.dem / --dem"
    dtype = str(ds.dtypes[0])
    if dtype.startswith("complex") or dtype.startswith("c"):
        return (f"{name} has complex {dtype} pixels (radar or interferometric data), not "
                f"elevations{fix}")
    ci = list(ds.colorinterp)
    if ci and ci[0] == ColorInterp.palette:
        return (f"{name} is a colour-indexed (palette) image: its pixel values are colour "
                f"numbers, not elevations{fix}")
    rgb = {ColorInterp.red, ColorInterp.green, ColorInterp.blue}
    if ci and (ci[0] in rgb or (len(ci) >= 3 and set(ci[:3]) == rgb)):
        kind = "RGBA" if ColorInterp.alpha in ci else "RGB"
        return (f"{name} is an {kind} colour image ({ds.count} bands of {dtype}), not "
                f"elevations (a map or a rendered hillshade?){fix}")
    unit = ds.units[0] if ds.units else None
    if length_unit_factor(unit) is None:
        return (f"{name} has band unit {unit!r}, which is not a length: an elevation raster "
                "is in metres or feet; if the values are elevations, fix the unit (gdal_edit.py "
                f"-units m FILE){fix.replace('; give', ', or give')}")
    return None


@dataclasses.dataclass(frozen=True)
class Sentinel:
    """An undeclared nodata value found in a raster.

    Attributes
    ----------
    value : float
        The stored number (before scale/offset).
    pixels : int
        How many pixels hold it and were taken as nodata.
    reason : str
        Why: outside the Earth's elevations, or steps impossible for terrain.
    """

    value: float
    pixels: int
    reason: str

    def describe(self) -> str:
        """E.g. ``"1200 pixels of -32768 (outside the Earth's elevations)"``."""
        return f"{self.pixels} pixel(s) of {self.value:g} ({self.reason})"


def _candidates(dtype: Any) -> list[float]:
    vals = list(SENTINELS)
    dt = np.dtype(dtype)
    if dt.kind in "iu":
        info = np.iinfo(dt)
        vals += [float(info.min), float(info.max)]
    f32 = float(np.finfo(np.float32).max)
    vals += [-f32, f32]
    if dt.kind == "f" and dt.itemsize >= 8:
        vals += [float(np.finfo(np.float64).min), float(np.finfo(np.float64).max)]
    return sorted(set(vals))


def _steps(z: np.ndarray, dx: np.ndarray, dy: np.ndarray) -> list[tuple[tuple[slice, slice],
                                                                        tuple[slice, slice],
                                                                        np.ndarray]]:
    """Neighbour pairs (4 directions of the 8-neighbourhood): (slices of a, slices of b,
    distance [m] per pair row)."""
    rows = z.shape[0]
    dxr = np.broadcast_to(np.asarray(dx, dtype=float), (rows,))
    dyr = np.broadcast_to(np.asarray(dy, dtype=float), (rows,))
    e = (slice(None), slice(None, -1)), (slice(None), slice(1, None)), dxr[:, None]
    s = (slice(None, -1), slice(None)), (slice(1, None), slice(None)), dyr[:-1, None]
    diag = np.hypot(dxr[:-1], dyr[:-1])[:, None]
    se = (slice(None, -1), slice(None, -1)), (slice(1, None), slice(1, None)), diag
    sw = (slice(None, -1), slice(1, None)), (slice(1, None), slice(None, -1)), diag
    return [e, s, se, sw]


def _implausible_counts(z: np.ndarray, dx: Any, dy: Any) -> tuple[np.ndarray, np.ndarray]:
    """Per pixel: how many valid neighbours it steps from impossibly, and how many valid
    neighbours it has (8-neighbourhood)."""
    bad = np.zeros(z.shape, dtype=np.int16)
    near = np.zeros(z.shape, dtype=np.int16)
    with np.errstate(invalid="ignore"):
        for (ia, ib, dist) in _steps(z, dx, dy):
            a, b = z[ia], z[ib]
            both = np.isfinite(a) & np.isfinite(b)
            far = both & (np.abs(a - b) > max_step(dist))
            near[ia] += both
            near[ib] += both
            bad[ia] += far
            bad[ib] += far
    return bad, near


#: Pixels per block when scanning a large raster for impossible steps (bounds the memory).
_BLOCK = 4_000_000


def _any_step_above(z: np.ndarray, limit: float) -> bool:
    """Whether any two neighbouring pixels (8-neighbourhood) differ by more than ``limit``."""
    import warnings

    with np.errstate(invalid="ignore"), warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # an all-NaN block: no step
        if not (np.nanmax(z) - np.nanmin(z) > limit):
            return False
        return bool(np.any(np.abs(z[:, 1:] - z[:, :-1]) > limit)
                    or np.any(np.abs(z[1:] - z[:-1]) > limit)
                    or np.any(np.abs(z[1:, 1:] - z[:-1, :-1]) > limit)
                    or np.any(np.abs(z[1:, :-1] - z[:-1, 1:]) > limit))


def _worst_step(z: np.ndarray, dx: Any, dy: Any
                ) -> tuple[int, int, int, float, bool] | None:
    """The pixel stepping impossibly from the largest share of its neighbours, scanned in
    blocks of rows: (row, col, pixels with an impossible step, their most common value,
    whether that value repeats), or None when every step is possible."""
    rows, cols = z.shape
    dxr = np.broadcast_to(np.asarray(dx, dtype=float), (rows,))
    dyr = np.broadcast_to(np.asarray(dy, dtype=float), (rows,))
    per = max(2, _BLOCK // max(cols, 1))
    best: tuple[float, int, int] | None = None
    n_bad = 0
    values: list[np.ndarray] = []
    for r0 in range(0, rows, per):
        a, b = max(r0 - 1, 0), min(r0 + per + 1, rows)
        blk = z[a:b]
        if not _any_step_above(blk, MAX_WALL):
            continue
        bad, near = _implausible_counts(blk, dxr[a:b], dyr[a:b])
        own = slice(r0 - a, r0 - a + min(per, rows - r0))
        bad, near = bad[own], near[own]
        if not bad.any():
            continue
        share = np.where(near > 0, bad / np.maximum(near, 1), 0.0)
        n_bad += int(((bad > 0) & (share > 0.5)).sum()) or int((bad > 0).sum())
        score = share * 16 + bad
        k = int(np.argmax(score))
        rr, cc = np.unravel_index(k, bad.shape)
        if best is None or float(score.flat[k]) > best[0]:
            best = (float(score.flat[k]), int(rr) + r0, int(cc))
        culprits = (bad > 0) & (share > 0.5)
        values.append(z[r0:r0 + bad.shape[0]][culprits if culprits.any() else bad > 0])
    if best is None:
        return None
    uv, uc = np.unique(np.concatenate(values), return_counts=True)
    common = float(uv[np.argmax(uc)]) if uv.size else float(z[best[1], best[2]])
    return best[1], best[2], n_bad, common, bool(uc.size and int(uc.max()) > 1)


def find_sentinels(raw: np.ndarray, dtype: Any, to_metres: Callable[[np.ndarray], np.ndarray],
                   dx: Any, dy: Any) -> tuple[np.ndarray, list[Sentinel]]:
    """Undeclared nodata in ``raw`` (stored numbers, NaN where already masked).

    Parameters
    ----------
    raw : ndarray (rows, cols)
        The stored values (before scale/offset/unit), NaN for nodata already known.
    dtype :
        The raster's stored data type (its integer extremes are candidates too).
    to_metres : callable
        Stored values → elevations [m] (scale, offset, unit).
    dx, dy : float or ndarray (rows,)
        Pixel size on the ground [m] (per row for geographic rasters).

    Returns
    -------
    mask : ndarray of bool
        Pixels that are undeclared nodata.
    found : list of Sentinel
        One entry per value found.
    """
    mask = np.zeros(raw.shape, dtype=bool)
    found: list[Sentinel] = []
    finite = np.isfinite(raw)
    if not finite.any():
        return mask, found
    lo, hi = float(np.nanmin(raw)), float(np.nanmax(raw))
    metres = None
    cands = _candidates(dtype)
    if dtype is not None and np.dtype(dtype) == np.float32:  # as a float32 file stores them
        cands = sorted(set(cands) | {float(np.float32(v)) for v in cands
                                     if abs(v) <= float(np.finfo(np.float32).max)})
    for v in cands:
        if v < lo or v > hi:
            continue
        hit = raw == v
        n = int(hit.sum())
        if n == 0:
            continue
        m_v = float(to_metres(np.array([v]))[0])
        if not EARTH_LOWEST <= m_v <= EARTH_HIGHEST:
            mask |= hit
            found.append(Sentinel(v, n, f"{m_v:g} m is outside the Earth's elevations"))
            continue
        # inside the Earth's range (-9999 m could be a trench floor): nodata only where
        # its pixels step from their measured neighbours more than terrain can
        if metres is None:
            metres = to_metres(np.where(finite, raw, np.nan))
        others = np.where(hit | mask, np.nan, metres)
        labels, _ = ndimage.label(hit, structure=np.ones((3, 3), dtype=bool))
        probe = np.where(hit, m_v, others)
        bad, _ = _implausible_counts(probe, dx, dy)
        culprits = np.unique(labels[hit & (bad > 0)])
        culprits = culprits[culprits > 0]
        if culprits.size:
            sel = np.isin(labels, culprits)
            k = int(sel.sum())
            mask |= sel
            found.append(Sentinel(v, k, "steps from its neighbours more than any terrain"))
    return mask, found


def check_plausible(z: np.ndarray, dx: Any, dy: Any, where: str,
                    locate: Callable[[int, int], str]) -> None:
    """Refuse elevations no terrain on Earth can have (see the module docstring).

    Parameters
    ----------
    z : ndarray (rows, cols)
        Elevations [m] after nodata and the sea-level clamp (NaN = nodata).
    dx, dy : float or ndarray (rows,)
        Pixel size on the ground [m].
    where : str
        What the raster is, for the message (``"the DEM dem.tif"``).
    locate : callable
        ``(row, col)`` → text of where that pixel is (e.g. lon/lat).

    Raises
    ------
    WorldError
        Elevations outside :data:`EARTH_LOWEST` .. :data:`EARTH_HIGHEST` (another
        unit or an undeclared nodata value), or a step between neighbouring pixels
        larger than :func:`max_step` of their distance.
    """
    finite = z[np.isfinite(z)]
    out = finite[(finite < EARTH_LOWEST) | (finite > EARTH_HIGHEST)]
    if out.size:
        vals, counts = np.unique(out, return_counts=True)
        v, n = float(vals[np.argmax(counts)]), int(counts.max())
        side = (f"above {EARTH_HIGHEST:g} m" if v > EARTH_HIGHEST else
                f"below {EARTH_LOWEST:g} m")
        if n * 2 >= out.size and n > 1:
            raise WorldError(
                f"{where} has {out.size} pixel(s) {side}, {n} of them exactly {v:g}, which no "
                "ground on Earth is (Everest 8849 m, the Challenger Deep -10935 m): an "
                f"undeclared nodata value; declare it with world.nodata_value: {v:g} (CLI "
                f"--nodata-value {v:g}) or in the file (gdal_edit.py -a_nodata {v:g} FILE)")
        raise WorldError(
            f"{where} has {out.size} pixel(s) {side} (from {float(out.min()):g} to "
            f"{float(out.max()):g} m), which no ground on Earth is (Everest 8849 m, the "
            "Challenger Deep -10935 m); are the elevations in another unit (feet: gdal_edit.py "
            "-units ft FILE; centimetres: -scale 0.01) or is a nodata value undeclared "
            "(world.nodata_value, CLI --nodata-value)?")
    if min(z.shape) < 2:
        return
    worst = _worst_step(z, dx, dy)
    if worst is None:
        return
    r, c, n_bad, common, repeated = worst
    nb = z[max(r - 1, 0):r + 2, max(c - 1, 0):c + 2]
    nb = nb[np.isfinite(nb) & (nb != z[r, c])]
    dxr = float(np.broadcast_to(np.asarray(dx, dtype=float), (z.shape[0],))[r])
    dyr = float(np.broadcast_to(np.asarray(dy, dtype=float), (z.shape[0],))[r])
    dist = min(dxr, dyr)
    lo, hi = (float(nb.min()), float(nb.max())) if nb.size else (float("nan"),) * 2
    step = max(abs(float(z[r, c]) - lo), abs(float(z[r, c]) - hi)) if nb.size else 0.0
    slope = float(np.degrees(np.arctan2(step, dist)))
    hint = ("; if such values mark missing data, declare them with world.nodata_value: "
            f"{common:g} (CLI --nodata-value {common:g})" if repeated else
            "; if the value marks missing data, declare it with world.nodata_value (CLI "
            "--nodata-value)")
    raise WorldError(
        f"{where}: pixel (row {r}, col {c}) at {locate(int(r), int(c))} is "
        f"{float(z[r, c]):g} m while its neighbours {dist:.0f} m away lie between {lo:g} and "
        f"{hi:g} m, a step of {step:.0f} m ({slope:.0f}°); no terrain on Earth steps like "
        f"that (vertical walls reach ~{MAX_WALL:g} m, slopes beyond them {MAX_SLOPE_DEG:g}°), "
        f"so the DEM has a data error there ({n_bad} pixel(s) affected): "
        f"repair the file{hint}")


def pixel_sizes(transform: Any, crs: Any, shape: tuple[int, int]
                ) -> tuple[np.ndarray, np.ndarray]:
    """Pixel size on the ground [m] of each row of a raster: ``(along a row, along a column)``.

    Rotated geotransforms are measured along their own axes (``hypot(a, d)``,
    ``hypot(b, e)``). Geographic rasters: degrees → metres at each row's latitude
    (spherical, 0.5 % is plenty for a plausibility scale). Projected rasters: the
    CRS unit and the point scale factor at the centre (Web Mercator at 60°N stores
    2 projected metres per ground metre).
    """
    from .geo import parse_crs

    a, b, c, d, e, f = (float(v) for v in list(transform)[:6])
    rows, cols = int(shape[0]), int(shape[1])
    sa, sb = float(np.hypot(a, d)), float(np.hypot(b, e))
    crs_ = parse_crs(crs)
    if crs_.is_geographic:
        rr = np.arange(rows) + 0.5
        lat = d * (0.5 * cols) + e * rr + f
        coslat = np.cos(np.radians(np.clip(lat, -89.9, 89.9)))
        # a pixel's sides in degrees of longitude (x) and latitude (y)
        ex = np.hypot(a * 111320.0 * coslat, d * 111132.0)
        ey = np.hypot(b * 111320.0 * coslat, e * 111132.0)
        return ex, ey
    unit = crs_.axis_info[0].unit_conversion_factor if crs_.axis_info else 1.0
    k = 1.0
    try:
        from pyproj import Proj, Transformer

        xc = a * (0.5 * cols) + b * (0.5 * rows) + c
        yc = d * (0.5 * cols) + e * (0.5 * rows) + f
        lon, lat = Transformer.from_crs(crs_, "EPSG:4326", always_xy=True).transform(xc, yc)
        fac = Proj(crs_).get_factors(lon, lat)
        k = float(np.sqrt(float(fac.tissot_semimajor) * float(fac.tissot_semiminor)))
    except Exception:  # projections without factors (or outside their area): units as they are
        k = 1.0
    if not (np.isfinite(k) and k > 0):
        k = 1.0
    return np.full(rows, sa * unit / k), np.full(rows, sb * unit / k)
