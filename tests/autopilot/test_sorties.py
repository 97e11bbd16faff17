"""One mission per battery (fm2uav.autopilot.sorties): each sortie a complete, valid mission
whose written file flies the energy and time the summary gives."""

from __future__ import annotations

import io

import numpy as np
import pytest

from fm2uav.autopilot.build import ExportOptions
from fm2uav.autopilot.items import CMD_DO_SET_CAM_TRIGG_DIST, CMD_NAV_LAND, CMD_NAV_TAKEOFF
from fm2uav.autopilot.sorties import build_sorties, field_ways, straight_ways
from fm2uav.autopilot.validate import validate_mission
from fm2uav.io import export_mission
from fm2uav.missions.coverage import plan_coverage
from fm2uav.missions.coverage.triggers import camera_plan
from fm2uav.planning.params import FlightLevel
from fm2uav.scenarios.coverage import coverage_area, coverage_world
from fm2uav.vehicles.energy import fly_legs
from fm2uav.vehicles.power import get_power_model
from fm2uav.world.geo import from_lonlat
from fm2uav.world.wind import WindField

WIND = WindField.constant(4.0, 200.0)


@pytest.fixture(scope="module")
def survey():
    world = coverage_world(0)
    cp = plan_coverage(world, coverage_area("S1"), 80.0, level=FlightLevel(agl=100.0), seed=0)
    shots = camera_plan(cp)
    opt = ExportOptions(battery_wh=60.0, wind=WIND)
    mission, _ = export_mission(cp.plan, [], opt, agl=100.0, camera=shots)
    return world, cp, shots, mission


def _build(plan, opt, **kw):
    return export_mission(plan, ["wpl", "plan"], opt, **kw)


@pytest.fixture(scope="module")
def sorties(survey):
    world, cp, shots, mission = survey
    ways = field_ways(world, cp.path[0], level=cp.level)
    return build_sorties(mission, cp.plan, ways=ways, camera=shots, agl=100.0, build=_build)


def flown(text: str, world, model, *, climb: float, descent: float, wind) -> tuple[float, float]:
    """Energy [Wh] and time [s] of a QGC WPL 110 file, read here from its columns and flown
    by the power model: the take-off climb, every leg at the speed the last
    DO_CHANGE_SPEED set, the holds, the descent at the landing item."""
    rows = np.array([ln.split("\t") for ln in text.strip().splitlines()[1:]], dtype=float)
    home, items = rows[0], rows[1:]
    cmd = items[:, 3].astype(int)
    pts, holds, speeds, speed = [], [], [], None
    for it, c in zip(items, cmd):
        if c == 178:
            speed = it[5]
        elif c in (16, 22):
            if pts:
                speeds.append(speed)
            alt = {0: it[10], 3: it[10] + home[10]}[int(it[2])]
            pts.append([it[9], it[8], alt])
            holds.append(it[4] if c == 16 else 0.0)
    assert cmd[0] == CMD_NAV_TAKEOFF and cmd[-1] == CMD_NAV_LAND
    xyz = from_lonlat(world, np.array(pts))
    agl = xyz[:, 2] - np.asarray(world.ground_height(xyz[:, 0], xyz[:, 1]), dtype=float)
    mid = 0.5 * (xyz[1:] + xyz[:-1])
    f = fly_legs(xyz, model, speed=np.array(speeds, float), climb_rate=climb,
                 descent_rate=descent, wind=wind.at(mid, 0.5 * (agl[1:] + agl[:-1])),
                 holds=np.array(holds), takeoff_climb=agl[0], final_descent=agl[-1])
    return f.energy_wh, f.time_s


