"""Mission files: the examples run, lon/lat points resolve, and a catalogue of bad files
each gives one specific line (field, bad value, allowed range) and exit code 2."""

import json
import os
import shutil
from pathlib import Path

import numpy as np
import pytest
import rasterio
from rasterio.transform import from_origin
from typer.testing import CliRunner

from fm2uav.cli import app
from fm2uav.errors import InputError
from fm2uav.autopilot import validate_mission
from fm2uav.io import read_plan, read_wpl, to_lonlat, validate_plan
from fm2uav.io.mission import load_mission, parse_mission

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
runner = CliRunner()


def _write_dem(path, crs="EPSG:32630", size=(40, 50)):
    rows, cols = size
    y, x = np.mgrid[0:rows, 0:cols]
    z = (600 + 40 * np.sin(x / 7.0) + 30 * np.cos(y / 9.0)).astype("float32")
    prof = {"driver": "GTiff", "height": rows, "width": cols, "count": 1, "dtype": "float32",
            "transform": from_origin(440000.0, 4471000.0, 30.0, 30.0)}
    if crs:
        prof["crs"] = crs
    with rasterio.open(path, "w", **prof) as ds:
        ds.write(z, 1)
    return path


@pytest.fixture(scope="module")
def examples(tmp_path_factory):
    """A copy of examples/ with the generated GeoTIFF (as a user makes it), in a folder of
    its own named ``examples`` (the docs' commands name ``examples/...``)."""
    import importlib.util

    d = tmp_path_factory.mktemp("user") / "examples"
    shutil.copytree(EXAMPLES, d)
    spec = importlib.util.spec_from_file_location("mk", d / "make_jacksboro_geotiff.py")
    mk = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mk)
    mk.write_geotiff(d / "jacksboro.tif")
    return d


@pytest.mark.parametrize("name", sorted(p.name for p in EXAMPLES.glob("*.yaml")))
def test_every_example_validates(examples, name):
    m = load_mission(examples / name)
    assert m.version == 1 and m.outputs.formats


def _example_run(cli_once, examples: Path, name: str):
    """``fm2uav run examples/NAME --json`` from the folder holding ``examples``: one run per
    example for the session (tests/conftest.py), shared with the docs' run of the same command
    (docs/operator.md runs ``examples/jacksboro_geotiff.yaml`` so)."""
    old = Path.cwd()
    os.chdir(examples.parent)
    try:
        return cli_once(["run", f"examples/{name}", "--json"])
    finally:
        os.chdir(old)


@pytest.mark.parametrize("name", ["open_field_tff.yaml", "town_buildings.yaml",
                                  "jacksboro_geotiff.yaml"])
def test_examples_run_end_to_end(examples, name, cli_once):
    # the default mission's run is shared with
    # test_export_converts_an_existing_path_for_another_firmware
    run = _example_run(cli_once, examples, name)
    res, out = run.result, run.out
    assert res.exit_code == 0, res.output
    summary = json.loads(res.output)
    m = load_mission(examples / name)
    names = {"csv": "path.csv", "geojson": "path.geojson", "kml": "path.kml",
             "kmz": "path.kmz", "plan": "mission.plan", "wpl": "mission.waypoints",
             "html": "report.html", "png": "plan.png", "json": "summary.json"}
    for f in m.outputs.formats:
        assert (out / names[f]).stat().st_size > 0
    assert 3 <= summary["waypoints"] <= 300  # the final profile follows the DEM pixels
    assert validate_plan(json.loads((out / "mission.plan").read_text())) == []
    plan = read_plan(out / "mission.plan")
    wpl = read_wpl(out / "mission.waypoints")
    np.testing.assert_allclose(plan["lat"], wpl["lat"], atol=1e-7, rtol=0)
    # auto frame: ArduPilot flies terrain-frame items, PX4 gets AMSL from the DEM
    want = ({"ardupilot": 10}.get(m.airframe.firmware, 0) if m.planner.agl else 3)
    route = plan["command"] == 16
    assert set(plan["frame"][route]) == {summary["mavlink_frame"]} == {want}
    assert plan["command"][0] in (22, 84) and plan["command"][-1] in (17, 20, 21, 85)
    assert validate_mission(plan["items"], m.airframe.firmware, vehicle=m.airframe.type,
                            home_alt=plan["home"][2]) == []
    assert summary["autopilot"]["home"]["source"]
    # the file on disk says the same as the printed summary
    assert json.loads((out / "summary.json").read_text())["waypoints"] == summary["waypoints"]
    # no overwrite without --force; exit 2, files untouched
    before = (out / "mission.plan").read_bytes()
    res = runner.invoke(app, ["run", str(examples / name), "--out", str(out)])
    assert res.exit_code == 2 and "--force" in res.output
    assert (out / "mission.plan").read_bytes() == before


