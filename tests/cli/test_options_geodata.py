"""Real data on every planning command (issue 12 part 4): --dem/--buildings/--bbox/--sea-level,
lon/lat points, the mission file's world section, one-line errors naming the flag."""

from __future__ import annotations

import hashlib
import json
import re

import numpy as np
import pytest
import shapely
from pyproj import Transformer
from shapely.geometry import Polygon
from typer.testing import CliRunner

from fm2uav.cli import app
from fm2uav.io import read_path_csv

from tests.world import geodata_data as gd

runner = CliRunner()
BBOX = "10.05,45.54,10.20,45.66"
PTS = ["--lonlat", "--start", f"{gd.START[0]},{gd.START[1]}", "--goal",
       f"{gd.GOAL[0]},{gd.GOAL[1]}"]
FAST = ["--cell-size", "200"]


@pytest.fixture(scope="module")
def data(tmp_path_factory):
    d = tmp_path_factory.mktemp("cli")
    return {"4326": gd.dem_4326(d / "country_4326.tif"), "3857": gd.dem_3857(d / "merc.tif"),
            "coast": gd.topo_bathy(d / "coast.tif"), "dir": d}


@pytest.fixture(scope="module")
def plan_4326(data):
    """The output folder of ``fm2uav plan`` on the lon/lat DEM (BBOX, lon/lat points, 120 m
    AGL, 200 m cells), run once for the module: the tests that want this plan read it."""
    out, _ = _ok(["plan", "--dem", str(data["4326"]), "--bbox", BBOX, *PTS, "--agl", "120",
                  *FAST], data["dir"], "plan_4326")
    return out


def _ok(args, tmp_path, name):
    out = tmp_path / name
    res = runner.invoke(app, [*args, "--out", str(out)])
    assert res.exit_code == 0, res.output
    return out, res


def _error(args, tmp_path):
    res = runner.invoke(app, [*args, "--out", str(tmp_path / "never")])
    assert res.exit_code == 2, res.output
    lines = [ln for ln in res.output.splitlines() if ln.strip()]
    assert len(lines) == 1 and lines[0].startswith("error:"), res.output
    assert not (tmp_path / "never").exists()
    return lines[0]


def test_plan_on_a_lonlat_dem_records_where_it_is(data, plan_4326, tmp_path):
    msg = _error(["plan", "--dem", str(data["4326"]), *PTS, "--agl", "120"], tmp_path)
    assert "--bbox W,S,E,N" in msg and "--nodata fill" in msg  # nodata outside the border
    out = plan_4326
    s = json.loads((out / "summary.json").read_text())
    g = s["world"]["georef"]
    assert g["epsg"] == 32632 and g["crs"] == "EPSG:32632" and g["vertical_assumed"]
    assert "mean sea level" in g["vertical"]
    sha = hashlib.sha256(data["4326"].read_bytes()).hexdigest()
    assert g["sources"][0]["sha256"] == sha and g["sources"][0]["role"] == "dem"
    first = (out / "path.csv").read_text().splitlines()[0]
    assert first.startswith("# crs=EPSG:32632; z=DEM heights") and sha[:12] in first
    path = read_path_csv(out / "path.csv")  # the comment is skipped
    assert path.shape[1] == 3 and len(path) > 10


def test_web_mercator_and_lonlat_dems_plan_the_same_length(data, plan_4326, tmp_path):
    lengths = {"4326": json.loads((plan_4326 / "summary.json").read_text())["length_m"]}
    out, _ = _ok(["plan", "--dem", str(data["3857"]), "--bbox", BBOX, *PTS, "--agl", "120",
                  *FAST], tmp_path, "3857")
    lengths["3857"] = json.loads((out / "summary.json").read_text())["length_m"]
    assert lengths["3857"] == pytest.approx(lengths["4326"], rel=0.01), lengths


def test_sea_level_keeps_the_path_over_the_water(data, tmp_path):
    args = ["plan", "--dem", str(data["coast"]), "--bbox", BBOX, *PTS, "--agl", "100", *FAST]
    out, res = _ok(args, tmp_path, "raw")
    assert "warning:" in res.output and "--sea-level 0" in res.output
    out, res = _ok([*args, "--sea-level", "0"], tmp_path, "sea")
    assert "warning:" not in res.output
    path = read_path_csv(out / "path.csv")
    assert path[:, 2].min() >= 0.0
    s = json.loads((out / "summary.json").read_text())
    assert "sea_level = 0 m" in s["world"]["georef"]["vertical"]


