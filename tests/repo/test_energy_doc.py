"""docs/energy.md: its preset table is what the models give, its code runs as written.

Print the table with ``.venv/bin/python -m tests.repo.test_energy_doc``.
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from .docs_run import runs_by_out

ROOT = Path(__file__).resolve().parents[2]
DOC = ROOT / "docs" / "energy.md"
BEGIN, END = "<!-- energy-presets:begin -->", "<!-- energy-presets:end -->"


def preset_table() -> str:
    from fm2uav.vehicles.airframes import AIRFRAMES
    from fm2uav.vehicles.power import POWER_MODELS

    rows = ["| preset | kind | mass [kg] | battery [Wh] | power at the mission speed [W] | "
            "least-power speed [m/s] | best-range speed [m/s] | endurance, 80 % [min] | "
            "range, 80 % [km] |", "|---|---|---|---|---|---|---|---|---|"]
    for name, m in POWER_MODELS.items():
        af = AIRFRAMES[name]
        if m.kind == "multirotor":
            v, lo, hi, label = 0.0, 0.0, m.max_airspeed(), "hover"
        else:
            v, lo, hi, label = af.cruise_speed, af.min_speed, af.max_speed, f"{v:g} m/s"
            label = f"cruise {af.cruise_speed:g} m/s"
        p = float(m.power(v, 0.0))
        best = m.best_range_speed(max(lo, 0.5), hi)
        per_m = float(m.power(best, 0.0)) / best
        rows.append(f"| `{name}` | {m.kind} | {m.mass_kg:g} | {m.battery_wh:g} | {p:.0f} "
                    f"({label}) | {m.minimum_power_speed(lo, hi):.1f} | {best:.1f} | "
                    f"{0.8 * m.battery_wh / p * 60:.0f} | "
                    f"{0.8 * m.battery_wh * 3600 / per_m / 1000:.1f} |")
    return "\n".join(rows)


def test_the_preset_table_is_the_models():
    text = DOC.read_text()
    block = text[text.index(BEGIN) + len(BEGIN):text.index(END)].strip()
    assert block == preset_table()


def test_the_python_block_runs():
    blocks = re.findall(r"```python\n(.*?)```", DOC.read_text(), flags=re.S)
    assert blocks
    for i, block in enumerate(blocks):
        exec(compile(block, f"docs/energy.md python block {i + 1}", "exec"), {})


@pytest.mark.slow
def test_the_guides_commands_write_what_it_says(doc_runs):
    """The guide's commands as the docs' run makes them (tests/repo/conftest.py; each exits 0,
    test_docs_run.py) leave the files the guide names: the fitted model, three sorties where
    equal parts need four, the energy plan."""
    runs = runs_by_out(doc_runs, DOC)
    assert {"out/calibrate", "out/energy", "out/sorties"} <= set(runs)
    assert all(r.code == 0 for r in runs.values()), [r.output for r in runs.values()]
    assert (runs["out/calibrate"].out / "power.yaml").is_file()
    assert (runs["out/sorties"].out / "sortie-03.waypoints").is_file()
    assert not (runs["out/sorties"].out / "sortie-04.waypoints").exists()
    assert (runs["out/energy"].out / "summary.json").is_file()


if __name__ == "__main__":
    print(preset_table())
