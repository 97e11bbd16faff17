"""fm2uav.viz.mapdata: a planned mission as one lon/lat GeoJSON document for the map."""

from __future__ import annotations

import numpy as np
import pytest
import shapely

from fm2uav.io import ExportOptions, export_mission
from fm2uav.io.mission import load_mission
from fm2uav.io.geojson import geojson_document
from fm2uav.missions.route import plan_route
from fm2uav.viz.mapdata import mission_map
from tests.app.dem import make_dem, mission_yaml


@pytest.fixture(scope="module")
def planned(tmp_path_factory):
    root = tmp_path_factory.mktemp("mapdata")
    mf = mission_yaml(root / "m.yaml", make_dem(root / "dem.tif"),
                      via="[{lon: 10.3275, lat: 46.038, agl: 60}]",
                      no_fly_zones="[{circle: {center: [10.3275, 46.025], radius: 300}, "
                                   "lonlat: true, name: mast, buffer: 20}]")
    m = load_mission(mf)
    rm = m.resolve()
    shaping, level, opts = m.plan_objects()
    route = plan_route(rm.world, rm.start, rm.goal, via=rm.via, shaping=shaping, level=level,
                       options=opts)
    from fm2uav.autopilot.geofence import zone_fences

    fences, _ = zone_fences(rm.world.zones, rm.world, None)
    built, _ = export_mission(route.plan, [], ExportOptions(name="t"), via=route.junctions[1:-1],
                              fences=fences)
    return rm, route, built


def test_route_in_lonlat_with_height_above_ground_and_distance(planned):
    rm, route, built = planned
    doc = mission_map(route.plan, built, points={"start": rm.start, "via 1": rm.via[0],
                                                 "goal": rm.goal},
                      junctions=route.junctions)
    r = next(f for f in doc["features"] if f["properties"]["kind"] == "route")
    coords = np.array(r["geometry"]["coordinates"])
    ref = np.array(geojson_document(route.plan.path, rm.world)["features"][0]["geometry"]
                   ["coordinates"])
    assert coords[:, :2] == pytest.approx(ref[:, :2], abs=1e-7)      # the exports' lon/lat
    path = route.plan.path
    ground = rm.world.ground_height(path[:, 0], path[:, 1])
    assert r["properties"]["agl"] == pytest.approx(path[:, 2] - ground, abs=0.06)
    d = np.array(r["properties"]["distance"])
    assert d[0] == 0 and d[-1] == pytest.approx(
        np.sum(np.linalg.norm(np.diff(path[:, :2], axis=0), axis=1)), abs=0.1)
    assert r["properties"]["requested_agl"] == 60.0
    assert r["properties"]["junctions"] == [int(v) for v in route.junctions]
    w, s, e, n = doc["bbox"]
    assert w == pytest.approx(coords[:, 0].min()) and n == pytest.approx(coords[:, 1].max())
    kinds = [f["properties"]["kind"] for f in doc["features"]]
    assert kinds.count("start") == kinds.count("goal") == kinds.count("via") == 1


def test_items_zones_fences_and_summary(planned):
    rm, route, built = planned
    doc = mission_map(route.plan, built, {"height_above_ground": {"path": {"min_m": 55.0,
                                                                          "max_m": 61.0}},
                                          "zones": {"distance_m": {"mast": 42.5},
                                                    "path_entries": []}},
                      rows={"length [m]": "1.0"})
    items = [f for f in doc["features"] if f["properties"]["kind"] == "item"]
    positioned = [k + 1 for k, it in enumerate(built.items) if it.agl is not None]
    assert [f["properties"]["seq"] for f in items] == positioned
    assert items[0]["properties"]["command"] == built.items[0].name
    zone = next(f for f in doc["features"] if f["properties"]["kind"] == "zone")
    p = zone["properties"]
    assert (p["name"], p["ceiling"], p["buffer"], p["radius"]) == ("mast", None, 20.0, 300.0)
    assert p["center"] == pytest.approx([10.3275, 46.025], abs=1e-6)
    poly = shapely.geometry.shape(zone["geometry"])
    assert poly.contains(shapely.Point(10.3275, 46.025))
    fences = [f for f in doc["features"] if f["properties"]["kind"] == "fence"]
    assert len(fences) == 1 and fences[0]["properties"]["inclusion"] is False
    s = doc["summary"]
    assert (s["min_agl_m"], s["max_agl_m"], s["nearest_zone_m"]) == (55.0, 61.0, 42.5)
    assert s["items"] == len(built.items) and s["flight_time_s"] > 0
    assert s["length_m"] == pytest.approx(route.plan.length, abs=0.1)
    assert doc["rows"] == {"length [m]": "1.0"}