def test_geotiff_mission_runs_with_lonlat_points(tmp_path):
    _write_dem(tmp_path / "dem.tif")
    (tmp_path / "m.yaml").write_text(
        "world: {dem: dem.tif, cell_size: 60, dz: 20}\n"
        "start: {lon: -3.7033, lat: 40.3847, agl: 100}\n"
        "goal: {lon: -3.6927, lat: 40.3785, agl: 100}\n"
        "planner: {agl: 100}\n"
        "outputs: {formats: [plan, wpl, json]}\n")
    m = load_mission(tmp_path / "m.yaml")
    rm = m.resolve()
    assert rm.world.crs == "EPSG:32630"
    # the resolved start is at that lon/lat (and 100 m above the DEM there)
    lon, lat, _ = to_lonlat(rm.world, rm.start[None])[0]
    assert (lon, lat) == pytest.approx((-3.7033, 40.3847), abs=1e-9)
    res = runner.invoke(app, ["run", str(tmp_path / "m.yaml"), "--out", str(tmp_path / "o"),
                              "--quiet"])
    assert res.exit_code == 0, res.output
    assert res.output == ""
    wpl = read_wpl(tmp_path / "o" / "mission.waypoints")
    assert set(wpl["frame"][wpl["command"] == 16]) == {0}  # PX4: AMSL, never frame 10
    assert (wpl["lat"][0], wpl["lon"][0]) == pytest.approx((40.3847, -3.7033), abs=1e-7)
    assert wpl["command"][0] == 22 and wpl["command"][-1] == 21  # takeoff ... land


def test_lonlat_start_matches_metres_through_the_anchor():
    base = {"world": {"scenario": "open-field", "anchor": {"lon": 2.0, "lat": 45.0}}}
    m = parse_mission({**base, "start": [300, 300, 300]})
    lon, lat, alt = to_lonlat(None, [[300.0, 300.0, 300.0]], anchor=m.anchor())[0]
    m2 = parse_mission({**base, "start": {"lon": lon, "lat": lat, "alt": alt}})
    np.testing.assert_allclose(m2.resolve().start, [300, 300, 300], atol=1e-6)


