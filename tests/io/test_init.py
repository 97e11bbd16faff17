"""``fm2uav.io`` loads its writers on first use: every command's output set (``io.outdir``,
entered before the command's body) costs no numpy, numba or geodata library."""

from __future__ import annotations

import subprocess
import sys


def _run(code: str) -> str:
    return subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          timeout=300, check=True).stdout.strip()


def test_the_output_set_loads_without_the_writers():
    code = ("import sys, fm2uav.io.outdir; "
            "print(sorted(m for m in ('numpy', 'numba', 'shapely', 'pyproj', 'rasterio', "
            "'fm2uav.autopilot', 'fm2uav.io.exports') if m in sys.modules))")
    assert _run(code) == "[]"


def test_every_public_name_still_resolves():
    code = ("import fm2uav.io as io; missing = [n for n in io.__all__ if not hasattr(io, n)]; "
            "print(missing, io.ExportOptions.__module__.split('.')[1], "
            "'write_plan' in dir(io))")
    assert _run(code) == "[] autopilot True"
