"""Gridded wind from files, sampled onto a world: NetCDF (xarray) and two-band GeoTIFFs.

* **NetCDF** (``.nc``; weather-model output such as ERA5, GFS or ICON), read with
  xarray: the east and north wind are the first pair of variables named
  ``u``/``v``, ``u10``/``v10``, ``u100``/``v100``, ``eastward_wind``/``northward_wind``,
  ``U``/``V`` or ``ugrd``/``vgrd``, on ``lon``/``lat`` (or ``longitude``/``latitude``)
  coordinates in degrees (0–360 longitudes are taken as −180–180). Any other
  dimension (time, level) is taken at its first index, and the summary says so.
* **GeoTIFF** (``.tif``/``.tiff``): band 1 the east wind ``u``, band 2 the north wind
  ``v`` [m/s], in the raster's CRS (it must have one); nodata is refused.

The wind is sampled bilinearly at every horizontal node of the world (through the
world's CRS, or its anchor for a world without one) into a
:class:`~fm2uav.world.wind.WindField` of kind ``grid``. The file must cover the whole
map. ``u`` and ``v`` are taken as the world's x and y components (a projected CRS's
grid north differs from true north by the meridian convergence, under 2° within a
UTM zone's usual extent; it is not corrected).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from ..errors import InputError
from .wind import WindField

__all__ = ["read_wind_file", "check_wind_file", "resolve_wind", "WIND_VARIABLES"]

#: (east, north) variable names searched in a NetCDF file, in this order.
WIND_VARIABLES = (("u", "v"), ("u10", "v10"), ("u100", "v100"),
                  ("eastward_wind", "northward_wind"), ("U", "V"), ("ugrd", "vgrd"))
_WHERE = "(mission file: wind.file; CLI: --wind-file)"


def _node_axes(world: Any) -> tuple[np.ndarray, np.ndarray]:
    return tuple(world.origin[k] + world.spacing[k] * np.arange(world.shape[k])
                 for k in (0, 1))  # type: ignore[return-value]


def _kind(path: Path) -> str:
    ext = path.suffix.lower()
    if ext in (".nc", ".nc4", ".netcdf"):
        return "netcdf"
    if ext in (".tif", ".tiff"):
        return "geotiff"
    raise InputError(f"wind file {path}: unknown kind {ext!r}; give a NetCDF (.nc) file with "
                     f"u/v on lon/lat, or a two-band GeoTIFF (.tif) of u and v {_WHERE}")


def _open_netcdf(path: Path) -> tuple[Any, str, str, str, str]:
    import xarray as xr

    try:
        ds = xr.open_dataset(path)
    except Exception as exc:  # xarray names many backends' errors
        raise InputError(f"wind file {path} cannot be read as NetCDF ({exc}) {_WHERE}") from None
    pair = next(((u, v) for u, v in WIND_VARIABLES if u in ds and v in ds), None)
    if pair is None:
        ds.close()
        raise InputError(f"wind file {path} has no wind variables: looked for "
                         f"{', '.join('/'.join(p) for p in WIND_VARIABLES)}; it has "
                         f"{', '.join(map(str, ds.data_vars)) or 'none'} {_WHERE}")
    da = ds[pair[0]]
    lon = next((c for c in ("lon", "longitude") if c in da.dims), None)
    lat = next((c for c in ("lat", "latitude") if c in da.dims), None)
    if lon is None or lat is None:
        ds.close()
        raise InputError(f"wind file {path}: {pair[0]} must be on lon/lat (or longitude/"
                         f"latitude) coordinates, it has dimensions {tuple(da.dims)} {_WHERE}")
    return ds, pair[0], pair[1], lon, lat


def check_wind_file(path: str | Path) -> Path:
    """The wind file, checked before any work: it exists, its kind is known and it has
    the wind (NetCDF: the variables and coordinates; GeoTIFF: two bands and a CRS).

    Raises
    ------
    InputError
        What is missing, naming ``wind.file`` / ``--wind-file``.
    """
    p = Path(path).expanduser()
    if not p.is_file():
        raise InputError(f"wind file {p} not found {_WHERE}")
    if _kind(p) == "netcdf":
        _open_netcdf(p)[0].close()
    else:
        import rasterio

        try:
            with rasterio.open(p) as src:
                if src.count < 2 or src.crs is None:
                    raise InputError(f"wind file {p} must have two bands (u, v) and a CRS; it "
                                     f"has {src.count} band(s), CRS {src.crs} {_WHERE}")
        except rasterio.errors.RasterioIOError as exc:
            raise InputError(f"wind file {p} cannot be read as a raster ({exc}) {_WHERE}"
                             ) from None
    return p


def _bilinear(axis0: np.ndarray, axis1: np.ndarray, values: np.ndarray, q0: np.ndarray,
              q1: np.ndarray, path: Path, slack: float = 0.0) -> np.ndarray:
    """Bilinear values at ``(q0, q1)``; ``slack`` (in axis units) past the outer nodes is
    the edge value (a raster's outer half pixels), further out an error."""
    from scipy.interpolate import RegularGridInterpolator

    a0, a1, vals = axis0, axis1, values
    if a0[0] > a0[-1]:
        a0, vals = a0[::-1], vals[::-1]
    if a1[0] > a1[-1]:
        a1, vals = a1[::-1], vals[:, ::-1]
    tol0 = 1e-9 * max(1.0, abs(a0).max()) + slack
    tol1 = 1e-9 * max(1.0, abs(a1).max()) + slack
    if (q0.min() < a0[0] - tol0 or q0.max() > a0[-1] + tol0 or q1.min() < a1[0] - tol1
            or q1.max() > a1[-1] + tol1):
        raise InputError(f"wind file {path} does not cover the map: the map spans "
                         f"{q0.min():.6g}..{q0.max():.6g} x {q1.min():.6g}..{q1.max():.6g}, the "
                         f"file {a0[0]:.6g}..{a0[-1]:.6g} x {a1[0]:.6g}..{a1[-1]:.6g} {_WHERE}")
    f = RegularGridInterpolator((a0, a1), vals, method="linear", bounds_error=False,
                                fill_value=None)
    out = f(np.column_stack([np.clip(q0, a0[0], a0[-1]), np.clip(q1, a1[0], a1[-1])]))
    if not np.all(np.isfinite(out)):
        raise InputError(f"wind file {path} has missing values over the map {_WHERE}")
    return out


def read_wind_file(path: str | Path, world: Any, *, anchor: Any = None) -> WindField:
    """The wind of a NetCDF or GeoTIFF file on the world's horizontal nodes.

    Parameters
    ----------
    path : str or Path
    world : World
        The map (its CRS, or ``anchor`` for a world without one, places its nodes).
    anchor : Anchor, optional
        Where a world without a CRS sits (default: the default anchor).

    Returns
    -------
    WindField
        Kind ``grid``, on the world's x/y node axes.

    Raises
    ------
    InputError
        The file is missing, unreadable, without the wind, or does not cover the map.
    """
    from .geo import to_lonlat

    p = check_wind_file(path)
    xs, ys = _node_axes(world)
    X, Y = np.meshgrid(xs, ys, indexing="ij")
    pts = np.column_stack([X.ravel(), Y.ravel()])
    if _kind(p) == "netcdf":
        ds, un, vn, lon, lat = _open_netcdf(p)
        try:
            picked = []
            u_da, v_da = ds[un], ds[vn]
            for dim in u_da.dims:
                if dim not in (lon, lat):
                    picked.append(f"{dim}={u_da[dim].values[0]}" if dim in u_da.coords
                                  else f"{dim}[0]")
                    u_da, v_da = u_da.isel({dim: 0}), v_da.isel({dim: 0})
            u_da = u_da.transpose(lon, lat)
            v_da = v_da.transpose(lon, lat)
            lons = np.asarray(ds[lon].values, dtype=float)
            lats = np.asarray(ds[lat].values, dtype=float)
            uu = np.asarray(u_da.values, dtype=float)
            vv = np.asarray(v_da.values, dtype=float)
        finally:
            ds.close()
        ll = to_lonlat(world, pts, anchor=anchor)
        qlon = ll[:, 0]
        if lons.max() > 180.0:
            qlon = np.where(qlon < 0, qlon + 360.0, qlon)
        u = _bilinear(lons, lats, uu, qlon, ll[:, 1], p)
        v = _bilinear(lons, lats, vv, qlon, ll[:, 1], p)
        source = f"{p.name}: {un}/{vn}" + (f" at {', '.join(picked)}" if picked else "")
    else:
        import rasterio
        from pyproj import Transformer

        with rasterio.open(p) as src:
            bands = src.read([1, 2], masked=True)
            if np.ma.is_masked(bands) and np.ma.getmaskarray(bands).any():
                raise InputError(f"wind file {p} has nodata cells; fill them first {_WHERE}")
            data = np.asarray(bands, dtype=float)
            crs = src.crs
            inv = ~src.transform
            if getattr(world, "crs", None):
                tr = Transformer.from_crs(world.crs, crs, always_xy=True)
                fx, fy = tr.transform(pts[:, 0], pts[:, 1])
            else:
                ll = to_lonlat(world, pts, anchor=anchor)
                tr = Transformer.from_crs("EPSG:4326", crs, always_xy=True)
                fx, fy = tr.transform(ll[:, 0], ll[:, 1])
            col, row = inv * (np.asarray(fx), np.asarray(fy))
            rows = np.arange(data.shape[1]) + 0.5
            cols = np.arange(data.shape[2]) + 0.5
            u = _bilinear(rows, cols, data[0], np.asarray(row), np.asarray(col), p, 0.5)
            v = _bilinear(rows, cols, data[1], np.asarray(row), np.asarray(col), p, 0.5)
        source = f"{p.name}: bands 1/2 (u/v, {crs.to_string()})"
    shape = (len(xs), len(ys))
    return WindField.grid(xs, ys, u.reshape(shape), v.reshape(shape), source=source)


def resolve_wind(field: WindField | None, world: Any, *, anchor: Any = None) -> WindField | None:
    """``field`` ready for ``world``: a file's wind read onto its nodes, any other as is."""
    if field is None or field.kind != "file":
        return field
    return read_wind_file(field.file, world, anchor=anchor)
