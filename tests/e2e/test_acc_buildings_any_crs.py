"""Acceptance (issue 25): buildings read from any CRS, without a DEM.

The same blocks as a Swiss-grid (EPSG:2056) Shapefile and as lon/lat GeoJSON: the summary's
clearance equals the distance from the written path to the buildings read back from the
file with pyogrio in its own CRS and measured with shapely, on a path that flies 12 m
above the ground between the blocks (nearer the walls than the ground, so the walls are
measured; the grid's columns, dilated by up to a cell, read less); the ground's altitude
is the given
``world.ground_elevation`` (the PX4 mission in AMSL on it), or — without it — the mission
is relative to home and says so (it was written at 30–45 m "AMSL" on an implicit 0 m).
"""

from __future__ import annotations

import json
import re

import numpy as np
import pyogrio
import pytest
import shapely
from pyproj import Transformer
from typer.testing import CliRunner

from fm2uav.cli import app

E0, N0 = 2683000.0, 1248000.0
GROUND = 408.0


@pytest.fixture(scope="module")
def town(tmp_path_factory):
    d = tmp_path_factory.mktemp("town")
    polys = [shapely.box(E0 + 60 * i, N0 + 60 * j, E0 + 60 * i + 35, N0 + 60 * j + 35)
             for i in range(3) for j in range(3)]
    heights = np.array([20.0 + 5 * k for k in range(9)])
    pyogrio.raw.write(str(d / "town.shp"), np.array(shapely.to_wkb(polys), dtype=object),
                      field_data=[heights], fields=["height"], geometry_type="Polygon",
                      crs="EPSG:2056", driver="ESRI Shapefile")
    tr = Transformer.from_crs("EPSG:2056", "EPSG:4326", always_xy=True)
    ll = [shapely.transform(g, lambda xy: np.column_stack(tr.transform(xy[:, 0], xy[:, 1])))
          for g in polys]
    pyogrio.raw.write(str(d / "town.geojson"), np.array(shapely.to_wkb(ll), dtype=object),
                      field_data=[heights], fields=["height"], geometry_type="Polygon",
                      crs="EPSG:4326", driver="GeoJSON")
    # take-off 13 m west of the outermost building (no world.margin given), landing beyond
    # the far corner; 12 m up: the path threads between the blocks
    s = tr.transform(E0 - 13.0, N0 + 47.5)
    g = tr.transform(E0 + 120 + 35 + 13.0, N0 + 120 + 47.5 - 60)
    return d, s, g


def _run(town, source, *, ground=True, agl=12.0, level=True):
    d, s, g = town
    name = f"{source.replace('.', '-')}-{'g' if ground else 'nog'}-{agl:g}{'-l' if level else ''}"
    (d / f"{name}.yaml").write_text(f"""
world: {{buildings: {source}{f', ground_elevation: {GROUND}' if ground else ''}}}
start: {{lon: {s[0]}, lat: {s[1]}, agl: {agl}}}
goal: {{lon: {g[0]}, lat: {g[1]}, agl: {agl}}}
{f'planner: {{agl: {agl}}}' if level else ''}
airframe: {{firmware: px4}}
outputs: {{formats: [geojson, kml, plan, json]{', frame: amsl' if ground else ''}}}
""")
    out = d / name
    res = CliRunner().invoke(app, ["run", str(d / f"{name}.yaml"), "--out", str(out),
                                   "--quiet"])
    assert res.exit_code == 0, res.output
    return out, json.loads((out / "summary.json").read_text())


def _path(out):
    gj = json.loads((out / "path.geojson").read_text())
    return np.array(next(f for f in gj["features"] if f["properties"].get("name") == "path")
                    ["geometry"]["coordinates"])


def _clearance_from_the_file(path_ll, building_file, base):
    """Distance [m] from the path points (lon, lat, alt) to the buildings as prisms on flat
    ground at ``base`` and to that ground, in the buildings file's own CRS."""
    meta, _, wkb, fields = pyogrio.raw.read(str(building_file))
    polys = shapely.from_wkb(wkb)
    h = np.asarray(fields[list(meta["fields"]).index("height")], dtype=float)
    crs = meta["crs"]
    if Transformer.from_crs(crs, "EPSG:4326").source_crs.is_geographic:
        crs = "EPSG:2056"  # measure lon/lat footprints in metres (Swiss grid)
        tr = Transformer.from_crs("EPSG:4326", crs, always_xy=True)
        polys = [shapely.transform(p, lambda xy: np.column_stack(tr.transform(xy[:, 0],
                                                                             xy[:, 1])))
                 for p in polys]
    x, y = Transformer.from_crs("EPSG:4326", crs, always_xy=True).transform(path_ll[:, 0],
                                                                            path_ll[:, 1])
    pts = shapely.points(np.asarray(x), np.asarray(y))
    z = path_ll[:, 2]
    best = z - base
    for p, hh in zip(polys, h):
        best = np.minimum(best, np.hypot(shapely.distance(pts, p),
                                         np.maximum(z - (base + hh), 0.0)))
    return best


