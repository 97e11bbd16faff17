"""Safe returns of a mission: ways back, point of no return, the safe return the mission carries."""

import numpy as np
import pytest

from fm2uav.autopilot.items import (
    CMD_DO_LAND_START,
    CMD_DO_RETURN_PATH_START,
    CMD_NAV_LAND,
    CMD_NAV_TAKEOFF,
)
from fm2uav.autopilot.returns import route_samples
from fm2uav.autopilot.safe_return import ReturnOptions, flown_plan
from fm2uav.autopilot.validate import validate_mission
from fm2uav.errors import PlanningError
from fm2uav.vehicles.endurance import return_time

from .return_cases import build
from .return_cases import ridge_plan as _ridge_plan


@pytest.fixture(scope="module")
def ridge_plan():
    return _ridge_plan()


@pytest.fixture(scope="module")
def embedded(ridge_plan):
    return build(ridge_plan, end="rtl")


def test_no_return_altitude_under_the_ceiling_so_the_mission_carries_the_return(embedded,
                                                                                 ridge_plan):
    rep = embedded.returns
    assert not rep.firmware.feasible and rep.embedded == "return"
    assert embedded.end == "return"
    items = embedded.items
    assert items[0].command == CMD_NAV_TAKEOFF and items[1].command == CMD_DO_RETURN_PATH_START
    land = [i for i, it in enumerate(items) if it.command == CMD_NAV_LAND]
    start = [i for i, it in enumerate(items) if it.command == CMD_DO_LAND_START]
    assert land == [len(items) - 1] and len(start) == 1 and start[0] < land[0]
    assert validate_mission(items, "ardupilot", vehicle="multirotor") == []
    # the flight ends over home: the route, then the FM² way back
    path = embedded.path_m
    assert len(path) > len(ridge_plan.path)
    assert np.hypot(*(path[-1, :2] - ridge_plan.path[0, :2])) < 1e-6
    flown = flown_plan(ridge_plan, embedded)
    assert len(flown.path) == len(path) and np.shape(flown.w) == (len(path),)
    # the parameters send the failsafes to the mission, the plain RTL still clears the ridge
    names = {p.name: p.value for p in rep.params.params}
    assert names["FS_THR_ENABLE"] == 6 and names["RTL_ALT_M"] >= 150 + 30
    assert any("ceiling" in w for w in embedded.warnings)


def test_the_point_of_no_return_balances_the_budget(ridge_plan):
    m = build(ridge_plan, endurance_s=240.0, reserve=0.2)
    pnr = m.returns.pnr
    assert pnr["reached"] and pnr["passed_before_end"]
    assert pnr["t_mission_s"] + pnr["return"]["time_s"] == pytest.approx(192.0, abs=0.05)
    assert 0 <= pnr["margin_s"] < 0.5
    # its way back, timed again independently of the report
    back = m.returns.pnr_path
    g = m.world.ground_height(back[-1, 0], back[-1, 1])
    sp = m.returns.speeds
    t, _ = return_time(back, speed=sp["forward_mps"], climb_rate=sp["climb_mps"],
                       descent_rate=sp["descent_mps"], landing_height=back[-1, 2] - g)
    assert t == pytest.approx(pnr["return"]["time_s"], abs=0.01)
    # and the time flown to it is the mission's clock at that point
    s = route_samples(m, legs=[(pnr["after_waypoint"], pnr["leg_fraction"])])
    assert s.time[0] == pytest.approx(pnr["t_mission_s"], abs=0.01)
    assert any("point of no return" in w for w in m.warnings)
    with pytest.raises(PlanningError, match="strict"):
        build(ridge_plan, endurance_s=240.0, returns=ReturnOptions(strict=True))


def _battery_for(ridge_plan, share):
    """A battery [Wh] whose usable 80 % is ``share`` of the mission's energy."""
    m = build(ridge_plan, endurance_s=None, firmware="px4")
    return share * m.info["energy"]["energy_wh"] / 0.8


