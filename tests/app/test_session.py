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


def test_rally_and_returns_keys_round_trip_through_a_saved_mission(tmp_path):
    """``rally:`` (sites, ``auto:K``, or a file — copied beside the mission like the other
    uploaded files) and ``returns:`` are saved as given and read back by ``fm2uav run``."""
    s = Session(tmp_path / "session", {}, tmp_path / "m.yaml")
    dem = s.upload("dem.tif", make_dem(tmp_path / "x.tif").read_bytes())
    rally = s.upload("rally.csv", b"lon,lat,agl\n10.33,46.035,50\n")
    base = {"version": 1, "world": {"dem": str(dem)},
            "start": {"lon": 10.30, "lat": 46.03, "agl": 60},
            "goal": {"lon": 10.355, "lat": 46.03, "agl": 60},
            "returns": {"enabled": True, "min_agl": 35.0, "strict": True}}
    assert file_refs({"rally": "auto:2"}) == [] and file_refs({"rally": [{"lon": 1}]}) == []
    assert file_refs({"rally": str(rally)}) == [(["rally"], str(rally))]
    for form in ({"file": str(rally)}, str(rally)):
        target = s.save({**base, "rally": form}, tmp_path / "saved" / "mission.yaml")
        saved = yaml.safe_load(target.read_text())
        assert saved["rally"] in ({"file": "rally.csv"}, "rally.csv")
        assert (target.parent / "rally.csv").read_bytes() == rally.read_bytes()
        assert saved["returns"] == base["returns"]
        m = load_mission(target)
        assert m.rally.file == str(target.parent / "rally.csv")
        assert (m.returns.min_agl, m.returns.strict) == (35.0, True)
    sites = [{"lon": 10.33, "lat": 46.035, "agl": 50.0}]
    for rally_key, check in ((sites, lambda r: [(p.lon, p.lat, p.agl) for p in r.points]
                              == [(10.33, 46.035, 50.0)]),
                             ("auto:2", lambda r: r.auto == 2)):
        target = s.save({**base, "rally": rally_key}, tmp_path / "again.yaml")
        assert yaml.safe_load(target.read_text())["rally"] == rally_key
        assert check(load_mission(target).rally)


def test_the_cover_command_passes_every_world_key_as_its_flag(tmp_path):
    """Issue 25's world keys (ground_elevation, margin; dem_fill lists) reach fm2uav cover as
    the flags the CLI knows, and the mission-file world they come from is valid."""
    from fm2uav.app.session import cover_command
    from fm2uav.cli.options import WORLD_FLAGS
    from fm2uav.io.mission import parse_world

    (tmp_path / "town.geojson").write_text('{"type": "FeatureCollection", "features": []}')
    world = {"buildings": "town.geojson", "crs": "EPSG:32630", "ground_elevation": 650.0,
             "margin": 40.0, "cell_size": 5.0}
    parse_world(world, source="world", base_dir=tmp_path)  # the keys of a mission file
    argv = cover_command(world, {"agl": 20.0, "spacing": 30.0}, {}, [], None)
    for key, v in world.items():
        k = argv.index(WORLD_FLAGS[key])
        assert argv[k + 1] == (v if isinstance(v, str) else repr(v))
    argv = cover_command({"dem": ["a.tif", "b.tif"], "dem_fill": ["c.tif", "d.tif"]},
                         {"agl": 20.0, "spacing": 30.0}, {}, [], None)
    assert argv[2:10] == ["--dem", "a.tif", "--dem", "b.tif", "--dem-fill", "c.tif",
                          "--dem-fill", "d.tif"]