# ------------------------------------------------------------------ bad mission files
OK_WORLD = "world: {scenario: open-field}\n"
BAD = [
    # (id, yaml text, [substrings the one-line message must contain])
    ("empty", "", ["empty"]),
    ("not-yaml", "world: [scenario: open-field\n", ["not valid YAML", "line"]),
    ("not-mapping", "- 1\n- 2\n", ["must be a mapping"]),
    ("missing-world", "name: x\n", ["world is missing"]),
    ("no-source", "world: {seed: 1}\n", ["world", "exactly one of scenario, dem, buildings"]),
    ("two-sources", "world: {scenario: open-field, dem: a.tif}\n", ["world.dem", "a.tif"]),
    ("unknown-scenario", "world: {scenario: moon}\n",
     ["world.scenario = 'moon'", "unknown scenario", "open-field"]),
    ("unknown-field", OK_WORLD + "planner: {saturaton: 0.5}\n",
     ["planner.saturaton", "not a known field", "saturation"]),
    ("sat-range", OK_WORLD + "planner: {saturation: 1.5}\n",
     ["planner.saturation = 1.5", "out of range", "0 < saturation <= 1"]),
    ("sat-type", OK_WORLD + "planner: {saturation: high}\n",
     ["planner.saturation = 'high'", "wrong type", "number", "0 < saturation <= 1"]),
    ("order", OK_WORLD + "planner: {order: 3}\n", ["planner.order = 3", "1 or 2"]),
    ("agl-neg", OK_WORLD + "planner: {agl: -10}\n",
     ["planner.agl = -10", "0 < agl <= 5000 m"]),
    ("agl-bool", OK_WORLD + "planner: {agl: true}\n", ["planner.agl = True", "wrong type"]),
    # YAML 1.2 core: yes is text, not a boolean (and 5e-1 is a number, below)
    ("agl-yes", OK_WORLD + "planner: {agl: yes}\n", ["planner.agl = 'yes'", "wrong type"]),
    ("seed", "world: {scenario: open-field, seed: -1}\n", ["world.seed = -1", "0 <= seed"]),
    ("seed-type", "world: {scenario: open-field, seed: 1.5}\n",
     ["world.seed = 1.5", "integer"]),
    ("speed", OK_WORLD + "airframe: {cruise_speed: 0}\n",
     ["airframe.cruise_speed = 0", "0 < cruise_speed <= 100 m/s"]),
    ("airframe-type", OK_WORLD + "airframe: {type: blimp}\n",
     ["airframe.type = 'blimp'", "multirotor"]),
    ("airframe-scalar", OK_WORLD + "airframe: fast\n", ["airframe = 'fast'", "mapping"]),
    ("format", OK_WORLD + "outputs: {formats: [plan, pdf]}\n",
     ["outputs.formats[1] = 'pdf'", "'wpl'"]),
    ("tolerance", OK_WORLD + "outputs: {thin_tolerance: -1}\n",
     ["outputs.thin_tolerance = -1", "0 <= thin_tolerance <= 1000 m"]),
    ("frame", OK_WORLD + "outputs: {frame: msl}\n", ["outputs.frame = 'msl'", "'amsl'"]),
    ("end", OK_WORLD + "outputs: {end: crash}\n", ["outputs.end = 'crash'", "'rtl'", "'land'"]),
    ("via", OK_WORLD + "via: [[1, 2]]\n", ["via[0]", "3 numbers"]),
    ("return", OK_WORLD + "return: yes please\n", ["return = 'yes please'", "true or false"]),
    ("endurance", OK_WORLD + "airframe: {endurance: -5}\n", ["airframe.endurance = -5",
                                                             "min"]),
    ("power-preset", OK_WORLD + "airframe: {power: zeppelin}\n",
     ["airframe.power", "no power model for airframe 'zeppelin'", "arducopter"]),
    ("power-parameter", OK_WORLD + "airframe: {power: {preset: disco, wingspan: 2}}\n",
     ["airframe.power", "unknown parameter(s) ['wingspan']", "cd0"]),
    ("battery", OK_WORLD + "airframe: {battery: 0}\n", ["airframe.battery = 0", "Wh"]),
    ("wind-from", OK_WORLD + "wind: {speed: 5, from: 400}\n", ["wind.from = 400", "360"]),
    ("wind-speed", OK_WORLD + "wind: {from: 90}\n", ["wind", "needs speed and from"]),
    ("wind-file", OK_WORLD + "wind: {file: nowhere.nc}\n", ["wind.file", "not found"]),
    ("start-short", OK_WORLD + "start: [1, 2]\n", ["start", "[x, y, z]"]),
    ("start-no-height", OK_WORLD + "start: {x: 1, y: 2}\n", ["start", "exactly one height"]),
    ("start-lon", OK_WORLD + "start: {lon: 200, lat: 40, agl: 50}\n",
     ["start.lon = 200", "-180 <= lon <= 180 deg"]),
    ("start-mixed", OK_WORLD + "start: {x: 1, y: 2, lon: 3, lat: 4, agl: 5}\n",
     ["start", "exactly one of"]),
    ("cell-len", OK_WORLD + "goal: {cell: [1, 2]}\n", ["goal.cell = [1, 2]", "exactly 3"]),
    ("version", "version: 2\n" + OK_WORLD, ["version = 2", "1"]),
    ("scenario-cell-size", "world: {scenario: open-field, cell_size: 10}\n",
     ["cell_size does not apply"]),
    ("dem-missing-file", "world: {dem: nowhere.tif, cell_size: 30}\nstart: [0, 0, 0]\n"
     "goal: [1, 1, 1]\n", ["world.dem = 'nowhere.tif'", "file not found"]),
    ("dem-bbox", "world: {dem: dem.tif, bbox: [-3.69, 40.37, -3.71, 40.39]}\nstart: [0, 0, 0]\n"
     "goal: [1, 1, 1]\n", ["world.bbox", "west < east", "W,S,E,N"]),
    ("dem-bbox-len", "world: {dem: dem.tif, bbox: [-3.69, 40.37]}\n", ["world.bbox", "4"]),
    ("dem-no-crs", "world: {dem: nocrs.tif, cell_size: 30}\nstart: [0, 0, 0]\n"
     "goal: [1, 1, 1]\n", ["world.dem = 'nocrs.tif'", "no coordinate reference system"]),
    ("dem-not-raster", "world: {dem: notes.txt, cell_size: 30}\nstart: [0, 0, 0]\n"
     "goal: [1, 1, 1]\n", ["world.dem = 'notes.txt'", "cannot be read as a raster"]),
    ("dem-no-start", "world: {dem: dem.tif, cell_size: 30}\n", ["start is missing"]),
    ("crs-unknown", "world: {buildings: dem.tif, cell_size: 5, crs: EPSG:999999}\n"
     "start: [0, 0, 0]\ngoal: [1, 1, 1]\n", ["world.crs = 'EPSG:999999'", "not a CRS"]),
    ("sea-level-scenario", "world: {scenario: open-field, sea_level: 0}\n",
     ["sea_level does not apply to a built-in scenario"]),
    ("scenario-and-dem", "world: {scenario: open-field, dem: dem.tif}\n",
     ["either scenario or real data"]),
    ("heights-on-dem", "world: {dem: dem.tif, height_cells: 30}\nstart: [0, 0, 0]\n"
     "goal: [1, 1, 1]\n", ["height_cells only applies to a world with buildings"]),
    # issue 25: integers are never booleans or floats; no NaN/inf; speeds consistent
    ("order-bool", OK_WORLD + "planner: {order: true}\n",
     ["planner.order = True", "wrong type (bool)", "1, 2"]),
    ("order-float", OK_WORLD + "planner: {order: 2.0}\n", ["planner.order = 2.0", "integer"]),
    ("version-bool", "version: true\n" + OK_WORLD, ["version = True", "wrong type (bool)"]),
    ("agl-nan", OK_WORLD + "planner: {agl: .nan}\n", ["planner.agl = nan", "not a finite"]),
    ("start-inf", OK_WORLD + "start: {x: .inf, y: 1, z: 1}\n", ["start.x = inf", "finite"]),
    ("nodata-value-nan", "world: {dem: dem.tif, nodata_value: .nan}\nstart: [0, 0, 0]\n"
     "goal: [1, 1, 1]\n", ["world.nodata_value = nan", "finite"]),
    ("min-speed-multirotor", OK_WORLD + "airframe: {min_speed: 8, hover_speed: 5}\n",
     ["airframe", "min_speed 8 m/s is above hover_speed 5 m/s"]),
    ("min-speed-fixed-wing", OK_WORLD + "airframe: {type: fixed_wing, min_speed: 20, "
     "cruise_speed: 15}\n", ["min_speed 20 m/s is above cruise_speed 15 m/s"]),
    ("walls-yes", OK_WORLD + "planner: {walls: on}\n",
     ["planner.walls = 'on'", "true or false", "YAML 1.2"]),
    ("circle-radius", OK_WORLD + "no_fly_zones: [{circle: {center: [500, 500], radius: -5}}]\n",
     ["no_fly_zones[0].circle.radius = -5", "0 < radius"]),
]


