"""No-fly zones and the operating area as written in a mission file (and ``--no-fly``).

::

    no_fly_zones:                      # a list; each entry a file or an inline zone
      - airports.geojson               # every polygon (and point with a radius [m]) in it
      - file: danger.kml               # a file with defaults for its features
        buffer: 50                     # [m] kept horizontally and vertically
        ceiling: 120                   # [m] zone top (none: the whole column of air)
        reference: agl                 # floor/ceiling above ground (agl) or sea level (amsl)
      - polygon: [[600, 200], [800, 200], [800, 900], [600, 900]]   # world metres
        name: range
      - polygon: [[-3.760, 40.335], [-3.752, 40.335], [-3.752, 40.340]]
        lonlat: true                   # coordinates in degrees (lon, lat)
      - circle: {center: [-3.755, 40.338], radius: 150}
        lonlat: true
        floor: 0
        ceiling: 60
    operating_area: area.geojson       # or an inline polygon; the plan stays inside it

File paths are relative to the mission file. Files are read by
:func:`fm2uav.world.zones.read_zones` (GeoJSON lon/lat per RFC 7946, KML/KMZ,
GeoPackage, Shapefile, ...; ``crs:`` for files that declare none); per-feature
properties ``name``, ``floor``, ``ceiling``, ``reference``, ``buffer`` override
the entry's. Inline coordinates are world metres, or lon/lat degrees with
``lonlat: true`` (placed with the world's CRS, or the mission's ``anchor`` for
a world without one).
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING, Any, Literal

from pydantic import BaseModel, ConfigDict, Field, ValidationInfo, field_validator, model_validator

from .. import _validate
from ..errors import InputError

if TYPE_CHECKING:  # numpy loads with the zones' resolution, not with the schema
    import numpy as np

__all__ = ["ZoneSpec", "CircleSpec", "resolve_zones", "zones_from_cli"]

_STRICT = ConfigDict(strict=True, extra="forbid", frozen=True, allow_inf_nan=False)


def _base(info: ValidationInfo | None) -> Path | None:
    base = (info.context or {}).get("base_dir") if info is not None else None
    return None if base is None else Path(base)


class CircleSpec(BaseModel):
    """A circular zone: centre and radius [m]."""

    model_config = _STRICT
    center: list[float] = Field(..., min_length=2, max_length=2,
                                description="[x, y] metres, or [lon, lat] with lonlat: true")
    radius: float = Field(..., gt=0, le=1_000_000, description="radius [m]")


class ZoneSpec(BaseModel):
    """One no-fly zone (or the operating area): a file, a polygon or a circle."""

    model_config = _STRICT
    file: str | None = Field(None, description="vector file (relative to the mission file)")
    polygon: list[list[float]] | None = Field(None, min_length=3,
                                              description="[[x, y], ...] metres (or lon/lat)")
    circle: CircleSpec | None = Field(None, description="{center, radius}")
    lonlat: bool = Field(False, description="inline coordinates are lon/lat degrees")
    crs: str | None = Field(None, description="CRS of a file that declares none")
    name: str | None = Field(None, description="zone name")
    floor: float | None = Field(None, ge=-1000, le=100000, description="zone bottom [m]")
    ceiling: float | None = Field(None, ge=-1000, le=100000, description="zone top [m]")
    reference: Literal["amsl", "agl"] = Field("amsl", description="floor/ceiling measured from")
    buffer: float = Field(0.0, ge=0, le=100000, description="margin kept [m]")

    @model_validator(mode="before")
    @classmethod
    def _from_text(cls, data: Any) -> Any:
        return {"file": data} if isinstance(data, str) else data

    @field_validator("file")
    @classmethod
    def _file(cls, v: str | None, info: ValidationInfo) -> str | None:
        if v is None:
            return v
        p = Path(v).expanduser()
        base = _base(info)
        if not p.is_absolute() and base is not None:
            p = base / p
        if not p.exists():
            raise ValueError(f"file not found ({p}); allowed: a GeoJSON/KML/GPKG/SHP file")
        _validate.note_input(p, "a zone file (no_fly_zones / operating_area)")
        try:  # no folder, no named pipe (a reader would block on it), readable
            _validate.input_file(p, "file")
        except InputError as exc:
            raise ValueError(str(exc).removeprefix("file ")) from None
        return str(p)

    @field_validator("polygon")
    @classmethod
    def _polygon(cls, v: list[list[float]] | None) -> list[list[float]] | None:
        if v is not None and any(len(pt) != 2 for pt in v):
            raise ValueError("must be a list of [x, y] (or [lon, lat]) pairs")
        return v

    @model_validator(mode="after")
    def _one_shape(self) -> ZoneSpec:
        given = [k for k in ("file", "polygon", "circle") if getattr(self, k) is not None]
        if len(given) != 1:
            raise ValueError("give exactly one of file, polygon, circle (got "
                             f"{', '.join(given) or 'none'})")
        if self.file is not None and self.lonlat:
            raise ValueError("lonlat applies to inline polygon/circle coordinates, not to a "
                             "file (files say their CRS; GeoJSON is lon/lat)")
        if self.floor is not None and self.ceiling is not None and self.floor >= self.ceiling:
            raise ValueError(f"floor {self.floor:g} m must be below ceiling {self.ceiling:g} m")
        return self


def _to_metres(pts: np.ndarray, spec: ZoneSpec, world: Any, anchor: Any) -> np.ndarray:
    if not spec.lonlat:
        return pts
    import numpy as np

    from ..world.geo import from_lonlat

    if np.any(np.abs(pts[:, 0]) > 180) or np.any(np.abs(pts[:, 1]) > 90):
        raise InputError("a lonlat zone has coordinates outside lon [-180, 180], lat [-90, 90]; "
                         "give degrees as [lon, lat] or drop lonlat: true for metres")
    return np.asarray(from_lonlat(world, pts, anchor=anchor), dtype=float)[:, :2]


def _one(spec: ZoneSpec, world: Any, anchor: Any, *, inclusion: bool, where: str) -> list[Any]:
    from ..world.zones import read_zones, zone_from_mapping

    opts = {k: getattr(spec, k) for k in ("name", "floor", "ceiling", "buffer")
            if getattr(spec, k) is not None}
    opts["reference"] = spec.reference
    if spec.file is not None:
        return read_zones(spec.file, world, crs=spec.crs, defaults=opts, inclusion=inclusion)
    import numpy as np

    from ..world.zones import check_zones_on_map

    raw = np.asarray(spec.polygon if spec.polygon is not None else [spec.circle.center],
                     dtype=float)
    if spec.polygon is not None:
        pts = _to_metres(raw, spec, world, anchor)
        mapping = {"polygon": pts.tolist(), **opts}
    else:
        c = _to_metres(raw, spec, world, anchor)[0]
        mapping = {"circle": {"center": c.tolist(), "radius": spec.circle.radius}, **opts}
    zones = [zone_from_mapping(mapping, inclusion=inclusion, where=where)]
    ll = ((raw[:, 0].min(), raw[:, 1].min(), raw[:, 0].max(), raw[:, 1].max())
          if spec.lonlat else None)
    check_zones_on_map(zones, world, where, lonlat_bounds=ll, anchor=anchor, inline=True)
    return zones


def resolve_zones(no_fly: Any, operating_area: Any, world: Any, anchor: Any = None) -> list[Any]:
    """The :class:`~fm2uav.world.zones.Zone` objects of the mission's zone entries.

    Parameters
    ----------
    no_fly : sequence of ZoneSpec
        ``no_fly_zones:`` entries.
    operating_area : ZoneSpec or None
        ``operating_area:``.
    world : World
    anchor : Anchor, optional
        Placement of lon/lat coordinates on a world without CRS.

    Raises
    ------
    InputError, WorldError
        A file or an entry that cannot be used (message names ``no_fly_zones[i]``).
    """
    out: list[Any] = []
    for k, spec in enumerate(no_fly or ()):
        where = f"no_fly_zones[{k}]"
        try:
            zs = _one(spec, world, anchor, inclusion=False, where=where)
        except InputError as exc:
            raise InputError(str(exc) if str(exc).startswith(where) else f"{where}: {exc}"
                             ) from None
        out.extend(z if z.name else replace(z, name=f"no-fly {k + 1}" + (
            f".{j + 1}" if len(zs) > 1 else "")) for j, z in enumerate(zs))
    if operating_area is not None:
        try:
            zs = _one(operating_area, world, anchor, inclusion=True, where="operating_area")
        except InputError as exc:
            raise InputError(str(exc) if str(exc).startswith("operating_area") else
                             f"operating_area: {exc}") from None
        if len(zs) > 1:  # one area: the union of the file's polygons
            import shapely  # resolving zones only: the schema loads without it

            zs = [replace(zs[0], geometry=shapely.union_all([z.geometry for z in zs]),
                          circle=None)]
        out.extend(z if z.name else replace(z, name="operating area") for z in zs)
    return out


def zones_from_cli(files: Any, world: Any, *, crs: Any = None) -> list[Any]:
    """Zones of ``--no-fly FILE`` options (each file read whole)."""
    from ..world.zones import read_zones

    out: list[Any] = []
    for f in files or ():
        # a missing file, a folder, a FIFO: one line each, naming the flag (no hang on a pipe)
        p = _validate.input_file(f, "the no-fly file (GeoJSON/KML/GPKG/SHP)",
                                 where=(None, "--no-fly"))
        try:
            out.extend(read_zones(str(p), world, crs=crs))
        except InputError as exc:
            raise InputError(f"--no-fly {exc}") from None
    return out
