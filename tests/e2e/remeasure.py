"""Safety figures of a run re-measured from its written files, independently of fm2uav.

The ground comes from the source raster read with rasterio (bilinear between pixel centres with
scipy, NaN where a pixel is nodata), lon/lat reprojected with pyproj; for a synthetic world
without CRS from its height array, placed with pyproj's azimuthal equidistant projection at the
anchor. The flown points come from ``path.geojson`` (the dense path and the waypoints, lon/lat
and metres above mean sea level) and the mission items from ``mission.plan``. Nothing is taken
from ``summary.json`` except the figures under test and which points are the cruise.

``check_run(out, ground)`` asserts that the summary's height above ground (whole path, cruise,
over measured ground), the lowest AGL along the mission's legs and every mission item's
altitude agree with what is measured here, to ``tol`` (1 m).
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

import numpy as np
import pytest

#: ground(lon, lat) -> metres above mean sea level (NaN: no measurement)
Ground = Callable[[np.ndarray, np.ndarray], np.ndarray]


def dem_ground(tif, *, sea_level: float | None = None) -> Ground:
    """Bilinear ground of a GeoTIFF (any CRS) at lon/lat points; NaN next to nodata pixels."""
    import rasterio
    from pyproj import Transformer
    from scipy import ndimage

    with rasterio.open(tif) as ds:
        z = ds.read(1, masked=True).astype(float).filled(np.nan)
        inv = ~ds.transform
        tr = Transformer.from_crs("EPSG:4326", ds.crs.to_wkt(), always_xy=True)

    def ground(lon, lat):
        x, y = tr.transform(np.asarray(lon, float), np.asarray(lat, float))
        col, row = inv * (np.asarray(x), np.asarray(y))
        g = ndimage.map_coordinates(z, [np.asarray(row) - 0.5, np.asarray(col) - 0.5], order=1,
                                    mode="nearest", cval=np.nan)
        return g if sea_level is None else np.where(np.isnan(g), g, np.maximum(g, sea_level))
    return ground


def array_ground(heights, spacing, *, origin=(0.0, 0.0), anchor=(-3.7649, 40.3326, 0.0)
                 ) -> Ground:
    """Bilinear ground of a synthetic world's height array ``[ix, iy]`` (nodes at ``origin +
    i * spacing``), the world placed on the azimuthal equidistant plane of ``anchor`` (lon,
    lat, alt): fm2uav's convention for worlds without CRS (docs/operator.md section 5)."""
    from pyproj import Transformer
    from scipy import ndimage

    lon0, lat0, alt0 = anchor
    tr = Transformer.from_crs("EPSG:4326", f"+proj=aeqd +lat_0={lat0} +lon_0={lon0} +x_0=0 "
                              "+y_0=0 +datum=WGS84 +units=m +no_defs", always_xy=True)
    h = np.asarray(heights, float)
    sx, sy = (spacing, spacing) if np.isscalar(spacing) else spacing[:2]

    def ground(lon, lat):
        x, y = tr.transform(np.asarray(lon, float), np.asarray(lat, float))
        idx = [(np.asarray(x) - origin[0]) / sx, (np.asarray(y) - origin[1]) / sy]
        return ndimage.map_coordinates(h, idx, order=1, mode="nearest") + alt0
    return ground


def _metric(lon, lat):
    """Local metres (azimuthal equidistant at the first point), for distances along legs."""
    from pyproj import Transformer

    tr = Transformer.from_crs("EPSG:4326", f"+proj=aeqd +lat_0={lat[0]} +lon_0={lon[0]} "
                              "+datum=WGS84 +units=m +no_defs", always_xy=True)
    return np.column_stack(tr.transform(lon, lat)), tr


@dataclass
class Files:
    """What one output folder says about the flight."""

    summary: dict
    path: np.ndarray  # (N, 3) lon, lat, alt AMSL
    waypoints: np.ndarray  # (n, 3) lon, lat, alt AMSL
    frame: str  # "amsl", "relative", "terrain"
    plan: dict | None


def read(out, prefix: str = "") -> Files:
    out = Path(out)
    summary = json.loads((out / "summary.json").read_text())
    doc = json.loads((out / f"{prefix}path.geojson").read_text())
    feats = {f["properties"].get("name"): f for f in doc["features"]}
    path = np.asarray(feats["path"]["geometry"]["coordinates"], float)
    wps = np.asarray(feats["waypoints"]["geometry"]["coordinates"], float)
    frame = feats["path"]["properties"].get("frame_name") or \
        feats["waypoints"]["properties"].get("frame_name")
    plan_file = out / f"{prefix}mission.plan"
    plan = json.loads(plan_file.read_text()) if plan_file.exists() else None
    return Files(summary, path, wps, frame, plan)


