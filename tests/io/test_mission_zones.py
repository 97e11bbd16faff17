"""Mission-file no_fly_zones / operating_area: files (lon/lat GeoJSON, KML) and inline zones."""

from __future__ import annotations

import json

import numpy as np
import pytest

from fm2uav.errors import InputError, PlanningError
from fm2uav.io.mission import parse_mission

WEST, NORTH = -3.80, 40.36
EAST, SOUTH = WEST + 200 / 1200, NORTH - 160 / 1200


def _square(lon, lat, d):
    return [[lon - d, lat - d], [lon + d, lat - d], [lon + d, lat + d], [lon - d, lat + d],
            [lon - d, lat - d]]


def _mission(rough_tif, **extra):
    return {"world": {"dem": str(rough_tif), "cell_size": 250},
            "start": {"lon": WEST + 0.02, "lat": SOUTH + 0.02, "agl": 40},
            "goal": {"lon": EAST - 0.02, "lat": NORTH - 0.02, "agl": 40},
            "planner": {"agl": 120}, **extra}


def test_zone_files_and_inline_zones_become_obstacles(tmp_path, rough_tif):
    mid_lon, mid_lat = (WEST + EAST) / 2, (SOUTH + NORTH) / 2
    gj = tmp_path / "zones.geojson"
    gj.write_text(json.dumps({"type": "FeatureCollection", "features": [
        {"type": "Feature", "properties": {"name": "square", "buffer": 40},
         "geometry": {"type": "Polygon", "coordinates": [_square(mid_lon, mid_lat, 0.01)]}},
        {"type": "Feature", "properties": {"name": "disc", "radius": 300, "ceiling": 100,
                                           "reference": "agl"},
         "geometry": {"type": "Point", "coordinates": [mid_lon + 0.04, mid_lat]}}]}))
    kml = tmp_path / "zone.kml"
    ring = " ".join(f"{lo},{la},0" for lo, la in _square(mid_lon - 0.04, mid_lat, 0.005))
    kml.write_text(f"""<?xml version="1.0" encoding="UTF-8"?>
<kml xmlns="http://www.opengis.net/kml/2.2"><Document><Placemark><name>k</name>
<Polygon><outerBoundaryIs><LinearRing><coordinates>{ring}</coordinates></LinearRing>
</outerBoundaryIs></Polygon></Placemark></Document></kml>""")
    data = _mission(rough_tif, no_fly_zones=[
        "zones.geojson", {"file": "zone.kml", "buffer": 25},
        {"circle": {"center": [mid_lon, mid_lat + 0.04], "radius": 200}, "lonlat": True,
         "name": "inline"}],
        operating_area={"polygon": _square(mid_lon, mid_lat, 0.075)[:-1], "lonlat": True,
                        "buffer": 100})
    rm = parse_mission(data, base_dir=tmp_path).resolve()
    names = [z.name for z in rm.world.zones]
    assert names[:2] == ["square", "disc"] and "inline" in names
    assert rm.world.zones[-1].inclusion
    kz = [z for z in rm.world.zones if z.source.endswith("zone.kml")][0]
    assert kz.buffer == 25
    sq = rm.world.zones[0]
    # ~0.02 deg lon x 0.02 deg lat at 40.3 N: 1.70 km x 2.22 km
    minx, miny, maxx, maxy = sq.geometry.bounds
    assert 1600 < maxx - minx < 1800 and 2150 < maxy - miny < 2300
    c = np.array(sq.geometry.centroid.coords[0])
    i, j = rm.world.to_cell([*c, rm.world.bounds[2, 1]])[:2]
    assert rm.world.occupancy[i, j].all()
    disc = rm.world.zones[1]
    assert disc.circle is not None and disc.circle[1] == 300 and disc.ceiling == 100


def test_a_start_in_a_zone_is_refused(rough_tif):
    lon, lat = WEST + 0.02, SOUTH + 0.02
    data = _mission(rough_tif, no_fly_zones=[
        {"polygon": _square(lon, lat, 0.003)[:-1], "lonlat": True, "name": "home"}])
    with pytest.raises(PlanningError, match="home"):
        parse_mission(data).resolve()


def test_bad_zone_entries_name_the_key(rough_tif):
    with pytest.raises(InputError, match=r"no_fly_zones\[0\]"):
        parse_mission(_mission(rough_tif, no_fly_zones=[{"polygon": [[0, 0], [1, 1]]}]))
    with pytest.raises(InputError, match=r"no_fly_zones\[0\].*exactly one"):
        parse_mission(_mission(rough_tif, no_fly_zones=[
            {"polygon": [[0, 0], [1, 0], [1, 1]], "circle": {"center": [0, 0], "radius": 1}}]))
    with pytest.raises(InputError, match="operating_area"):
        parse_mission(_mission(rough_tif, operating_area={"file": "missing.geojson"}))
