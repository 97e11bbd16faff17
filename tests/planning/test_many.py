"""plan_many: every route equals plan() from its start, failures per start with a reason."""

from __future__ import annotations

import numpy as np
import pytest

from fm2uav import FlightLevel, PlanOptions, Shaping, World, plan, scenarios
from fm2uav.errors import InputError, PlanningError, PointError
from fm2uav.planning.many import FAILURE_REASONS, ManyPlans, RouteFailure, plan_many
from fm2uav.planning.planner import Plan


def _blocks(n: int = 120, seed: int = 3) -> World:
    """A seeded city of rectangular blocks, 2 m cells, the centre square kept free."""
    rng = np.random.default_rng(seed)
    occ = np.zeros((n, n), bool)
    for _ in range(n // 3):
        x, y = rng.integers(0, n, 2)
        w, h = rng.integers(3, 12, 2)
        occ[x:x + w, y:y + h] = True
    occ[n // 2 - 5:n // 2 + 5, n // 2 - 5:n // 2 + 5] = False
    return World(occ, spacing=2.0)


def _outcome(world, start, goal, **kw):
    try:
        return plan(world, start, goal, **kw)
    except PlanningError as exc:
        return exc


def _assert_same(route, single) -> None:
    """The route of plan_many and the plan of plan() agree element for element."""
    if isinstance(single, Exception):
        assert isinstance(route, RouteFailure), (route, single)
        assert route.message == str(single)
        return
    assert isinstance(route, Plan), route
    assert route.path.shape == single.path.shape
    assert np.array_equal(route.path, single.path)
    assert np.array_equal(route.w, single.w)
    assert route.length == single.length
    assert route.clearance == single.clearance
    assert route.params == single.params
    if single.profile is not None:
        assert np.array_equal(route.profile.path, single.profile.path)
        assert np.array_equal(route.profile.phase, single.profile.phase)
    assert route.summary()["height_above_ground" if single.path.shape[1] == 3 else "length_m"] \
        == single.summary()["height_above_ground" if single.path.shape[1] == 3 else "length_m"]


@pytest.mark.parametrize("order", [1, 2])
def test_every_sampled_route_equals_a_single_plan_2d(order):
    world = _blocks()
    goal = (121.0, 119.0)
    rng = np.random.default_rng(order)
    starts = rng.uniform(world.bounds[:, 0], world.bounds[:, 1], (60, 2))
    shaping = Shaping(exponent=0.5)
    many = plan_many(world, goal, starts, shaping=shaping, options=PlanOptions(order=order),
                     threads=2)
    assert isinstance(many, ManyPlans) and len(many) == 60
    assert many.ok.sum() >= 20  # the sample has routes and failures
    assert (~many.ok).sum() >= 3
    for k in range(0, 60, 3):
        _assert_same(many.routes[k], _outcome(world, starts[k], goal, shaping=shaping,
                                              options=PlanOptions(order=order)))


def test_starts_near_the_goal_and_on_ties_equal_single_plans():
    # an empty symmetric map: the starts in the source ball and their mirror twins tie
    world = World(np.zeros((41, 41), bool), spacing=1.0)
    goal = (20.0, 20.0)
    starts = [(21.0, 20.0), (20.0, 23.0), (17.0, 20.0), (22.0, 22.0), (20.0, 21.0),
              (35.0, 21.0), (5.0, 19.0), (21.0, 35.0), (2.0, 2.0), (38.0, 2.0)]
    many = plan_many(world, goal, starts, threads=1)
    for s, r in zip(starts, many.routes):
        _assert_same(r, _outcome(world, s, goal))


def test_terrain_following_routes_equal_single_plans():
    sc = scenarios.open_field()
    level = FlightLevel(agl=150.0, p1=0.5, p2=1.3)
    shaping = Shaping(saturation=0.5)
    rng = np.random.default_rng(7)
    b = sc.world.bounds
    xy = rng.uniform(b[:2, 0] + 100, b[:2, 1] - 100, (6, 2))
    starts = [np.array([x, y, float(sc.world.ground_height(x, y)) + 150.0]) for x, y in xy]
    starts.append(np.asarray(sc.start, float))
    many = plan_many(sc.world, sc.goal, starts, shaping=shaping, level=level, threads=2)
    assert many.ok.all()
    for s, r in zip(starts, many.routes):
        single = plan(sc.world, s, sc.goal, shaping=shaping, level=level)
        assert single.profile is not None
        _assert_same(r, single)


def test_threads_do_not_change_the_routes():
    world = _blocks(80, seed=5)
    rng = np.random.default_rng(11)
    starts = rng.uniform(world.bounds[:, 0], world.bounds[:, 1], (40, 2))
    one = plan_many(world, (81.0, 79.0), starts, threads=1)
    two = plan_many(world, (81.0, 79.0), starts, threads=3)
    assert [type(r) for r in one.routes] == [type(r) for r in two.routes]
    for a, b in zip(one.routes, two.routes):
        if isinstance(a, Plan):
            assert np.array_equal(a.path, b.path)
        else:
            assert a == b


def test_each_failure_has_its_reason_and_plans_message():
    occ = np.zeros((40, 30), bool)
    occ[18:22, :] = True          # a wall across the map: the right side is cut off
    world = World(occ, spacing=1.0)
    goal = (5.0, 5.0)
    starts = [(10.0, 10.0),        # fine
              (20.0, 10.0),        # in the wall
              (30.0, 10.0),        # cut off
              (100.0, 10.0),       # outside
              (5.2, 5.1),          # on the goal's node
              (float("nan"), 3.0),  # not a point
              (1.0, 2.0, 3.0)]     # wrong dimension
    many = plan_many(world, goal, starts)
    reasons = [r.reason if isinstance(r, RouteFailure) else "ok" for r in many.routes]
    assert reasons == ["ok", "blocked", "unreachable", "outside", "at-goal", "invalid",
                       "invalid"]
    assert set(reasons) - {"ok"} <= set(FAILURE_REASONS)
    for s, r in zip(starts[:5], many.routes[:5]):
        if isinstance(r, RouteFailure):
            with pytest.raises(PlanningError) as err:
                plan(world, s, goal)
            assert str(err.value) == r.message
    s = many.summary()
    assert s["starts"] == 7 and s["routes"] == 1
    assert s["failed_by_reason"] == {"at-goal": 1, "blocked": 1, "invalid": 2, "outside": 1,
                                     "unreachable": 1}
    assert list(many.failures()) == [1, 2, 3, 4, 5, 6]


def test_no_fly_zone_start_is_reported_with_the_zone():
    from fm2uav.world.zones import Zone, with_zones

    world = World(np.zeros((60, 60), bool), spacing=1.0)
    shapely = pytest.importorskip("shapely")
    zone = Zone(name="school", geometry=shapely.box(30, 30, 40, 40))
    zw = with_zones(world, [zone])
    many = plan_many(zw, (5.0, 5.0), [(35.0, 35.0), (50.0, 10.0)])
    assert isinstance(many.routes[0], RouteFailure)
    assert many.routes[0].reason == "no-fly" and "school" in many.routes[0].message
    assert isinstance(many.routes[1], Plan)


def test_bad_goal_and_arguments_raise():
    world = _blocks(40)
    occ_cell = np.argwhere(world.occupancy)[0] * 2.0
    with pytest.raises(PointError):
        plan_many(world, tuple(occ_cell), [(1.0, 1.0)])
    with pytest.raises(PointError, match="outside"):
        plan_many(world, (500.0, 5.0), [(1.0, 1.0)])
    with pytest.raises(InputError, match="threads"):
        plan_many(world, (41.0, 39.0), [(1.0, 1.0)], threads=0)
    with pytest.raises(InputError, match="list of points"):
        plan_many(world, (41.0, 39.0), np.array([1.0, 1.0]))
    assert len(plan_many(world, (41.0, 39.0), []).routes) == 0
