"""`fm2uav plan` safety flags: --no-fly (repeatable), --min-agl, --max-agl; one-line refusals."""

from __future__ import annotations

import json

import shapely
from typer.testing import CliRunner

from fm2uav.cli import app


def _zone(tmp_path, name, ring):
    p = tmp_path / f"{name}.geojson"
    p.write_text(json.dumps({"type": "FeatureCollection", "features": [
        {"type": "Feature", "properties": {"name": name, "buffer": 30},
         "geometry": {"type": "Polygon", "coordinates": [ring + [ring[0]]]}}]}))
    return p


def test_plan_keeps_out_of_two_no_fly_files_and_below_max_agl(tmp_path):
    a = _zone(tmp_path, "wall", [[700, 300], [900, 300], [900, 1000], [700, 1000]])
    b = _zone(tmp_path, "box", [[1100, 900], [1300, 900], [1300, 1100], [1100, 1100]])
    out = tmp_path / "out"
    res = CliRunner().invoke(app, [
        "plan", "--agl", "120", "--min-agl", "30", "--max-agl", "250", "--no-fly", str(a),
        "--no-fly", str(b), "--export", "plan", "--report", "--out", str(out), "--json"])
    assert res.exit_code == 0, res.output
    s = json.loads((out / "summary.json").read_text())
    assert s["safety"]["zones"]["count"] == 2 and s["safety"]["zones"]["path_entries"] == []
    assert all(c["ok"] for c in s["safety"]["checks"].values())
    lines = [ln for ln in (out / "path.csv").read_text().splitlines() if not ln.startswith("#")]
    xy = [[float(v) for v in ln.split(",")[:2]] for ln in lines[1:]]
    for ring in ([[700, 300], [900, 300], [900, 1000], [700, 1000]],
                 [[1100, 900], [1300, 900], [1300, 1100], [1100, 1100]]):
        assert not shapely.intersects(shapely.LineString(xy), shapely.Polygon(ring).buffer(30))
    fence = json.loads((out / "mission.plan").read_text())["geoFence"]
    assert len(fence["polygons"]) == 2
    html = (out / "report.html").read_text()
    assert "no-fly zone: wall" in html and "no-fly zone: box (buffer 30 m)" in html


def test_agl_above_max_agl_is_one_line_naming_the_flag(tmp_path):
    res = CliRunner().invoke(app, ["plan", "--agl", "150", "--max-agl", "120", "--out",
                                   str(tmp_path / "x")])
    assert res.exit_code == 2
    msg = res.output.strip()
    assert "--max-agl" in msg and "planner.max_agl" in msg and len(msg.splitlines()) == 1


def test_no_fly_folder_or_missing_file_is_one_line_naming_the_flag(tmp_path):
    # acceptance B: a folder given as --no-fly said "file not found"
    folder = tmp_path / "zones.geojson"
    folder.mkdir()
    for arg, says in ((folder, "is a directory, not a file"),
                      (tmp_path / "none.geojson", "not found")):
        out = tmp_path / "x"
        res = CliRunner().invoke(app, ["plan", "--agl", "150", "--no-fly", str(arg),
                                       "--out", str(out), "--quiet"])
        msg = res.output.strip()
        assert res.exit_code == 2, msg
        assert says in msg and "--no-fly" in msg and str(arg) in msg
        assert len(msg.splitlines()) == 1 and not out.exists()
