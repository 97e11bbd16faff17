"""Acceptance (issue 25): a survey whose bands are narrower than the DEM's pixels, across a
no-fly zone with a ceiling, plans: ``fm2uav cover`` chooses a cell that resolves the bands
(and says so), or — with a cell given that cannot — names the flag to change."""

from __future__ import annotations

import json

import numpy as np
import pytest
from pyproj import Transformer
from typer.testing import CliRunner

from fm2uav.cli import app

from tests.e2e.conftest import write_dem

X0, Y0, PX, CRS = 465000.0, 5248200.0, 10.0, "EPSG:32632"


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    d = tmp_path_factory.mktemp("survey")
    r, c = np.mgrid[0:40, 0:60].astype(float)
    tif = write_dem(d / "dem.tif", 400 + 20 * np.sin(c / 8.0) + 10 * np.cos(r / 6.0),
                    x0=X0, y0=Y0, px=PX, crs=CRS)
    ll = Transformer.from_crs(CRS, "EPSG:4326", always_xy=True)

    def ring(x0, y0, x1, y1):
        pts = [list(ll.transform(x, y)) for x, y in ((x0, y0), (x1, y0), (x1, y1), (x0, y1))]
        return [pts + [pts[0]]]

    area = d / "field.geojson"
    area.write_text(json.dumps({"type": "Feature", "properties": {}, "geometry": {
        "type": "Polygon", "coordinates": ring(X0 + 100, Y0 - 300, X0 + 500, Y0 - 120)}}))
    zone = d / "zone.geojson"
    zone.write_text(json.dumps({"type": "FeatureCollection", "features": [{
        "type": "Feature", "properties": {"name": "low", "ceiling": 40, "reference": "agl",
                                          "buffer": 5},
        "geometry": {"type": "Polygon", "coordinates": ring(X0 + 280, Y0 - 450,
                                                            X0 + 330, Y0 + 50)}}]}))
    return d, tif, area, zone


def _cover(files, *extra):
    d, tif, area, zone = files
    out = d / ("out" + "".join(e.strip("-") for e in extra))
    res = CliRunner().invoke(app, [
        "cover", "--dem", str(tif), "--area", str(area), "--spacing", "8", "--agl", "60",
        "--no-fly", str(zone), "--angle", "0", "--out", str(out), "--quiet", *extra])
    return res, out


@pytest.mark.slow
def test_narrow_bands_across_a_ceiling_zone_get_a_cell_that_resolves_them(files):
    res, out = _cover(files)
    assert res.exit_code == 0, res.output
    s = json.loads((out / "summary.json").read_text())
    assert s["world"]["spacing_m"][0] <= 8.0 / 2.5
    rule = s["world"]["georef"]["sources"][0]["details"]["cell_size_rule"]
    assert "D / 2.5" in rule and "bands" in rule
    assert s["params"]["grid"] == "route"
    # every band has its camera on and off in the mission
    plan = json.loads((out / "mission.plan").read_text())
    trig = [it for it in plan["mission"]["items"] if it["command"] == 206]
    assert len(trig) == 2 * s["bands"]
    assert s["safety"]["zones"]["path_entries"] == []


def test_a_given_cell_that_cannot_resolve_the_bands_names_the_flags(files):
    res, _ = _cover(files, "--cell-size", "10")
    assert res.exit_code == 2
    msg = res.output.strip().splitlines()[-1]
    assert "--cell-size 3" in msg and "bands at least 25 m apart (--spacing)" in msg
