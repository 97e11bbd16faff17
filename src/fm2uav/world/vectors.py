"""Vector files (buildings, survey areas, no-fly zones) read into the world's CRS.

One reader, :func:`read_vectors`, for every vector input of fm2uav. Files go
through GDAL/OGR via pyogrio: GeoJSON, GeoPackage, Shapefile (also zipped),
KML and KMZ (GDAL's LIBKML driver; every folder/layer is read), FlatGeobuf,
GML and anything else OGR opens. In-memory GeoJSON (a ``dict`` or a list of
Features) is read with shapely.

Which CRS the coordinates are in, first rule that applies:

1. the file declares one (GeoPackage, a Shapefile's ``.prj``, a legacy GeoJSON
   ``crs`` member such as ``urn:ogc:def:crs:OGC:1.3:CRS84`` or
   ``EPSG:32630``): that one;
2. KML/KMZ: always lon/lat WGS84 (the KML specification);
3. ``crs`` is given (mission file ``world.crs``, CLI ``--crs``): that one, for
   files that declare none (e.g. an old GeoJSON in UTM metres);
4. GeoJSON (file) without a ``crs`` member: lon/lat WGS84, per RFC 7946;
5. in-memory GeoJSON without a ``crs`` member: the world's own x/y metres
   (the API of :func:`fm2uav.world.buildings.from_buildings`);
6. otherwise (e.g. a Shapefile without ``.prj``): an error asking for ``crs``.

A file declared (or assumed) lon/lat whose coordinates leave [-180, 180] x
[-90, 90], a projected file whose coordinates fall outside its CRS's area of
use, or one whose coordinates look like degrees while the CRS says metres, is
refused with an error naming ``world.crs`` / ``--crs``. Nothing in lon/lat is
ever read as metres. Geometries are then reprojected with pyproj into the
world's CRS (``target_crs``). For a world without a CRS (a synthetic
scenario), only data without a declared CRS can be used, read as the map's
metres, and coordinates that look like lon/lat are refused.
"""

from __future__ import annotations

import json
import re
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from os import PathLike
from pathlib import Path
from typing import Any

import numpy as np
import shapely
from shapely.geometry import shape as shapely_shape

from ..errors import InputError, WorldError
from .geo import (
    SourceFile,
    bounds_lonlat,
    check_fit,
    crs_label,
    local_metric_crs,
    parse_crs,
    sha256_file,
    transformer,
)

__all__ = ["VectorData", "read_vectors", "POLYGONS"]

#: Geometry kinds of footprints, areas and zones.
POLYGONS = ("Polygon", "MultiPolygon")

_LONLAT = "EPSG:4326"
_RULE_DECLARED = "declared by the file"
_RULE_KML = "KML (always lon/lat WGS84)"
_RULE_GIVEN = "given (world.crs / --crs)"
_RULE_RFC = "RFC 7946 (GeoJSON without a crs member: lon/lat WGS84)"
_RULE_MAP = "the map's metres (no CRS declared, and the map has none)"
_CRS_HINT = "world.crs (CLI --crs)"


@dataclass(frozen=True)
class VectorData:
    """Features read by :func:`read_vectors`.

    Attributes
    ----------
    geometries : tuple of shapely geometries
        2D, in :attr:`crs` (the world's CRS), or the map's metres if ``None``.
    properties : tuple of dict
        Attribute table row of each geometry (OSM tags, ``name``, ...).
    crs : str or None
        CRS of :attr:`geometries`.
    source : SourceFile
        The file, its checksum, the CRS it was read in and the rule that gave it.
    skipped : dict
        Features left out, by reason (e.g. ``{"Point": 12, "empty": 1}``).
    source_bounds : tuple or None
        Bounds (minx, miny, maxx, maxy) of the kept features as read, in the CRS they
        were read in (``source.crs``), before any reprojection.
    """

    geometries: tuple[Any, ...]
    properties: tuple[dict[str, Any], ...]
    crs: str | None
    source: SourceFile
    skipped: dict[str, int] = field(default_factory=dict)
    source_bounds: tuple[float, float, float, float] | None = None

    def __len__(self) -> int:
        return len(self.geometries)


# ---------------------------------------------------------------------- CRS rules
def _geojson_crs_member(path: Path) -> Any:
    """The legacy ``crs`` member of a GeoJSON file, or None (read as text)."""
    try:
        head = path.read_text(encoding="utf-8", errors="replace")
    except OSError:
        return None
    if not re.search(r'"crs"\s*:', head):
        return None
    try:
        doc = json.loads(head)
    except json.JSONDecodeError:
        return None
    return doc.get("crs") if isinstance(doc, Mapping) else None