def figures(h: np.ndarray) -> dict[str, float]:
    return {"min_m": float(h.min()), "p5_m": float(np.percentile(h, 5)),
            "median_m": float(np.median(h)), "max_m": float(h.max())}


def assert_figures(got: dict, h: np.ndarray, tol: float, what: str) -> None:
    for key, want in figures(h).items():
        assert got[key] == pytest.approx(want, abs=tol), \
            f"{what} {key}: summary {got[key]}, measured from the files {want:.3f}"


def leg_agl(wps: np.ndarray, ground: Ground, terrain: bool, step: float = 2.0) -> np.ndarray:
    """AGL every ``step`` metres along the straight legs between waypoints (lon, lat, AMSL);
    in the terrain frame the autopilot interpolates the height above ground, otherwise the
    altitude."""
    xy, tr = _metric(wps[:, 0], wps[:, 1])
    g_wp = ground(wps[:, 0], wps[:, 1])
    out = []
    for k in range(len(wps) - 1):
        n = max(int(np.ceil(np.hypot(*(xy[k + 1] - xy[k])) / step)), 1)
        t = np.linspace(0.0, 1.0, n + 1)
        p = xy[k] + t[:, None] * (xy[k + 1] - xy[k])
        lon, lat = tr.transform(p[:, 0], p[:, 1], direction="INVERSE")
        g = ground(np.asarray(lon), np.asarray(lat))
        if terrain:
            a = wps[k, 2] - g_wp[k]
            b = wps[k + 1, 2] - g_wp[k + 1]
            out.append(a + t * (b - a))
        else:
            out.append(wps[k, 2] + t * (wps[k + 1, 2] - wps[k, 2]) - g)
    return np.concatenate(out)


def item_amsl(plan: dict, ground: Ground) -> tuple[np.ndarray, np.ndarray]:
    """(lon/lat (n, 2), AMSL altitude (n,)) of the .plan's position items, from each item's
    frame: 0 as written, 3 above ``plannedHomePosition``, 10 above the ground here."""
    home = plan["mission"]["plannedHomePosition"]
    pos = [it for it in plan["mission"]["items"]
           if it.get("type") == "SimpleItem" and it["frame"] in (0, 3, 10)]
    ll = np.array([[it["params"][5], it["params"][4]] for it in pos], float)
    alt = np.array([it["params"][6] for it in pos], float)
    frame = np.array([it["frame"] for it in pos])
    amsl = np.where(frame == 0, alt, np.where(frame == 3, alt + home[2],
                                              alt + ground(ll[:, 0], ll[:, 1])))
    return ll, amsl


def check_run(out, ground: Ground, *, tol: float = 1.0, prefix: str = "",
              safety: dict | None = None) -> dict[str, np.ndarray]:
    """Assert that the run's summary figures equal the measurement of its files (module
    docstring); returns the measured AGL arrays (``path``, ``legs``) for more checks."""
    f = read(out, prefix)
    s = safety if safety is not None else f.summary["safety"]
    h = f.path[:, 2] - ground(f.path[:, 0], f.path[:, 1])
    known = np.isfinite(h)
    assert known.any(), "no path point over measured ground"
    filled = s.get("ground", {}).get("filled", {}).get("length_m", 0.0)
    if known.all() and not filled:
        assert_figures(s["height_above_ground"]["path"], h, tol, "path AGL")
        i0, i1 = s["cruise_points"]
        assert_figures(s["height_above_ground"]["cruise"], h[i0:i1 + 1], tol, "cruise AGL")
    if "ground" in s:
        m = s["ground"]["measured"]
        if m.get("height_above_ground"):
            assert_figures(m["height_above_ground"], h[known], tol, "AGL over measured ground")
    legs = leg_agl(f.waypoints, ground, terrain=f.frame == "terrain")
    if "legs" in s and np.isfinite(legs).all():
        assert s["legs"]["min_m"] == pytest.approx(legs.min(), abs=tol), \
            f"legs min AGL: summary {s['legs']['min_m']}, measured {legs.min():.3f}"
    if f.plan is not None:
        ll, amsl = item_amsl(f.plan, ground)
        n = len(f.waypoints)
        assert len(ll) >= n, "mission.plan holds fewer position items than path.geojson"
        np.testing.assert_allclose(ll[:n], f.waypoints[:, :2], atol=1e-6)
        ok = np.isfinite(amsl[:n])
        np.testing.assert_allclose(amsl[:n][ok], f.waypoints[:n, 2][ok], atol=tol)
    return {"path": h, "legs": legs}
