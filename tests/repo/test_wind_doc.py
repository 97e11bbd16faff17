"""docs/wind.md: its table of flown routes is what the code gives, its code runs as written.

Print the table with ``.venv/bin/python -m tests.repo.test_wind_doc``.
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from .docs_run import runs_by_out

ROOT = Path(__file__).resolve().parents[2]
DOC = ROOT / "docs" / "wind.md"
BEGIN, END = "<!-- wind-flown:begin -->", "<!-- wind-flown:end -->"


def flown_table() -> str:
    """The jet case of tests/planning/test_wind.py flown by the tracking model."""
    import numpy as np

    from fm2uav import World, plan
    from fm2uav.planning.wind import WindOptions, path_timing
    from fm2uav.vehicles.wind_flight import fly_in_wind
    from fm2uav.world.wind import WindField

    h, V = 25.0, 12.0
    world = World(np.zeros((61, 41), bool), spacing=h)
    x, y = np.arange(61) * h, np.arange(41) * h
    rows = ["| wind | route | length [m] | predicted [s] | flown [s] | predicted − flown |",
            "|---|---|---|---|---|---|"]
    for frm in (90.0, 60.0):
        s = 9.0 * np.exp(-((y[None, :] - 500.0) / 120.0) ** 2) * np.ones((61, 1))
        th = np.radians(frm)
        jet = WindField.grid(x, y, -s * np.sin(th), -s * np.cos(th))
        a, b = (100.0, 500.0), (1400.0, 500.0)
        for name, p in (("wind-aware", plan(world, a, b, wind=WindOptions(jet, V))),
                        ("still-air", plan(world, a, b))):
            pred = path_timing(world, p.path, p.w, WindOptions(jet, V)).total_s
            f = fly_in_wind(p.path, p.w * V, jet, dt=0.05)
            rows.append(f"| 9 m/s jet from {frm:g}° | {name} | {p.length:.0f} | {pred:.1f} | "
                        f"{f.time_s:.1f} | {100 * (pred - f.time_s) / f.time_s:+.2f} % |")
    return "\n".join(rows)


def test_the_flown_table_is_the_code():
    text = DOC.read_text()
    block = text[text.index(BEGIN) + len(BEGIN):text.index(END)].strip()
    assert block == flown_table()


def test_the_python_block_runs():
    blocks = re.findall(r"```python\n(.*?)```", DOC.read_text(), flags=re.S)
    assert blocks
    for i, block in enumerate(blocks):
        exec(compile(block, f"docs/wind.md python block {i + 1}", "exec"), {})


@pytest.mark.slow
def test_the_guides_command_writes_the_mission(doc_runs):
    """The guide's command as the docs' run makes it (tests/repo/conftest.py; it exits 0,
    test_docs_run.py) writes the mission for the ground station."""
    runs = runs_by_out(doc_runs, DOC)
    assert runs["out/wind"].code == 0, runs["out/wind"].output
    assert (runs["out/wind"].out / "mission.plan").is_file()


if __name__ == "__main__":
    print(flown_table())
