"""`fm2uav run` on a GeoTIFF with a no-fly polygon across the direct route, checked from the
written files only: path.csv and mission.plan read back, the GeoTIFF sampled bilinearly with
rasterio + scipy here, the figures compared with summary.json to 1 m."""

from __future__ import annotations

import json

import numpy as np
import pytest
import shapely
from pyproj import Transformer
from typer.testing import CliRunner

from fm2uav.cli import app

from tests.world.rough_terrain import rough_dem, source_ground, write_geotiff

WEST, NORTH = -3.80, 40.36
PIX = 1.0 / 1200.0
AGL, MAX_AGL, BUFFER = 120.0, 135.0, 60.0


class _W:  # what source_ground needs: the world's CRS
    def __init__(self, crs):
        self.crs = crs


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    d = tmp_path_factory.mktemp("run")
    tif = write_geotiff(d / "dem.tif", rough_dem(21, rows=150, cols=190, relief=450.0))
    east, south = WEST + 190 * PIX, NORTH - 150 * PIX
    s_ll = (WEST + 0.03, south + 0.03)
    g_ll = (east - 0.03, NORTH - 0.03)
    mid = ((s_ll[0] + g_ll[0]) / 2, (s_ll[1] + g_ll[1]) / 2)
    # a band across the direct route, 0.03 deg wide, with room at both ends
    dx, dy = g_ll[0] - s_ll[0], g_ll[1] - s_ll[1]
    n = np.array([-dy, dx]) / np.hypot(dx, dy)
    t = np.array([dx, dy]) / np.hypot(dx, dy)
    c = np.array(mid)
    ring = [c + 0.035 * n - 0.006 * t, c + 0.035 * n + 0.006 * t, c - 0.035 * n + 0.006 * t,
            c - 0.035 * n - 0.006 * t]
    poly = [[float(x), float(y)] for x, y in ring] + [[float(ring[0][0]), float(ring[0][1])]]
    (d / "nofly.geojson").write_text(json.dumps({"type": "FeatureCollection", "features": [
        {"type": "Feature", "properties": {"name": "band"},
         "geometry": {"type": "Polygon", "coordinates": [poly]}}]}))
    (d / "m.yaml").write_text(f"""
name: safety outputs
world: {{dem: dem.tif, cell_size: 200}}
start: {{lon: {s_ll[0]}, lat: {s_ll[1]}, agl: 30}}
goal: {{lon: {g_ll[0]}, lat: {g_ll[1]}, agl: 30}}
planner: {{agl: {AGL}, max_agl: {MAX_AGL}, min_agl: 25}}
no_fly_zones: [{{file: nofly.geojson, buffer: {BUFFER}}}]
airframe: {{firmware: px4}}
outputs: {{formats: [csv, plan, json]}}
""")
    out = d / "out"
    res = CliRunner().invoke(app, ["run", str(d / "m.yaml"), "--out", str(out), "--quiet"])
    assert res.exit_code == 0, res.output
    summary = json.loads((out / "summary.json").read_text())
    lines = [ln for ln in (out / "path.csv").read_text().splitlines() if not ln.startswith("#")]
    head = lines[0].split(",")
    data = np.array([[float(v) for v in ln.split(",")] for ln in lines[1:]])
    path = data[:, [head.index("x_m"), head.index("y_m"), head.index("z_m")]]
    return {"dir": d, "out": out, "tif": tif, "summary": summary, "path": path, "poly": poly}


def _crs(run):
    return run["summary"]["world"]["crs"]


def _agl(run, pts):
    g = source_ground(run["tif"], _W(_crs(run)), pts[:, 0], pts[:, 1])
    return pts[:, 2] - g


def test_summary_figures_equal_an_independent_check(run):
    s = run["summary"]["safety"]
    h = _agl(run, run["path"])
    i0, i1 = s["cruise_points"]
    hc = h[i0:i1 + 1]
    for key, f in (("path", h), ("cruise", hc)):
        fig = s["height_above_ground"][key]
        assert fig["min_m"] == pytest.approx(f.min(), abs=1.0)
        assert fig["p5_m"] == pytest.approx(np.percentile(f, 5), abs=1.0)
        assert fig["median_m"] == pytest.approx(np.median(f), abs=1.0)
        assert fig["max_m"] == pytest.approx(f.max(), abs=1.0)
    assert hc.min() >= AGL - 2.0 and abs(np.median(hc) - AGL) <= 5.0
    assert h[1:-1].min() >= 25.0 - 0.5 and h.max() <= MAX_AGL + 0.5


def _plan_points(run):
    doc = json.loads((run["out"] / "mission.plan").read_text())
    items = [it for it in doc["mission"]["items"] if it["command"] in (16, 22)]
    assert {it["frame"] for it in items} == {0}  # PX4: AMSL
    lat = np.array([it["params"][4] for it in items])
    lon = np.array([it["params"][5] for it in items])
    alt = np.array([it["params"][6] for it in items])
    x, y = Transformer.from_crs("EPSG:4326", _crs(run), always_xy=True).transform(lon, lat)
    return doc, np.column_stack([x, y, alt])


def test_path_and_legs_stay_out_of_the_zone_and_its_buffer(run):
    doc, wps = _plan_points(run)
    to_xy = Transformer.from_crs("EPSG:4326", _crs(run), always_xy=True)
    ring = np.array(run["poly"])
    zx, zy = to_xy.transform(ring[:, 0], ring[:, 1])
    keep_out = shapely.Polygon(np.column_stack([zx, zy])).buffer(BUFFER)
    assert not shapely.intersects(shapely.LineString(run["path"][:, :2]), keep_out)
    assert not shapely.intersects(shapely.LineString(wps[:, :2]), keep_out)
    # ... and the .plan carries the zone as an exclusion polygon (without the buffer)
    fences = doc["geoFence"]["polygons"]
    assert len(fences) == 1 and fences[0]["inclusion"] is False
    got = np.array(sorted(map(tuple, fences[0]["polygon"])))
    want = np.array(sorted((la, lo) for lo, la in run["poly"][:-1]))
    np.testing.assert_allclose(got, want, atol=1e-6)


def test_legs_keep_the_floor_and_the_summary_says_so(run):
    _, wps = _plan_points(run)
    legs = np.concatenate([a + np.linspace(0, 1, max(int(np.hypot(*(b - a)[:2])), 1) + 1)[:, None]
                           * (b - a) for a, b in zip(wps[:-1], wps[1:])])
    h = _agl(run, legs)
    s = run["summary"]["safety"]["legs"]
    assert s["min_m"] == pytest.approx(h.min(), abs=1.0)
    # min_agl holds off the take-off and landing columns (vertical legs there are exempt)
    d = np.minimum(np.hypot(*(legs[:, :2] - wps[0, :2]).T), np.hypot(*(legs[:, :2] - wps[-1, :2]).T))
    assert h[d > 1e-6].min() >= 25.0 - 0.5
    assert s["cruise"]["min_m"] >= AGL - 2.0 - 0.5
