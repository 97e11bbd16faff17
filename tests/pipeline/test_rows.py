"""fm2uav.pipeline.rows: the printed rows say what the summary says (issue 25: 'cells 150 m ()'
in the summary of the Jacksboro example, the 120 m advice, a home whose altitude above sea
level is unknown)."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import rasterio
from rasterio.transform import from_origin

from fm2uav.pipeline.rows import mission_rows, safety_rows, world_rows
from fm2uav.scenarios.jacksboro import jacksboro_world
from fm2uav.world.load import WorldSpec, load_world


def test_a_world_built_in_code_has_no_empty_brackets_or_sources():
    rows = world_rows(jacksboro_world())
    assert rows["grid"].endswith("nodes, cells 150 m, dz 30 m")
    assert "()" not in " ".join(rows.values())
    assert "sources" not in rows  # built-in data carry no checksum


def test_a_loaded_dem_names_the_rule_behind_each_size(tmp_path):
    f = tmp_path / "dem.tif"
    z = 300.0 + 20.0 * np.add.outer(np.sin(np.arange(40) / 6), np.cos(np.arange(50) / 5))
    with rasterio.open(f, "w", driver="GTiff", height=40, width=50, count=1, dtype="float32",
                       crs="EPSG:32630", transform=from_origin(440000, 4470000, 30, 30)) as d:
        d.write(z.astype("float32")[None])
    spec = WorldSpec.model_validate({"dem": str(f), "cell_size": 60.0})
    rows = world_rows(load_world(spec, agl=120.0))
    assert "cells 60 m (given (world.cell_size)), dz 20 m (auto: at most agl / 6" \
        in rows["grid"]
    assert "()" not in " ".join(rows.values())
    assert rows["sources"].startswith("dem.tif (sha256 ")


def _mission(alt):
    return SimpleNamespace(summary=lambda: {
        "firmware": "px4", "vehicle": "multirotor", "items": 8, "waypoints": 7, "end": "land",
        "frame": {"name": "relative" if alt is None else "amsl",
                  "mav_frame": 3 if alt is None else 0},
        "home": {"lat": 40.3790621, "lon": -3.7060042, "alt_amsl_m": alt, "source": "ground"},
        "flight": {"flight_distance_m": 540.0, "flight_time_s": 120.0},
        "speed_changes": {"items": 0, "speeds_mps": []}, "warnings": ["w"]})


def test_home_altitude_unknown_is_said_never_printed_as_a_number():
    assert mission_rows(_mission(None))["home lat, lon, alt"] == (
        "40.3790621, -3.7060042, altitude above sea level unknown (ground)")
    assert mission_rows(_mission(650.0))["home lat, lon, alt"] == (
        "40.3790621, -3.7060042, 650.0 m AMSL (ground)")


def test_every_safety_warning_gets_a_row():
    rows = safety_rows({"warnings": ["the path flies up to 130.0 m above the ground", "b"]})
    assert rows["safety warning 1"] == "the path flies up to 130.0 m above the ground"
    assert rows["safety warning 2"] == "b"
    assert not any(k.startswith("safety warning") for k in safety_rows({"warnings": []}))