def _member_crs(member: Any, where: str) -> Any:
    """pyproj CRS of a GeoJSON ``crs`` member ({"type": "name"|"EPSG", ...})."""
    props = member.get("properties") or {} if isinstance(member, Mapping) else {}
    text = props.get("name") if "name" in props else (
        f"EPSG:{props['code']}" if "code" in props else None)
    if text is None:
        raise WorldError(f"{where}: cannot read its GeoJSON crs member {member!r}; remove it "
                         "(RFC 7946 GeoJSON is lon/lat) or name a CRS such as EPSG:32630")
    try:
        return parse_crs(text)
    except WorldError:
        raise WorldError(f"{where}: its GeoJSON crs member names an unknown CRS {text!r}; fix "
                         "it or remove it (RFC 7946 GeoJSON is lon/lat)") from None


def _same_crs(a: Any, b: Any) -> bool:
    try:
        return parse_crs(a).equals(parse_crs(b), ignore_axis_order=True)
    except WorldError:
        return False


# ---------------------------------------------------------------------- readers
def _read_file(path: Path, layer: str | None) -> tuple[list[Any], list[dict], Any, str, list[str]]:
    """(geometries, properties, declared CRS or None, driver, layer names) through pyogrio."""
    import pyogrio
    from pyogrio.errors import DataSourceError, DataLayerError

    target = str(path)
    if path.suffix.lower() == ".zip":
        target = f"/vsizip/{path}"
    try:
        layers = [str(row[0]) for row in pyogrio.list_layers(target)]
    except (DataSourceError, DataLayerError, OSError) as exc:
        raise WorldError(
            f"cannot read {path} as a vector file ({str(exc).splitlines()[0]}); give GeoJSON, "
            "GeoPackage, Shapefile, KML/KMZ or another format GDAL/OGR reads") from None
    if layer is not None:
        if layer not in layers:
            raise WorldError(f"{path} has no layer {layer!r}; its layers are {', '.join(layers)}")
        layers = [layer]
    geoms: list[Any] = []
    props: list[dict] = []
    crs_found: list[Any] = []
    driver = ""
    for name in layers:
        try:
            meta, _, wkb, fields = pyogrio.raw.read(target, layer=name)
        except (DataSourceError, DataLayerError) as exc:
            raise WorldError(f"cannot read layer {name!r} of {path}: "
                             f"{str(exc).splitlines()[0]}") from None
        names = list(meta.get("fields", []))
        n = len(wkb) if wkb is not None else 0
        if n == 0:
            continue
        crs_found.append(meta.get("crs"))
        g = shapely.from_wkb(np.asarray(wkb, dtype=object), on_invalid="ignore")
        geoms.extend(g.tolist())
        cols = [np.asarray(f, dtype=object) for f in fields]
        for i in range(n):
            row = {}
            for k, col in zip(names, cols):
                v = col[i]
                if v is None or (isinstance(v, float) and np.isnan(v)):
                    continue
                row[str(k)] = v.item() if isinstance(v, np.generic) else v
            props.append(row)
    declared = [c for c in crs_found if c]
    if len({parse_crs(c).to_wkt() for c in declared}) > 1:
        raise WorldError(f"{path} has layers in different CRSs ({', '.join(map(str, declared))}); "
                         "export them to one CRS first (e.g. ogr2ogr -t_srs EPSG:4326)")
    info = pyogrio.read_info(target, layer=layers[0]) if layers else {}
    driver = str(info.get("driver", "")) or driver
    return geoms, props, (declared[0] if declared else None), driver, layers


