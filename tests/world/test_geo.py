"""World metres ⇄ WGS84: anchored tangent plane and projected CRS worlds."""

import numpy as np
import pytest
from pyproj import Geod, Transformer

from fm2uav import PlanOptions, World
from fm2uav.errors import InputError, WorldError
from fm2uav.io import DEFAULT_ANCHOR, Anchor, from_lonlat, to_lonlat

from .conftest import hill_world

GEOD = Geod(ellps="WGS84")


def test_anchor_sits_at_world_origin_and_distances_are_exact(hill):
    a = Anchor(lon=8.545594, lat=47.3977419, alt=488.0)
    geo = to_lonlat(hill, [[0.0, 0.0, 0.0], [3000.0, 4000.0, 100.0]], anchor=a)
    assert geo[0].tolist() == pytest.approx([a.lon, a.lat, 488.0], abs=1e-12)
    az, _, dist = GEOD.inv(a.lon, a.lat, geo[1, 0], geo[1, 1])
    assert dist == pytest.approx(5000.0, abs=1e-6)           # azimuthal equidistant
    assert az == pytest.approx(np.degrees(np.arctan2(3000, 4000)), abs=1e-9)  # +x east, +y north
    assert geo[1, 2] == pytest.approx(588.0)


def test_default_anchor_and_round_trip(hill):
    rng = np.random.default_rng(1)
    pts = rng.uniform([-5e3, -5e3, -100], [5e3, 5e3, 3e3], size=(100, 3))
    geo = to_lonlat(hill, pts)
    assert geo[:, 0].mean() == pytest.approx(DEFAULT_ANCHOR.lon, abs=0.1)
    back = from_lonlat(hill, geo)
    np.testing.assert_allclose(back, pts, atol=1e-6)


def test_projected_crs_world_uses_pyproj():
    origin = (440000.0, 4470000.0, 600.0)  # UTM 30N, near Madrid
    w = hill_world(crs="EPSG:32630", origin=origin)
    pts = np.array([[origin[0] + 55.0, origin[1] + 105.0, 700.0]])
    lon, lat = Transformer.from_crs("EPSG:32630", "EPSG:4326", always_xy=True).transform(
        pts[0, 0], pts[0, 1])
    geo = to_lonlat(w, pts, anchor=Anchor(0.0, 0.0))  # the anchor is ignored with a CRS
    np.testing.assert_allclose(geo[0], [lon, lat, 700.0], atol=1e-12)
    np.testing.assert_allclose(from_lonlat(w, geo), pts, atol=1e-6)


def test_geographic_crs_is_refused():
    w = World(np.zeros((3, 3), bool), spacing=1.0, crs="EPSG:4326")
    with pytest.raises(WorldError, match="geographic"):
        to_lonlat(w, [[0.0, 0.0]])


def test_bad_anchor_and_coordinates(hill):
    with pytest.raises(InputError, match="lat"):
        Anchor(lon=0.0, lat=95.0)
    with pytest.raises(InputError, match="latitude"):
        from_lonlat(hill, [[0.0, 91.0, 0.0]])


def test_ground_height_is_bilinear_terrain():
    h = np.add.outer(np.arange(5) * 2.0, np.arange(4) * 3.0)  # plane z = 0.2 x + 0.3 y
    w = World.from_heightmap(h, 10.0, 5)
    np.testing.assert_allclose(w.ground_height([15.0, 0.0], [25.0, 0.0]), [10.5, 0.0])
    flat = World(np.zeros((4, 4, 4), bool), spacing=5.0, origin=(0, 0, 12.0))
    assert flat.ground_height(3.0, 3.0) == 12.0


def test_one_conversion_world_first():
    """fm2uav.io re-exports the world's own conversion (one function, world first)."""
    import fm2uav.world.geo as geo

    assert to_lonlat is geo.to_lonlat and from_lonlat is geo.from_lonlat
    hill = hill_world()
    one = to_lonlat(hill, [100.0, 200.0, 30.0])
    assert one.shape == (3,)
    np.testing.assert_allclose(from_lonlat(hill, one), [100.0, 200.0, 30.0], atol=1e-6)
    np.testing.assert_allclose(to_lonlat(hill, [[100.0, 200.0]])[0, 2], DEFAULT_ANCHOR.alt)


def test_same_as_plan_lonlat_on_the_real_dem():
    from fm2uav import plan
    from fm2uav.scenarios import get_scenario

    sc = get_scenario("jacksboro")
    w = sc.world
    p = plan(w, sc.start, sc.goal, options=PlanOptions(step=1.0))
    np.testing.assert_allclose(to_lonlat(w, p.path), p.lonlat(), atol=1e-12)
