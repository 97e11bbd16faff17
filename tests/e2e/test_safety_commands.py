"""Flight-safety options on `fm2uav cover` / `fm2uav formation` (issue 13 on every command),
the coverage route around no-fly zones, and the report's filled-nodata hatch (issue 12)."""

from __future__ import annotations

import json

import numpy as np
import pytest
import shapely
from shapely.geometry import Polygon
from typer.testing import CliRunner

from fm2uav.cli import app
from fm2uav.missions.coverage import plan_coverage
from fm2uav.planning import FlightLevel
from fm2uav.world import World
from fm2uav.world.zones import Zone, with_zones, zone_violations

STRIP = [[570, 335], [650, 335], [650, 805], [570, 805]]  # across coverage area S3 (x 110-1110)
BOX = [[1000, 480], [1100, 480], [1100, 720], [1000, 720]]  # across the fissure route (y 600)


def _zone_file(tmp_path, name, ring, buffer=20):
    p = tmp_path / f"{name}.geojson"
    p.write_text(json.dumps({"type": "FeatureCollection", "features": [
        {"type": "Feature", "properties": {"name": name, "buffer": buffer},
         "geometry": {"type": "Polygon", "coordinates": [ring + [ring[0]]]}}]}))
    return p


def _xy(csv_text):
    rows = [ln for ln in csv_text.splitlines() if ln and not ln.startswith("#")][1:]
    return np.array([[float(v) for v in ln.split(",")[:2]] for ln in rows])


def _plan_legs_outside_fences(plan):
    """Every straight leg between the .plan's position items (lat, lon) stays outside each
    exclusion fence polygon (read from the same file); returns the fence count."""
    items = [i for i in plan["mission"]["items"] if i.get("command") in (16, 22)]
    latlon = np.array([i["params"][4:6] for i in items], dtype=float)
    fences = plan["geoFence"]["polygons"]
    for f in fences:
        assert f["inclusion"] is False
        assert not shapely.intersects(shapely.LineString(latlon), shapely.Polygon(f["polygon"]))
    return len(fences)


def _legs_outside(points, keep_out):
    """True if no straight leg between successive points touches ``keep_out``."""
    return not shapely.intersects(shapely.LineString(np.asarray(points)[:, :2]), keep_out)


def test_coverage_goes_around_a_zone_across_the_area():
    """Tiny world: the zigzag crosses a no-fly strip; the coverage becomes an FM² route
    around it that never enters the strip or its buffer, and covers the rest."""
    x = np.arange(60) * 10.0
    heights = 20.0 + 10.0 * np.sin(x / 90.0)[:, None] * np.ones((1, 40))
    world = World.from_heightmap(heights, 10.0, 20)
    area = Polygon([(60, 60), (540, 60), (540, 330), (60, 330)])
    zone = Zone(Polygon([(270, 20), (330, 20), (330, 370), (270, 370)]), name="strip",
                buffer=10)
    wz = with_zones(world, [zone])
    cp = plan_coverage(wz, area, 60.0, level=FlightLevel(agl=60.0), angle=0.0)
    assert cp.params["grid"] == "route"
    assert zone_violations(wz, cp.path) == []
    assert _legs_outside(cp.path, zone.keep_out())
    # both sides of the strip are flown: the bands left and right of it are covered
    xs = cp.path[:, 0]
    assert xs.min() < 100 and xs.max() > 500
    kept = area.difference(zone.keep_out()).area / area.area
    assert 0.8 * kept < cp.coverage <= 1.0
    # without zones the corridor method is used as before
    assert plan_coverage(world, area, 60.0, level=FlightLevel(agl=60.0),
                         angle=0.0).params["grid"] == "corridor"


@pytest.mark.slow
def test_cover_cli_no_fly_strip_path_legs_geofence_report(tmp_path):
    z = _zone_file(tmp_path, "strip", STRIP)
    out = tmp_path / "c"
    res = CliRunner().invoke(app, [
        "cover", "--area", "S3", "--spacing", "80", "--agl", "100", "--angle", "0",
        "--no-fly", str(z), "--min-agl", "60", "--max-agl", "150",
        "--saturation-distance", "100", "--report", "--out", str(out), "--quiet"])
    assert res.exit_code == 0, res.output
    keep_out = shapely.Polygon(STRIP).buffer(20)
    path = _xy((out / "path.csv").read_text())
    assert _legs_outside(path, keep_out)
    s = json.loads((out / "summary.json").read_text())
    assert s["params"]["grid"] == "route"
    assert s["safety"]["zones"]["count"] == 1 and s["safety"]["zones"]["path_entries"] == []
    assert all(c["ok"] for c in s["safety"]["checks"].values())
    assert s["safety"]["legs"]["min_m"] >= 60.0 - 1e-6
    assert s["safety"]["legs"]["zone_entries"] == []
    # the .plan carries the zone in geoFence, and every leg of its waypoints stays outside it
    assert _plan_legs_outside_fences(json.loads((out / "mission.plan").read_text())) == 1
    html = (out / "report.html").read_text()
    assert "no-fly zone: strip" in html and "(buffer 20 m)" in html