def _read_mapping(source: Any) -> tuple[list[Any], list[dict], Any]:
    """(geometries, properties, crs member or None) of in-memory GeoJSON."""
    member = None
    if isinstance(source, Mapping):
        member = source.get("crs")
        kind = source.get("type")
        if kind == "FeatureCollection":
            feats: Iterable[Any] = source.get("features") or []
        elif kind == "Feature":
            feats = [source]
        elif kind in ("Polygon", "MultiPolygon", "Point", "LineString", "MultiPoint",
                      "MultiLineString", "GeometryCollection"):
            feats = [{"type": "Feature", "geometry": dict(source), "properties": {}}]
        else:
            raise WorldError(
                "GeoJSON must be a FeatureCollection, a Feature, a geometry or a list of "
                f"Features; got a mapping of type {kind!r}")
    elif isinstance(source, Iterable) and not isinstance(source, (str, bytes)):
        feats = list(source)
    else:
        raise WorldError(f"vector data must be a file path or GeoJSON (dict or list of "
                         f"Features), got {type(source).__name__}")
    geoms, props = [], []
    for i, f in enumerate(feats):
        if not isinstance(f, Mapping) or "geometry" not in f:
            raise WorldError(f"feature {i} is not a GeoJSON Feature with a 'geometry'")
        if f["geometry"] is None:
            geoms.append(None)
        else:
            try:
                geoms.append(shapely_shape(f["geometry"]))
            except Exception as exc:  # shapely raises several types on bad GeoJSON
                raise WorldError(f"feature {i}: invalid GeoJSON geometry ({exc})") from None
        props.append(dict(f.get("properties") or {}))
    return geoms, props, member


def _skipped_text(skipped: Mapping[str, int]) -> str:
    if not skipped:
        return "the file has no features"
    return "left out: " + ", ".join(f"{n} {k}" for k, n in sorted(skipped.items()))


def _reproject(geoms: Sequence[Any], src: Any, dst: Any) -> list[Any]:
    tr = transformer(src, dst)

    def fn(xy: np.ndarray) -> np.ndarray:
        x, y = tr.transform(xy[:, 0], xy[:, 1])
        return np.column_stack([np.asarray(x), np.asarray(y)])

    out = shapely.transform(np.asarray(geoms, dtype=object), fn)
    bad = ~np.asarray([np.all(np.isfinite(shapely.bounds(g))) for g in out])
    if bad.any():
        raise WorldError(f"{int(bad.sum())} feature(s) cannot be projected from "
                         f"{crs_label(src)} to {crs_label(dst)} (outside its valid area)")
    return list(out)


def read_vectors(
    source: str | PathLike[str] | Mapping[str, Any] | Sequence[Any],
    *,
    target_crs: str | None = None,
    crs: Any = None,
    role: str = "vectors",
    kinds: Sequence[str] | None = POLYGONS,
    layer: str | None = None,
    repair: bool = True,
) -> VectorData:
    """Read vector features into the world's CRS (see the module docstring).

    Parameters
    ----------
    source : path, GeoJSON dict or list of Features
        A file GDAL/OGR reads (GeoJSON, GeoPackage, Shapefile or zipped
        Shapefile, KML, KMZ, ...), or in-memory GeoJSON.
    target_crs : str, optional
        CRS of the world (``World.crs``); ``None`` for a world without one;
        ``"auto"`` to choose it from the data (the file's own CRS if metric
        and true to 0.5 % over the data, else the local UTM zone; see
        :func:`fm2uav.world.geo.local_metric_crs`), or ``None`` for in-memory
        data without a CRS.
    crs : optional
        CRS of data that declare none (mission file ``world.crs``, CLI ``--crs``).
    role : str
        What the features are, for messages and the :class:`SourceFile`
        (``"buildings"``, ``"area"``, ``"no-fly"``).
    kinds : sequence of str, optional
        Geometry types kept (default polygons); others are counted in
        ``skipped``. ``None`` keeps all.
    layer : str, optional
        Read only this layer (default: every layer of the file).
    repair : bool
        Make invalid geometries valid (``shapely.make_valid``); ``False``
        leaves them to the caller's own validation (survey areas).

    Returns
    -------
    VectorData

    Raises
    ------
    WorldError
        Unreadable file, unknown or conflicting CRS, coordinates that do not
        fit the CRS, data with a CRS on a world without one.
    """
    is_file = isinstance(source, (str, PathLike))
    where, geoms, props, declared, kml, geojson, layers, driver, sha, shown = _read_source(
        source, role, layer)
    src_crs, rule = _source_crs_rule(declared, crs, kml, geojson, is_file, where)
    kept_g, kept_p, skipped = _keep_kinds(geoms, props, kinds, repair)
    bounds = (shapely.total_bounds(np.asarray(kept_g, dtype=object)) if kept_g
              else np.zeros(4))

    reason = ""
    if target_crs == "auto":
        target_crs, reason = _auto_target(src_crs, kept_g, bounds, kinds, skipped, rule, where)
    if target_crs is None and rule in (_RULE_RFC, _RULE_MAP):
        # a map without CRS (synthetic scenario): data without a declared CRS are its metres
        if _looks_lonlat(kept_g, bounds) and not is_file:
            minx, miny, maxx, maxy = bounds
            raise WorldError(
                f"{where} has no CRS and is read in the map's metres, but its coordinates "
                f"(x {minx:.6g}..{maxx:.6g}, y {miny:.6g}..{maxy:.6g}) look like lon/lat "
                f"degrees; say so with {_CRS_HINT} = EPSG:4326 (or a 'crs' member), or give "
                "a file path (RFC 7946 GeoJSON files are lon/lat)")
        if _looks_lonlat(kept_g, bounds):
            minx, miny, maxx, maxy = bounds
            raise WorldError(
                f"{where} looks like lon/lat degrees (x {minx:.6g}..{maxx:.6g}, y "
                f"{miny:.6g}..{maxy:.6g}), but the map has no CRS (a built-in synthetic "
                "scenario) to place them; plan on real terrain with world.dem (CLI --dem), or "
                "give the coordinates in the map's metres")
        src_crs, rule, out_crs = None, _RULE_MAP, None
    elif target_crs is None:
        raise WorldError(
            f"{where} is in {crs_label(src_crs)} ({rule}), but the map has no CRS (a built-in "
            "synthetic scenario), so it cannot be placed; plan on real terrain with world.dem "
            "(CLI --dem), or give the features in the map's metres without a CRS")
    elif src_crs is None:
        # in-memory GeoJSON without a CRS on a geo-referenced world: the world's own x/y
        if _looks_lonlat(kept_g, bounds):
            minx, miny, maxx, maxy = bounds
            raise WorldError(
                f"{where} has no CRS and is read in the map's metres ({crs_label(target_crs)}), "
                f"but its coordinates (x {minx:.6g}..{maxx:.6g}, y {miny:.6g}..{maxy:.6g}) look "
                f"like lon/lat degrees; say so with {_CRS_HINT} = EPSG:4326 (or a 'crs' "
                "member), or give a file path (RFC 7946 GeoJSON files are lon/lat)")
        out_crs = target_crs
    else:
        if kept_g:
            check_fit(bounds, src_crs, rule, where, _CRS_HINT)
        out_crs = target_crs
        if kept_g and not _same_crs(src_crs, target_crs):
            kept_g = _reproject(kept_g, src_crs, target_crs)
    src = _source_file(shown, role, sha, src_crs, rule, len(kept_g), skipped, reason, layers,
                       driver)
    return VectorData(geometries=tuple(kept_g), properties=tuple(kept_p), crs=out_crs,
                      source=src, skipped=skipped,
                      source_bounds=tuple(float(v) for v in bounds) if kept_g else None)


