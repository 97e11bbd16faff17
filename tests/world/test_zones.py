"""No-fly zones on the world and the continuous surface clearance."""

from __future__ import annotations

import numpy as np
import pytest
import shapely
from scipy.spatial import cKDTree

from fm2uav.errors import InputError, PlanningError
from fm2uav.scenarios import get_scenario
from fm2uav.world import World
from fm2uav.world.clearance import surface_clearance
from fm2uav.world.zones import (
    Zone, check_points_allowed, read_zones, with_zones, zone_bounds_along, zone_from_mapping,
    zone_violations,
)


@pytest.fixture(scope="module")
def field():
    return get_scenario("open-field").world


def test_zone_nodes_cover_the_buffered_polygon_and_nothing_far(field):
    z = zone_from_mapping({"polygon": [[700, 300], [900, 300], [900, 1000], [700, 1000]],
                           "buffer": 30, "name": "wall"})
    w = with_zones(field, [z])
    added = w.occupancy & ~field.occupancy
    nodes = np.argwhere(added.any(axis=2))
    xy = w.to_world(np.column_stack([nodes, np.zeros(len(nodes))]))[:, :2]
    # every blocked column is within buffer + half a cell diagonal of the polygon
    assert xy[:, 0].min() >= 700 - 30 - 10.7 and xy[:, 0].max() <= 900 + 30 + 10.7
    # every node whose cell touches the buffered polygon is blocked (nearest-node rule)
    gx = np.arange(700 - 30, 900 + 30 + 1e-9, 2.5)
    gy = np.arange(300 - 30 + 1, 1000 + 30 - 1 + 1e-9, 2.5)
    X, Y = np.meshgrid(gx, gy, indexing="ij")
    pts = np.column_stack([X.ravel(), Y.ravel()])
    pts = pts[shapely.contains_xy(z.geometry.buffer(30.0), pts[:, 0], pts[:, 1])]
    cells = np.floor(pts / 15.0 + 0.5).astype(int)
    assert w.occupancy[cells[:, 0], cells[:, 1], 30].all()
    # zones are not roofs: the surface did not move
    xs = np.arange(0, 1700, 7.0)
    assert np.array_equal(w.surface_height(xs, 600.0), field.surface_height(xs, 600.0))
    assert w.zones == (z,)


def test_zone_with_a_ceiling_blocks_only_below_it(field):
    z = zone_from_mapping({"circle": {"center": [800, 600], "radius": 150}, "ceiling": 100,
                           "reference": "agl", "buffer": 10, "name": "low"})
    w = with_zones(field, [z])
    i, j = w.to_cell([800.0, 600.0, 0.0])[:2]
    g = float(field.ground_height(800.0, 600.0))
    zs = w.origin[2] + np.arange(w.shape[2]) * w.spacing[2]
    col = w.occupancy[i, j]
    assert col[(zs > g) & (zs <= g + 100)].all()
    assert not col[zs > g + 100 + 10 + 7.5 + 1e-6].any()
    # along a route crossing it at 200 m AGL the bound is "over the ceiling"
    xy = np.column_stack([np.linspace(500, 1100, 61), np.full(61, 600.0)])
    ground = field.ground_height(xy[:, 0], xy[:, 1])
    lo, hi = zone_bounds_along(w, xy, ground + 200.0)
    # samples 10 m apart: a sample whose chord to a neighbour meets the buffered circle is
    # bounded too (the whole chord is flown over it), raised by the ground's bulge
    inside = np.abs(xy[:, 0] - 800) < 150 + 10 + 10 - 1e-9
    assert np.isinf(lo[~inside]).all()
    assert np.all(lo[inside] >= ground[inside] + 110.0)
    assert np.all(lo[inside] <= ground[inside] + 110.0 + 0.5)
    assert np.isinf(hi).all()


def test_violations_use_the_true_geometry(field):
    z = Zone(geometry=zone_from_mapping({"polygon": [[0, 0], [10, 0], [10, 10]]}).geometry,
             name="tri", buffer=5.0)
    w = with_zones(field, [z])
    far = np.array([[0.0, 40.0, 300.0], [60.0, 40.0, 300.0]])
    assert zone_violations(w, far) == []
    near = np.array([[0.0, 13.0, 300.0], [60.0, 13.0, 300.0]])  # 3 m from the vertex (10,10)
    v = zone_violations(w, near)
    assert v and v[0].inside_buffer_only
    with pytest.raises(PlanningError, match="tri"):
        check_points_allowed(w, {"start": [5.0, 2.0, 300.0]})


