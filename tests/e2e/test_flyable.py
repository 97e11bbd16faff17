"""Missions the autopilot flies as planned (issue 24): ``fm2uav run`` of a fixed-wing
ArduPilot terrain-following mission, checked against the firmware's documented behaviour
and flown by :mod:`tests.e2e.ardupilot_sim` (ArduPlane's navigation written from its
documentation, reading only the written files: ``mission.waypoints`` with pymavlink and
the ``terrain/`` files for the terrain frame).

What each test holds the export to (the SITL findings of issue 24):

* climb-out — ``NAV_TAKEOFF`` ends at its altitude on the launch heading (Plane wiki,
  "TAKEOFF Mode"); the next item must be a ``NAV_LOITER_TO_ALT`` or a waypoint ahead on
  that course, and no altitude before the route may lie below the take-off altitude (the
  SITL flight overflew waypoints 53 m from home and 50 m lower and looped back, 171 m
  cross-track);
* speeds — ``DO_CHANGE_SPEED`` (178) param1 0 = airspeed for a plane, taken only within
  ``AIRSPEED_MIN`` .. ``AIRSPEED_MAX`` (``Plane::do_change_speed``); without one before the
  first waypoint ArduPlane flies ``AIRSPEED_CRUISE``, whatever the estimate assumed;
* flown time within 15 % of the summary's;
* terrain — a terrain-frame mission does not arm without the vehicle's terrain
  ("PreArm: waiting for terrain data"): the files come with it;
* landing — ``DO_LAND_START`` then the approach and ``NAV_LAND`` (Plane wiki "Automatic
  Landing"), a glide the sink limit can hold.
"""

from __future__ import annotations

import json
import math
import re
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from fm2uav.cli import app
from fm2uav.io.terrain_dat import read_terrain_folder

from .ardupilot_sim import PlaneSim, cross_track, read_waypoints

pytestmark = pytest.mark.slow

#: The airframe of the mission file (and the simulated ArduPlane's parameters).
CRUISE, MIN_SPEED, TECS_SINK_MAX = 18.0, 12.0, 5.0
PARAMS = {"AIRSPEED_CRUISE": CRUISE, "AIRSPEED_MIN": MIN_SPEED, "AIRSPEED_MAX": 22.0}

MISSION = """\
version: 1
name: fixed-wing terrain following
world: {{scenario: open-field, seed: 0, anchor: {{lon: -3.7649, lat: 40.3326, alt: 0}}}}
start: {{cell: [20, 20, 20]}}
goal: {{cell: [100, 80, 30]}}
planner: {{agl: 150, p1: 0.5, p2: 1.3}}
airframe: {{type: fixed_wing, firmware: ardupilot, cruise_speed: {cruise}, min_speed: {mn},
           max_speed: 22}}
outputs:
  formats: [csv, wpl, json]
  speed_changes: true
  end: {end}
"""


def _run(tmp: Path, end: str) -> tuple[Path, str]:
    spec = tmp / f"fw_{end}.yaml"
    spec.write_text(MISSION.format(cruise=CRUISE, mn=MIN_SPEED, end=end))
    out = tmp / f"out_{end}"
    res = CliRunner().invoke(app, ["run", str(spec), "--out", str(out)],
                             env={"COLUMNS": "400"})
    assert res.exit_code == 0, res.output
    return out, res.output


@pytest.fixture(scope="module", params=["rtl", "land"])
def flown(request, tmp_path_factory):
    """The mission written by ``fm2uav run`` and flown by the simulated ArduPlane."""
    out, text = _run(tmp_path_factory.mktemp("flyable"), request.param)
    home, items = read_waypoints(out / "mission.waypoints")
    terrain = read_terrain_folder(out / "terrain")
    ground = lambda lat, lon: float(terrain.height([lat], [lon])[0])  # noqa: E731
    takeoff = next(it for it in items if it.command == 22)
    ne = PlaneSim(home, items, heading_deg=0.0).ne(takeoff.lat, takeoff.lon)
    sim = PlaneSim(home, items, heading_deg=math.degrees(math.atan2(ne[1], ne[0])),
                   params=PARAMS, ground=ground)
    flight = sim.fly()
    summary = json.loads((out / "summary.json").read_text())["autopilot"]
    return {"out": out, "text": text, "home": home, "items": items, "sim": sim,
            "flight": flight, "summary": summary, "ground": ground, "end": request.param}


def _amsl(it, home, ground):
    return {0: it.alt, 3: it.alt + home[2], 10: it.alt + ground(it.lat, it.lon)
            if it.frame == 10 else None}[it.frame]