def _read_source(source: Any, role: str, layer: str | None) -> tuple[Any, ...]:
    """Features of a vector file or an in-memory GeoJSON, and what is known of their CRS.

    Returns ``where`` (for messages), geometries, properties, the declared CRS (or None),
    whether it is KML / a GeoJSON file, the file's layers, driver, sha256 and shown name.
    """
    if isinstance(source, (str, PathLike)):
        path = Path(source).expanduser()
        where = f"the {role} file {path}"
        if not path.exists():
            raise WorldError(f"{where} does not exist; check the path")
        from .. import _validate as v

        v.input_file(path, f"the {role} file")  # no directory / pipe (would block) / unreadable
        geoms, props, declared, driver, layers = _read_file(path, layer)
        kml = driver.upper() in ("LIBKML", "KML") or path.suffix.lower() in (".kml", ".kmz")
        geojson = driver.upper() in ("GEOJSON", "GEOJSONSEQ") or path.suffix.lower() in (
            ".geojson", ".json")
        member = _geojson_crs_member(path) if geojson else None
        if geojson and member is None:
            declared = None  # GDAL reports EPSG:4326 for RFC 7946 files: an assumption
        elif geojson and isinstance(member, Mapping) and (
                {"name", "code"} & set(member.get("properties") or {})):
            # GDAL silently ignores a crs member it cannot parse (then reads lon/lat): refuse
            declared = _member_crs(member, where)
        sha = sha256_file(path)
        shown = str(path)
    else:
        where = f"the {role} GeoJSON"
        geoms, props, member = _read_mapping(source)
        declared = _member_crs(member, where) if member is not None else None
        kml = geojson = False
        layers, driver, sha, shown = [], "GeoJSON (in memory)", None, "<in memory>"
    return where, geoms, props, declared, kml, geojson, layers, driver, sha, shown