def test_operating_area_blocks_outside(field):
    area = zone_from_mapping({"polygon": [[100, 100], [1600, 100], [1600, 1200], [100, 1200]],
                              "buffer": 20}, inclusion=True)
    w = with_zones(field, [area])
    assert w.occupancy[0, :, -1].all() and not w.occupancy[60, 45, -1]
    assert zone_violations(w, np.array([[50.0, 500, 400], [800, 500, 400]]))


def test_geojson_zones_with_circle_and_defaults(field):
    doc = {"type": "FeatureCollection", "features": [
        {"type": "Feature", "properties": {"name": "A", "buffer": 12},
         "geometry": {"type": "Polygon", "coordinates": [[[0, 0], [100, 0], [100, 100], [0, 0]]]}},
        {"type": "Feature", "properties": {"radius": 50},
         "geometry": {"type": "Point", "coordinates": [500, 500]}}]}
    zones = read_zones(doc, field, defaults={"ceiling": 80, "reference": "agl"})
    assert [z.name for z in zones][0] == "A" and zones[0].buffer == 12
    assert zones[1].circle == ((500.0, 500.0), 50.0) and zones[1].ceiling == 80
    bad = {"type": "FeatureCollection", "features": [
        {"type": "Feature", "properties": {}, "geometry": {"type": "Point", "coordinates": [300, 200]}}]}
    with pytest.raises(InputError, match="radius"):
        read_zones(bad, field)


def test_surface_clearance_matches_a_brute_force_surface(field):
    rng = np.random.default_rng(0)
    pts = np.column_stack([rng.uniform(100, 1600, 300), rng.uniform(100, 1200, 300),
                           rng.uniform(0, 580, 300)])
    above = pts[:, 2] - field.surface_height(pts[:, 0], pts[:, 1])
    pts = pts[above > 1.0]
    d = surface_clearance(field, pts)
    X, Y = np.meshgrid(np.arange(0, 1786, 2.0), np.arange(0, 1336, 2.0), indexing="ij")
    tree = cKDTree(np.column_stack([X.ravel(), Y.ravel(), field.ground_height(X, Y).ravel()]))
    brute, _ = tree.query(pts)
    # brute force samples the bilinear surface every 2 m: it can only be a little longer
    assert np.all(d <= pts[:, 2] - field.ground_height(pts[:, 0], pts[:, 1]) + 1e-9)
    assert np.all(brute - d > -0.2) and np.all(brute - d < 1.5)


def test_surface_clearance_to_a_building_box():
    occ = np.zeros((21, 21, 11), bool)
    occ[:, :, 0] = True
    occ[8:13, 8:13, :6] = True  # a building up to z = 5 m (nodes 0..5)
    w = World(occ, spacing=1.0)
    d = surface_clearance(w, np.array([[10.0, 10.0, 8.0], [15.0, 10.0, 3.0]]))
    assert d[0] == pytest.approx(3.0)          # above the roof
    assert d[1] == pytest.approx(15.0 - 12.5)  # beside the wall (box edge at 12.5)


# --------------------------------------------------------- points and zones (issue 25)
def test_points_in_a_zone_or_outside_the_area_are_bad_input_saying_which(field):
    from fm2uav.errors import PointError

    nofly = zone_from_mapping({"polygon": [[700, 300], [900, 300], [900, 1000], [700, 1000]],
                               "buffer": 30, "name": "range"})
    area = zone_from_mapping({"polygon": [[0, 0], [900, 0], [900, 900], [0, 900]],
                              "buffer": 50}, inclusion=True)
    w = with_zones(field, [nofly])
    with pytest.raises(PointError, match=r"the goal \[800.0, 500.0, 450.0\] m lies in the "
                       r"no-fly zone 'range' \(inside it\)"):
        check_points_allowed(w, {"goal": [800.0, 500.0, 450.0]})
    with pytest.raises(PointError, match=r"'range' \(in its buffer\)"):
        check_points_allowed(w, {"goal": [680.0, 500.0, 450.0]})
    a = with_zones(field, [area])
    with pytest.raises(PointError, match=r"the goal \[1500.0, 1200.0, 450.0\] m is not inside "
                       r"the operating area .*outside it, 671 m from its edge.*enlarge "
                       r"operating_area"):
        check_points_allowed(a, {"goal": [1500.0, 1200.0, 450.0]})
    with pytest.raises(PointError, match="within its buffer of 50 m from the edge"):
        check_points_allowed(a, {"start": [880.0, 450.0, 450.0]})
    check_points_allowed(a, {"start": [450.0, 450.0, 450.0]})  # well inside: fine


