"""load_world(WorldSpec) (issue 12 part 3): a world sized for the request, DEM + buildings,
filled cells under start/goal, errors that name the mission-file key and the CLI flag."""

from __future__ import annotations

import json
import warnings

import numpy as np
import pytest
import shapely
from pydantic import ValidationError
from pyproj import Transformer
from shapely.geometry import Polygon

import fm2uav
from fm2uav.errors import InputError, PointError, WorldError
from fm2uav.planning import FlightLevel
from fm2uav.world.dem import GeodataWarning
from fm2uav.world.geo import from_lonlat
from fm2uav.world.load import (
    WorldSpec,
    check_points,
    load_world,
    round_down,
    round_up,
    world_summary,
)

from . import geodata_data as gd

BBOX = [10.05, 45.54, 10.20, 45.66]


@pytest.fixture(scope="module")
def dem(tmp_path_factory):
    d = tmp_path_factory.mktemp("load")
    return {"full": gd.dem_4326(d / "full.tif", border=False),
            "border": gd.dem_4326(d / "border.tif"), "dir": d}


def _spec(**kw):
    return WorldSpec.model_validate(kw)


def test_round_numbers():
    assert [round_up(v) for v in (64.9, 20.0, 16.7, 0.37, 1234.0)] == [80.0, 20.0, 20.0,
                                                                        0.4, 1500.0]
    assert [round_down(v) for v in (64.9, 20.0, 16.7, 0.37, 1234.0)] == [60.0, 20.0, 15.0,
                                                                          0.3, 1000.0]


@pytest.mark.parametrize("agl", [30.0, 120.0, 400.0])
def test_a_request_always_has_sky_and_fine_enough_layers(dem, agl):
    w = load_world(_spec(dem=str(dem["full"]), bbox=BBOX, cell_size=300.0), agl=agl)
    dz = w.spacing[2]
    assert dz <= agl / 6.0
    assert w.bounds[2, 1] >= w.terrain.max() + agl + 10 * dz - 1e-6
    a = from_lonlat(w, [*gd.START, 0.0])
    b = from_lonlat(w, [*gd.GOAL, 0.0])
    s = np.array([a[0], a[1], w.ground_height(a[0], a[1]) + agl])
    g = np.array([b[0], b[1], w.ground_height(b[0], b[1]) + agl])
    p = fm2uav.plan(w, s, g, level=FlightLevel(agl=agl))  # never fails for lack of sky
    assert p.path[:, 2].max() < w.bounds[2, 1]


def test_default_cell_follows_the_dem_and_the_rules_are_recorded(dem):
    w = load_world(_spec(dem=str(dem["full"]), bbox=BBOX), agl=120.0)
    d = w.georef.sources[0].details
    assert d["cell_size"] == 60.0 and "DEM pixel" in d["cell_size_rule"]  # 3" ~ 65 m here
    assert d["dz"] == 20.0 and "agl / 6" in d["dz_rule"]
    s = world_summary(w)
    assert s["crs"] == "EPSG:32632" and s["georef"]["epsg"] == 32632
    assert s["georef"]["sources"][0]["sha256"] and s["filled_nodes"] == 0
    json.dumps(s)


def test_errors_name_the_key_and_the_flag(dem):
    with pytest.raises(WorldError, match=r"world.ceiling \(--ceiling\)"):
        load_world(_spec(dem=str(dem["full"]), bbox=BBOX, cell_size=300.0, ceiling=1300.0),
                   agl=120.0)
    with pytest.raises(InputError, match=r"world.dz \(--dz\) = 100 m .*world.dz <= 5"):
        load_world(_spec(dem=str(dem["full"]), bbox=BBOX, cell_size=300.0, dz=100.0), agl=30.0)
    with pytest.raises(WorldError, match=r"world.bbox \(CLI --bbox"):
        load_world(_spec(dem=str(dem["border"]), cell_size=300.0))
    with pytest.raises(InputError, match=r"world.dem \(CLI --dem\)"):
        load_world(_spec())
    with pytest.raises(ValidationError, match="west < east"):
        _spec(dem=str(dem["full"]), bbox=[10.2, 45.5, 10.1, 45.6])
    with pytest.raises(ValidationError, match="file not found"):
        _spec(dem=str(dem["dir"] / "nowhere.tif"))


