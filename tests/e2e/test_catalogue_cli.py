"""Bad-input catalogue: CLI options (issue 17 item 5).

Every case exits with code 2 (bad input), prints one ``error:`` line containing the
fragment — verbatim, never read as rich markup — and no traceback. The cases fail before
any planning, so the whole set runs in seconds.
"""

from __future__ import annotations

import os

import pytest
from typer.testing import CliRunner

from fm2uav.cli import app

runner = CliRunner()


def _files(tmp):
    """Bad files the cases point at."""
    (tmp / "dir.tif").mkdir()
    os.mkfifo(tmp / "pipe.geojson")
    os.mkfifo(tmp / "pipe.yaml")
    (tmp / "junk.tif").write_bytes(b"junk")
    from .conftest import relief, write_dem

    write_dem(tmp / "dem.tif", relief(60))
    (tmp / "bin.yaml").write_bytes(b"name: \xff\xfe\n")
    (tmp / "dup.yaml").write_text("version: 1\nname: a\nname: b\n")
    (tmp / "deep.yaml").write_text("[" * 4000)
    (tmp / "path.csv").write_text("x,y,z\n1,2,3\n")
    (tmp / "good.csv").write_text("x,y,z\n0,0,100\n100,0,100\n200,50,110\n300,100,120\n")
    (tmp / "bad.csv").write_text("x,y\nfoo,bar\n")
    (tmp / "binary.csv").write_bytes(b"\x89PNG\r\n\x1a\n\x00\x00")
    (tmp / "area.geojson").write_text("{broken")
    (tmp / "b[red]x[").mkdir()  # a path containing "[/b]"
    (tmp / "b[red]x[/b].yaml").write_text("version: 1\nversion: 2\n")
    _files_25(tmp)


OPEN = "world: {scenario: open-field}\nstart: {cell: [20, 20, 20]}\ngoal: {cell: [100, 80, 30]}\n"
JACKSBORO = "world: {scenario: jacksboro}\n"
SWAPPED = ('{"type": "FeatureCollection", "features": [{"type": "Feature", "properties": {}, '
           '"geometry": {"type": "Polygon", "coordinates": [[[36.55, -84.30], [36.55, -84.25], '
           '[36.60, -84.25], [36.55, -84.30]]]}}]}')


def _files_25(tmp):
    """Issue 25's bad inputs: YAML types, airframe speeds, zones, CSV columns, sizes."""
    texts = {
        "order_true.yaml": OPEN + "planner: {order: true}\n",
        "version_true.yaml": "version: true\n" + OPEN,
        "walls_yes.yaml": OPEN + "planner: {walls: yes}\n",
        "min_speed.yaml": OPEN + "airframe: {min_speed: 8, hover_speed: 5}\n",
        "min_speed_fw.yaml": OPEN + "airframe: {type: fixed_wing, cruise_speed: 15, "
                             "min_speed: 18}\n",
        "area_leaves_goal.yaml": OPEN + "operating_area: {polygon: [[0, 0], [900, 0], [900, 900], "
                                 "[0, 900]]}\n",
        "goal_in_zone.yaml": OPEN + "no_fly_zones: [{polygon: [[1400, 1100], [1600, 1100], "
                             "[1600, 1300], [1400, 1300]], name: range}]\n",
        "circle_negative.yaml": OPEN + "no_fly_zones: [{circle: {center: [500, 500], "
                                "radius: -5}}]\n",
        "swapped_inline.yaml": JACKSBORO + "no_fly_zones: [{polygon: [[36.55, -84.30], "
                               "[36.55, -84.25], [36.60, -84.25]], lonlat: true}]\n",
        "swapped_file.yaml": JACKSBORO + "no_fly_zones: [swapped.geojson]\n",
        "agl_nan.yaml": OPEN + "planner: {agl: .nan}\n",
        "agl_text.yaml": OPEN + "planner: {agl: 1e3 m}\n",
        "comment_only.yaml": "# nothing here\n",
        "swapped.geojson": SWAPPED,
        "sweep_huge.yaml": "pairs: 1000\nalpha: {start: 1.0e-7, stop: 1, step: 1.0e-7}\n"
                           "beta: {start: 1e-7, stop: 1, step: 1e-7}\n",
        "sweep_pairs_bool.yaml": "pairs: true\n",
        "sweep_empty.yaml": "",
        "sweep_dup.yaml": "pairs: 2\npairs: 3\n",
        "sweep_cell.yaml": "cell: 0.01\n",
        "sweep_list.yaml": "- pairs\n",
        "swapped_start.yaml": JACKSBORO + "start: {lon: 36.53435, lat: -84.36016, agl: 300}\n"
                              "goal: {lon: -84.12133, lat: 36.65048, agl: 300}\n",
        "laughs.yaml": "a0: &a0 [1, 1, 1, 1, 1, 1, 1, 1, 1, 1]\n" + "".join(
            f"a{i}: &a{i} [{', '.join([f'*a{i - 1}'] * 10)}]\n" for i in range(1, 9)),
        "self_alias.yaml": OPEN + "via: &v [*v]\n",
        "lonlat.csv": "lon,lat,alt\n-3.70,40.30,100\n-3.69,40.31,100\n",
        "unknown_col.csv": "x_m,y_m,z_m,heading\n0,0,100,1\n100,0,100,2\n",
        "no_y.csv": "x_m,north,z_m\n0,0,100\n100,0,100\n",
        "ragged.csv": "x_m,y_m,z_m\n0,0,100\n100,0\n",
        "nan.csv": "x_m,y_m,z_m\n0,0,100\nnan,0,100\n",
        "text_value.csv": "x_m,y_m,z_m\n0,0,100\n100,zero,100\n",
    }
    for name, text in texts.items():
        (tmp / name).write_text(text)
    (tmp / "utf16.csv").write_bytes("x_m,y_m,z_m\n0,0,100\n".encode("utf-16"))
    (tmp / "utf16.yaml").write_bytes(OPEN.encode("utf-16"))
    (tmp / "dangling.yaml").symlink_to(tmp / "nowhere.yaml")
    (tmp / "loop.csv").symlink_to(tmp / "loop.csv")


