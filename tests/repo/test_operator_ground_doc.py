"""The DEM messages quoted in docs/operator.md (Rasters, Known and unknown ground, Errors name
the fix) are what the program prints today, on the test DEMs of tests/world/dem_cases.py.

Print the lines with ``.venv/bin/python -m tests.repo.test_operator_ground_doc``.
"""

from __future__ import annotations

import os
from pathlib import Path

import pytest

DOC = Path(__file__).resolve().parents[2] / "docs" / "operator.md"

#: (files made in the folder, the command's arguments) of each quoted message.
RUNS = [
    ["plan", "--dem", "country.tif", "--nodata", "fill", "--lonlat", "--start", "10.0875,45.67",
     "--goal", "10.2125,45.57", "--agl", "100", "--cell-size", "150", "--quiet"],
    ["plan", "--dem", "srtm_voids.tif", "--lonlat", "--start", "7.02,46.18", "--goal",
     "7.13,46.09", "--agl", "80"],
    ["plan", "--dem", "dem.tif", "--start", "500300,4499500,150", "--goal",
     "501000,4499000,150"],
    ["plan", "--dem", "map.tif", "--start", "500300,4499500,150", "--goal",
     "501000,4499000,150"],
    ["plan", "--dem", "coast.tif", "--bbox", "10.05,45.54,10.20,45.66", "--cell-size", "250",
     "--dz", "25", "--lonlat", "--start", "10.06,45.55,120", "--goal", "10.19,45.65,120",
     "--quiet"],
]


def _files(folder: Path) -> None:
    from tests.e2e.conftest import relief, write_dem
    from tests.world import dem_cases as dc
    from tests.world import geodata_data as gd

    dc.country(folder / "country.tif")
    dc.srtm_voids(folder / "srtm_voids.tif")
    dc.rgb(folder / "map.tif")
    gd.topo_bathy(folder / "coast.tif")
    z = relief()
    z[12, 12] = -2000.0
    write_dem(folder / "dem.tif", z)


def messages(folder: Path) -> list[str]:
    """The ``warning:`` / ``error:`` lines the runs print, in order."""
    from typer.testing import CliRunner

    from fm2uav.cli import app

    _files(folder)
    old = os.getcwd()
    os.chdir(folder)
    lines: list[str] = []
    try:
        for k, args in enumerate(RUNS):
            res = CliRunner(env={"COLUMNS": "4000"}).invoke(app, [*args, "--out", f"o{k}"])
            lines += [ln for ln in res.output.splitlines()
                      if ln.startswith(("warning:", "error:"))]
    finally:
        os.chdir(old)
    return lines


@pytest.mark.slow
def test_the_quoted_dem_messages_are_printed_as_quoted(tmp_path):
    doc = DOC.read_text()
    lines = messages(tmp_path)
    assert len(lines) == 6
    for ln in lines:
        assert ln in doc, ln


if __name__ == "__main__":  # pragma: no cover - prints the lines for the doc
    import tempfile

    with tempfile.TemporaryDirectory() as d:
        print("\n".join(messages(Path(d))))
