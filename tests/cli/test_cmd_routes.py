"""`fm2uav routes`: one wave, every start of a file; outputs, per-start failures, exit codes."""

from __future__ import annotations

import csv
import json

import numpy as np
import pytest
from pyproj import Geod
from typer.testing import CliRunner

from fm2uav import Shaping, plan, scenarios
from fm2uav.cli import app
from fm2uav.world.geo import to_lonlat

runner = CliRunner()
GEOD = Geod(ellps="WGS84")


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
        assert float(r["planned_length_m"]) == round(single.length, 3)
        line = np.asarray(feats[r["id"]]["geometry"]["coordinates"])
        assert float(r["length_m"]) == pytest.approx(GEOD.line_length(*line.T), abs=6e-4)
        assert float(r["time_s"]) == pytest.approx(float(r["length_m"]) / 10.0, abs=6e-4)
        assert len(line) == len(single.path)  # --thin 0: every point
        np.testing.assert_allclose(line, np.round(to_lonlat(sc.world, single.path)[:, :2], 7))


def test_every_figure_equals_an_independent_check_of_the_written_files(tmp_path, city_starts):
    """Default thinning (1 m): each route's length_m / time_s are the written line's (WGS84
    geodesic of its positions, as pyproj measures the file), the summary's lengths those of
    routes.csv, planned_length_m the planner's; a start off the map is refused in lon/lat."""
    sc, pts, f, goal = city_starts
    out = tmp_path / "r"
    res = runner.invoke(app, ["routes", "--scenario", "city2d", f"--goal={goal}", "--starts",
                              str(f), "--exponent", "0.5", "--speed", "7", "--out", str(out)])
    assert res.exit_code == 0, res.output
    rows = {r["id"]: r for r in csv.DictReader(open(out / "routes.csv"))}
    feats = json.loads((out / "routes.geojson").read_text())["features"]
    assert len(feats) >= 10
    shorter = []
    for ft in feats:
        line = np.asarray(ft["geometry"]["coordinates"])
        measured = GEOD.line_length(*line.T)
        p, row = ft["properties"], rows[ft["properties"]["id"]]
        assert p["length_m"] == float(row["length_m"]) == pytest.approx(measured, abs=6e-4)
        assert p["time_s"] == float(row["time_s"]) == pytest.approx(measured / 7.0, abs=6e-4)
        assert p["points"] == len(line)
        assert p["planned_length_m"] == float(row["planned_length_m"])
        shorter.append(measured / p["planned_length_m"])
    # the thinned line is shorter than the planner's path, never longer (same endpoints)
    assert 0.98 < min(shorter) and max(shorter) <= 1.0 + 1e-6 and min(shorter) < 0.9995
    s = json.loads((out / "summary.json").read_text())
    lengths = sorted(float(r["length_m"]) for r in rows.values() if r["status"] == "ok")
    assert s["length_m"]["min"] == lengths[0] and s["length_m"]["max"] == lengths[-1]
    assert s["length_m"]["median"] == pytest.approx(float(np.median(lengths)), abs=6e-4)
    planned = sorted(float(r["planned_length_m"]) for r in rows.values() if r["status"] == "ok")
    assert s["planned_length_m"]["min"] == planned[0]
    assert f"{lengths[0]:.0f} / " in res.output  # the printed row: the written lengths
    outside = rows["house-14"]
    assert outside["reason"] == "outside"
    assert f"lon {outside['lon']}, lat {outside['lat']}" in outside["message"]
    assert "lies outside the map (lon -3." in outside["message"]
    assert "m lies outside the map, whose bounds are" in outside["message"]  # then in metres


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


def _lowest_agl_by_ground(tif, crs, to_map, ll, step=1.0):
    """Independently of fm2uav: min(alt - ground) along the straight legs (in the map's
    metres, every ``step`` m) of lon/lat/alt positions, over ground the GeoTIFF measures
    and over its nodata apart (None where there is none); ground = the GeoTIFF bilinear
    between its pixel centres."""
    import rasterio
    from pyproj import Transformer
    from scipy import ndimage

    from tests.world import dem_cases as dc

    xy = np.column_stack(to_map.transform(ll[:, 0], ll[:, 1]))
    pts = []
    for a, b, za, zb in zip(xy[:-1], xy[1:], ll[:-1, 2], ll[1:, 2]):
        t = np.linspace(0.0, 1.0, max(2, int(np.hypot(*(b - a)) / step) + 1))
        pts.append(np.column_stack([a + t[:, None] * (b - a), za + t * (zb - za)]))
    p = np.concatenate(pts)
    known = dc.measured_mask(tif, crs, p)
    with rasterio.open(tif) as ds:
        z, inv, dem_crs = ds.read(1).astype(float), ~ds.transform, ds.crs
    lon, lat = Transformer.from_crs(crs, dem_crs, always_xy=True).transform(p[:, 0], p[:, 1])
    col, row = inv * (np.asarray(lon), np.asarray(lat))
    ground = ndimage.map_coordinates(z, [np.asarray(row) - 0.5, np.asarray(col) - 0.5],
                                     order=1, mode="nearest")
    h = p[:, 2] - ground
    return (float(h[known].min()) if known.any() else None,
            float(h[~known].min()) if (~known).any() else None)


