"""Bad-input catalogue: files (DEM, buildings, areas, mission files) and mission keys.

Each case builds its bad file in ``tmp_path`` and asserts the error class and a message
fragment (issue 17 item 5). Mission keys go through :func:`fm2uav.io.mission.parse_mission`.
"""

from __future__ import annotations

import copy
import json
import os
import zipfile

import numpy as np
import pytest

from fm2uav.errors import Fm2uavError, InputError, WorldError
from fm2uav.io.mission import load_mission, parse_mission

from .conftest import relief, write_dem

# ------------------------------------------------------------------------- DEM files


def _dem(z, **kw):
    def make(tmp):
        return write_dem(tmp / "dem.tif", z, **kw)
    return make


def _bytes(name, data):
    def make(tmp):
        p = tmp / name
        p.write_bytes(data)
        return p
    return make


def _fifo(name):
    def make(tmp):
        p = tmp / name
        os.mkfifo(p)
        return p
    return make


def _dir(name):
    def make(tmp):
        p = tmp / name
        p.mkdir()
        return p
    return make


def _unreadable(name, data=b"x"):
    def make(tmp):
        p = tmp / name
        p.write_bytes(data)
        p.chmod(0)
        return p
    return make


_pit = relief()
_pit[5:9, 5:9] = -9999.0
_spike = relief()
_spike[20, 20] = 4000.0
_hole = relief()
_hole[12, 12] = -2000.0  # a one-pixel pit 2100 m deep on 30 m pixels: no terrain does that
_feet = relief() + 9500.0
_nan = np.full((40, 40), np.nan)
_nodata_all = np.full((40, 40), -32768.0)

DEM_CASES = [
    ("dem-undeclared-nodata", _dem(_pit), WorldError, "nodata the file does not declare"),
    ("dem-undeclared-nodata-value", _dem(_pit), WorldError, "16 pixel(s) of -9999"),
    ("dem-spike", _dem(_spike), WorldError, "no terrain on Earth steps like that"),
    ("dem-pit-2100m", _dem(_hole), WorldError, "a step of 2102 m (89°)"),
    ("dem-above-9000", _dem(_feet), WorldError, "above 9000 m"),
    ("dem-all-nan", _dem(_nan), WorldError, "no valid elevation"),
    ("dem-all-nodata", _dem(_nodata_all, nodata=-32768.0), WorldError, "no valid elevation"),
    ("dem-no-crs", _dem(relief(), crs=None), WorldError, "no coordinate reference system"),
    ("dem-crs-misfit", _dem(relief(), x0=5e7, y0=9e7, crs="EPSG:4326"), WorldError, "CRS"),
    ("dem-tiny", _dem(np.ones((1, 1))), Fm2uavError, "2 x 2"),
    ("dem-text", _bytes("dem.tif", b"not a raster at all"), InputError, "cannot read the DEM"),
    ("dem-empty", _bytes("dem.tif", b""), InputError, "cannot read the DEM"),
    ("dem-binary-junk", _bytes("dem.tif", bytes(range(256)) * 8), InputError,
     "cannot read the DEM"),
    ("dem-fifo", _fifo("dem.tif"), InputError, "named pipe"),
    ("dem-directory", _dir("dem.tif"), InputError, "is a directory"),
    ("dem-missing", lambda tmp: tmp / "nowhere.tif", InputError, "does not exist"),
    # rasters that are not elevation (issue 25)
    ("dem-rgb", lambda tmp: _dc().rgb(tmp / "map.tif"), InputError, "RGB colour image"),
    ("dem-palette", lambda tmp: _dc().palette(tmp / "lc.tif"), InputError, "colour-indexed"),
    ("dem-complex", lambda tmp: _dc().complex_raster(tmp / "ifg.tif"), InputError,
     "complex complex64"),
    ("dem-celsius", lambda tmp: _dc().temperature(tmp / "t.tif"), InputError,
     "unit 'degC', which is not a length"),
]


def _dc():
    from tests.world import dem_cases

    return dem_cases


@pytest.mark.parametrize("make, exc, fragment", [c[1:] for c in DEM_CASES],
                         ids=[c[0] for c in DEM_CASES])
def test_dem_file(tmp_path, make, exc, fragment):
    from fm2uav.world.dem import from_dem

    path = make(tmp_path)
    with pytest.raises(exc) as err:
        from_dem(path, 30.0)
    assert fragment in str(err.value)
    assert "\n" not in str(err.value)