def test_a_zone_file_wholly_off_the_map_is_warned_about(tmp_path):
    import json
    import warnings

    from fm2uav.world.zones import ZoneWarning

    jb = get_scenario("jacksboro").world
    far = [[-80.6, 36.25], [-80.55, 36.25], [-80.55, 36.3], [-80.6, 36.25]]
    p = tmp_path / "far.geojson"
    p.write_text(json.dumps({"type": "FeatureCollection", "features": [
        {"type": "Feature", "properties": {}, "geometry": {"type": "Polygon",
                                                           "coordinates": [far]}}]}))
    with warnings.catch_warnings(record=True) as rec:
        warnings.simplefilter("always")
        zs = read_zones(str(p), jb)
    msgs = [str(r.message) for r in rec if issubclass(r.category, ZoneWarning)]
    assert len(zs) == 1 and len(msgs) == 1
    assert "its zone lies off the map" in msgs[0] and "km from its edge" in msgs[0]


def test_a_zone_file_with_lat_lon_swapped_is_refused_with_the_fix(tmp_path):
    import json

    jb = get_scenario("jacksboro").world
    ring = [[36.55, -84.30], [36.55, -84.25], [36.60, -84.25], [36.55, -84.30]]  # [lat, lon]
    p = tmp_path / "swapped.geojson"
    p.write_text(json.dumps({"type": "FeatureCollection", "features": [
        {"type": "Feature", "properties": {}, "geometry": {"type": "Polygon",
                                                           "coordinates": [ring]}}] * 2}))
    with pytest.raises(InputError, match=r"all of its 2 zones lie off the map, but with "
                       r"longitude and latitude swapped they would lie on it.*\[lat, lon\].*"
                       r"swap the two coordinates"):
        read_zones(str(p), jb)
    # the same swap in an inline lon/lat zone of a mission file
    from fm2uav.io.zone_spec import ZoneSpec, resolve_zones

    spec = ZoneSpec(polygon=ring, lonlat=True)
    with pytest.raises(InputError, match=r"^no_fly_zones\[0\] lies off the map, but with "
                       "longitude and latitude swapped"):
        resolve_zones([spec], None, jb)
    # written the right way round it is on the map: no error, no warning
    ok = ZoneSpec(polygon=[[b, a] for a, b in ring], lonlat=True)
    assert len(resolve_zones([ok], None, jb)) == 1


def test_a_self_intersecting_zone_is_repaired_with_a_warning():
    import warnings

    from fm2uav.world.zones import ZoneWarning

    with warnings.catch_warnings(record=True) as rec:
        warnings.simplefilter("always")
        z = zone_from_mapping({"polygon": [[0, 0], [100, 100], [100, 0], [0, 100]],
                               "name": "bow tie"})
    msgs = [str(r.message) for r in rec if issubclass(r.category, ZoneWarning)]
    assert len(msgs) == 1 and "Self-intersection" in msgs[0] and "2 parts" in msgs[0]
    assert z.geometry.geom_type == "MultiPolygon" and abs(z.geometry.area - 5000) < 1e-6


def test_an_inline_zone_off_the_map_names_the_map_in_its_own_units():
    """A mission-file entry is no file and may be in metres: the warning says in which units
    the map lies (metres for lonlat: false, lon/lat degrees for lonlat: true)."""
    import warnings

    from fm2uav.io.zone_spec import ZoneSpec, resolve_zones
    from fm2uav.world.zones import ZoneWarning

    jb = get_scenario("jacksboro").world
    b = np.asarray(jb.bounds)
    far_m = ZoneSpec(polygon=[[b[0, 1] + 5e4, 0], [b[0, 1] + 6e4, 0], [b[0, 1] + 6e4, 1e4]])
    far_ll = ZoneSpec(polygon=[[-80.6, 36.25], [-80.55, 36.25], [-80.55, 36.3]], lonlat=True)
    msgs = []
    for spec in (far_m, far_ll):
        with warnings.catch_warnings(record=True) as rec:
            warnings.simplefilter("always")
            assert len(resolve_zones([spec], None, jb)) == 1
        msgs += [str(r.message) for r in rec if issubclass(r.category, ZoneWarning)]
    assert len(msgs) == 2 and all(m.startswith("no_fly_zones[0] lies off the map") for m in msgs)
    assert f"world metres (lonlat: false) and the map covers x {b[0, 0]:.0f}..{b[0, 1]:.0f} m" \
        in msgs[0] and "file" not in msgs[0]
    assert "check its [lon, lat] coordinates: the map covers lon -84." in msgs[1]
    assert "file" not in msgs[1]