def test_the_climb_out_never_falls_back_below_the_takeoff_altitude(flown):
    items, home, sim = flown["items"], flown["home"], flown["sim"]
    k = next(i for i, it in enumerate(items) if it.command == 22)
    takeoff = items[k]
    assert takeoff.frame == 3 and takeoff.alt > 0
    top = home[2] + takeoff.alt
    nxt = next(it for it in items[k + 1:] if it.command in (16, 31))
    course = sim.ne(takeoff.lat, takeoff.lon)
    if nxt.command == 16:  # a waypoint ahead on the take-off course, past the climb
        p = sim.ne(nxt.lat, nxt.lon)
        ang = math.degrees(math.acos(float(p @ course) / (np.hypot(*p) * np.hypot(*course))))
        assert ang <= 30.0 and np.hypot(*p) >= takeoff.alt * CRUISE / 5.0
    # from the take-off to the first route waypoint, every altitude stays at or above it
    first_wp = next(i for i, it in enumerate(items) if it.command == 16)
    for it in items[k + 1:first_wp + 1]:
        if it.command in (16, 31):
            assert _amsl(it, home, flown["ground"]) >= top - 0.5, it
    # and the flown climb-out does too (TECS never sinks back before the route)
    f = flown["flight"]
    z = f.array()[:, 2]
    t_top = next(t for t, zz in zip(f.t, z) if zz >= top - 0.5)
    route = next(t for (i, t, _) in f.reached if items[i].command == 16)
    seg = (np.asarray(f.t) > t_top) & (np.asarray(f.t) < route)
    assert z[seg].min() >= top - 1.0


def test_every_waypoint_is_flown_to_in_order_close_to_its_leg(flown):
    f, items = flown["flight"], flown["items"]
    assert f.done  # reached the end (RTL home, or touched down)
    wps = [i for i, it in enumerate(items) if it.command == 16]
    reached = [i for (i, _, _) in f.reached if items[i].command == 16]
    assert reached == wps  # none skipped, none flown twice (no loop back)
    times = [t for (i, t, _) in f.reached if items[i].command == 16]
    assert np.all(np.diff(times) >= 1.0)  # none reached at once on reaching the one before
    xt = cross_track(f, flown["sim"])
    # the judged bound (issue 24): two turn radii at cruise speed and ArduPlane's bank limit
    # (ROLL_LIMIT_DEG 45); the SITL finding was 171 m
    radius = CRUISE ** 2 / (9.80665 * math.tan(math.radians(45.0)))
    assert max(xt.values()) <= 2.0 * radius, (xt, radius)


def test_flown_time_is_the_summary_time_within_15_percent(flown):
    est = flown["summary"]["flight"]["flight_time_s"]
    assert abs(flown["flight"].t[-1] - est) <= 0.15 * est


def test_an_airspeed_in_the_airframe_range_is_commanded_before_the_route(flown):
    items = flown["items"]
    first_wp = next(i for i, it in enumerate(items) if it.command == 16)
    changes = [(i, it.p) for i, it in enumerate(items) if it.command == 178]
    assert changes and changes[0][0] < first_wp
    for _, p in changes:
        assert int(p[0]) == 0  # airspeed (ArduPlane: type 1 would set MIN_GROUNDSPEED)
        assert MIN_SPEED <= p[1] <= PARAMS["AIRSPEED_MAX"]
    assert flown["sim"].v_cmd == changes[-1][1][1]  # the firmware took it
    assert re.search(r"speeds\s*│\s*DO_CHANGE_SPEED airspeed", flown["text"])


def test_terrain_files_come_with_the_terrain_frame_mission(flown):
    out, items, home = flown["out"], flown["items"], flown["home"]
    assert any(it.frame == 10 for it in items)
    terrain = read_terrain_folder(out / "terrain")
    assert not terrain.problems
    pts = [(home[0], home[1])] + [(it.lat, it.lon) for it in items if it.lat or it.lon]
    assert np.all(terrain.covers([p[0] for p in pts], [p[1] for p in pts]))
    spacing = flown["summary"]["terrain"]["spacing_m"]
    assert (out / "terrain" / "terrain.param").read_text().split("\n")[1:3] == [
        "TERRAIN_ENABLE 1", f"TERRAIN_SPACING {spacing}"]
    row = " ".join(flown["text"].split())
    assert "APM/terrain/" in row and f"TERRAIN_SPACING={spacing}" in row
    assert "waiting for terrain data" in row


def test_the_landing_glides_from_do_land_start_to_touchdown(flown):
    if flown["end"] != "land":
        pytest.skip("RTL ending")
    items, home = flown["items"], flown["home"]
    cmds = [it.command for it in items]
    assert 189 in cmds and cmds.index(189) < cmds.index(21)  # DO_LAND_START before the land
    k = cmds.index(21)
    land, before = items[k], items[k - 1]
    assert before.command in (16, 31)
    sim = flown["sim"]
    dz = _amsl(before, home, flown["ground"]) - _amsl(land, home, flown["ground"])
    run = float(np.hypot(*(sim.ne(land.lat, land.lon) - sim.ne(before.lat, before.lon))))
    if before.command == 31:  # leaves the loiter on its tangent towards the touchdown
        run = math.sqrt(max(run ** 2 - before.p[1] ** 2, 0.0))
    assert dz >= 0 and math.degrees(math.atan2(dz, run)) <= math.degrees(
        math.asin(TECS_SINK_MAX / CRUISE)) + 0.5
    end = flown["flight"].array()[-1]
    assert np.hypot(*(end[:2] - sim.ne(land.lat, land.lon))) <= 10.0
    assert abs(end[2] - _amsl(land, home, flown["ground"])) <= 10.0