def test_dem_cell_too_fine(tmp_path):
    """A 0.05 m cell on a 1.2 km DEM: refused up front with the memory it would need."""
    from fm2uav.world.dem import from_dem

    p = write_dem(tmp_path / "dem.tif", relief())
    with pytest.raises(WorldError, match=r"GiB to plan on.*--cell-size"):
        from_dem(p, 0.05)


# ----------------------------------------------------------------- vector files

def _geojson(doc, name="b.geojson"):
    def make(tmp):
        p = tmp / name
        p.write_text(json.dumps(doc))
        return p
    return make


def _poly(coords, props=None):
    return {"type": "Feature", "properties": props if props is not None else {"height": 10},
            "geometry": {"type": "Polygon", "coordinates": [coords]}}


def _fc(*features, **extra):
    return {"type": "FeatureCollection", "features": list(features), **extra}


SQUARE_LL = [[-3.0, 40.0], [-2.999, 40.0], [-2.999, 40.001], [-3.0, 40.001], [-3.0, 40.0]]
SQUARE_UTM = [[440000, 4470000], [440050, 4470000], [440050, 4470050], [440000, 4470050],
              [440000, 4470000]]

VECTOR_CASES = [
    ("vec-not-json", _bytes("b.geojson", b"{not json"), Fm2uavError, "b.geojson"),
    ("vec-not-utf8", _bytes("b.geojson", b"\xff\xfe\x00\x81junk"), Fm2uavError, "b.geojson"),
    ("vec-empty-file", _bytes("b.geojson", b""), Fm2uavError, "b.geojson"),
    ("vec-fifo", _fifo("b.geojson"), Fm2uavError, "named pipe"),
    ("vec-directory", _dir("b.geojson"), Fm2uavError, "directory"),
    ("vec-missing", lambda tmp: tmp / "none.geojson", WorldError, "does not exist"),
    ("vec-utm-coords-as-lonlat", _geojson(_fc(_poly(SQUARE_UTM))), WorldError, "--crs"),
    ("vec-lat-out-of-range", _geojson(_fc(_poly([[10, 95], [11, 95], [11, 96], [10, 95]]))),
     WorldError, "--crs"),
    ("vec-bad-crs-member", _geojson(_fc(_poly(SQUARE_LL), crs={
        "type": "name", "properties": {"name": "EPSG:999999"}})), WorldError, "crs"),
    ("vec-only-points", _geojson(_fc({"type": "Feature", "properties": {},
                                      "geometry": {"type": "Point", "coordinates": [-3, 40]}})),
     WorldError, "Polygon"),
    ("vec-bad-zip-kmz", _bytes("b.kmz", b"PK\x03\x04 broken zip"), Fm2uavError, "b.kmz"),
    ("vec-no-features", _geojson(_fc()), WorldError, ""),
    ("vec-negative-height", _geojson(_fc(_poly(SQUARE_LL, {"height": -5}))), WorldError,
     "height"),
    ("vec-height-text", _geojson(_fc(_poly(SQUARE_LL, {"height": "tall"}))), WorldError,
     "height"),
    ("vec-no-height", _geojson(_fc(_poly(SQUARE_LL, {}))), WorldError, "default_height"),
]


@pytest.mark.parametrize("make, exc, fragment", [c[1:] for c in VECTOR_CASES],
                         ids=[c[0] for c in VECTOR_CASES])
def test_buildings_file(tmp_path, make, exc, fragment):
    from fm2uav.world.buildings import from_buildings

    path = make(tmp_path)
    with pytest.raises(exc) as err:
        from_buildings(path, 5.0)
    assert fragment in str(err.value)
    assert "\n" not in str(err.value)


def test_buildings_far_apart_refused_up_front(tmp_path):
    """Two buildings 2,700 km apart at 2 m cells: refused before allocating (size named)."""
    from fm2uav.world.buildings import from_buildings

    far = [[30.0, 40.0], [30.001, 40.0], [30.001, 40.001], [30.0, 40.001], [30.0, 40.0]]
    p = _geojson(_fc(_poly(SQUARE_LL), _poly(far)))(tmp_path)
    with pytest.raises(Fm2uavError, match=r"nodes.*GiB|too large|nodes \(limit"):
        from_buildings(p, 2.0)


