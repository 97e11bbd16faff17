"""The planner flags declared once (cli/_planner_options.py) for fm2uav plan and routes."""

from __future__ import annotations

import pytest
import typer
import typer.main

from fm2uav.cli import app
from fm2uav.cli._planner_options import MARCH, SHAPING, PlannerFlags, _level
from fm2uav.errors import InputError
from fm2uav.planning import FlightLevel, PlanOptions, Shaping

PLANNER = [n for n, _, _ in [*SHAPING, *_level("")]]


def _options(command: str) -> dict:
    cmd = typer.main.get_command(app).commands[command]
    return {p.name: p for p in cmd.params}


def test_plan_and_routes_read_the_same_planner_flags():
    plan, routes = _options("plan"), _options("routes")
    for name in PLANNER:
        a, b = plan[name], routes[name]
        assert (a.opts, a.default, a.type_descriptor.annotation) == (
            b.opts, b.default, b.type_descriptor.annotation), name
        if name != "agl":  # routes says what else it reads from --agl
            assert a.help == b.help, name
    assert "starts" in routes["agl"].help and "starts" not in plan["agl"].help
    assert {"threads", "storage"} <= set(plan)
    assert "storage" not in routes  # routes marches on the full grid, its --threads descends
    assert "descents" in routes["threads"].help


def test_the_flags_make_the_library_s_objects():
    shaping, level, options = PlannerFlags(exponent=0.5, order=1, agl=60.0, p2=1.3,
                                           max_agl=120.0, threads=2).objects()
    assert shaping == Shaping(exponent=0.5)
    assert level == FlightLevel(agl=60.0, p2=1.3, max_agl=120.0)
    assert repr(options) == repr(PlanOptions(order=1, threads=2))
    s, lv, o = PlannerFlags(storage="auto").objects(storage="full")
    assert lv is None and o.storage == "full" and s == Shaping()


@pytest.mark.parametrize("flags, message", [
    (dict(min_agl=30.0), "--min-agl / --max-agl limit a terrain-following flight"),
    (dict(p1=-1.0), "--p1"),
    (dict(band=1e6), "--band"),
    (dict(order=3), "--order"),
])
def test_bad_flags_are_one_line_naming_the_flag(flags, message):
    with pytest.raises(InputError, match=message.replace("/", ".")):
        PlannerFlags(**flags).objects()


def test_the_march_flags_follow_order_in_plan_s_help():
    names = [p.name for p in typer.main.get_command(app).commands["plan"].params]
    i = names.index("order")
    assert names[i + 1:i + 3] == [n for n, _, _ in MARCH] and names[i + 3] == "agl"
