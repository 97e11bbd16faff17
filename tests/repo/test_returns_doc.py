"""docs/returns.md: its measured table is what the code gives today, its figures are the
code's constants, its command runs.

Regenerate the table with ``.venv/bin/python -m tests.repo.test_returns_doc``.
"""

from __future__ import annotations

import re
import shlex
from pathlib import Path

import pytest

from .docs_run import _without, commands

DOC = Path(__file__).resolve().parents[2] / "docs" / "returns.md"
BEGIN, END = "<!-- returns-table:begin -->", "<!-- returns-table:end -->"
HEADER = ("| firmware / airframe | return altitude | straight lines checked | smallest "
          "clearance | longest way back | point of no return (10 min, 20 % reserve) |")
CASES = (("ardupilot", "multirotor"), ("px4", "multirotor"), ("ardupilot", "fixed_wing"),
         ("px4", "fixed_wing"))


def table_rows():
    """The open field of the papers, 150 m above ground, floor 100 m: each firmware's return."""
    from fm2uav import FlightLevel
    from fm2uav.autopilot.build import ExportOptions
    from fm2uav.autopilot.safe_return import ReturnOptions, build_with_returns
    from fm2uav.missions.route import plan_route
    from fm2uav.scenarios import get_scenario

    sc = get_scenario("open-field")
    p = plan_route(sc.world, sc.start, sc.goal,
                   level=FlightLevel(agl=150.0, p1=0.5, p2=1.3, min_agl=100.0)).plan
    rows = []
    for fw, vehicle in CASES:
        opt = ExportOptions(firmware=fw, vehicle=vehicle, endurance_s=600.0)
        m = build_with_returns(p.path, sc.world, opt, ReturnOptions(), plan=p, w=p.w,
                               agl=150.0, profile=p.profile)
        r = m.returns
        model = r.firmware.summary()["models"][0]
        alt = (f"{model['return_altitude_m']:g} m" if model["feasible"] else
               "none: " + "; ".join(model["reasons"]))
        pnr = r.pnr
        where = (f"{pnr['distance_m'] / 1000:.2f} km of {pnr['route_distance_m'] / 1000:.2f} km"
                 if pnr["reached"] else "none on the route")
        rows.append([f"{model['firmware']} ({vehicle.replace('_', '-')})", alt,
                     str(model["lines"]), f"{model['min_clearance_m']:.1f} m",
                     f"{r.time.max() / 60:.1f} min", where])
    return rows


def table_markdown(rows) -> str:
    sep = "|" + "---|" * (HEADER.count("|") - 1)
    return "\n".join([HEADER, sep] + ["| " + " | ".join(r) + " |" for r in rows])


def test_figures_in_the_doc_are_the_codes():
    from fm2uav.autopilot import rally, safe_return

    text = DOC.read_text()
    assert f"`DEFAULT_MAX_RETURNS` = {safe_return.DEFAULT_MAX_RETURNS}" in text
    assert f"`RETURN_THIN_M` = {safe_return.RETURN_THIN_M:g} m" in text
    assert f"`MAX_RALLY` = {rally.MAX_RALLY}" in text
    assert f"`DEFAULT_AUTO_RALLY` = {rally.DEFAULT_AUTO_RALLY}" in text
    import inspect

    sig = inspect.signature(rally.candidate_sites).parameters
    assert (f"slope at most {sig['max_slope_deg'].default:g}°, "
            f"{sig['building_clearance'].default:g} m from every roof, "
            f"{sig['zone_clearance'].default:g} m from") in text


@pytest.mark.slow
def test_doc_table_matches_a_fresh_run():
    text = DOC.read_text()
    m = re.search(re.escape(BEGIN) + r"\n(.*?)\n" + re.escape(END), text, re.S)
    assert m, "docs/returns.md lost its table markers"
    assert m.group(1).strip() == table_markdown(table_rows()).strip()


OPERATOR = DOC.parent / "operator.md"


def _block(doc: Path, after: str) -> list[str]:
    """The arguments of the first command after the heading ``after``, as the docs' run
    (tests/repo/docs_run.py) reads them."""
    text = doc.read_text()
    block = re.search(r"```bash\n(.*?)```", text[text.index(after):], re.S).group(1)
    (command,) = commands(block)
    args = shlex.split(command, comments=True)
    assert args[0] == ".venv/bin/fm2uav"
    return args[1:]


@pytest.mark.slow
@pytest.mark.parametrize("doc, after", [(DOC, "## Try it"),
                                        (OPERATOR, "## 10. Safe returns")])
def test_the_docs_commands_run(cli_once, doc, after):
    # the run the docs' run makes of the same command (cli_once: once per session)
    run = cli_once(_without(_block(doc, after), "--out"))
    assert run.result.exit_code == 0, run.result.output
    for f in ("mission.param", "rally.waypoints", "rally.txt", "returns.geojson"):
        assert (run.out / f).is_file(), f
    for row in ("longest way back", "rally points", "point of no return", "firmware return"):
        assert row in run.result.output


@pytest.mark.slow
def test_the_python_block_runs_and_its_ways_back_end_at_home(capsys):
    text = DOC.read_text()
    block = re.search(r"```python\n(.*?)```", text[text.index("## From Python"):], re.S).group(1)
    ns: dict = {}
    exec(compile(block, str(DOC), "exec"), ns)
    out = capsys.readouterr().out.splitlines()
    assert out[0].endswith("home") and ns["ways"][-1].length > 1000.0
    import numpy as np

    assert all(np.allclose(w.path[-1], ns["plan"].path[0]) for w in ns["ways"])
    assert np.isfinite(ns["home"].cost(ns["plan"].path[-1:])).all()


if __name__ == "__main__":
    print(table_markdown(table_rows()))
