"""Tiny mission files for the batch tests: examples/town_buildings.yaml on a coarser grid.

Each is the example mission (buildings from examples/data/town.geojson) with 10 m cells (5 m:
``big``), only the light formats, and its own goal; ``outside`` has its goal off the map (fails
as fast as a mission can, with a PointError).
"""

from __future__ import annotations

import shutil
from pathlib import Path

import yaml

ROOT = Path(__file__).resolve().parents[2]
EXAMPLE = ROOT / "examples" / "town_buildings.yaml"

#: name -> (goal x, goal y, cell size [m]) of the missions.
MISSIONS = {
    "east": (440460.0, 4470070.0, 10.0),
    "north": (440070.0, 4470330.0, 10.0),
    "far": (440460.0, 4470330.0, 10.0),
    "big": (440460.0, 4470330.0, 5.0),
    "outside": (990460.0, 4470330.0, 10.0),
}

#: Files the light formats write (summary.json holds timings: equal but for timings_s).
FILES = ["mission.param", "mission.plan", "mission.waypoints", "path.csv", "path.geojson",
         "path.kml", "returns.geojson"]


def write_missions(folder: Path, names=tuple(MISSIONS), **outputs) -> dict[str, Path]:
    """Write the missions ``names`` into ``folder`` (with the buildings file in
    ``folder/data``); ``outputs`` adds keys to each mission's ``outputs:``."""
    (folder / "data").mkdir(parents=True, exist_ok=True)
    shutil.copy(ROOT / "examples" / "data" / "town.geojson", folder / "data" / "town.geojson")
    base = yaml.safe_load(EXAMPLE.read_text(encoding="utf-8"))
    out = {}
    for name in names:
        x, y, cell = MISSIONS[name]
        m = yaml.safe_load(yaml.safe_dump(base))
        m["name"] = f"town {name}"
        m["world"].update(cell_size=cell, height_cells=24 if cell < 10 else 16)
        m["goal"] = {"x": x, "y": y, "agl": 20}
        m["outputs"].update(formats=["csv", "geojson", "kml", "plan", "wpl", "json"], **outputs)
        out[name] = folder / f"{name}.yaml"
        out[name].write_text(yaml.safe_dump(m, sort_keys=False), encoding="utf-8")
    return out


def same_as_single_run(batch_dir: Path, single_dir: Path) -> None:
    """Every file of ``fm2uav run FILE`` equal in the batch's folder, byte for byte
    (summary.json: but for the timings), and nothing else there."""
    import json

    assert sorted(p.name for p in batch_dir.iterdir()) == sorted(
        p.name for p in single_dir.iterdir())
    for name in FILES:
        assert (batch_dir / name).read_bytes() == (single_dir / name).read_bytes(), name
    a, b = (json.loads((d / "summary.json").read_text()) for d in (batch_dir, single_dir))
    assert a.pop("timings_s").keys() == b.pop("timings_s").keys()
    assert a == b
