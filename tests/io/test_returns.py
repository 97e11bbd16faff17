"""returns.geojson: the ways back, the rally points and the point of no return on a map."""

import json

import numpy as np
import pytest

from fm2uav.io.returns import read_returns, write_returns
from fm2uav.world.geo import from_lonlat


def test_every_waypoint_has_its_way_back_as_timed(returns_mission, tmp_path):
    f = tmp_path / "returns.geojson"
    with open(f, "w") as fh:
        doc = write_returns(fh, returns_mission)
    assert json.loads(f.read_text()) == doc  # RFC 7946: plain JSON, no NaN
    feats = read_returns(f)
    rep = returns_mission.returns
    n = len(returns_mission.waypoints)
    backs = [k for k in feats if k.startswith("return from waypoint")]
    # the last waypoint is over home (the mission carries its return): no way back to draw
    assert len(backs) >= n - 1
    home = feats["home"][1]
    assert home == pytest.approx([returns_mission.home[1], returns_mission.home[0],
                                  returns_mission.home[2]], abs=1e-3)
    props, coords = feats["return from waypoint 1"]
    i = int(np.flatnonzero(rep.samples.waypoint == 1)[0])
    xyz = from_lonlat(returns_mission.world, np.asarray(coords))
    assert np.allclose(xyz, rep.paths[i], atol=1e-3)
    assert props["time_s"] == pytest.approx(rep.time[i], abs=0.01)
    assert props["to"] == rep.to[i]
    assert feats["rally 1"][0]["kind"] == "rally"


def test_the_point_of_no_return_is_on_the_map_when_there_is_one(tmp_path):
    from tests.autopilot.return_cases import build, ridge_plan

    m = build(ridge_plan(), endurance_s=240.0, end="rtl")
    f = tmp_path / "r.geojson"
    with open(f, "w") as fh:
        write_returns(fh, m)
    feats = read_returns(f)
    props, pt = feats["point of no return"]
    assert props["distance_m"] == m.returns.pnr["distance_m"]
    line = feats["return from the point of no return"][1]
    assert line[0] == pytest.approx(pt, abs=1e-6)
