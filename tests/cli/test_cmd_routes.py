"""`fm2uav routes`: one wave, every start of a file; outputs, per-start failures, exit codes."""

from __future__ import annotations

import csv
import json

import numpy as np
import pytest
from typer.testing import CliRunner

from fm2uav import Shaping, plan, scenarios
from fm2uav.cli import app
from fm2uav.world.geo import to_lonlat

runner = CliRunner()


@pytest.fixture(scope="module")
def city_starts(tmp_path_factory):
    sc = scenarios.get_scenario("city2d")
    w = sc.world
    free = np.argwhere(~w.occupancy)
    rng = np.random.default_rng(2)
    pts = w.to_world(free[rng.choice(len(free), 12, replace=False)].astype(float))
    pts = np.vstack([pts, [[20.0, 3.0]], [[-50.0, 10.0]]])  # then: maybe blocked, outside
    ll = to_lonlat(w, pts)
    f = tmp_path_factory.mktemp("routes") / "addresses.csv"
    with open(f, "w") as fh:
        fh.write("lon,lat,id\n")
        for k, (lo, la) in enumerate(ll[:, :2]):
            fh.write(f"{lo:.9f},{la:.9f},house-{k + 1}\n")
        fh.write("oops,40.3,bad\n")
    goal_ll = to_lonlat(w, np.asarray(sc.goal, float)[None])[0]
    return sc, pts, f, f"{goal_ll[0]:.9f},{goal_ll[1]:.9f}"


def test_routes_equal_single_plans_and_failures_are_listed(tmp_path, city_starts):
    sc, pts, f, goal = city_starts
    out = tmp_path / "r"
    res = runner.invoke(app, ["routes", "--scenario", "city2d", f"--goal={goal}", "--starts",
                              str(f), "--exponent", "0.5", "--thin", "0", "--out", str(out)])
    assert res.exit_code == 0, res.output
    rows = list(csv.DictReader(open(out / "routes.csv")))
    assert [r["id"] for r in rows] == [f"house-{k + 1}" for k in range(14)] + ["bad"]
    assert rows[-1]["status"] == "failed" and rows[-1]["reason"] == "invalid"
    assert rows[13]["reason"] == "outside"
    gj = json.loads((out / "routes.geojson").read_text())
    feats = {ft["properties"]["id"]: ft for ft in gj["features"]}
    ok = [r for r in rows if r["status"] == "ok"]
    assert len(feats) == len(ok) >= 10
    summary = json.loads((out / "summary.json").read_text())
    assert summary["starts"] == 15 and summary["routes"] == len(ok)
    assert {x["id"] for x in summary["failures"]} == {r["id"] for r in rows
                                                     if r["status"] == "failed"}
    goal_m = np.asarray(sc.goal, float)
    for k in (0, 5, 9):
        r = rows[k]
        if r["status"] != "ok":
            continue
        single = plan(sc.world, pts[k], goal_m, shaping=Shaping(exponent=0.5))
        assert float(r["length_m"]) == round(single.length, 3)
        assert float(r["time_s"]) == round(single.length / 10.0, 3)
        line = np.asarray(feats[r["id"]]["geometry"]["coordinates"])
        assert len(line) == len(single.path)  # --thin 0: every point
        np.testing.assert_allclose(line, np.round(to_lonlat(sc.world, single.path)[:, :2], 7))


def test_exit_codes_and_one_line_errors(tmp_path, city_starts):
    sc, pts, f, goal = city_starts
    bad = tmp_path / "bad.csv"
    bad.write_text("x,y\n1,2\n")
    base = ["routes", "--scenario", "city2d", f"--goal={goal}"]
    for extra in (["--starts", str(bad)], ["--starts", str(tmp_path / "none.csv")],
                  ["--starts", str(f), "--speed", "0"], ["--starts", str(f), "--threads", "0"],
                  ["--starts", str(f), "--thin", "-1"]):
        res = runner.invoke(app, [*base, *extra, "--out", str(tmp_path / "o")])
        assert res.exit_code == 2, (extra, res.output)
        assert "Traceback" not in res.output
        assert not (tmp_path / "o").exists()
    lost = tmp_path / "lost.csv"
    lost.write_text("lon,lat\n0,0\n1,1\n")
    res = runner.invoke(app, [*base, "--starts", str(lost), "--out", str(tmp_path / "o2")])
    assert res.exit_code == 1, res.output
    assert "none of the 2 starts got a route" in res.output
    assert not (tmp_path / "o2").exists()


def test_report_draws_every_route_and_lists_the_failed_starts(tmp_path, city_starts):
    """``--report``: report.html beside the three files, opening on the map with the longest
    route as the main one and every other route as one layer, the failed starts listed."""
    import re

    _, _, f, goal = city_starts
    out = tmp_path / "rep"
    res = runner.invoke(app, ["routes", "--scenario", "city2d", f"--goal={goal}", "--starts",
                              str(f), "--report", "--out", str(out), "--quiet"])
    assert res.exit_code == 0, res.output
    assert sorted(p.name for p in out.iterdir()) == ["report.html", "routes.csv",
                                                      "routes.geojson", "summary.json"]
    page = (out / "report.html").read_text(encoding="utf-8")
    rows = list(csv.DictReader(open(out / "routes.csv")))
    ok = [r for r in rows if r["status"] == "ok"]
    longest = max(ok, key=lambda r: float(r["length_m"]))
    assert 'id="fm2uav-map"' in page
    assert f"longest route ({longest['id']})" in page
    assert f"every route ({len(ok)})" in page
    for r in rows:
        if r["status"] == "failed":  # each failed start named with its reason
            assert re.search(rf">{re.escape(r['id'])}<.*?>{r['reason']}<", page, re.S), r["id"]
    # the failed starts with a position are a map layer of their own, where routes.csv says
    from tests.viz.test_reportmap import _map_document

    failed = [r for r in rows if r["status"] == "failed" and r["lon"]]
    assert failed, "the case needs failed starts on the map"
    layers = [f for f in _map_document(page)["features"]
              if f["properties"].get("layer") == f"failed starts ({len(failed)})"]
    assert len(layers) == 1 and layers[0]["geometry"]["type"] == "MultiPoint"
    np.testing.assert_allclose(layers[0]["geometry"]["coordinates"],
                               [[float(r["lon"]), float(r["lat"])] for r in failed], atol=2e-7)