@pytest.mark.parametrize("cmd", [
    ["cover", "--area", "S3", "--spacing", "80", "--agl", "100", "--max-agl", "90"],
    ["formation", "--agl", "100", "--max-agl", "90", "--no-gif"],
])
def test_max_agl_below_agl_is_refused_in_one_line(tmp_path, cmd):
    res = CliRunner().invoke(app, cmd + ["--out", str(tmp_path / "x")])
    assert res.exit_code == 2, res.output
    msg = res.output.strip()
    assert len(msg.splitlines()) == 1 and "--max-agl" in msg
    assert not (tmp_path / "x").exists()


def test_limits_without_agl_name_the_flag(tmp_path):
    res = CliRunner().invoke(app, ["formation", "--min-agl", "30", "--no-gif",
                                   "--out", str(tmp_path / "x")])
    assert res.exit_code == 2
    assert "--min-agl" in res.output and "--agl" in res.output
    assert len(res.output.strip().splitlines()) == 1


def test_safety_flags_in_help():
    for cmd in ("cover", "formation"):
        res = CliRunner().invoke(app, [cmd, "--help"], env={"COLUMNS": "200"})
        for flag in ("--no-fly", "--min-agl", "--max-agl", "--saturation-distance"):
            assert flag in res.output, (cmd, flag)


@pytest.mark.slow
def test_formation_cli_no_fly_box_every_uav_and_leg_outside(tmp_path):
    z = _zone_file(tmp_path, "box", BOX, buffer=15)
    out = tmp_path / "f"
    res = CliRunner().invoke(app, ["formation", "--no-gif", "--no-fly", str(z),
                                   "--saturation-distance", "150", "--out", str(out),
                                   "--quiet"])
    assert res.exit_code == 0, res.output
    keep_out = shapely.Polygon(BOX).buffer(15)
    s = json.loads((out / "summary.json").read_text())
    assert s["completed"]
    names = ["leader", "follower1", "follower2"]
    for n in names:
        track = _xy((out / f"{n}_path.csv").read_text())
        assert _legs_outside(track, keep_out), n
        plan = json.loads((out / f"{n}_mission.plan").read_text())
        assert _plan_legs_outside_fences(plan) == 1, n
    for n in ("leader", "follower 1", "follower 2"):
        assert s["safety"][n]["zones"]["path_entries"] == []
        assert s["safety"][n]["legs"]["zone_entries"] == []
    # the trajectories themselves (every simulated sample) stay outside the zone
    rows = [r.split(",") for r in (out / "trajectories.csv").read_text().splitlines()[1:]]
    for n in ("leader", "follower 1", "follower 2"):
        xy = np.array([[float(r[2]), float(r[3])] for r in rows if r[1] == n])
        assert len(xy) > 10 and not shapely.intersects(shapely.LineString(xy), keep_out), n


def test_filled_nodata_hatch_in_report():
    from fm2uav.viz.overlays import FILLED_NAME, filled_overlay
    from fm2uav.viz.report import report_html

    world = World.from_heightmap(np.full((12, 10), 5.0), 10.0, 4)
    assert filled_overlay(world) == {}
    mask = np.zeros((12, 10), bool)
    mask[2:5, 3:6] = True
    import dataclasses

    wf = dataclasses.replace(world, filled=mask)
    ov = filled_overlay(wf)[FILLED_NAME]
    seg = ov["points"][np.all(np.isfinite(ov["points"]), axis=1)]
    assert seg[:, 0].min() == pytest.approx(15.0) and seg[:, 0].max() == pytest.approx(45.0)
    assert set(np.round(seg[:, 1])) <= {30.0, 40.0, 50.0}
    path = np.array([[5.0, 5.0, 30.0], [100.0, 80.0, 30.0]])
    html = report_html(wf, {"p": path}, title="t", overlays=filled_overlay(wf))
    assert FILLED_NAME in html


def test_plan_report_hatches_filled_nodata(tmp_path):
    """`fm2uav plan --dem ... --nodata fill --report`: the filled DEM gaps are in report.html."""
    from fm2uav.viz.overlays import FILLED_NAME

    from tests.world import geodata_data as gd

    dem = gd.dem_4326(tmp_path / "country_4326.tif")
    out = tmp_path / "p"
    res = CliRunner().invoke(app, [
        "plan", "--dem", str(dem), "--nodata", "fill", "--lonlat", "--start",
        f"{gd.START[0]},{gd.START[1]}", "--goal", f"{gd.GOAL[0]},{gd.GOAL[1]}", "--agl", "120",
        "--cell-size", "200", "--report", "--out", str(out), "--quiet"])
    assert res.exit_code == 0, res.output
    s = json.loads((out / "summary.json").read_text())
    assert s["world"]["filled_nodes"] > 0
    assert FILLED_NAME in (out / "report.html").read_text()