CASES = [
    # plan: points
    (["plan", "--start", "1,2"], "--start needs 3 numbers"),
    (["plan", "--start", "a,b,c"], "--start must be 3 numbers"),
    (["plan", "--goal", "[/b]"], "--goal must be 3 numbers like 300,300,300; got '[/b]'"),
    (["plan", "--goal", "[bold]x[/bold]"], "got '[bold]x[/bold]'"),
    (["plan", "--start", "nan,1,1"], "finite"),
    (["plan", "--start", "1e30,1,1"], "outside"),
    (["plan", "--start", "-50,1,1"], "outside"),
    (["plan", "--start", "300,300,300", "--goal", "300,300,300"],
     "start and goal are the same place"),
    (["plan", "--start", "300,300,300", "--goal", "300.1,300,300"], "same grid node"),
    (["plan", "--lonlat", "--cells", "--start", "1,1"], "not both"),
    (["plan", "--lonlat", "--start", "500,40,10"], "longitude"),
    (["plan", "--lonlat", "--start", "-3.7,95,10"], "latitude"),
    (["plan", "--lonlat", "--start", "-3.7,40"], "no height"),
    (["plan", "--lonlat", "--start", "-3.7,40,-5"], "> 0 m"),
    (["plan", "--lonlat", "--start", "x,y"], "LON,LAT"),
    # plan: planner options
    (["plan", "--exponent", "0"], "--exponent"),
    (["plan", "--exponent", "-2"], "--exponent"),
    (["plan", "--saturation", "0"], "--saturation"),
    (["plan", "--saturation", "3"], "--saturation"),
    (["plan", "--saturation-distance", "-1"], "saturation_distance"),
    (["plan", "--order", "5"], "--order"),
    (["plan", "--agl", "-10"], "--agl"),
    (["plan", "--agl", "0"], "--agl"),
    (["plan", "--agl", "100", "--p1", "0"], "p1"),
    (["plan", "--agl", "100", "--mode", "strict"], "mode"),
    (["plan", "--agl", "100", "--band", "-3"], "band"),
    (["plan", "--scenario", "atlantis"], "atlantis"),
    (["plan", "--export", "pdf"], "--export 'pdf'"),
    (["plan", "--export", "plan", "--thin", "-1"], "--thin"),
    (["plan", "--export", "plan", "--anchor", "1,2,3,4"], "--anchor"),
    (["plan", "--export", "plan", "--anchor", "east"], "--anchor"),
    # plan: world data options
    (["plan", "--bbox", "1,2,3"], "--bbox"),
    (["plan", "--sea-level", "0"], "needs real data"),
    (["plan", "--cell-size", "5"], "needs real data"),
    (["plan", "--dem", "{tmp}/dir.tif"], "is a directory"),
    (["plan", "--dem", "{tmp}/pipe.geojson"], "named pipe"),
    (["plan", "--dem", "{tmp}/missing.tif"], "file not found"),
    (["plan", "--dem", "{tmp}/junk.tif"], "cannot be read as a raster"),
    (["plan", "--dem", "{tmp}/no[/b]where.tif"], "no[/b]where.tif"),
    (["plan", "--buildings", "{tmp}/pipe.geojson"], "named pipe"),
    (["plan", "--buildings", "{tmp}/dir.tif"], "is a directory"),
    (["plan", "--buildings", "{tmp}/area.geojson"], "area.geojson"),
    (["plan", "--scenario", "open-field", "--buildings", "{tmp}/area.geojson"], "not both"),
    (["plan", "--dem", "{tmp}/dem.tif", "--dz", "0.001", "--start", "500100,4498300,150",
      "--goal", "501600,4498500,150"], "limit 1000"),
    # plan: output folder
    (["plan", "--out", "{tmp}/path.csv"], "is not a folder"),
    # run: mission files
    (["run", "{tmp}/dup.yaml"], "duplicate key 'name' (lines 2 and 3)"),
    (["run", "{tmp}/pipe.yaml"], "named pipe"),
    (["run", "{tmp}/dir.tif"], "is a directory"),
    (["run", "{tmp}/bin.yaml"], "not a UTF-8 text file"),
    (["run", "{tmp}/deep.yaml"], "nested too deeply"),
    (["run", "{tmp}/missing.yaml"], "not found"),
    (["run", "{tmp}/b[red]x[/b].yaml"], "b[red]x[/b].yaml"),
    # cover
    (["cover", "--area", "{tmp}/pipe.geojson", "--spacing", "80"], "named pipe"),
    (["cover", "--area", "{tmp}/dir.tif", "--spacing", "80"], "directory"),
    (["cover", "--area", "{tmp}/area.geojson", "--spacing", "80"], "area.geojson"),
    (["cover", "--area", "nowhere", "--spacing", "80"], "neither an existing vector file"),
    (["cover", "--area", "S1"], "--spacing"),
    (["cover", "--area", "S1", "--spacing", "0"], "spacing"),
    (["cover", "--area", "S1", "--spacing", "-5"], "spacing"),
    (["cover", "--area", "S1", "--spacing", "1e9"], "larger than the area"),
    (["cover", "--area", "S1", "--spacing", "0.3"], "--spacing"),
    (["cover", "--area", "S1", "--spacing", "0.001"], "bands"),
    # check / export
    (["check", "{tmp}/pipe.geojson"], "named pipe"),
    (["check", "{tmp}/dir.tif"], "directory"),
    (["check", "{tmp}/bad.csv"], "bad.csv"),
    (["check", "{tmp}/binary.csv"], "binary.csv is not a UTF-8 text file"),
    (["check", "{tmp}/path.csv", "--airframe", "concorde"], "concorde"),
    (["check", "{tmp}/good.csv", "--dt", "1e308"], "--dt"),
    (["check", "{tmp}/good.csv", "--dt", "1e-300"], "steps of dt"),
    (["check", "{tmp}/good.csv", "--dt", "0"], "--dt"),
    (["check", "{tmp}/good.csv", "--tolerance", "-1"], "tolerance"),
    (["check", "{tmp}/good.csv", "--lookahead", "-5"], "lookahead"),
    (["check", "{tmp}/good.csv", "--lookahead-points", "0"], "lookahead_points"),
    # formation: bounded speeds and cycles (1e-300 m/s never arrived)
    (["formation", "--speed", "1e308", "--no-gif"], "--speed"),
    (["formation", "--speed", "1e-300", "--no-gif"], "[0.1, 300] m/s"),
    (["formation", "--follower-speed", "1e308", "--no-gif"], "--follower-speed"),
    (["formation", "--cycle", "1e308", "--no-gif"], "--cycle"),
    (["formation", "--cycle", "0", "--no-gif"], "--cycle"),
    (["formation", "--followers", "0", "--no-gif"], "--followers"),
    (["formation", "--start", "[/b]", "--no-gif"], "[/b]"),
    (["export", "{tmp}/pipe.geojson", "--format", "plan", "--scenario", "open-field"],
     "named pipe"),
    (["export", "{tmp}/bad.csv", "--format", "plan"], "--mission"),
    (["export", "{tmp}/bad.csv", "--format", "plan", "--scenario", "open-field"], "bad.csv"),
    (["export", "{tmp}/path.csv", "--format", "pdf"], "pdf"),
    (["export", "{tmp}/path.csv", "--format", "plan", "--mission", "{tmp}/dup.yaml"],
     "duplicate key"),
    # ---- issue 25: mission-file types (YAML 1.2), speeds, zones, relative paths
    (["run", "{tmp}/order_true.yaml"], "planner.order = True has the wrong type (bool)"),
    (["run", "{tmp}/version_true.yaml"], "version = True has the wrong type (bool)"),
    (["run", "{tmp}/walls_yes.yaml"], "planner.walls = 'yes'"),
    (["run", "{tmp}/agl_nan.yaml"], "planner.agl = nan is not a finite number"),
    (["run", "{tmp}/agl_text.yaml"], "planner.agl = '1e3 m' has the wrong type"),
    (["run", "{tmp}/comment_only.yaml"], "the mission file is empty"),
    (["run", "{tmp}/utf16.yaml"], "is UTF-16 text"),
    (["run", "{tmp}/dangling.yaml"], "is a symbolic link to"),
    (["run", "{tmp}/min_speed.yaml"], "min_speed 8 m/s is above hover_speed 5 m/s"),
    (["run", "{tmp}/min_speed_fw.yaml"], "min_speed 18 m/s is above cruise_speed 15 m/s"),
    (["plan", "--min-speed", "7", "--hover-speed", "5", "--export", "plan"],
     "airframe.min_speed = 7 m/s (CLI --min-speed) is above airframe.hover_speed = 5 m/s"),
    (["run", "{tmp}/area_leaves_goal.yaml"],
     "the goal [1500.0, 1200.0, 450.0] m is not inside the operating area"),
    (["run", "{tmp}/goal_in_zone.yaml"], "lies in the no-fly zone 'range'"),
    (["run", "{tmp}/circle_negative.yaml"], "no_fly_zones[0].circle.radius = -5 is out of range"),
    (["run", "{tmp}/swapped_inline.yaml"], "with longitude and latitude swapped"),
    (["run", "{tmp}/swapped_file.yaml"], "the coordinates are written [lat, lon]"),
    (["plan", "--scenario", "jacksboro", "--no-fly", "{tmp}/swapped.geojson"],
     "--no-fly {tmp}/swapped.geojson: its zone lies off the map, but with longitude"),
    # ---- path CSVs read by name
    (["check", "{tmp}/lonlat.csv"], "lon/lat degrees are not read"),
    (["check", "{tmp}/unknown_col.csv"], "unknown column 'heading'"),
    (["check", "{tmp}/no_y.csv"], "no y column in the header"),
    (["check", "{tmp}/ragged.csv"], "line 3: 2 values where the first row has 3"),
    (["check", "{tmp}/nan.csv"], "line 3: x_m = 'nan' is not a finite number"),
    (["check", "{tmp}/text_value.csv"], "line 3: y_m = 'zero' is not a number"),
    (["check", "{tmp}/utf16.csv"], "is UTF-16 text"),
    (["check", "{tmp}/loop.csv"], "a loop of links"),
    (["export", "{tmp}/lonlat.csv", "--scenario", "open-field"], "lon/lat degrees"),
    (["export", "{tmp}/ragged.csv", "--scenario", "open-field"], "line 3"),
    (["plan", "--scenario", "jacksboro", "--lonlat", "--start", "36.53435,-84.36016,300",
      "--goal", "-84.12133,36.65048,300"], "lon and lat look swapped: lon -84.3602, lat 36.5344"),
    (["run", "{tmp}/swapped_start.yaml"], "lon and lat look swapped"),
    (["run", "{tmp}/laughs.yaml"], "billion laughs"),
    (["run", "{tmp}/self_alias.yaml"], "refers to itself through an alias"),
    (["sweep", "{tmp}/laughs.yaml"], "billion laughs"),
    # ---- output folders
    (["plan", "--out", "{tmp}/path.csv/sub"], "path.csv is a file, not a folder"),
    (["plan", "--out", "/"], "is the root of the file system"),
    # ---- sizes refused up front with what they would need
    (["sweep", "{tmp}/sweep_huge.yaml"], "the sweep would have 1e+17 cases (1000 pairs x "
     "10000000 alpha x 10000000 beta values)"),
    (["sweep", "{tmp}/sweep_pairs_bool.yaml"], "pairs = True"),
    (["sweep", "{tmp}/sweep_empty.yaml"], "is empty"),
    (["sweep", "{tmp}/sweep_dup.yaml"], "duplicate key 'pairs'"),
    (["sweep", "{tmp}/sweep_cell.yaml"], "cell = 0.01"),
    (["sweep", "{tmp}/sweep_list.yaml"], "must hold a YAML mapping"),
    (["sweep", "{tmp}/dir.tif"], "is a directory"),
    (["sweep", "{tmp}/pipe.yaml"], "named pipe"),
    (["sweep", "examples/sweeps/city2d_small.yaml", "--workers", "100000"],
     "--workers 100000 would start 100000 worker processes"),
    (["sweep", "examples/sweeps/city2d_small.yaml", "--workers", "0"], "--workers"),
    (["reproduce", "curvature", "--step", "1e-9"], "the limit is 2,000,000 cases"),
    (["reproduce", "curvature", "--pairs", "0"], "pairs must be at least 1"),
    (["reproduce", "tracking", "--workers", "-3"], "--workers"),
    (["formation", "--followers", "1000000", "--no-gif"], "the limit is 50 followers"),
    (["tune", "--p2", ",".join(f"{0.6 + k / 1000:g}" for k in range(1000))],
     "the tuning grid has 3000 combinations (3 p1 x 1000 p2"),
    (["formation", "--frames", "1000000000"], "the limit is 1000 frames"),
    # ---- seeds, unused-but-given flags, airframe speeds
    (["plan", "--seed", "-1"], "seed must be an integer in [0, 9223372036854775807]"),
    (["tune", "--seed", "-1"], "--seed"),
    (["reproduce", "urban", "--seed", "-1"], "--seed"),
    (["reproduce", "coverage", "--seed", "-1"], "--seed"),
    (["plan", "--p1", "nan"], "p1 must be a finite number"),
    (["plan", "--band", "-1"], "band must be in [0, 5000]"),
    (["check", "{tmp}/good.csv", "--speed", "5"], "below its stall (minimum) speed"),
    (["check", "{tmp}/good.csv", "--tolerance", "1e308"], "tolerance must be in (0, 10000] m"),
    (["cover", "--area", "S3", "--spacing", "80", "--side-overlap", "nan"], "--side-overlap"),
    (["cover", "--area", "S3", "--spacing", "80", "--angle", "1e308"], "--angle"),
    (["cover", "--area", "S3", "--spacing", "80", "--thin", "1e308"], "[0, 1000] m"),
    (["formation", "--p1", "nan", "--no-gif"], "p1 must be a finite number"),
    (["formation", "--frames", "0", "--no-gif"], "--frames"),
    (["plan", "--agl", "1e308"], "agl = 1e+308 m is too large; allowed: at most 5000 m"),
    (["plan", "--saturation-distance", "1e308"], "--saturation-distance"),
    (["plan", "--thin", "1e308", "--export", "plan"], "outputs.thin_tolerance"),
    (["check", "{tmp}/good.csv", "--airframe", "arducopter", "--speed", "5"],
     "applies to fixed-wings"),
]


@pytest.fixture(scope="module")
def bad_files(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("bad")
    _files(tmp)
    return tmp


@pytest.mark.parametrize("args, fragment", CASES, ids=[" ".join(a)[:60] for a, _ in CASES])
def test_cli_bad_input(bad_files, tmp_path, args, fragment):
    argv = [a.replace("{tmp}", str(bad_files)) for a in args]
    if "--out" not in argv and argv[0] in ("plan", "run", "cover", "export", "check",
                                           "formation", "sweep", "reproduce", "tune"):
        argv += ["--out", str(tmp_path / "out")]
    res = runner.invoke(app, argv)
    out = res.output
    assert res.exit_code == 2, out
    assert "Traceback" not in out and "internal error" not in out
    assert fragment.replace("{tmp}", str(bad_files)) in out, out
    # nothing written for a refused run, and no temporary folders left beside the target
    assert not (tmp_path / "out").exists()
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".out")]