@pytest.fixture
def mission_dir(tmp_path):
    _write_dem(tmp_path / "dem.tif")
    _write_dem(tmp_path / "nocrs.tif", crs=None)
    (tmp_path / "notes.txt").write_text("not a raster\n")
    return tmp_path


@pytest.mark.parametrize("case, text, expected", BAD, ids=[b[0] for b in BAD])
def test_bad_mission_gives_one_specific_line(mission_dir, case, text, expected):
    f = mission_dir / f"{case}.yaml"
    f.write_text(text)
    with pytest.raises(InputError) as err:
        load_mission(f)
    msg = str(err.value)
    assert "\n" not in msg
    assert msg.startswith(str(f))
    for part in expected:
        assert part in msg, msg
    res = runner.invoke(app, ["run", str(f), "--out", str(mission_dir / "out")])
    assert res.exit_code == 2, res.output
    lines = [ln for ln in res.output.splitlines() if ln.strip()]
    assert len(lines) == 1 and lines[0].startswith("error:"), res.output
    assert not (mission_dir / "out").exists()


@pytest.mark.parametrize("text, code, part", [
    # a start inside the terrain is bad input (2), named with the ground height
    (OK_WORLD + "start: [300, 300, 15]\n", 2, "inside an obstacle"),
    (OK_WORLD + "goal: [99999, 0, 300]\n", 2, "goal = (99999.0, 0.0, 300.0) m lies outside"),
    # a flight level above the ceiling cannot be planned (1)
    (OK_WORLD + "planner: {agl: 580}\n", 1, "flight level"),
])
def test_resolve_and_planning_errors_exit_codes(tmp_path, text, code, part):
    f = tmp_path / "m.yaml"
    f.write_text(text)
    res = runner.invoke(app, ["run", str(f), "--out", str(tmp_path / "o")])
    assert res.exit_code == code, res.output
    assert part in res.output and len(res.output.strip().splitlines()) == 1


