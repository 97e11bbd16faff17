"""Regional (coarse-to-fine) plans against the full-grid plan where the full grid fits."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import ndimage

import fm2uav
from fm2uav import FlightLevel, InputError, PlanOptions, World
from fm2uav.analysis.safety import safety_summary
from fm2uav.eikonal import _edt
from fm2uav.planning import regional
from fm2uav.planning.planner import max_distance
from fm2uav.world._columns import column_tops

CELL, DZ, AGL = 30.0, 20.0, 120.0


def _relief(n: int, sigma: float, relief_m: float, seed: int = 0) -> np.ndarray:
    rng = np.random.default_rng(seed)
    r = ndimage.gaussian_filter(rng.standard_normal((n, n)), sigma, mode="wrap")
    return (r - r.min()) / np.ptp(r) * relief_m + 200.0


def _world(heights: np.ndarray) -> World:
    nz = int(np.ceil((heights.max() + AGL + 10 * DZ - 180.0) / DZ)) + 1
    return World.from_heightmap(heights, (CELL, CELL, DZ), nz, origin=(0.0, 0.0, 180.0))


def _at(world: World, i: int, j: int) -> np.ndarray:
    x, y = i * CELL, j * CELL
    return np.array([x, y, float(world.ground_height(x, y)) + AGL])


@pytest.fixture(scope="module")
def medium():
    return _world(_relief(260, 10.0, 500.0))


def test_column_layer_edt_is_the_full_edt_layer(medium):
    sub = medium.occupancy[:70, :50]
    full = _edt.squared_edt(np.ascontiguousarray(sub), CELL, CELL, DZ)
    top, solid = column_tops(sub)
    assert solid
    for k in (0, 7, sub.shape[2] - 1):
        np.testing.assert_array_equal(
            _edt.squared_column_edt_layer(top, k, CELL, CELL, DZ), full[:, :, k])


def test_world_max_distance_is_the_full_plans(medium):
    assert regional.world_max_distance(medium) == max_distance(medium)


def test_regional_plan_matches_full_plan(medium):
    level = FlightLevel(agl=AGL, min_agl=100.0)
    s, g = _at(medium, 8, 10), _at(medium, 250, 245)
    full = fm2uav.plan(medium, s, g, level=level, options=PlanOptions(storage="full"))
    reg = fm2uav.plan(medium, s, g, level=level, options=PlanOptions(storage="regional"))
    assert "storage" not in full.params and reg.params["storage"] == "regional"
    assert reg.params["regional"]["windows"] >= 2  # really stitched from several windows
    np.testing.assert_allclose(reg.path[[0, -1]], full.path[[0, -1]])
    assert abs(reg.length / full.length - 1.0) < 0.01
    for p in (full, reg):
        summary = safety_summary(medium, p.path, requested=AGL, phase=p.phase, level=level)
        assert summary["checks"] and all(c["ok"] for c in summary["checks"].values())
        cruise = summary["height_above_ground"]["cruise"]
        assert cruise["min_m"] >= AGL - level.tolerance - 1e-6
    assert reg.clearance > 0.5 * AGL


def test_auto_storage_picks_regional_when_the_full_grid_is_too_big(medium, monkeypatch):
    level = FlightLevel(agl=AGL)
    s, g = _at(medium, 8, 10), _at(medium, 120, 100)
    monkeypatch.setattr(regional, "FULL_PLAN_MEMORY_SHARE", 0.0)
    assert fm2uav.plan(medium, s, g, level=level).params["storage"] == "regional"
    # no flight level: the full grid, whatever its size
    assert "storage" not in fm2uav.plan(medium, s, g).params


def test_regional_storage_refuses_what_it_cannot_plan(medium):
    s, g = _at(medium, 8, 10), _at(medium, 60, 50)
    with pytest.raises(InputError, match="needs a flight level.*--storage"):
        fm2uav.plan(medium, s, g, options=PlanOptions(storage="regional"))
    with pytest.raises(InputError, match="storage must be one of"):
        PlanOptions(storage="banded")


def test_auto_storage_names_the_fix_when_nothing_fits(medium, monkeypatch):
    monkeypatch.setattr(regional, "FULL_PLAN_MEMORY_SHARE", 0.0)
    monkeypatch.setattr(regional, "_memory_bytes", lambda: 1.0)
    s, g = _at(medium, 8, 10), _at(medium, 60, 50)
    with pytest.raises(InputError, match="needs a flight level.*--cell-size"):
        fm2uav.plan(medium, s, g)
    # any full-grid map of it (coverage, formation, ...) says the same, not MemoryError
    medium._cache.clear()
    with pytest.raises(InputError, match="GiB to plan on one full grid.*--agl.*--cell-size"):
        fm2uav.planning.base_velocity(medium)


def test_with_fields_shares_the_grid(medium):
    w = medium.with_fields(name="renamed", crs="EPSG:32630")
    assert w.occupancy is medium.occupancy and w.name == "renamed" and w.crs == "EPSG:32630"
    assert not w.occupancy.flags.writeable and w._cache == {}


@pytest.mark.parametrize("shaping", [fm2uav.Shaping(), fm2uav.Shaping(saturation_distance=200.0,
                                                                       exponent=1.5)])
def test_window_velocity_is_the_worlds_w_away_from_its_sides(medium, shaping):
    from fm2uav.planning.planner import plan_velocity

    level = FlightLevel(agl=AGL, band=20.0)
    full = plan_velocity(medium, shaping, level, PlanOptions())
    top = medium.surface_index()
    layer = top + int(round(AGL / DZ))
    xy = np.array([[60 * CELL, 50 * CELL], [140 * CELL, 120 * CELL]])
    sub = regional._window(medium, top, layer, xy, (np.r_[xy[0], 900.0], np.r_[xy[1], 900.0]))
    W = regional.window_velocity(sub, regional.world_max_distance(medium), shaping, level)
    i0, j0, k0 = (int(round(v)) for v in medium.to_index(np.asarray(sub.origin)))
    nx, ny, nz = W.shape
    inner = (slice(15, nx - 15), slice(15, ny - 15), slice(None))
    ref = full[i0:i0 + nx, j0:j0 + ny, k0:k0 + nz]
    np.testing.assert_array_equal(W[inner], ref[inner])