def _osm(tmp_path, n=9):
    """OSM-like buildings in lon/lat, 2 of 3 without any height."""
    to_ll = Transformer.from_crs("EPSG:32632", "EPSG:4326", always_xy=True)
    c = Transformer.from_crs("EPSG:4326", "EPSG:32632", always_xy=True).transform(10.12, 45.60)
    feats, polys = [], []
    for k in range(n):
        x0, y0 = c[0] - 300 + 200 * (k % 3), c[1] - 300 + 200 * (k // 3)
        sq = Polygon([(x0, y0), (x0 + 70, y0), (x0 + 70, y0 + 50), (x0, y0 + 50)])
        ll = shapely.transform(sq, lambda xy: np.column_stack(to_ll.transform(xy[:, 0],
                                                                               xy[:, 1])))
        props = {"@id": f"way/{k}", "building": "yes"}
        if k % 3 == 0:
            props["height"] = "45 m"
        feats.append({"type": "Feature", "properties": props,
                      "geometry": shapely.geometry.mapping(ll)})
        polys.append((sq, 45.0 if k % 3 == 0 else 15.0))
    f = tmp_path / "osm.geojson"
    f.write_text(json.dumps({"type": "FeatureCollection", "features": feats}))
    return f, polys


def test_osm_buildings_in_lonlat_with_most_heights_missing(data, tmp_path):
    f, polys = _osm(tmp_path)
    start = ["--lonlat", "--start", "10.112,45.593,10", "--goal", "10.128,45.607,10",
             "--bbox", "10.11,45.59,10.13,45.61"]
    msg = _error(["plan", "--buildings", str(f), *start, "--cell-size", "10"], tmp_path)
    assert "6 of 9 buildings" in msg and "--default-height" in msg
    out, res = _ok(["plan", "--buildings", str(f), "--default-height", "15", *start,
                    "--cell-size", "10"], tmp_path, "b")
    s = json.loads((out / "summary.json").read_text())
    b = s["world"]["buildings"]
    assert b["count"] == 9 and b["height_rule"] == {"height": 3, "building:levels": 0,
                                                    "default_height": 6}
    text = re.sub(r"[│┃\s]+", " ", res.output)  # the table wraps long cells
    assert "3 from height" in text and "6 from --default-height" in text
    path = read_path_csv(out / "path.csv")
    for sq, h in polys:  # never inside a footprint below its roof
        inside = shapely.contains_xy(sq, path[:, 0], path[:, 1])
        assert np.all(path[inside, 2] > h), (h, path[inside, 2].min())


@pytest.mark.slow
def test_buildings_on_the_dem(data, tmp_path):
    f, polys = _osm(tmp_path)
    out, _ = _ok(["plan", "--dem", str(data["4326"]), "--bbox", BBOX, "--buildings", str(f),
                  "--default-height", "15", "--lonlat", "--start", "10.112,45.593,40", "--goal",
                  "10.128,45.607,40", "--cell-size", "20", "--agl", "40"], tmp_path, "db")
    s = json.loads((out / "summary.json").read_text())
    assert [x["role"] for x in s["world"]["georef"]["sources"]] == ["dem", "buildings"]
    path = read_path_csv(out / "path.csv")
    for sq, h in polys:
        inside = shapely.contains_xy(sq, path[:, 0], path[:, 1])
        if inside.any():
            x0, y0, x1, y1 = sq.bounds
            ground = gd.terrain(*Transformer.from_crs("EPSG:32632", "EPSG:4326", always_xy=True)
                                .transform([x0, x1, x0, x1], [y0, y0, y1, y1]))
            assert np.all(path[inside, 2] > ground.max() + h)


def test_mission_file_world_section_and_run_overrides(data, tmp_path):
    m = tmp_path / "m.yaml"
    m.write_text(
        f"name: transit\nworld: {{dem: {data['4326'].name}, bbox: [{BBOX}], cell_size: 200}}\n"
        f"start: {{lon: {gd.START[0]}, lat: {gd.START[1]}, agl: 120}}\n"
        f"goal: {{lon: {gd.GOAL[0]}, lat: {gd.GOAL[1]}, agl: 120}}\n"
        "planner: {agl: 120}\noutputs: {formats: [csv, json]}\n")
    (tmp_path / data["4326"].name).write_bytes(data["4326"].read_bytes())
    out, _ = _ok(["run", str(m)], tmp_path, "r1")
    s1 = json.loads((out / "summary.json").read_text())
    assert s1["world"]["georef"]["epsg"] == 32632
    # the same mission on the Web Mercator DEM, given on the command line
    out, _ = _ok(["run", str(m), "--dem", str(data["3857"])], tmp_path, "r2")
    s2 = json.loads((out / "summary.json").read_text())
    assert "EPSG:3857 distorts" in s2["world"]["georef"]["reprojection"]
    assert s2["length_m"] == pytest.approx(s1["length_m"], rel=0.01)
    # the coast with sea_level from the command line, lon/lat points overridden
    out, _ = _ok(["run", str(m), "--dem", str(data["coast"]), "--sea-level", "0", "--lonlat",
                  "--start", f"{gd.START[0]},{gd.START[1]},80"], tmp_path, "r3")
    assert read_path_csv(out / "path.csv")[:, 2].min() >= 0.0


@pytest.mark.slow
def test_tune_formation_cover_and_check_take_the_world_options(data, plan_4326, tmp_path):
    dem = ["--dem", str(data["4326"]), "--bbox", BBOX]
    out, res = _ok(["tune", *dem, *PTS, "--agl", "120", *FAST, "--p1", "0.5", "--p2", "1.3"],
                   tmp_path, "tune")
    assert json.loads((out / "tune.json").read_text())["world"]["georef"]["epsg"] == 32632
    # a formation on a 3 x 4 km corner of the DEM (64 x 79 cells of 50 m: what is checked is
    # that the world options reach it, in lon/lat, and that it completes there)
    small = ["--dem", str(data["4326"]), "--bbox", "10.05,45.54,10.09,45.575"]
    out, _ = _ok(["formation", *small, "--lonlat", "--start", "10.06,45.55", "--goal",
                  "10.08,45.565", "--agl", "150", "--cell-size", "50", "--no-gif"],
                 tmp_path, "formation")
    s = json.loads((out / "summary.json").read_text())
    assert s["world"]["crs"] == "EPSG:32632" and s["completed"]
    assert s["world"]["shape"][:2] == [64, 79]  # the bbox given, not the whole DEM
    # check the planned path against the same world
    out, _ = _ok(["check", str(plan_4326 / "path.csv"), "--airframe", "disco", *dem, *FAST],
                 tmp_path, "check")
    rep = json.loads((out / "report.json").read_text())
    assert rep["world"]["georef"]["epsg"] == 32632
    assert (out / "flown.csv").read_text().startswith("# crs=EPSG:32632")
    # a KML survey area in lon/lat on the DEM
    import pyogrio

    ring = Polygon([(10.08, 45.57), (10.14, 45.565), (10.16, 45.61), (10.10, 45.625)])
    kml = tmp_path / "field.kml"
    pyogrio.raw.write(str(kml), np.array(shapely.to_wkb([ring]), dtype=object), field_data=[],
                      fields=[], geometry_type="Polygon", crs="EPSG:4326", driver="LIBKML")
    out, _ = _ok(["cover", *dem, "--area", str(kml), "--spacing", "400", "--agl", "100",
                  "--cell-size", "100"], tmp_path, "cover")
    s = json.loads((out / "summary.json").read_text())
    assert s["area_source"]["crs_rule"] == "declared by the file" and s["world"]["crs"]


@pytest.mark.parametrize("args, part", [
    (["plan", "--bbox", "10,45,11"], "--bbox must be 4 numbers"),
    (["plan", "--sea-level", "0"], "--sea-level needs real data: give --dem FILE"),
    (["plan", "--dem", "DEM", "--bbox", "10.2,45.5,10.1,45.6"], "--bbox"),
    (["plan", "--dem", "DEM", "--scenario", "open-field"], "either --scenario or --dem"),
    (["plan", "--dem", "DEM", "--bbox", BBOX, "--lonlat", "--start", "10.06,45.55",
      "--goal", "10.19,45.65"], "add ,AGL (metres above the ground) or give --agl"),
    (["plan", "--dem", "DEM", "--bbox", BBOX, "--lonlat", "--start", "45.55,10.06,100",
      "--goal", "10.19,45.65,100"], "lies outside the map"),
    (["plan", "--dem", "DEM", "--bbox", BBOX, "--ceiling", "900", "--agl", "120"],
     "--ceiling"),
    (["plan", "--dem", "NOWHERE.tif"], "--dem"),
    (["cover", "--dem", "DEM", "--bbox", BBOX, "--area", "S1", "--spacing", "80"],
     "built-in area"),
])
def test_bad_world_options_give_one_line_naming_the_flag(data, tmp_path, args, part):
    args = [str(data["4326"]) if a == "DEM" else a for a in args]
    msg = _error(args, tmp_path)
    assert part in msg, msg
