"""Vector files (issue 12 part 1): GeoJSON per RFC 7946 / CRS84, GeoPackage, Shapefile,
KML/KMZ, reprojected into the world's CRS; buildings with most heights missing."""

from __future__ import annotations

import json

import numpy as np
import pyogrio
import pytest
import shapely
from pyproj import Geod, Transformer
from shapely.geometry import Polygon

from fm2uav import World
from fm2uav.errors import WorldError
from fm2uav.missions.coverage.area import load_area
from fm2uav.world.vectors import read_vectors

# a block of Toulouse-like buildings around lon 1.44, lat 43.60 (UTM 31N)
LON0, LAT0 = 1.4400, 43.6000
M_LON = 1.0 / (111320.0 * np.cos(np.radians(LAT0)))  # degrees per metre east
M_LAT = 1.0 / 111132.0                                 # degrees per metre north


def _ll_square(x, y, w):
    """A w x w metre square at (x, y) metres east/north of (LON0, LAT0), in lon/lat."""
    return Polygon([(LON0 + (x + dx) * M_LON, LAT0 + (y + dy) * M_LAT)
                    for dx, dy in ((0, 0), (w, 0), (w, w), (0, w), (0, 0))])


def _town(n=12, seed=0):
    """n buildings on a 4 x 3 lattice; only 1 in 4 has a height, 1 in 4 levels."""
    rng = np.random.default_rng(seed)
    polys, props = [], []
    for k in range(n):
        x, y = 40.0 + 70.0 * (k % 4), 40.0 + 70.0 * (k // 4)
        polys.append(_ll_square(x, y, float(rng.uniform(12, 30))))
        if k % 4 == 0:
            props.append({"@id": f"way/{k}", "building": "yes", "height": f"{10 + k} m"})
        elif k % 4 == 1:
            props.append({"@id": f"way/{k}", "building": "yes", "building:levels": "4"})
        else:
            props.append({"@id": f"way/{k}", "building": "yes"})
    return polys, props


def _fc(polys, props, crs_member=None):
    fc = {"type": "FeatureCollection",
          "features": [{"type": "Feature", "properties": p,
                        "geometry": shapely.geometry.mapping(g)} for g, p in zip(polys, props)]}
    if crs_member is not None:
        fc["crs"] = {"type": "name", "properties": {"name": crs_member}}
    return fc


def _write(path, polys, props=None, *, driver, crs="EPSG:4326"):
    props = props or [{} for _ in polys]
    keys = sorted({k for p in props for k in p})
    fields = [np.array([p.get(k) for p in props], dtype=object) for k in keys]
    pyogrio.raw.write(str(path), np.array(shapely.to_wkb(polys), dtype=object),
                      field_data=fields, fields=keys, geometry_type="Polygon", crs=crs,
                      driver=driver)
    return path


def _roof_ok(world, polys_ll, heights):
    """Every world node inside a footprint (reprojected) and below its roof is occupied."""
    tr = Transformer.from_crs("EPSG:4326", world.crs, always_xy=True)
    X, Y = np.meshgrid(world.origin[0] + np.arange(world.shape[0]) * world.spacing[0],
                       world.origin[1] + np.arange(world.shape[1]) * world.spacing[1],
                       indexing="ij")
    zs = world.origin[2] + np.arange(world.shape[2]) * world.spacing[2]
    for g, h in zip(polys_ll, heights):
        gm = shapely.transform(g, lambda xy: np.column_stack(tr.transform(xy[:, 0], xy[:, 1])))
        inside = shapely.intersects_xy(gm, X, Y)
        assert inside.any()
        below = zs <= world.origin[2] + h
        assert world.occupancy[inside][:, below].all()


@pytest.mark.parametrize("member", [None, "urn:ogc:def:crs:OGC:1.3:CRS84"])
def test_rfc7946_and_crs84_geojson_buildings_in_lonlat(tmp_path, member):
    polys, props = _town()
    f = tmp_path / "osm.geojson"
    f.write_text(json.dumps(_fc(polys, props, member)))
    # 6 of 12 have neither height nor levels: one error naming the key and the flag
    with pytest.raises(WorldError, match=r"6 of 12 buildings .*way/2.*world.default_height "
                                         r"\(CLI --default-height\)"):
        World.from_buildings(f, 5.0)
    w = World.from_buildings(f, 5.0, default_height=9.0, margin=20.0)
    assert w.crs == "EPSG:32631"  # lon/lat -> local UTM, never read as metres
    ext = w.bounds[:2, 1] - w.bounds[:2, 0]
    assert 250 < ext[0] < 320 and 180 < ext[1] < 240
    src = w.georef.sources[0]
    assert src.role == "buildings" and len(src.sha256) == 64
    assert src.details["height_rule"] == {"height": 3, "building:levels": 3, "default_height": 6}
    assert ("RFC 7946" in src.crs_rule) == (member is None)
    heights = [10.0 + k if k % 4 == 0 else 12.0 if k % 4 == 1 else 9.0 for k in range(12)]
    _roof_ok(w, polys, heights)


def test_small_footprints_block_their_cells_with_all_touched(tmp_path):
    # a 4 m hut on 10 m cells: no node falls inside it, but its cell is blocked
    g = _ll_square(103.0, 103.0, 4.0)
    f = tmp_path / "hut.geojson"
    f.write_text(json.dumps(_fc([g, _ll_square(0, 0, 12), _ll_square(200, 200, 12)],
                                [{"height": 30}, {"height": 5}, {"height": 5}])))
    exact = World.from_buildings(f, 10.0)
    safe = World.from_buildings(f, 10.0, all_touched=True)
    assert exact.georef.sources[0].details.get("not_on_a_node", 0) >= 1
    tr = Transformer.from_crs("EPSG:4326", safe.crs, always_xy=True)
    cx, cy = tr.transform(*np.asarray(g.centroid.coords)[0])
    i, j = safe.to_cell(np.array([cx, cy, 0.0]))[:2]
    assert safe.surface_index()[i, j] * safe.spacing[2] + safe.origin[2] >= 30.0 - 10.0
    assert safe.occupancy[i, j, :3].all()


def test_geopackage_shapefile_kml_kmz_read_alike(tmp_path):
    polys, props = _town(8)
    props = [dict(p, height=p.get("height", "7 m")) for p in props]
    worlds = {}
    for driver, name in (("GPKG", "b.gpkg"), ("ESRI Shapefile", "b.shp"),
                         ("LIBKML", "b.kml"), ("LIBKML", "b.kmz")):
        f = _write(tmp_path / name, polys, props, driver=driver)
        worlds[name] = World.from_buildings(f, 5.0, margin=10.0)
    ref = worlds["b.gpkg"]
    for name, w in worlds.items():
        assert w.crs == "EPSG:32631" and w.shape == ref.shape, name
        np.testing.assert_array_equal(w.occupancy, ref.occupancy)
        assert w.georef.sources[0].details["buildings"] == 8


def test_projected_geopackage_is_reprojected_and_kept(tmp_path):
    polys, props = _town(4)
    props = [{"height": 20} for _ in polys]
    tr = Transformer.from_crs("EPSG:4326", "EPSG:2154", always_xy=True)  # Lambert-93 metres
    l93 = [shapely.transform(g, lambda xy: np.column_stack(tr.transform(xy[:, 0], xy[:, 1])))
           for g in polys]
    f = _write(tmp_path / "l93.gpkg", l93, props, driver="GPKG", crs="EPSG:2154")
    w = World.from_buildings(f, 5.0)
    # Lambert-93 distorts lengths by < 0.5 % in Toulouse: kept
    assert w.crs == "EPSG:2154" and "kept" in w.georef.reprojection
    # the same buildings in a 3857 file are reprojected (Web Mercator: +38 % here)
    tr2 = Transformer.from_crs("EPSG:4326", "EPSG:3857", always_xy=True)
    merc = [shapely.transform(g, lambda xy: np.column_stack(tr2.transform(xy[:, 0], xy[:, 1])))
            for g in polys]
    f2 = _write(tmp_path / "merc.gpkg", merc, props, driver="GPKG", crs="EPSG:3857")
    w2 = World.from_buildings(f2, 5.0)
    assert w2.crs == "EPSG:32631" and "distorts lengths" in w2.georef.reprojection
    a = read_vectors(f, target_crs="EPSG:32631").geometries
    b = read_vectors(f2, target_crs="EPSG:32631").geometries
    for ga, gb in zip(a, b):
        assert ga.area == pytest.approx(gb.area, rel=1e-6)


def test_shapefile_without_prj_needs_crs(tmp_path):
    polys, _ = _town(3)
    f = _write(tmp_path / "noprj.shp", polys, [{"height": 9}] * 3, driver="ESRI Shapefile")
    (tmp_path / "noprj.prj").unlink()
    with pytest.raises(WorldError, match=r"declares no CRS.*world.crs \(CLI --crs\)"):
        World.from_buildings(f, 5.0)
    w = World.from_buildings(f, 5.0, crs="EPSG:4326")
    assert w.crs == "EPSG:32631"


def test_metres_in_a_crs_less_geojson_file_are_refused_with_the_fix(tmp_path):
    f = tmp_path / "utm.geojson"
    sq = Polygon([(440100, 4470100), (440140, 4470100), (440140, 4470160), (440100, 4470160)])
    f.write_text(json.dumps(_fc([sq], [{"height": 40}])))
    with pytest.raises(WorldError, match=r"not degrees; .*world.crs \(CLI --crs\), e.g. "):
        World.from_buildings(f, 5.0)
    w = World.from_buildings(f, 5.0, crs="EPSG:32630")  # the fix
    assert w.crs == "EPSG:32630" and w.origin[:2] == (440100.0, 4470100.0)
    # a file that declares its CRS must not be contradicted
    f2 = tmp_path / "utm_member.geojson"
    f2.write_text(json.dumps(_fc([sq], [{"height": 40}], "EPSG:32630")))
    assert World.from_buildings(f2, 5.0).crs == "EPSG:32630"
    with pytest.raises(WorldError, match="declares its CRS EPSG:32630.*remove world.crs"):
        World.from_buildings(f2, 5.0, crs="EPSG:32631")
    # UTM metres declared as UTM zone 30 but lying in Australia (outside its area of use)
    f3 = tmp_path / "wrongzone.geojson"
    f3.write_text(json.dumps(_fc([shapely.affinity.translate(sq, 0, -11_000_000)],
                                 [{"height": 4}], "EPSG:32630")))
    with pytest.raises(WorldError, match="area of use"):
        World.from_buildings(f3, 5.0)


def test_lonlat_never_read_as_metres_in_memory_or_on_a_synthetic_map(tmp_path):
    polys, _ = _town(2)
    fc = _fc(polys, [{"height": 9}] * 2)
    # in-memory GeoJSON is the world's metres (synthetic city API) ... unless it is lon/lat
    with pytest.raises(WorldError, match="look like lon/lat degrees.*EPSG:4326"):
        World.from_buildings(fc, 1.0)
    assert World.from_buildings(fc, 5.0, crs="EPSG:4326").crs == "EPSG:32631"
    # a lon/lat area file on a built-in (CRS-less) map: refused, naming --dem
    f = tmp_path / "area.geojson"
    f.write_text(json.dumps(_fc([_ll_square(0, 0, 300)], [{}])))
    synthetic = World(np.zeros((30, 30, 5), bool), spacing=10.0)
    with pytest.raises(WorldError, match=r"lon/lat.*no CRS.*world.dem \(CLI --dem\)"):
        load_area(f, synthetic)


def test_only_points_is_an_error_and_points_are_counted(tmp_path):
    f = tmp_path / "nodes.geojson"
    f.write_text(json.dumps({"type": "FeatureCollection", "features": [
        {"type": "Feature", "properties": {"building": "yes"},
         "geometry": {"type": "Point", "coordinates": [LON0, LAT0]}}]}))
    with pytest.raises(WorldError, match="Polygon or MultiPolygon.*1 Point"):
        World.from_buildings(f, 5.0)
    polys, _ = _town(2)
    fc = _fc(polys, [{"height": "40 ft"}, {"height": 3}])
    fc["features"].append({"type": "Feature", "properties": {"building": "yes"},
                           "geometry": {"type": "Point", "coordinates": [LON0, LAT0]}})
    f.write_text(json.dumps(fc))
    w = World.from_buildings(f, 2.0)
    d = w.georef.sources[0].details
    assert d["skipped"] == {"Point": 1} and d["buildings"] == 2
    assert w.occupancy.any(axis=(0, 1)).sum() - 1 == int(np.floor(40 * 0.3048 / 2.0))


def _lonlat_world():
    """A flat 2 x 2 km DEM world around (LON0, LAT0) (EPSG:4326 array -> UTM 31N)."""
    z = np.full((80, 100), 150.0)
    return World.from_dem(z, 20.0, crs="EPSG:4326",
                          bounds=(LON0 - 0.005, LAT0 - 0.004, LON0 + 0.025, LAT0 + 0.018))


@pytest.mark.parametrize("driver, name", [("LIBKML", "area.kml"), ("LIBKML", "area.kmz"),
                                          ("GPKG", "area.gpkg"), ("GeoJSON", "area.geojson")])
def test_survey_area_files_in_lonlat(tmp_path, driver, name):
    w = _lonlat_world()
    ring = Polygon([(LON0 + 0.002, LAT0 + 0.001), (LON0 + 0.015, LAT0 + 0.002),
                    (LON0 + 0.012, LAT0 + 0.012), (LON0 + 0.004, LAT0 + 0.010)])
    f = _write(tmp_path / name, [ring], driver=driver)
    area, src = load_area(f, w)
    geod_area = abs(Geod(ellps="WGS84").geometry_area_perimeter(ring)[0])
    assert area.area == pytest.approx(geod_area, rel=0.005)  # UTM: true to 0.5 %
    assert src.role == "area" and len(src.sha256) == 64
    b = w.bounds
    assert b[0, 0] < area.bounds[0] < area.bounds[2] < b[0, 1]


def test_an_empty_buildings_file_on_a_dem_warns(tmp_path):
    # acceptance note C: an empty FeatureCollection with --buildings ran without a word
    from fm2uav.world.dem import GeodataWarning

    f = tmp_path / "none.geojson"
    f.write_text(json.dumps({"type": "FeatureCollection", "features": []}))
    dem = _lonlat_world()
    with pytest.warns(GeodataWarning, match="no features, so no building is drawn"):
        w = World.from_buildings(f, None, terrain=dem)
    assert w.occupancy.sum() == dem.occupancy.sum()