def test_missing_mission_file(tmp_path):
    res = runner.invoke(app, ["run", str(tmp_path / "nope.yaml")])
    assert res.exit_code == 2 and "not found" in res.output


def test_help_shows_examples():
    for args in (["--help"], ["run", "--help"], ["plan", "--help"]):
        res = runner.invoke(app, args)
        assert res.exit_code == 0 and "Example" in res.output, args
    assert "fm2uav run examples/open_field_tff.yaml" in runner.invoke(app, ["run", "--help"]).output


def test_plan_command_report_and_exports(tmp_path):
    out = tmp_path / "p"
    res = runner.invoke(app, ["plan", "--out", str(out), "--report", "--export", "all",
                              "--anchor", "2.35,48.85,35", "--thin", "10", "--json"])
    assert res.exit_code == 0, res.output
    data = json.loads(res.output)
    # + path.kmz, and the safe returns: returns.geojson, mission.param
    assert len(data["files"]) == 11 and data["waypoints"] < 60
    plan = read_plan(out / "mission.plan")
    assert plan["home"][:2] == pytest.approx((48.85, 2.35), abs=0.05)
    assert (out / "report.html").stat().st_size > 1_000_000
    res = runner.invoke(app, ["plan", "--out", str(tmp_path / "q"), "--export", "pdf"])
    assert res.exit_code == 2 and "'pdf'" in res.output
    assert not (tmp_path / "q").exists()


def test_a_mission_file_with_two_via_points_and_a_return_leg(tmp_path):
    f = tmp_path / "via.yaml"
    f.write_text(
        "world: {scenario: open-field}\n"
        "start: {x: 300, y: 300, agl: 150}\n"
        "via: [{x: 1400, y: 300, agl: 150}, {x: 500, y: 1100, agl: 150}]\n"
        "goal: {x: 1500, y: 1200, agl: 150}\n"
        "return: true\n"
        "planner: {agl: 150}\n"
        "airframe: {type: multirotor, firmware: ardupilot, endurance: 30}\n"
        "outputs: {formats: [plan, wpl, json], thin_tolerance: 10}\n")
    out = tmp_path / "o"
    res = runner.invoke(app, ["run", str(f), "--out", str(out), "--json"])
    assert res.exit_code == 0, res.output
    summary = json.loads(res.output)
    assert summary["route"]["legs"] == 4
    m = load_mission(f)
    rm = m.resolve()
    plan = read_plan(out / "mission.plan")
    geo = to_lonlat(rm.world, np.array([*rm.via, rm.goal]), anchor=m.anchor())
    found = []
    for lon, lat, _ in geo:  # each via (and the goal, passed on the way back) is a waypoint
        hit = np.flatnonzero((np.abs(plan["lat"] - lat) < 1e-9) & (np.abs(plan["lon"] - lon) < 1e-9)
                             & (plan["command"] == 16))
        assert hit.size, (lon, lat)
        found.append(int(hit[0]))
    assert found == sorted(found)  # in order
    assert plan["command"][-1] == 21  # lands where it started
    assert (plan["lat"][-1], plan["lon"][-1]) == pytest.approx(plan["home"][:2], abs=1e-9)
    assert summary["autopilot"]["flight"]["endurance_s"] == 1800


