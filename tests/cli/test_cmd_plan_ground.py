"""`fm2uav plan` on real DEMs (issue 25): a border route over filled nodata is reported in
summary.json, the printed summary, report.html and plan.png and equals an independent
measurement of the written path.geojson against the source GeoTIFF; `--nodata
error_on_route` refuses it (exit 1, nothing written); `--dem-fill` makes it measured ground;
topo-bathymetry with and without `--sea-level`."""

from __future__ import annotations

import json

import numpy as np
import pytest
from pyproj import Transformer
from typer.testing import CliRunner

from fm2uav.cli import app

from tests.world import dem_cases as dc

START = ",".join(f"{v}" for v in dc.BORDER_START)
GOAL = ",".join(f"{v}" for v in dc.BORDER_GOAL)


@pytest.fixture(scope="module")
def dems(tmp_path_factory):
    d = tmp_path_factory.mktemp("plan_ground")
    return {"country": dc.country(d / "country.tif"), "neighbour": dc.neighbour(d / "nb.tif"),
            "bathy": dc.topo_bathy(d / "bathy.tif"), "dir": d}


def _plan(dems, out, *extra):
    return CliRunner().invoke(app, [
        "plan", "--dem", str(dems["country"]), "--lonlat", "--start", START, "--goal", GOAL,
        "--agl", "100", "--cell-size", "150", "--out", str(out), *extra])


@pytest.fixture(scope="module")
def filled_run(dems):
    out = dems["dir"] / "fill"
    res = _plan(dems, out, "--nodata", "fill", "--export", "geojson,plan", "--report")
    return res, out


def test_flying_over_filled_ground_is_said_everywhere(filled_run):
    res, out = filled_run
    assert res.exit_code == 0, res.output
    s = json.loads((out / "summary.json").read_text())
    g = s["safety"]["ground"]
    assert g["filled"]["length_m"] > 1500.0
    km = g["filled"]["length_m"] / 1000
    # the warning line and the printed rows
    assert f"warning: the path flies {km:.2f} km of" in " ".join(res.output.split())
    table = res.output[res.output.index("FM² plan"):]  # the printed rows (cells wrap)
    assert "ground under the path" in table and "invented" in table
    assert table.count("FILLED") >= 2
    # report.html: the warning first, the path over filled ground drawn
    html = (out / "report.html").read_text()
    assert 'id="fm2uav-warnings"' in html and f"flies {km:.2f} km" in html
    assert "path over FILLED ground (unknown)" in html


def test_the_split_equals_an_independent_measurement_of_the_written_files(filled_run, dems):
    res, out = filled_run
    s = json.loads((out / "summary.json").read_text())
    g = s["safety"]["ground"]
    doc = json.loads((out / "path.geojson").read_text())
    ll = np.array(next(f for f in doc["features"] if f["properties"]["name"] == "path")
                  ["geometry"]["coordinates"])
    crs = s["world"]["georef"]["crs"]
    x, y = Transformer.from_crs("EPSG:4326", crs, always_xy=True).transform(ll[:, 0], ll[:, 1])
    pts = np.column_stack([x, y, ll[:, 2]])

    def unknown(p):
        return ~dc.measured_mask(dems["country"], crs, p)

    over, total = dc.length_over(pts, unknown, step=0.25)
    assert g["length_m"] == pytest.approx(total, abs=1.0)
    assert g["filled"]["length_m"] == pytest.approx(over, abs=1.0)
    assert g["measured"]["length_m"] == pytest.approx(total - over, abs=1.0)
    # the lowest AGL over measured ground, from the GeoTIFF itself under the geojson points
    from tests.world.rough_terrain import source_ground

    class _W:  # the CRS the points are in, for the independent sampler
        pass
    _W.crs = crs
    agl = pts[:, 2] - source_ground(dems["country"], _W, pts[:, 0], pts[:, 1])
    known = ~unknown(pts)
    assert g["measured"]["height_above_ground"]["min_m"] == pytest.approx(agl[known].min(),
                                                                          abs=1.0)
    assert g["filled"]["points"] == int((~known).sum())
    # the mission's legs say the same ground
    legs = s["safety"]["legs"]["ground"]
    assert legs["filled_samples"] > 0 and legs["filled_min_m"] is not None


def test_error_on_route_refuses_the_plan_in_one_line(dems):
    out = dems["dir"] / "refused"
    res = _plan(dems, out, "--nodata", "error_on_route")
    assert res.exit_code == 1, res.output
    err = [ln for ln in res.output.splitlines() if ln.startswith("error:")]
    assert len(err) == 1 and "over filled DEM nodata" in err[0]
    assert "lon 10." in err[0] and "--dem-fill" in err[0] and "error_on_route" in err[0]
    assert not out.exists()


def test_the_neighbours_dem_makes_the_route_measured_ground(dems):
    out = dems["dir"] / "both"
    res = _plan(dems, out, "--dem-fill", str(dems["neighbour"]), "--nodata", "error_on_route")
    assert res.exit_code == 0, res.output
    s = json.loads((out / "summary.json").read_text())
    g = s["safety"]["ground"]
    assert g["filled"]["length_m"] == 0
    names = [src["dem"] for src in g["sources"]]
    assert names == ["country.tif", "nb.tif"]
    assert g["sources"][1]["length_m"] > 1500.0  # the bay, measured by the neighbour
    roles = [src["role"] for src in s["world"]["georef"]["sources"]]
    assert roles == ["dem", "dem_fill"]
    assert "gaps from nb.tif" in " ".join(res.output.split())


def test_topo_bathymetry_with_and_without_sea_level(dems):
    args = ["plan", "--dem", str(dems["bathy"]), "--lonlat", "--start", "24.45,38.95,120",
            "--goal", "25.6,38.3,120", "--cell-size", "4000", "--dz", "40"]
    res = CliRunner().invoke(app, [*args, "--sea-level", "0", "--out", str(dems["dir"] / "b")])
    assert res.exit_code == 0, res.output
    res = CliRunner().invoke(app, [*args, "--quiet", "--out", str(dems["dir"] / "b2")])
    text = " ".join(res.output.split())
    assert "deeper than any dry land" in text and "--sea-level 0" in text
    assert "world.sea_level" in text