def _source_crs_rule(declared: Any, crs: Any, kml: bool, geojson: bool, is_file: bool,
                     where: str) -> tuple[Any, str]:
    """The CRS of the features and the rule that gave it (declared, KML, given, RFC 7946, map)."""
    given = parse_crs(crs) if crs is not None else None
    if declared is not None:
        if given is not None and not _same_crs(declared, given):
            raise WorldError(
                f"{where} declares its CRS {crs_label(declared)}, but {_CRS_HINT} says "
                f"{crs_label(given)}; remove world.crs / --crs (it is only for files that "
                "declare none) or fix the file")
        src_crs, rule = parse_crs(declared), _RULE_DECLARED
    elif kml:
        src_crs, rule = parse_crs(_LONLAT), _RULE_KML
    elif given is not None:
        src_crs, rule = given, _RULE_GIVEN
    elif is_file and geojson:
        src_crs, rule = parse_crs(_LONLAT), _RULE_RFC
    elif not is_file:
        src_crs, rule = None, _RULE_MAP
    else:
        raise WorldError(
            f"{where} declares no CRS (e.g. a Shapefile without its .prj); give it with "
            f"{_CRS_HINT}, e.g. EPSG:4326 for lon/lat or EPSG:32630")
    return src_crs, rule


def _keep_kinds(geoms: Any, props: Any, kinds: Any, repair: bool
                ) -> tuple[list[Any], list[Any], dict[str, int]]:
    """The 2D geometries of the wanted ``kinds`` (invalid ones repaired if ``repair``) and their
    properties; the others counted per reason (empty, geometry type, invalid)."""
    # keep the wanted kinds, count the others
    kept_g, kept_p, skipped = [], [], {}
    for g, p in zip(geoms, props):
        if g is None or g.is_empty:
            skipped["empty"] = skipped.get("empty", 0) + 1
            continue
        if kinds is not None and g.geom_type not in kinds:
            skipped[g.geom_type] = skipped.get(g.geom_type, 0) + 1
            continue
        g = shapely.force_2d(g)
        if repair and not g.is_valid:
            g = shapely.make_valid(g)
            if kinds is not None and g.geom_type not in kinds:
                polys = [p_ for p_ in getattr(g, "geoms", [g]) if p_.geom_type in kinds]
                if not polys:
                    skipped["invalid"] = skipped.get("invalid", 0) + 1
                    continue
                g = shapely.union_all(polys)
        kept_g.append(g)
        kept_p.append(p)
    return kept_g, kept_p, skipped


def _looks_lonlat(kept_g: list[Any], bounds: Any) -> bool:
    """True when the features' bounds look like lon/lat degrees of a small area (< 2 deg)."""
    minx, miny, maxx, maxy = bounds
    return bool(kept_g) and (-180 <= minx and maxx <= 180 and -90 <= miny and maxy <= 90
                             and max(maxx - minx, maxy - miny) < 2.0)


def _auto_target(src_crs: Any, kept_g: list[Any], bounds: Any, kinds: Any,
                 skipped: dict[str, int], rule: str, where: str) -> tuple[Any, str]:
    """``target_crs="auto"``: the features' projected CRS, or a local metric CRS around them
    (and its reprojection note); None for features without a CRS."""
    reason = ""
    target_crs: Any = None
    if src_crs is None or not kept_g:
        target_crs = None if src_crs is None else (
            src_crs.to_string() if src_crs.is_projected else None)
        if target_crs is None and src_crs is not None:
            wanted = " or ".join(kinds) if kinds else "usable"
            raise WorldError(f"{where} has no {wanted} features to build a world from "
                             f"({_skipped_text(skipped)})")
    else:
        check_fit(bounds, src_crs, rule, where, _CRS_HINT)
        target_crs, _, reason = local_metric_crs(src_crs, bounds_lonlat(bounds, src_crs))
    return target_crs, reason


def _source_file(shown: str, role: str, sha: str | None, src_crs: Any, rule: str, n: int,
                 skipped: dict[str, int], reason: str, layers: Any, driver: str) -> SourceFile:
    """The provenance record of ``n`` features read (skipped counts, reprojection, layers, driver)."""
    return SourceFile(
        path=shown, role=role, sha256=sha,
        crs=None if src_crs is None else crs_label(src_crs), crs_rule=rule,
        details={"features": n, **({"skipped": dict(skipped)} if skipped else {}),
                 **({"reprojection": reason} if reason else {}),
                 **({"layers": list(layers)} if len(layers) > 1 else {}),
                 **({"driver": driver} if driver else {})},
    )
