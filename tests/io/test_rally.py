"""Rally point files: MAVLink rally mission (QGC WPL 110, 5100 items) and ArduPilot RALLY lines."""

import os

import numpy as np
import pytest

from fm2uav.errors import InputError
from fm2uav.io.rally import (
    parse_rally_text,
    rally_rows,
    read_rally_sites,
    read_rally_waypoints,
    write_rally_txt,
    write_rally_waypoints,
)


@pytest.fixture(scope="module")
def files(returns_mission, tmp_path_factory):
    d = tmp_path_factory.mktemp("rally")
    with open(d / "rally.waypoints", "w") as fh:
        write_rally_waypoints(fh, returns_mission)
    with open(d / "rally.txt", "w") as fh:
        write_rally_txt(fh, returns_mission)
    return d


_LOAD = """
import json, sys
from pymavlink import mavutil, mavwp
new = mavwp.MissionItemProtocol_Rally()
new.load(sys.argv[1])
old = mavwp.MAVRallyLoader()
old.load(sys.argv[2])
print(json.dumps({
    "new": [[w.command, w.frame, w.x, w.y, w.z] for w in new.wpoints],
    "old": [[p.lat, p.lng, p.alt] for p in old.rally_points],
    "cmd": mavutil.mavlink.MAV_CMD_NAV_RALLY_POINT,
    "frame": mavutil.mavlink.MAV_FRAME_GLOBAL_RELATIVE_ALT}))
"""


def test_pymavlink_loads_both_files(returns_mission, files):
    import json
    import subprocess
    import sys

    # the rally mission protocol needs MAVLink 2, chosen when pymavlink is first imported
    env = {**os.environ, "MAVLINK20": "1"}
    out = subprocess.run([sys.executable, "-c", _LOAD, str(files / "rally.waypoints"),
                          str(files / "rally.txt")], env=env, capture_output=True, text=True,
                         check=True)
    got = json.loads(out.stdout)
    rows = rally_rows(returns_mission)
    assert len(rows) == 1 and len(got["new"]) == 1 and len(got["old"]) == 1
    cmd, frame, la, lo, alt = got["new"][0]
    assert (cmd, frame) == (got["cmd"], got["frame"])
    assert (la, lo, alt) == pytest.approx(rows[0], abs=1e-7)
    lat, lng, alt_i = got["old"][0]
    assert lat == int(rows[0][0] * 1e7) and alt_i == int(np.ceil(rows[0][2] - 1e-6))
    assert read_rally_waypoints(files / "rally.waypoints") == [
        pytest.approx(r) for r in rows]


def test_the_altitude_is_the_firmwares_rally_altitude(returns_mission):
    alt = returns_mission.returns.firmware.rally_altitudes["rally 1"]
    assert rally_rows(returns_mission)[0][2] == alt


def test_rally_text():
    assert parse_rally_text("auto") == ("auto", 3)
    assert parse_rally_text("AUTO:5") == ("auto", 5)
    assert parse_rally_text("-3.7, 40.3") == (-3.7, 40.3, None)
    for bad, match in (("auto:0", "1 <= K"), ("auto:x", "1 <= K"), ("1,2,3,4", "LON,LAT"),
                       ("200,10", "longitude"), ("1,2,0", "> 0 m")):
        with pytest.raises(InputError, match=match):
            parse_rally_text(bad)


def test_rally_sites_from_csv_and_geojson(tmp_path):
    from fm2uav.scenarios import get_scenario
    from fm2uav.world.geo import to_lonlat

    w = get_scenario("open-field").world
    lo, la, _ = to_lonlat(w, [[300.0, 400.0, 0.0]])[0]
    (tmp_path / "r.csv").write_text(f"lon,lat,agl\n{lo},{la},45\n")
    (tmp_path / "r.geojson").write_text(
        '{"type": "FeatureCollection", "features": [{"type": "Feature", "properties": '
        f'{{"agl": 35}}, "geometry": {{"type": "Point", "coordinates": [{lo}, {la}]}}}}]}}')
    for name, agl in (("r.csv", 45.0), ("r.geojson", 35.0)):
        (x, y, a), = read_rally_sites(tmp_path / name, w)
        assert (x, y, a) == (pytest.approx(300.0, abs=1e-3), pytest.approx(400.0, abs=1e-3), agl)
    (tmp_path / "bad.csv").write_text("lon,lat\n1,2,3,4\n")
    with pytest.raises(InputError, match="row 2"):
        read_rally_sites(tmp_path / "bad.csv", w)