def test_without_an_endurance_the_battery_gives_the_point_of_no_return(ridge_plan):
    from fm2uav.autopilot.returns import leg_speeds
    from fm2uav.vehicles.energy import fly_legs
    from fm2uav.vehicles.power import get_power_model

    battery = _battery_for(ridge_plan, 0.8)
    m = build(ridge_plan, endurance_s=None, firmware="px4", battery_wh=battery)
    pnr = m.returns.pnr
    assert pnr["computed"] and pnr["budget"] == "energy" and pnr["reached"]
    assert pnr["passed_before_end"] and "endurance_s" not in pnr
    assert "energy model arducopter (class default)" in pnr["model"]
    usable = 0.8 * battery
    assert pnr["usable_wh"] == pytest.approx(usable, abs=1e-3)
    assert pnr["spent_wh"] + pnr["return"]["energy_wh"] == pytest.approx(usable, abs=0.05)
    assert 0 <= pnr["margin_wh"] < 0.05
    # flown again here: the legs as written up to the point, then its way back as written
    quad = get_power_model("arducopter")
    wps = m.waypoints
    p = wps.points_m
    k = pnr["after_waypoint"]
    speeds, holds = leg_speeds(m.items, len(p), m.options.forward_speed)
    route = np.vstack([p[:k + 1], pnr["point_m"]])
    rates = dict(climb_rate=m.info["flight"]["climb_rate_mps"],
                 descent_rate=m.info["flight"]["descent_rate_mps"])
    out = fly_legs(route, quad, speed=speeds[:k + 1], holds=np.r_[holds[:k + 1], 0.0],
                   takeoff_climb=wps.agl[0], **rates)
    back = m.returns.pnr_path
    g = m.world.ground_height(back[-1, 0], back[-1, 1])
    home = fly_legs(back, quad, speed=m.options.forward_speed, final_descent=back[-1, 2] - g,
                    **rates)
    assert out.energy_wh == pytest.approx(pnr["spent_wh"], abs=0.02)
    assert home.energy_wh == pytest.approx(pnr["return"]["energy_wh"], abs=1e-3)
    assert out.energy_wh + home.energy_wh == pytest.approx(usable, abs=0.1)
    # one point of no return: the energy block no longer gives the straight one
    assert "no_return_waypoint" not in m.info["energy"]
    assert m.info["energy"]["no_return"].startswith("point_of_no_return")
    assert any("battery" in w and "point of no return" in w for w in m.warnings)
    with pytest.raises(PlanningError, match="--battery"):
        build(ridge_plan, endurance_s=None, firmware="px4", battery_wh=battery,
              returns=ReturnOptions(strict=True))


def test_the_first_budget_reached_binds_and_the_other_is_told(ridge_plan):
    battery = _battery_for(ridge_plan, 0.8)
    e_only = build(ridge_plan, endurance_s=None, battery_wh=battery).returns.pnr
    t_only = build(ridge_plan, endurance_s=240.0).returns.pnr        # a big default battery
    assert t_only["budget"] == "endurance" and t_only["other_budgets"]["energy"]["reached"] \
        is False
    both = build(ridge_plan, endurance_s=240.0, battery_wh=battery).returns.pnr
    first = min((e_only, t_only), key=lambda p: p["distance_m"])
    assert both["budget"] == first["budget"]
    assert both["distance_m"] == pytest.approx(first["distance_m"], abs=0.5)
    other = "endurance" if both["budget"] == "energy" else "energy"
    assert both["other_budgets"][other]["distance_m"] >= both["distance_m"]
    assert both["endurance_s"] == 240.0 and both["battery_wh"] == pytest.approx(battery, 1e-3)


@pytest.mark.parametrize("end", ["land", "auto"])
def test_a_landing_at_the_goal_is_marked_as_the_safe_return(ridge_plan, end):
    m = build(ridge_plan, end=end, firmware="px4")
    assert m.returns.embedded == "landing" and m.end == "land"
    assert len(m.path_m) == len(ridge_plan.path)
    cmds = [it.command for it in m.items]
    assert CMD_DO_LAND_START in cmds and CMD_DO_RETURN_PATH_START not in cmds  # PX4
    assert {p.name: p.value for p in m.returns.params.params}["RTL_TYPE"] == 2


def test_ways_back_from_every_waypoint_and_a_rally_point_chosen_to_shorten_them(ridge_plan,
                                                                             embedded):
    rep = embedded.returns
    s = rep.summary()
    assert [r["waypoint"] for r in s["waypoints"]] == list(range(len(embedded.waypoints)))
    assert all(np.isfinite(rep.time)) and rep.time[0] < rep.time.max()
    auto = build(ridge_plan, end="rtl", returns=ReturnOptions(auto_rally=1))
    chosen = auto.returns.rally
    assert len(chosen) == 1 and chosen[0].chosen_by == "planner"
    assert chosen[0].facts["slope_deg"] <= 8.0
    # the rally point is on the far side of the ridge: the worst way back gets much shorter
    assert auto.returns.time.max() < 0.7 * rep.time.max()
    assert "rally 1" in auto.returns.to


def test_returns_off_or_a_user_rally_point(ridge_plan):
    m = build(ridge_plan, returns=ReturnOptions(enabled=False))
    assert m.returns is None
    m = build(ridge_plan, returns=ReturnOptions(rally=((1100.0, 700.0),)))
    assert [r.name for r in m.returns.rally] == ["rally 1"]
    assert m.returns.rally[0].chosen_by == "user"


def test_a_plane_gets_the_way_back_and_loiters_over_home_on_ardupilot_lands_on_px4(ridge_plan):
    ardu = build(ridge_plan, vehicle="fixed_wing", min_speed=12.0)
    assert ardu.returns.embedded == "return" and ardu.end == "return"
    cmds = [it.command for it in ardu.items]
    assert cmds[1] == CMD_DO_RETURN_PATH_START and cmds[-1] == 17  # NAV_LOITER_UNLIM
    assert CMD_DO_LAND_START not in cmds
    assert ardu.returns.params.as_dict()["RTL_AUTOLAND"] == 4
    px4 = build(ridge_plan, vehicle="fixed_wing", firmware="px4")
    cmds = [it.command for it in px4.items]
    assert cmds[-1] == CMD_NAV_LAND and cmds.count(CMD_DO_LAND_START) == 1
    assert validate_mission(px4.items, "px4", vehicle="fixed_wing") == []
