"""fm2uav.app.session: the session folder, the jobs' mission files, saving a mission."""

from __future__ import annotations

import pytest
import yaml

from fm2uav.app.session import Session, dump_mission, file_refs
from fm2uav.errors import InputError
from fm2uav.io.mission import load_mission

from .dem import make_dem


def test_file_refs_name_every_data_file_of_a_mission():
    doc = {"world": {"dem": ["/a/1.tif", "/a/2.tif"], "buildings": "/a/b.geojson"},
           "no_fly_zones": ["/z/1.kml", {"file": "/z/2.geojson", "buffer": 5},
                            {"polygon": [[0, 0], [1, 0], [1, 1]]}],
           "operating_area": {"file": "/z/area.gpkg"}}
    assert file_refs(doc) == [
        (["world", "dem", 0], "/a/1.tif"), (["world", "dem", 1], "/a/2.tif"),
        (["world", "buildings"], "/a/b.geojson"), (["no_fly_zones", 0], "/z/1.kml"),
        (["no_fly_zones", 1, "file"], "/z/2.geojson"), (["operating_area", "file"], "/z/area.gpkg")]


def test_dump_keeps_order_and_floats_exactly():
    doc = {"version": 1, "name": "é", "start": {"lon": 10.303287506103517, "lat": 0.1 + 0.2,
                                                "agl": 60}}
    text = dump_mission(doc)
    assert text.startswith("# fm2uav mission file written by `fm2uav app`")
    assert list(yaml.safe_load(text)) == ["version", "name", "start"]
    assert yaml.safe_load(text) == doc


def test_save_copies_uploaded_files_beside_the_mission_and_keeps_others(tmp_path):
    s = Session(tmp_path / "session", {}, tmp_path / "m.yaml")
    up = s.upload("../my dem.tif", make_dem(tmp_path / "x.tif").read_bytes())
    assert up.parent == s.data and up.name == "my_dem.tif"
    external = tmp_path / "zones.geojson"
    external.write_text('{"type": "FeatureCollection", "features": []}')
    doc = {"version": 1, "world": {"dem": str(up)},
           "start": {"lon": 10.30, "lat": 46.03, "agl": 60},
           "goal": {"lon": 10.355, "lat": 46.03, "agl": 60}, "no_fly_zones": [str(external)]}
    target = s.save(doc, tmp_path / "saved" / "mission.yaml")
    saved = yaml.safe_load(target.read_text())
    assert saved["world"]["dem"] == "my_dem.tif"                    # beside the mission file
    assert (target.parent / "my_dem.tif").read_bytes() == up.read_bytes()
    assert saved["no_fly_zones"] == [str(external)]                 # the user's own file
    assert doc["world"]["dem"] == str(up)                           # the page's copy unchanged
    m = load_mission(target)                                        # fm2uav run reads it
    assert m.world.dem == str(target.parent / "my_dem.tif")
    with pytest.raises(InputError, match="ends in .yaml"):
        s.save(doc, tmp_path / "mission.txt")
    (tmp_path / "d.yaml").mkdir()
    with pytest.raises(InputError, match="is a folder"):
        s.save(doc, tmp_path / "d.yaml")


def test_job_files_write_the_mission_the_job_runs(tmp_path):
    s = Session(tmp_path, {}, tmp_path / "m.yaml")
    mf, out = s.job_files("7", {"version": 1, "name": "x"})
    assert mf == tmp_path / "jobs" / "7" / "mission.yaml" and out == mf.parent / "out"
    assert yaml.safe_load(mf.read_text()) == {"version": 1, "name": "x"}
