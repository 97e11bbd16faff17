"""Rally points: the operator's checked, the planner's chosen among open, reachable sites."""

import numpy as np
import pytest
from shapely.geometry import box

from fm2uav import World
from fm2uav.autopilot.rally import (
    MAX_RALLY,
    candidate_sites,
    choose_rally,
    rally_points,
    site_facts,
)
from fm2uav.errors import InputError
from fm2uav.planning.returns import ReturnField
from fm2uav.world.zones import Zone, with_zones


@pytest.fixture(scope="module")
def town():
    """1 km x 1 km, flat at 0 m except a steep slope in the north-east and one building."""
    h = np.zeros((50, 50))
    h[35:, 35:] = np.linspace(0, 200, 15)[:, None]  # ~34 deg: not a landing site
    w = World.from_heightmap(h, 20.0, 20)
    occ = np.array(w.occupancy)
    occ[10:12, 30:32, :4] = True  # a 60 m building
    w = World(occ, spacing=w.spacing, origin=w.origin, terrain=w.terrain)
    return with_zones(w, [Zone(box(600, 0, 700, 200), name="school")])


@pytest.fixture(scope="module")
def home(town):
    W = np.where(town.occupancy, 0.0, 1.0)
    return ReturnField(town, W, (100.0, 100.0, 40.0))


def test_site_facts(town):
    f = site_facts(town, [[100.0, 100.0], [900.0, 900.0], [210.0, 620.0], [650.0, 100.0]])
    assert f["slope_deg"][0] == pytest.approx(0.0) and f["slope_deg"][1] > 20
    assert f["building_distance_m"][2] < 20 and f["building_distance_m"][0] > 300
    assert f["zone_distance_m"][3] < 0 and f["zone_distance_m"][0] > 400
    assert not f["unknown_ground"].any()


def test_the_operators_points_are_checked(town, home):
    ok = rally_points(town, [(300.0, 300.0), (500.0, 800.0, 25.0)], agl=40.0, reach=home)
    assert [r.name for r in ok] == ["rally 1", "rally 2"]
    assert ok[0].point[2] == pytest.approx(40.0) and ok[1].agl == 25.0
    assert ok[0].chosen_by == "user" and ok[0].facts["slope_deg"] == 0.0
    with pytest.raises(InputError, match="outside the map.*--rally"):
        rally_points(town, [(5000.0, 0.0)], agl=40.0)
    with pytest.raises(InputError, match="no-fly zone.*--rally"):
        rally_points(town, [(650.0, 100.0)], agl=40.0)
    with pytest.raises(InputError, match="obstacle"):
        rally_points(town, [(210.0, 610.0, 20.0)], agl=20.0)
    with pytest.raises(InputError, match=f"at most {MAX_RALLY}"):
        rally_points(town, [(300.0, 300.0)] * (MAX_RALLY + 1), agl=40.0)
    with pytest.raises(InputError, match="> 0 m"):
        rally_points(town, [(300.0, 300.0, -1.0)], agl=40.0)


def test_candidates_are_flat_open_reachable_and_away_from_buildings_and_zones(town, home):
    sites, counts = candidate_sites(town, home, agl=40.0)
    f = site_facts(town, sites[:, :2])
    assert len(sites) and counts["open"] == len(sites)
    assert counts["steep"] > 0 and counts["near_buildings"] > 0 and counts["near_zones"] > 0
    assert f["slope_deg"].max() <= 8.0 and f["building_distance_m"].min() >= 25.0
    assert f["zone_distance_m"].min() >= 30.0
    assert np.all(np.isfinite(home.cost(sites)))


def test_the_greedy_bounds_the_worst_way_back(town, home):
    clients = np.array([[x, 950.0, 40.0] for x in np.linspace(100, 600, 11)])
    chosen, fields, rep = choose_rally(home, clients, 2, agl=40.0)
    assert 1 <= len(chosen) <= 2 and len(fields) == len(chosen)
    worst = rep["worst_cost"]
    assert worst == sorted(worst, reverse=True) and worst[-1] < 0.6 * worst[0]
    # every chosen point is an open candidate
    sites, _ = candidate_sites(town, home, agl=40.0)
    for r in chosen:
        assert np.min(np.linalg.norm(sites - r.point, axis=1)) < 1e-9
        assert r.chosen_by == "planner"
    with pytest.raises(InputError, match="auto:K"):
        choose_rally(home, clients, 11, agl=40.0)
