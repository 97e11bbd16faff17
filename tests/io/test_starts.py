"""read_starts: CSV lon/lat rows and point files in any CRS to world metres."""

from __future__ import annotations

import json

import numpy as np
import pytest

from fm2uav import scenarios
from fm2uav.errors import InputError
from fm2uav.io.starts import read_starts
from fm2uav.world.geo import to_lonlat


@pytest.fixture(scope="module")
def city():
    return scenarios.get_scenario("city2d").world


def test_csv_rows_ids_and_bad_rows(tmp_path, city):
    pts = np.array([[20.0, 30.0], [150.0, 100.0], [390.0, 290.0]])
    ll = to_lonlat(city, pts)
    f = tmp_path / "s.csv"
    f.write_text("name,LAT,lon,ID\n" + "".join(
        f"x,{la:.9f},{lo:.9f},{i}\n" for i, (lo, la) in zip(["a", "", "c"], ll[:, :2]))
        + "x,abc,1.0,d\nx,95,1.0,e\n\n")
    s = read_starts(f, city)
    assert s.ids == ("a", "2", "c", "d", "e")  # the row number where the id is empty
    np.testing.assert_allclose(s.points[:3], pts, atol=1e-3)
    assert set(s.problems) == {3, 4}
    assert "not finite numbers" in s.problems[3] and "data row 4" in s.problems[3]
    assert "lat in [-90, 90]" in s.problems[4]
    assert np.isnan(s.points[3]).all()


def test_csv_refusals(tmp_path, city):
    cases = {"empty.csv": "", "nohead.csv": "x,y\n1,2\n", "dup.csv": "lon,lat,id\n1,2,a\n1,2,a\n",
             "rows.csv": "lon,lat\n"}
    for name, text in cases.items():
        (tmp_path / name).write_text(text)
        with pytest.raises(InputError, match="--starts"):
            read_starts(tmp_path / name, city)
    with pytest.raises(InputError, match="no such file"):
        read_starts(tmp_path / "missing.csv", city)


def test_geojson_points_ids_from_a_property_and_heights(tmp_path):
    sc = scenarios.open_field()
    pts = np.array([[300.0, 400.0], [900.0, 1000.0]])
    ll = to_lonlat(sc.world, np.column_stack([pts, [0.0, 0.0]]))
    doc = {"type": "FeatureCollection", "features": [
        {"type": "Feature", "properties": {"ref": "P1", "agl": 80},
         "geometry": {"type": "Point", "coordinates": [ll[0, 0], ll[0, 1]]}},
        {"type": "Feature", "properties": {"ref": "P2"},
         "geometry": {"type": "Point", "coordinates": [ll[1, 0], ll[1, 1]]}},
        {"type": "Feature", "properties": {}, "geometry": {"type": "LineString",
                                                            "coordinates": [[0, 0], [1, 1]]}}]}
    f = tmp_path / "p.geojson"
    f.write_text(json.dumps(doc))
    # a world without a CRS reads a GeoJSON in the map's metres: write metres then
    doc_m = json.loads(json.dumps(doc))
    for feat, p in zip(doc_m["features"], pts):
        feat["geometry"]["coordinates"] = p.tolist()
    f.write_text(json.dumps(doc_m))
    s = read_starts(f, sc.world, agl=150.0, id_field="ref")
    assert s.ids == ("P1", "P2")
    ground = sc.world.ground_height(pts[:, 0], pts[:, 1])
    np.testing.assert_allclose(s.points, np.column_stack([pts, ground + [80.0, 150.0]]))
    with pytest.raises(InputError, match="--agl"):
        read_starts(f, sc.world)  # P2 has no height
    with pytest.raises(InputError, match="--id-field"):
        read_starts(f, sc.world, agl=100.0, id_field="nope")
