"""Acceptance (issue 25): a no-fly zone with a ceiling (or a floor) across the only route is
flown over (or under) — never refused by the planner's own check — and the written files
say so when re-measured independently: path.geojson and the mission.plan legs read back,
the zone file read with pyogrio and reprojected with pyproj, the GeoTIFF sampled
bilinearly with rasterio + scipy here."""

from __future__ import annotations

import json

import numpy as np
import pyogrio
import pytest
import shapely
from pyproj import Transformer
from typer.testing import CliRunner

from fm2uav.cli import app

from tests.e2e.conftest import write_dem
from tests.e2e.remeasure import dem_ground

X0, Y0, PX = 465000.0, 5248200.0, 10.0
ROWS, COLS = 60, 130
CRS = "EPSG:32632"


def _terrain():
    r, c = np.mgrid[0:ROWS, 0:COLS].astype(float)
    return 400.0 + 25.0 * np.sin(c / 9.0) + 15.0 * np.cos(r / 7.0) + 0.2 * c


def _ground(tif, lon, lat):
    """The GeoTIFF's bilinear ground at lon/lat, measured as every acceptance test does."""
    return dem_ground(tif)(np.asarray(lon), np.asarray(lat))


def _slug(name):
    return "".join(c if c.isalnum() else "-" for c in name)


CASES = {
    "amsl ceiling, buffer 10": {"ceiling": 480, "buffer": 10},
    "amsl ceiling, buffer 0": {"ceiling": 480, "buffer": 0},
    "agl ceiling, buffer 5": {"ceiling": 60, "reference": "agl", "buffer": 5},
    "agl floor, buffer 5 (under)": {"floor": 90, "reference": "agl", "buffer": 5},
}


@pytest.fixture(scope="module")
def data(tmp_path_factory):
    d = tmp_path_factory.mktemp("zones")
    tif = write_dem(d / "hills.tif", _terrain(), x0=X0, y0=Y0, px=PX, crs=CRS)
    to_ll = Transformer.from_crs(CRS, "EPSG:4326", always_xy=True)
    # a strip 150 m wide across the whole map (and beyond): the only way is over or under
    ring = [(X0 + 550, Y0 - ROWS * PX - 200), (X0 + 700, Y0 - ROWS * PX - 200),
            (X0 + 700, Y0 + 200), (X0 + 550, Y0 + 200)]
    ll = [list(to_ll.transform(*p)) for p in ring]
    for name, props in CASES.items():
        (d / f"{_slug(name)}.geojson").write_text(json.dumps({
            "type": "FeatureCollection", "features": [{
                "type": "Feature", "properties": {"name": "strip", **props},
                "geometry": {"type": "Polygon", "coordinates": [ll + [ll[0]]]}}]}))
    s = to_ll.transform(X0 + 150, Y0 - 300)
    g = to_ll.transform(X0 + COLS * PX - 150, Y0 - 300)
    return d, tif, s, g


def _run(data, case):
    d, tif, s, g = data
    zfile = d / f"{_slug(case)}.geojson"
    (d / "m.yaml").write_text(f"""
world: {{dem: hills.tif}}
start: {{lon: {s[0]}, lat: {s[1]}, agl: 40}}
goal: {{lon: {g[0]}, lat: {g[1]}, agl: 40}}
planner: {{agl: 40}}
no_fly_zones: [{zfile.name}]
airframe: {{firmware: px4}}
outputs: {{formats: [geojson, plan, json]}}
""")
    out = d / f"out-{_slug(case)}"
    res = CliRunner().invoke(app, ["run", str(d / "m.yaml"), "--out", str(out), "--quiet"])
    assert res.exit_code == 0, res.output
    return out, zfile


def _dense(pts, step=1.0):
    rows = [pts[:1]]
    x, y = Transformer.from_crs("EPSG:4326", CRS, always_xy=True).transform(pts[:, 0], pts[:, 1])
    m = np.column_stack([x, y])
    for k in range(len(pts) - 1):
        n = max(int(np.ceil(np.hypot(*(m[k + 1] - m[k])) / step)), 1)
        t = np.arange(1, n + 1)[:, None] / n
        rows.append(pts[k] + t * (pts[k + 1] - pts[k]))
    return np.concatenate(rows)


def _check_outside(points_ll, zfile, tif):
    """Every point inside the buffered footprint is over the ceiling (under the floor)."""
    meta, _, wkb, fields = pyogrio.raw.read(str(zfile))
    props = dict(zip(meta["fields"], [f[0] for f in fields]))
    zone = shapely.from_wkb(wkb[0])
    tr = Transformer.from_crs(meta["crs"] or "EPSG:4326", CRS, always_xy=True)
    zone_m = shapely.transform(zone, lambda xy: np.column_stack(tr.transform(xy[:, 0], xy[:, 1])))
    buf = float(props.get("buffer") or 0.0)
    keep = zone_m.buffer(buf) if buf else zone_m
    x, y = tr.transform(points_ll[:, 0], points_ll[:, 1])
    inside = shapely.contains_xy(keep, np.asarray(x), np.asarray(y))
    assert inside.sum() > 20
    base = _ground(tif, points_ll[:, 0], points_ll[:, 1]) if props.get("reference") == "agl" \
        else 0.0
    z = points_ll[:, 2]
    ok = np.zeros(len(z), bool)
    if props.get("ceiling") is not None:
        ok |= z >= base + float(props["ceiling"]) + buf - 0.01
    if props.get("floor") is not None:
        ok |= z <= base + float(props["floor"]) - buf + 0.01
    assert ok[inside].all(), (z - base)[inside & ~ok][:5]


@pytest.mark.parametrize("case", list(CASES))
def test_zone_across_the_only_route_is_flown_over_or_under(data, case):
    out, zfile = _run(data, case)
    _, tif, _, _ = data
    gj = json.loads((out / "path.geojson").read_text())
    path = np.array(next(f for f in gj["features"] if f["properties"].get("name") == "path")
                    ["geometry"]["coordinates"])
    _check_outside(_dense(path), zfile, tif)
    # the legs the autopilot flies (PX4: frame 0, altitudes above mean sea level)
    plan = json.loads((out / "mission.plan").read_text())
    wps = np.array([[it["params"][5], it["params"][4], it["params"][6]]
                    for it in plan["mission"]["items"] if it["command"] == 16])
    assert all(it["frame"] == 0 for it in plan["mission"]["items"] if it["command"] == 16)
    _check_outside(_dense(wps), zfile, tif)
    s = json.loads((out / "summary.json").read_text())
    assert s["safety"]["zones"]["path_entries"] == []
    # a 2D geofence cannot carry a floor or ceiling: the zone is not in the .plan's fence,
    # and the .plan's fm2uav metadata and the summary say so
    assert plan["geoFence"]["polygons"] == [] and plan["geoFence"]["circles"] == []
    st = plan["fm2uav"]["geofence"]
    assert [e["zone"] for e in st["not_carried"]] == ["strip"] and "2D" in st["limits"]
    assert st == s["autopilot"]["geofence"]
    assert any("geofence" in w and "strip" in w for w in s["autopilot"]["warnings"])