def test_export_converts_an_existing_path_for_another_firmware(examples, tmp_path, cli_once):
    # the default mission's run of test_examples_run_end_to_end (one run per session)
    run = _example_run(cli_once, examples, "open_field_tff.yaml")
    res, out = run.result, run.out
    assert res.exit_code == 0, res.output
    conv = tmp_path / "conv"
    res = runner.invoke(app, ["export", str(out / "path.csv"), "--mission",
                              str(examples / "open_field_tff.yaml"), "--format", "plan",
                              "--format", "waypoints,kmz", "--firmware", "ardupilot",
                              "--end", "rtl", "--out", str(conv), "--json"])
    assert res.exit_code == 0, res.output
    s = json.loads(res.output)["autopilot"]
    assert (s["firmware"], s["frame"]["name"], s["end"]) == ("ardupilot", "terrain", "rtl")
    assert {p.name for p in conv.iterdir()} == {"mission.plan", "mission.waypoints", "path.kmz",
                                                "summary.json", "terrain"}
    # a terrain-frame ArduPilot mission comes with the vehicle's terrain (issue 24)
    assert {p.suffix for p in (conv / "terrain").iterdir()} == {".DAT", ".param"}
    assert s["terrain"]["files"] and "TERRAIN_SPACING" in s["terrain"]["load"]
    a, b = read_plan(out / "mission.plan"), read_plan(conv / "mission.plan")
    wa, wb = a["command"] == 16, b["command"] == 16
    assert set(a["frame"][wa]) == {0} and set(b["frame"][wb]) == {10}
    assert (b["lat"][wb][-1], b["lon"][wb][-1]) == (a["lat"][wa][-1], a["lon"][wa][-1])
    # the same settings give the same mission back from path.csv (6 decimals: 1 um)
    same = tmp_path / "same"
    res = runner.invoke(app, ["export", str(out / "path.csv"), "--mission",
                              str(examples / "open_field_tff.yaml"), "--out", str(same)])
    assert res.exit_code == 0, res.output
    c = read_plan(same / "mission.plan")
    np.testing.assert_array_equal(c["command"], a["command"])
    np.testing.assert_allclose(c["lat"], a["lat"], atol=1e-9)
    np.testing.assert_allclose(c["alt"], a["alt"], atol=1e-3)
    res = runner.invoke(app, ["export", str(out / "path.csv"), "--scenario", "city",
                              "--out", str(tmp_path / "bad")])
    assert res.exit_code == 2 and "outside" in res.output
    res = runner.invoke(app, ["export", str(out / "path.csv"), "--out", str(tmp_path / "x")])
    assert res.exit_code == 2 and "--mission" in res.output


def test_run_flags_override_the_mission_export_and_route(examples, tmp_path):
    out = tmp_path / "o"
    res = runner.invoke(app, ["run", str(examples / "open_field_tff.yaml"), "--out", str(out),
                              "--firmware", "ardupilot", "--end", "rtl", "--frame", "relative",
                              "--via", "1400,300,480", "--return", "--json"])
    assert res.exit_code == 0, res.output
    s = json.loads(res.output)
    assert s["route"]["legs"] == 3
    a = s["autopilot"]
    assert (a["firmware"], a["frame"]["name"], a["end"]) == ("ardupilot", "relative", "rtl")
    assert not any("straight line home" in w for w in a["warnings"])  # the route came back
    res = runner.invoke(app, ["run", str(examples / "open_field_tff.yaml"), "--out",
                              str(tmp_path / "p"), "--frame", "terrain"])
    assert res.exit_code == 2 and "px4 would reject" in res.output and "outputs.frame" in res.output
    res = runner.invoke(app, ["run", str(examples / "open_field_tff.yaml"), "--out",
                              str(tmp_path / "q"), "--via", "1,2"])
    assert res.exit_code == 2 and "--via 1 must be x,y,z" in res.output


# ------------------------------------------------------------ YAML 1.2 numbers (issue 25)
def test_exponent_numbers_are_numbers(tmp_path):
    f = tmp_path / "m.yaml"
    f.write_text(OK_WORLD + "planner: {exponent: 5e-1, saturation: 1E-1, agl: 1.5e2}\n")
    m = load_mission(f)
    assert (m.planner.exponent, m.planner.saturation, m.planner.agl) == (0.5, 0.1, 150.0)