def test_each_written_sortie_flies_the_energy_and_time_of_the_summary(survey, sorties):
    world, cp, _, mission = survey
    model = get_power_model("arducopter")
    usable = 0.8 * 60.0
    s = sorties.summary()
    assert s["count"] == len(sorties.sorties) >= 2
    assert s["ways"]["kind"] == "return field"
    for row, sm in zip(s["sorties"], sorties.sorties):
        fh = io.StringIO()
        sm.files[f"sortie-{s['sorties'].index(row) + 1:02d}.waypoints"].write(fh)
        e, t = flown(fh.getvalue(), world, model, climb=2.5, descent=1.5, wind=WIND)
        # the resume point named is the item of that number in the file
        seq = fh.getvalue().strip().splitlines()[1 + row["resume_item"]].split("\t")
        assert int(seq[0]) == row["resume_item"] and int(seq[3]) in (16, 22)
        lon, lat, _ = row["resume_lon_lat_alt"]
        assert (float(seq[8]), float(seq[9])) == pytest.approx((lat, lon), abs=2e-7)
        assert row["energy_wh"] == pytest.approx(e, rel=2e-3)
        assert row["time_s"] == pytest.approx(t, rel=2e-3)
        assert e <= usable and row["ok"]
    # never more sorties than equal parts of the waypoint list (here, in this wind, as many),
    # whose energies the summary gives beside the sorties'
    assert s["even_split_count"] is None or s["count"] <= s["even_split_count"]
    assert len(s["even_split_energy_wh"]) == (s["even_split_count"] or 0)
    assert all(0 < v <= usable for v in s["even_split_energy_wh"])


def test_sorties_are_complete_valid_missions_that_fly_the_whole_survey(survey, sorties):
    world, cp, shots, mission = survey
    home = mission.waypoints.points_m[0]
    n = len(cp.path)
    spans = [sm.survey for sm in sorties.sorties]
    assert spans[0][0] == 0 and spans[-1][1] == n - 1
    assert all(a[1] == b[0] for a, b in zip(spans[:-1], spans[1:]))   # resume where it stopped
    on = 0
    for k, sm in enumerate(sorties.sorties):
        m = sm.mission
        problems = validate_mission(m.items, "ardupilot", vehicle="multirotor",
                                    home_alt=m.waypoints.home[2], fences=m.fences)
        assert not [p for p in problems if p.is_error]
        assert m.items[0].command == CMD_NAV_TAKEOFF and m.items[-1].command == CMD_NAV_LAND
        wp = m.waypoints.points_m
        # takes off at home, lands at home
        assert np.hypot(*(wp[0, :2] - home[:2])) < 1.0
        assert np.hypot(*(wp[-1, :2] - home[:2])) < 1.0
        # the resume point is a waypoint of the sortie, on the survey path
        r = wp[sm.resume_waypoint]
        assert np.allclose(r[:2], cp.path[sm.survey[0], :2], atol=1e-6)
        assert np.allclose(sm.resume, cp.path[sm.survey[0]])
        on += sum(1 for it in m.items if it.command == CMD_DO_SET_CAM_TRIGG_DIST
                  and it.params[0] > 0)
    # every band is photographed: each band starts once, plus once per sortie resuming in one
    assert len(shots.bands) <= on <= len(shots.bands) + len(sorties.sorties) - 1
    # the whole mission is longer than any sortie's survey piece: the split is real
    assert all(sm.survey[1] - sm.survey[0] < n - 1 for sm in sorties.sorties)


def test_straight_ways_clear_the_surface_and_fit(survey):
    world, cp, shots, mission = survey
    ways = straight_ways(world, cp.path[0], agl=100.0)
    got = build_sorties(mission, cp.plan, ways=ways, camera=shots, agl=100.0)
    assert got.summary()["ways"]["kind"] == "straight"
    assert all(sm.energy_wh <= 0.8 * 60.0 for sm in got.sorties)
    from fm2uav.world.segments import surface_points

    for p in (cp.path[400], cp.path[-1]):
        way = ways.paths([p])[0]
        assert np.allclose(way[0], p) and np.allclose(way[-1], cp.path[0])
        top = way[1:-1, 2]
        s = surface_points(world, p[None, :2], cp.path[:1, :2])
        assert np.all(top >= s.z.max() + 100.0 - 1e-6)


def test_one_battery_needs_no_sorties(survey):
    world, cp, shots, _ = survey
    big, _ = export_mission(cp.plan, [], ExportOptions(battery_wh=500.0), agl=100.0,
                            camera=shots)
    assert build_sorties(big, cp.plan, ways=straight_ways(world, cp.path[0], agl=100.0)) is None