def test_routes_over_filled_ground_say_so_as_an_independent_measurement_finds(tmp_path):
    """A DEM whose nodata is filled (``--nodata fill``): the metres of each written line over
    unknown ground (filled_ground_m) equal an independent reading of the GeoTIFF's mask under
    routes.geojson; the summary and the printed rows say how many routes fly over it."""
    from pyproj import Transformer

    from tests.world import dem_cases as dc

    tif = dc.country(tmp_path / "country.tif")
    starts = tmp_path / "starts.csv"
    starts.write_text("lon,lat,id\n"
                      f"{dc.BORDER_START[0]},{dc.BORDER_START[1]},border\n"
                      "10.17,45.62,inland\n")
    goal = ",".join(f"{v}" for v in dc.BORDER_GOAL)
    out = tmp_path / "r"
    res = runner.invoke(app, ["routes", "--dem", str(tif), f"--goal={goal}", "--starts",
                              str(starts), "--agl", "100", "--cell-size", "150", "--nodata",
                              "fill", "--out", str(out), "--report"])
    assert res.exit_code == 0, res.output
    s = json.loads((out / "summary.json").read_text())
    crs = s["world"]["georef"]["crs"]
    rows = {r["id"]: r for r in csv.DictReader(open(out / "routes.csv"))}
    to_map = Transformer.from_crs("EPSG:4326", crs, always_xy=True)
    measured = {}
    for ft in json.loads((out / "routes.geojson").read_text())["features"]:
        ll = np.asarray(ft["geometry"]["coordinates"])
        pts = np.column_stack([*to_map.transform(ll[:, 0], ll[:, 1]), ll[:, 2]])
        over, _ = dc.length_over(pts, lambda p: ~dc.measured_mask(tif, crs, p), step=0.25)
        p = ft["properties"]
        assert p["filled_ground_m"] == pytest.approx(over, abs=1.0)
        assert float(rows[p["id"]]["filled_ground_m"]) == p["filled_ground_m"]
        measured[p["id"]] = over
    assert measured["border"] > 500.0, measured  # the case needs a route over the fill
    # the lowest height above ground over measured ground only, as the GeoTIFF itself says
    # (bilinear between its pixel centres); a height above the invented fill apart
    for ft in json.loads((out / "routes.geojson").read_text())["features"]:
        p, row = ft["properties"], rows[ft["properties"]["id"]]
        ll = np.asarray(ft["geometry"]["coordinates"])
        low_measured, low_filled = _lowest_agl_by_ground(tif, crs, to_map, ll)
        assert p["lowest_agl_m"] == pytest.approx(low_measured, abs=0.05)
        assert float(row["lowest_agl_m"]) == p["lowest_agl_m"]
        if measured[p["id"]] > 0:
            assert low_filled is not None and p["lowest_agl_filled_m"] is not None
            assert float(row["lowest_agl_filled_m"]) == p["lowest_agl_filled_m"]
        else:
            assert low_filled is None and p["lowest_agl_filled_m"] is None
            assert row["lowest_agl_filled_m"] == ""
    assert s["over_filled_ground"]["lowest_agl_m"] == min(
        float(rows[k]["lowest_agl_filled_m"]) for k in measured if measured[k] > 0)
    assert "above that invented" in res.output and "lowest_agl_filled_m" in res.output
    page = (out / "report.html").read_text()  # the starts table says it too
    assert "<th>filled_ground_m</th>" in page and "<th>lowest_agl_filled_m</th>" in page
    over_ids = [k for k, v in measured.items() if v > 0]
    assert s["over_filled_ground"]["routes"] == len(over_ids)
    assert s["over_filled_ground"]["ids"] == over_ids
    assert "over FILLED ground" in res.output