def test_zero_area_and_outside_footprints_are_reported():
    """Not silently turned into walls or dropped: one warning line naming both."""
    import warnings

    from fm2uav.world.buildings import from_buildings
    from fm2uav.world.dem import GeodataWarning

    fc = _fc(_poly([[10, 10], [20, 10], [30, 10], [10, 10]]),
             _poly([[40, 40], [50, 40], [50, 50], [40, 50], [40, 40]]),
             _poly([[400, 400], [500, 400], [500, 500], [400, 500], [400, 400]]))
    with warnings.catch_warnings(record=True) as rec:
        warnings.simplefilter("always")
        w = from_buildings(fc, 2.0, shape=(50, 50, 20))
    msgs = [str(r.message) for r in rec if issubclass(r.category, GeodataWarning)]
    assert len(msgs) == 1 and "zero-area" in msgs[0] and "outside the grid" in msgs[0]
    # the zero-area footprint (the line y = 10, x 10..30) did not become a wall
    assert not w.occupancy[5:15, 5, 1].any()


# ------------------------------------------------------------------- area files

AREA_CASES = [
    ("area-fifo", _fifo("a.geojson"), Fm2uavError, "named pipe"),
    ("area-directory", _dir("a.geojson"), Fm2uavError, "directory"),
    ("area-not-json", _bytes("a.geojson", b"[[[[["), Fm2uavError, "a.geojson"),
    ("area-not-utf8", _bytes("a.geojson", b"\x80\x81\x82"), Fm2uavError, "a.geojson"),
    ("area-points-only", _geojson(_fc({"type": "Feature", "properties": {},
                                       "geometry": {"type": "Point", "coordinates": [1, 1]}}),
                                  "a.geojson"), Fm2uavError, ""),
]


@pytest.mark.parametrize("make, exc, fragment", [c[1:] for c in AREA_CASES],
                         ids=[c[0] for c in AREA_CASES])
def test_area_file(tmp_path, make, exc, fragment):
    from fm2uav.missions.coverage.area import load_area
    from fm2uav.scenarios.coverage import coverage_world

    path = make(tmp_path)
    with pytest.raises(exc) as err:
        load_area(path, coverage_world())
    assert fragment in str(err.value)


# ---------------------------------------------------------------- mission files

BASE = {"version": 1, "name": "t", "world": {"scenario": "open-field"},
        "start": {"cell": [20, 20, 20]}, "goal": {"cell": [100, 80, 30]}}


def _yaml(text, name="m.yaml"):
    def make(tmp):
        p = tmp / name
        p.write_text(text)
        return p
    return make


MISSION_FILE_CASES = [
    ("mission-duplicate-start", _yaml("version: 1\nname: t\nworld: {scenario: open-field}\n"
                                      "start: [1, 1, 1]\ngoal: [5, 5, 5]\nstart: [2, 2, 2]\n"),
     "duplicate key 'start' (lines 4 and 6)"),
    ("mission-duplicate-nested", _yaml("version: 1\nworld:\n  scenario: open-field\n"
                                       "  scenario: city\n"), "duplicate key 'scenario'"),
    ("mission-duplicate-planner", _yaml("planner:\n  agl: 10\n  agl: 20\n"), "lines 2 and 3"),
    ("mission-syntax", _yaml("world: [scenario: open-field\n"), "not valid YAML"),
    ("mission-tabs", _yaml("world:\n\tscenario: x\n"), "not valid YAML"),
    ("mission-deep", _yaml("[" * 5000 + "]" * 5000), "nested too deeply"),
    ("mission-not-utf8", _bytes("m.yaml", b"name: \xff\xfe\n"), "not a UTF-8 text file"),
    ("mission-empty", _yaml(""), "empty"),
    ("mission-list", _yaml("- a\n- b\n"), ""),
    ("mission-scalar", _yaml("42\n"), ""),
    ("mission-fifo", _fifo("m.yaml"), "named pipe"),
    ("mission-directory", _dir("m.yaml"), "is a directory"),
    ("mission-missing", lambda tmp: tmp / "none.yaml", "not found"),
    ("mission-python-tag", _yaml("name: !!python/object:os.system ls\n"), "not valid YAML"),
    ("mission-binary", _bytes("m.yaml", bytes(range(256))), "m.yaml"),
]
if os.geteuid() != 0:  # root reads everything
    MISSION_FILE_CASES.append(("mission-unreadable", _unreadable("m.yaml"), "permission"))


