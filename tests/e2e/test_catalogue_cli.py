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
                                           "formation"):
        argv += ["--out", str(tmp_path / "out")]
    res = runner.invoke(app, argv)
    out = res.output
    assert res.exit_code == 2, out
    assert "Traceback" not in out and "internal error" not in out
    assert fragment.replace("{tmp}", str(bad_files)) in out, out
    # nothing written for a refused run, and no temporary folders left beside the target
    assert not (tmp_path / "out").exists()
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".out")]
