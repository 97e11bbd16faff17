"""The CLI's shared option groups (cli/options.py): defined once, the same flags everywhere."""

from __future__ import annotations

import inspect

import pytest
import typer
from typer.testing import CliRunner

from fm2uav.cli import app
from fm2uav.cli.options import WorldFlags, option_group, world_options

WORLD = ["--dem", "--dem-fill", "--buildings", "--bbox", "--sea-level", "--cell-size", "--dz",
         "--ceiling", "--nodata", "--nodata-value", "--crs", "--default-height", "--allow-filled",
         "--ground-elevation", "--margin"]


def _flags(*path: str) -> list[str]:
    cmd = typer.main.get_command(app)
    ctx = cmd.make_context("fm2uav", list(path) + ["--help"], resilient_parsing=True)
    for name in path:
        cmd = cmd.get_command(ctx, name)
    return [o for p in cmd.params for o in p.opts]


@pytest.mark.parametrize("command", [("plan",), ("cover",), ("check",), ("tune",),
                                     ("formation",), ("run",)])
def test_planning_commands_take_the_world_flags_in_one_block(command):
    flags = _flags(*command)
    k = flags.index("--dem")
    assert flags[k:k + len(WORLD)] == WORLD


@pytest.mark.parametrize("command", [("plan",), ("cover",), ("check",), ("tune",),
                                     ("formation",), ("run",), ("export",), ("sweep",),
                                     ("reproduce", "tff"), ("reproduce", "city"),
                                     ("reproduce", "coverage"), ("reproduce", "formation"),
                                     ("reproduce", "curvature")])
def test_every_command_has_the_output_flags(command):
    flags = _flags(*command)
    k = flags.index("--out")
    assert flags[k:k + 4] == ["--out", "--force", "--json", "--quiet"]


def test_option_group_puts_the_flags_where_the_parameter_was_and_passes_one_object():
    seen = {}

    @world_options
    def cmd(a: int = typer.Option(1), world: WorldFlags = None, b: int = typer.Option(2)):
        seen.update(a=a, world=world, b=b)

    names = list(inspect.signature(cmd).parameters)
    assert names[0] == "a" and names[-1] == "b" and names[1:-1] == [
        f.lstrip("-").replace("-", "_") for f in WORLD]
    cmd(a=3, b=4, crs="EPSG:32630", nodata="fill", dem=None)
    assert seen["a"] == 3 and seen["b"] == 4
    assert seen["world"].crs == "EPSG:32630" and seen["world"].nodata == "fill"
    assert seen["world"].allow_filled is False


def test_option_group_refuses_a_command_without_its_parameter():
    with pytest.raises(TypeError, match="no parameter 'world'"):
        option_group("world", [], WorldFlags)(lambda a=1: a)


def test_world_flag_without_data_names_the_flag(tmp_path):
    res = CliRunner().invoke(app, ["plan", "--crs", "EPSG:32630", "--out", str(tmp_path / "o")])
    assert res.exit_code == 2
    assert "--crs needs real data" in res.output