@pytest.mark.parametrize("make, fragment", [c[1:] for c in MISSION_FILE_CASES],
                         ids=[c[0] for c in MISSION_FILE_CASES])
def test_mission_file(tmp_path, make, fragment):
    path = make(tmp_path)
    with pytest.raises(InputError) as err:
        load_mission(path)
    assert fragment in str(err.value)
    assert "\n" not in str(err.value)


def _with(path, value):
    d = copy.deepcopy(BASE)
    keys = path.split(".")
    node = d
    for k in keys[:-1]:
        node = node.setdefault(k, {})
    if value is _DROP:
        node.pop(keys[-1], None)
    else:
        node[keys[-1]] = value
    return d


_DROP = object()

MISSION_KEY_CASES = [
    ("planner.exponent", -1, "exponent"),
    ("planner.exponent", "big", "exponent"),
    ("planner.saturation", 0, "saturation"),
    ("planner.saturation", 1.5, "saturation"),
    ("planner.step", 1e-9, "step"),
    ("planner.step", 5, "step"),
    ("planner.order", 3, "order"),
    ("planner.agl", -10, "agl"),
    ("planner.agl", 0, "agl"),
    ("planner.p1", 0, "p1"),
    ("planner.mode", "strict", "mode"),
    ("planner.band", -1, "band"),
    ("planner.max_agl", 5, "max_agl"),
    ("planner.unknown_key", 1, "unknown_key"),
    ("planner.method", "bfs", "method"),
    ("world.scenario", "atlantis", "atlantis"),
    ("world.seed", "abc", "seed"),
    ("world.unknown", 1, "unknown"),
    ("world", _DROP, "world"),
    ("world", "open-field", "world"),
    ("start", {"cell": "a"}, "start"),
    ("start", "here", "start"),
    ("start", [1, 2], "start"),
    ("start", [1, "a", 2], "start"),
    ("start.cell", [1, 2], "start"),
    ("goal", {"lon": 500, "lat": 40, "agl": 10}, "goal"),
    ("goal", {"lon": -3.7, "lat": 95, "agl": 10}, "goal"),
    ("goal", {"x": 1, "y": 1}, "goal"),
    ("version", 99, "version"),
    ("name", ["a"], "name"),
    ("airframe.type", "helicopter", "helicopter"),
    ("airframe.firmware", "betaflight", "betaflight"),
    ("airframe.cruise_speed", -5, "cruise_speed"),
    ("airframe.endurance", 0, "endurance"),
    ("outputs.formats", ["pdf"], "pdf"),
    ("outputs.formats", "csv", "formats"),
    ("outputs.thin_tolerance", -1, "thin_tolerance"),
    ("outputs.frame", "sideways", "frame"),
    ("outputs.end", "crash", "end"),
    ("unknown_top_level", 1, "unknown_top_level"),
]


@pytest.mark.parametrize("key, value, fragment", MISSION_KEY_CASES,
                         ids=[f"{k}={v!r}"[:40] if v is not _DROP else f"{k}-missing"
                              for k, v, _ in MISSION_KEY_CASES])
def test_mission_key(key, value, fragment):
    with pytest.raises(InputError) as err:
        m = parse_mission(_with(key, value), source="m.yaml")
        m.plan_kwargs()  # the planner objects validate themselves here
        from fm2uav.planning.params import planner_objects

        planner_objects(m.plan_kwargs())
    msg = str(err.value)
    assert msg.startswith("m.yaml") or fragment in msg
    assert fragment in msg
    assert "\n" not in msg


def test_mission_start_equal_goal_refused_before_writing(tmp_path):
    from typer.testing import CliRunner

    from fm2uav.cli import app

    f = tmp_path / "m.yaml"
    f.write_text("version: 1\nname: t\nworld: {scenario: open-field}\n"
                 "start: {cell: [20, 20, 20]}\ngoal: {cell: [20, 20, 20]}\n")
    out = tmp_path / "out"
    res = CliRunner().invoke(app, ["run", str(f), "--out", str(out)])
    assert res.exit_code == 2, res.output
    assert "start and goal are the same place" in res.output
    assert not out.exists() and not list(tmp_path.glob(".out*"))
