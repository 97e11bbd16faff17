"""Summary rows of a data world (pipeline/rows.py): the grid row says why the cell sizes were
chosen when the loader says so, and prints no empty '()' and no empty sources row when it
does not (issue 25: 'cells 150 m ()' in the summary of the Jacksboro example)."""

from __future__ import annotations

import numpy as np
import rasterio
from rasterio.transform import from_origin

from fm2uav.pipeline.rows import world_rows
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