# ------------------------------------------- one rule for relative paths (issue 25)
def test_outputs_dir_is_relative_to_the_mission_file(tmp_path, monkeypatch):
    """outputs.dir is read like world.dem: against the mission file's folder, wherever
    the command runs; where that differs from the old reading, a warning says so."""
    proj = tmp_path / "proj"
    proj.mkdir()
    f = proj / "m.yaml"
    f.write_text(OK_WORLD + "outputs: {dir: results, formats: [csv]}\n")
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    monkeypatch.chdir(elsewhere)
    m = load_mission(f)
    assert m.output_dir() == proj / "results"
    notice = m.output_dir_notice()
    assert "relative to the mission file's folder" in notice
    assert str(proj / "results") in notice and str(elsewhere / "results") in notice
    res = runner.invoke(app, ["run", str(f)])
    assert res.exit_code == 0, res.output
    assert (proj / "results" / "path.csv").exists() and list(elsewhere.iterdir()) == []
    assert "warning: outputs.dir 'results' is relative to the mission file's folder" \
        in res.output
    # run from the mission's folder: both readings agree, no warning
    monkeypatch.chdir(proj)
    assert load_mission("m.yaml").output_dir_notice() is None
    res = runner.invoke(app, ["run", "m.yaml", "--force"])
    assert res.exit_code == 0 and "warning: outputs.dir" not in res.output, res.output
    # --out and absolute paths are taken as given
    assert parse_mission({"world": {"scenario": "open-field"},
                          "outputs": {"dir": str(tmp_path / "abs")}},
                         base_dir=proj).output_dir() == tmp_path / "abs"
    assert parse_mission({"world": {"scenario": "open-field"},
                          "outputs": {"dir": "rel"}}).output_dir() == Path("rel")


def test_rally_and_returns_keys(tmp_path):
    from fm2uav.io.mission import parse_mission
    from fm2uav.scenarios import get_scenario

    base = {"world": {"scenario": "open-field"}}
    m = parse_mission({**base, "rally": "auto:2", "returns": {"strict": True, "min_agl": 25}})
    w = get_scenario("open-field").world
    ro = m.return_options(w)
    assert ro.auto_rally == 2 and ro.strict and ro.min_agl == 25 and ro.rally == ()
    m = parse_mission({**base, "rally": [{"x": 300, "y": 400, "agl": 50},
                                         {"lon": -3.76, "lat": 40.336}]})
    ro = m.return_options(w)
    assert ro.rally[0] == (300.0, 400.0, 50.0) and ro.rally[1][2] is None
    (tmp_path / "r.csv").write_text("-3.76,40.336\n")
    m = parse_mission({**base, "rally": "r.csv"}, base_dir=tmp_path)
    assert len(m.return_options(w).rally) == 1
    assert parse_mission({**base, "returns": {"enabled": False}}).returns.enabled is False
    for bad, part in (({"rally": "auto:11"}, "auto:K"), ({"rally": "missing.csv"},
                      "file not found"), ({"rally": [{"x": 1}]}, "lon and lat"),
                      ({"returns": {"min_agl": -1}}, "returns.min_agl")):
        with pytest.raises(InputError, match=part):
            parse_mission({**base, **bad}, base_dir=tmp_path)


def test_parse_world_checks_the_world_section_alone_in_the_mission_words(tmp_path):
    from fm2uav.io.mission import parse_world

    bad = tmp_path / ("a-long-folder-name-" * 4) / "not-a-raster.tif"
    bad.parent.mkdir()
    bad.write_text("text")
    with pytest.raises(InputError) as e:
        parse_world({"dem": str(bad)}, source="m.yaml")
    msg = str(e.value)
    assert msg.startswith("m.yaml: world.dem = '/") and "...'" not in msg
    assert "/not-a-raster.tif' cannot be read as a raster" in msg   # the file's name kept
    data = Path(__file__).resolve().parents[2] / "examples" / "data"
    with pytest.raises(InputError, match=r"^m.yaml: world.cell_size = -1 is out of range"):
        parse_world({"buildings": "town.geojson", "cell_size": -1}, source="m.yaml",
                    base_dir=data)
    with pytest.raises(InputError, match="world must be a mapping"):
        parse_world(["x"])
    spec = parse_world({"buildings": "town.geojson"}, base_dir=data)
    assert spec.buildings.endswith("examples/data/town.geojson")