@pytest.mark.slow
@pytest.mark.parametrize("source", ["town.shp", "town.geojson"])
def test_clearance_and_altitudes_equal_the_files(town, source):
    out, s = _run(town, source)
    path = _path(out)
    clr = _clearance_from_the_file(path, town[0] / source, GROUND)
    assert s["safety"]["clearance_m"] == pytest.approx(clr.min(), abs=0.05)
    # the path passes between the buildings, nearer their walls than the ground 12 m below
    assert 3.0 < clr.min() < 11.0, clr.min()
    # the grid's columns (FM²'s conservative view) would read less: footprints grown by up
    # to a 2 m cell (docs/safety.md quotes these figures)
    from fm2uav.world.clearance import surface_clearance
    from fm2uav.world.load import WorldSpec, load_world

    w = load_world(WorldSpec(buildings=str(town[0] / source), ground_elevation=GROUND), agl=12.0)
    x, y = Transformer.from_crs("EPSG:4326", w.crs, always_xy=True).transform(path[:, 0],
                                                                              path[:, 1])
    pts = np.column_stack([x, y, path[:, 2]])
    assert surface_clearance(w, pts).min() == pytest.approx(s["safety"]["clearance_m"], abs=0.01)
    grid = surface_clearance(w.with_fields(buildings=None), pts).min()
    assert 0.3 < clr.min() - grid < 2.0
    # PX4 on the given ground (frame amsl asked): AMSL
    # altitudes on 408 m, home on the ground
    plan = json.loads((out / "mission.plan").read_text())
    wps = [it for it in plan["mission"]["items"] if it["command"] == 16]
    assert {it["frame"] for it in wps} == {0}
    assert plan["mission"]["plannedHomePosition"][2] == pytest.approx(GROUND)
    assert s["autopilot"]["home"]["alt_amsl_m"] == pytest.approx(GROUND)
    alts = np.array([it["params"][6] for it in wps])
    assert alts.min() > GROUND + 5.0
    # the lowest height above the ground along the path is the summary's
    assert s["safety"]["height_above_ground"]["path"]["min_m"] == pytest.approx(
        (path[:, 2] - GROUND).min(), abs=0.01)


@pytest.mark.slow
def test_without_a_ground_elevation_the_mission_is_relative_and_says_so(town):
    out, s = _run(town, "town.geojson", ground=False)
    plan = json.loads((out / "mission.plan").read_text())
    wps = [it for it in plan["mission"]["items"] if it["command"] == 16]
    assert {it["frame"] for it in wps} == {3}  # above home, never AMSL on an implicit 0 m
    assert s["autopilot"]["home"]["alt_amsl_m"] is None
    assert s["autopilot"]["frame"]["name"] == "relative"
    assert any("ground elevation" in w and "--ground-elevation" in w
               for w in s["autopilot"]["warnings"])
    assert plan["fm2uav"]["home"]["alt_amsl_m"] is None
    assert "unknown" in s["world"]["georef"]["vertical"]
    # Google Earth gets heights above its ground, not absolute altitudes
    kml = (out / "path.kml").read_text()
    assert "relativeToGround" in kml and "<altitudeMode>absolute" not in kml
    coords = re.search(r"<name>path</name>.*?<coordinates>(.*?)</coordinates>", kml, re.S)
    z = np.array([float(c.split(",")[2]) for c in coords.group(1).split()])
    path = _path(out)
    assert np.allclose(z, path[:, 2], atol=2e-3)  # both heights above the flat ground
    rel = np.array([it["params"][6] for it in wps])
    assert rel.min() > 5.0  # above home, which is on the ground
    # asking for AMSL altitudes without a datum is refused, naming the fix
    d = town[0]
    (d / "amsl.yaml").write_text((d / "town-geojson-nog-12-l.yaml").read_text().replace(
        "formats: [geojson, kml, plan, json]", "formats: [plan], frame: amsl"))
    res = CliRunner().invoke(app, ["run", str(d / "amsl.yaml"), "--out", str(d / "amsl")])
    assert res.exit_code == 2 and "--ground-elevation" in res.output


@pytest.mark.slow
def test_a_plan_above_120_m_without_a_ceiling_is_warned(town):
    out, s = _run(town, "town.shp", agl=125.0, level=False)  # no flight level, no ceiling
    w = s["safety"]["warnings"]
    assert w and "120 m" in w[0] and "--max-agl" in w[0]
