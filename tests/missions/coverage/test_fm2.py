import numpy as np
import pytest
from typer.testing import CliRunner

from fm2uav import FlightLevel, World
from fm2uav.cli import app
from fm2uav.missions.coverage import corridor_speed, plan_coverage, zigzag
from fm2uav.scenarios.coverage import COVERAGE_AREAS, coverage_area, coverage_world
from fm2uav.scenarios import get_scenario


def test_corridor_speed_exact():
    w = World(np.zeros((11, 5, 3), bool), spacing=1.0)
    c = corridor_speed(w, np.array([[0.0, 2.0], [10.0, 2.0]]), 2.0)
    np.testing.assert_allclose(c[:, 2], 1.0)
    np.testing.assert_allclose(c[:, 1], 0.5, atol=1e-9)
    np.testing.assert_allclose(c[:, 0], 0.0)


def test_scenario_registered():
    sc = get_scenario("coverage")
    assert sc.world.shape == (118, 87, 40)
    assert sc.world.spacing == (10.0, 10.0, 10.0)
    assert set(COVERAGE_AREAS) == {"S1", "S2", "S3", "S4"}


@pytest.mark.parametrize("name, base, grid, bar", [("S3", "world", "corridor", 0.998),
                                                   ("S2", "uniform", "corridor", 0.998),
                                                   ("S1", "world", "map", 0.97)])
def test_coverage_plan_end_to_end(name, base, grid, bar):
    world = coverage_world(0)
    cp = plan_coverage(world, coverage_area(name), 80.0, level=FlightLevel(agl=100.0),
                       level_base=base, grid=grid)
    assert cp.zigzag_coverage > 0.999
    # the seeds' W0 on the map's grid drifts off the slanted bands (~98-99.6 %);
    # the unrolled corridor keeps the ground track on the zigzag
    assert cp.coverage >= bar
    assert cp.params["grid"] == grid
    assert (cp.grid is None) == (grid == "map")
    # the Plan is on the map whatever the grid
    assert cp.plan.world is world and cp.plan.W.shape == world.shape
    assert cp.plan.T.shape == world.shape
    # the path keeps the flight level (10 m cells): mean error under one cell
    assert np.abs(cp.agl_error).mean() < 10.0
    ground_clear = cp.agl_error + 100.0
    assert ground_clear.min() > 50.0
    # the path stays in the corridor of the zigzag
    zz = cp.zigzag.line()
    import shapely

    d = shapely.distance(shapely.points(cp.path[:, :2]), zz)
    assert d.max() <= 0.25 * 80.0 + 10.0
    s = cp.summary()
    assert s["bands"] == cp.zigzag.n_bands


def test_cli_cover_and_bad_input(tmp_path):
    runner = CliRunner()
    out = tmp_path / "c"
    r = runner.invoke(app, ["cover", "--area", "S3", "--spacing", "80", "--agl", "100",
                            "--out", str(out), "--quiet"])
    assert r.exit_code == 0, r.output
    for f in ("path.csv", "zigzag.csv", "bands.png", "coverage.png", "coverage.html",
              "summary.json"):
        assert (out / f).exists()
    # never overwrite without --force
    r = runner.invoke(app, ["cover", "--area", "S3", "--spacing", "80", "--out", str(out)])
    assert r.exit_code == 2
    bad = tmp_path / "bow.geojson"
    bad.write_text('{"type": "Polygon", "coordinates": [[[0,0],[100,100],[0,100],[100,0],[0,0]]]}')
    r = runner.invoke(app, ["cover", "--area", str(bad), "--spacing", "80",
                            "--out", str(tmp_path / "b")])
    assert r.exit_code == 2
    assert "not a valid polygon" in r.output
    r = runner.invoke(app, ["cover", "--area", "S1", "--spacing", "-1",
                            "--out", str(tmp_path / "n")])
    assert r.exit_code == 2


def test_zigzag_of_scenario_areas_inside_map():
    world = coverage_world(0)
    b = world.bounds
    for name in COVERAGE_AREAS:
        z = zigzag(coverage_area(name), 80.0, np.radians(10.0))
        p = z.path()
        assert p[:, 0].min() >= b[0, 0] - 50 and p[:, 0].max() <= b[0, 1] + 50
