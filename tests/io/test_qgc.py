"""Plans QGroundControl wrote, read back: survey transects expanded into their items,
complex items saved without them refused by name (QGC's own files in tests/io/data)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from fm2uav.autopilot import FenceCircle, validate_mission
from fm2uav.errors import InputError
from fm2uav.io import read_plan, validate_plan

DATA = Path(__file__).parent / "data"


def test_a_qgc_survey_plan_is_read_with_its_transect_items():
    r = read_plan(DATA / "qgc_survey.plan")
    cmds = r["command"].tolist()
    assert cmds[0] == 22 and cmds[-1] == 20
    assert cmds.count(206) == 8 and cmds.count(16) == 16  # 4 transects x (2 + 2 turnarounds)
    assert r["sources"][1] == "items[1] survey" and r["sources"][-1] == "items[2]"
    assert [it.params[0] for it in r["items"] if it.command == 206] == [25, 0] * 4
    assert r["home"] == pytest.approx((47.3977419, 8.545594, 487.989))
    assert isinstance(r["fences"][0], FenceCircle) and r["fences"][0].inclusion
    assert len(r["rally"]) == 2
    problems = validate_mission(r["items"], "px4", home_alt=r["home"][2])
    # QGC's survey commands no speed: PX4 flies MPC_XY_CRUISE (a warning, not a rejection)
    assert [(p.code, p.severity) for p in problems] == [("no-cruise-speed", "warning")]


def test_complex_items_without_stored_items_are_refused_by_name(tmp_path):
    with pytest.raises(InputError, match=r"mission item 2 is a QGroundControl 'StructureScan'"):
        read_plan(DATA / "qgc_structure_scan.plan")
    doc = json.loads((DATA / "qgc_survey.plan").read_text())
    del doc["mission"]["items"][1]["TransectStyleComplexItem"]["Items"]
    del doc["geoFence"], doc["rallyPoints"]  # optional in QGC plans
    (tmp_path / "s.plan").write_text(json.dumps(doc))
    assert validate_plan(doc) == []
    with pytest.raises(InputError, match=r"'survey' complex item.*saved without"):
        read_plan(tmp_path / "s.plan")
    doc["mission"]["items"].pop(1)
    (tmp_path / "t.plan").write_text(json.dumps(doc))
    assert read_plan(tmp_path / "t.plan")["command"].tolist() == [22, 20]


def test_rally_points_are_written_as_qgc_writes_them(returns_mission, tmp_path):
    import json

    from fm2uav.io.qgc import plan_document, read_plan, validate_plan
    from fm2uav.io.rally import rally_rows

    doc = plan_document(returns_mission)
    rp = doc["rallyPoints"]
    # QGroundControl's RallyPointController: {"points": [[lat, lon, alt], ...], "version": 2}
    assert set(rp) == {"points", "version"} and rp["version"] == 2
    assert rp["points"] == [list(r) for r in rally_rows(returns_mission)]
    assert validate_plan(doc) == []
    f = tmp_path / "m.plan"
    f.write_text(json.dumps(doc))
    assert read_plan(f)["rally"] == [tuple(p) for p in rp["points"]]
    bad = {**doc, "rallyPoints": {"points": [[95.0, 0.0, 10.0]], "version": 2}}
    assert any("rallyPoints.points[0]" in p for p in validate_plan(bad))
