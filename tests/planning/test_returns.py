"""Return fields: one FM² wave from a destination, the way back from any point."""

import numpy as np
import pytest

from fm2uav import FlightLevel, World, plan
from fm2uav.errors import InputError, PlanningError, UnreachableError
from fm2uav.planning.geodesic import descend
from fm2uav.planning.returns import ReturnField, descend_many, return_fields


@pytest.fixture(scope="module")
def walled():
    occ = np.zeros((60, 40), bool)
    occ[30, 0:32] = True  # a wall with a gap at the top
    return World(occ, spacing=1.0)


def test_the_way_back_goes_round_the_wall_and_ends_at_home(walled):
    f = ReturnField(walled, np.where(walled.occupancy, 0.0, 1.0), (5.0, 5.0))
    back = f.path((50.0, 5.0))
    assert np.allclose(back.path[0], (50, 5)) and np.allclose(back.path[-1], (5, 5))
    assert back.path[:, 1].max() > 31  # through the gap
    assert back.length > 2 * 26  # much longer than the 45 m straight line
    assert back.destination == "home"
    # the field's cost is the planner's own: lower nearer home
    c = f.cost([[10.0, 5.0], [50.0, 5.0]])
    assert c[0] < c[1]


def test_the_way_back_equals_a_plan_from_that_point(walled):
    W = np.where(walled.occupancy, 0.0, 1.0)
    f = ReturnField(walled, W, (5.0, 5.0), order=2)
    back = f.path((50.0, 5.0))
    from fm2uav import PlanOptions

    p = plan(walled, (50.0, 5.0), (5.0, 5.0), options=PlanOptions(speed_map=W))
    assert back.length == pytest.approx(p.length, rel=0.02)


def test_descend_many_is_descend_one_by_one(walled):
    W = np.where(walled.occupancy, 0.0, 1.0)
    f = ReturnField(walled, W, (5.0, 5.0))
    starts = [np.array([50.0, 5.0]), np.array([40.0, 30.0]), np.array([5.0, 5.0])]
    many = descend_many(f.T, starts, np.array([5.0, 5.0]), spacing=walled.spacing)
    for s, q in zip(starts[:2], many[:2]):
        assert np.array_equal(q, descend(f.T, s, (5.0, 5.0), spacing=walled.spacing))
    assert len(many[2]) == 2  # on the source node: the straight two-point path


def test_cut_off_points_and_bad_sources_are_refused():
    occ = np.zeros((40, 20), bool)
    occ[20, :] = True
    w = World(occ, spacing=1.0)
    W = np.where(occ, 0.0, 1.0)
    f = ReturnField(w, W, (5.0, 5.0))
    assert not np.isfinite(f.cost([[30.0, 5.0]])[0])
    with pytest.raises(UnreachableError, match="no way back to home"):
        f.path((30.0, 5.0))
    with pytest.raises(PlanningError, match="obstacle"):
        ReturnField(w, W, (20.0, 5.0))
    with pytest.raises(InputError, match="full-grid"):
        ReturnField(w, W[:10], (5.0, 5.0))


def test_terrain_following_returns_get_the_final_altitude_profile():
    h = np.zeros((40, 30))
    h[15:25, :] = np.linspace(0, 60, 10)[:, None]  # a slope
    w = World.from_heightmap(h, 10.0, 25)
    lev = FlightLevel(agl=40.0)
    p = plan(w, (20.0, 150.0, 40.0), (350.0, 150.0, 100.0), level=lev)
    f = ReturnField.from_plan(p, p.path[0])
    back = f.path(p.path[-1])
    agl = back.path[:, 2] - np.asarray(w.ground_height(back.path[:, 0], back.path[:, 1]))
    assert back.profile is not None
    assert agl[back.profile.phase == "cruise"].min() >= 40.0 - 2.0 - 1e-6
    fields = return_fields(p, {"home": p.path[0], "end": p.path[-1]})
    assert set(fields) == {"home", "end"} and fields["end"].name == "end"


def test_a_regional_plan_has_no_return_field():
    class Fake:
        params = {"storage": "regional"}
        W = np.ones((3, 3))
        world = World(np.zeros((9, 9), bool), spacing=1.0)
        level = None
        path = np.zeros((2, 2))

    with pytest.raises(InputError, match="regional"):
        ReturnField.from_plan(Fake(), (1.0, 1.0))