def test_filled_cells_under_start_or_goal(dem):
    w = load_world(_spec(dem=str(dem["border"]), cell_size=400.0, nodata="fill"))
    assert w.filled.any()
    corner = w.to_world(np.array([0.0, 0.0, 0.0]))
    centre = w.to_world(np.array([w.shape[0] // 2, w.shape[1] // 2, 0.0]))
    check_points(w, {"start": centre, "goal": centre})
    with pytest.raises(PointError, match=r"start \(lon .*filled.*--allow-filled "
                                         r"\(mission file: world.allow_filled: true\)"):
        check_points(w, {"start": corner, "goal": centre})
    with pytest.warns(GeodataWarning, match="allowed by --allow-filled"):
        check_points(w, {"start": centre, "goal": corner}, allow_filled=True)


def _town_lonlat(n=6):
    tr = Transformer.from_crs("EPSG:32632", "EPSG:4326", always_xy=True)
    c = Transformer.from_crs("EPSG:4326", "EPSG:32632", always_xy=True).transform(*gd.START)
    polys, props = [], []
    for k in range(n):
        x0, y0 = c[0] + 200.0 + 160.0 * k, c[1] + 150.0 + 110.0 * k
        sq = Polygon([(x0, y0), (x0 + 60, y0), (x0 + 60, y0 + 45), (x0, y0 + 45)])
        polys.append(shapely.transform(
            sq, lambda xy: np.column_stack(tr.transform(xy[:, 0], xy[:, 1]))))
        props.append({"height": 35.0} if k % 2 == 0 else {"building": "yes"})
    return polys, props


def test_buildings_on_the_dem_and_alone(dem, tmp_path):
    polys, props = _town_lonlat()
    f = tmp_path / "town.geojson"
    f.write_text(json.dumps({"type": "FeatureCollection", "features": [
        {"type": "Feature", "properties": p, "geometry": shapely.geometry.mapping(g)}
        for g, p in zip(polys, props)]}))
    w = load_world(_spec(dem=str(dem["full"]), buildings=str(f), bbox=BBOX, cell_size=50.0,
                         default_height=12.0), agl=60.0)
    assert [s.role for s in w.georef.sources] == ["dem", "buildings"]
    b = w.georef.sources[1].details
    assert b["height_rule"] == {"height": 3, "building:levels": 0, "default_height": 3}
    assert b["footprint_rule"] == "cells touched"
    # every node whose cell (node +- half a cell) touches a footprint is blocked up to the
    # highest ground under it + the height
    tr = Transformer.from_crs("EPSG:4326", w.crs, always_xy=True)
    X, Y = np.meshgrid(w.origin[0] + np.arange(w.shape[0]) * w.spacing[0],
                       w.origin[1] + np.arange(w.shape[1]) * w.spacing[1], indexing="ij")
    zs = w.origin[2] + np.arange(w.shape[2]) * w.spacing[2]
    for g, p in zip(polys, props):
        gm = shapely.transform(g, lambda xy: np.column_stack(tr.transform(xy[:, 0], xy[:, 1])))
        h = 0.5 * w.spacing[0] - 1e-6
        inside = shapely.intersects(shapely.box(X - h, Y - h, X + h, Y + h), gm)
        assert inside.any()
        roof = w.terrain[inside].max() + p.get("height", 12.0)
        assert w.occupancy[inside][:, zs <= roof].all()
    # a 120 m request over buildings alone (flat ground) has room too
    alone = load_world(_spec(buildings=str(f), default_height=12.0), agl=120.0)
    assert alone.spacing == (2.0, 2.0, 2.0)  # auto: 2 m cells for buildings
    assert alone.bounds[2, 1] >= 35.0 + 120.0
    assert "altitude above sea level is unknown" in alone.georef.vertical
    assert alone.georef.amsl is False
    with pytest.raises(WorldError, match=r"world.height_cells = 20 leaves no room to fly 120 m"):
        load_world(_spec(buildings=str(f), default_height=12.0, cell_size=5.0,
                         height_cells=20), agl=120.0)


def test_buildings_alone_ground_elevation_and_default_margin(tmp_path):
    """Issue 25: an AMSL frame needs a ground elevation, and a take-off 13 m beside the
    outermost building is on the map without world.margin."""
    polys, props = _town_lonlat()
    f = tmp_path / "town.geojson"
    f.write_text(json.dumps({"type": "FeatureCollection", "features": [
        {"type": "Feature", "properties": p, "geometry": shapely.geometry.mapping(g)}
        for g, p in zip(polys, props)]}))
    w = load_world(_spec(buildings=str(f), default_height=12.0), agl=30.0)
    tr = Transformer.from_crs("EPSG:4326", w.crs, always_xy=True)
    foot = shapely.union_all([shapely.transform(
        g, lambda xy: np.column_stack(tr.transform(xy[:, 0], xy[:, 1]))) for g in polys])
    x0, y0, x1, y1 = foot.bounds
    b = w.bounds
    # 50 m of free ground around the footprints (2 m cells: more than 10 cells)
    assert b[0, 0] <= x0 - 50.0 + 1e-6 and b[0, 1] >= x1 + 50.0 - 2.0
    assert b[1, 0] <= y0 - 50.0 + 1e-6 and b[1, 1] >= y1 + 50.0 - 2.0
    assert w.contains([x0 - 13.0, 0.5 * (y0 + y1), 30.0])
    assert w.origin[2] == 0.0 and not w.georef.amsl
    assert not w.georef.as_dict()["amsl"]
    # on coarse cells the margin is at least 10 cells
    coarse = load_world(_spec(buildings=str(f), default_height=12.0, cell_size=10.0), agl=60.0)
    assert coarse.bounds[0, 0] <= x0 - 100.0 + 1e-6
    # a given ground elevation is the grid's floor: z is an altitude above sea level
    e = load_world(_spec(buildings=str(f), default_height=12.0, ground_elevation=408.0),
                   agl=30.0)
    assert e.origin[2] == 408.0 and e.georef.amsl and "408" in e.georef.vertical
    assert e.ground_height(x0 - 13.0, y0) == 408.0
    assert e.surface_height(*foot.representative_point().coords[0]) >= 408.0 + 12.0 - 1e-9
    assert e.bounds[2, 1] >= 408.0 + 35.0 + 30.0
    assert load_world(_spec(buildings=str(f), default_height=12.0, margin=0.0),
                      agl=30.0).bounds[0, 0] >= x0 - 2.0
    with pytest.raises(InputError, match=r"ground_elevation.*--ground-elevation.*DEM"):
        load_world(_spec(buildings=str(f), default_height=12.0, ground_elevation=400.0,
                         dem=str(gd.dem_4326(tmp_path / "d.tif"))), agl=30.0)
    with pytest.raises(InputError, match=r"world.margin \(--margin\).*DEM"):
        load_world(_spec(buildings=str(f), default_height=12.0, margin=10.0,
                         dem=str(gd.dem_4326(tmp_path / "d.tif"))), agl=30.0)
    with pytest.raises(ValidationError):
        _spec(buildings=str(f), ground_elevation=20000.0)


def test_sea_level_from_the_spec(tmp_path):
    f = gd.topo_bathy(tmp_path / "coast.tif")
    with warnings.catch_warnings():
        warnings.simplefilter("error", GeodataWarning)
        w = load_world(_spec(dem=str(f), bbox=BBOX, cell_size=250.0, sea_level=0.0), agl=100.0)
    assert w.terrain.min() == 0.0


def test_automatic_cells_keep_the_grid_small(dem):
    from fm2uav.world.load import AUTO_NODES

    w = load_world(_spec(dem=str(dem["full"])), agl=120.0)  # whole DEM, no cell size given
    assert np.prod(w.shape) <= AUTO_NODES
    assert "million nodes" in w.georef.sources[0].details["cell_size_rule"]
    assert w.spacing[2] <= 20.0
