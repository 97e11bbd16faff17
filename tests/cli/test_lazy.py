"""Sub-commands built on demand and typer's coercion without pydantic (issue 27, an instant
command line): the same help pages, errors and values as the app typer assembles eagerly.

Import checks and comparisons, not timings (the seconds: benchmarks/bench_cli.py).
"""

from __future__ import annotations

import json
import os
import pkgutil
import subprocess
import sys
from pathlib import Path

import pytest
import typer
import typer.main
from typer.testing import CliRunner

try:
    from typer._click import Context
except ImportError:  # pragma: no cover - a typer on click
    from click import Context

import fm2uav.cli as cli
from fm2uav.cli import _coerce, _lazy

ROOT = Path(__file__).resolve().parents[2]


def _eager_app() -> typer.Typer:
    """The app as it was assembled before the lazy group: every module registered, typer's
    own group class (the reference the lazy app must match)."""
    app = typer.Typer(name="fm2uav", help=cli.app.info.help, no_args_is_help=True,
                      add_completion=False, pretty_exceptions_enable=False,
                      rich_markup_mode="rich")
    rep = typer.Typer(help=cli.reproduce_app.info.help, no_args_is_help=True)
    app.add_typer(rep, name="reproduce")
    for mod in sorted(pkgutil.iter_modules(cli.__path__), key=lambda m: m.name):
        if mod.name.startswith("cmd_"):
            __import__(f"fm2uav.cli.{mod.name}", fromlist=["register"]).register(app, rep)
    return app


def _modules_of(section: str) -> dict[str, str]:
    out: dict[str, str] = {}
    for mod in sorted(pkgutil.iter_modules(cli.__path__), key=lambda m: m.name):
        if mod.name.startswith("cmd_"):
            for name in _lazy.registered("fm2uav.cli", mod.name, section):
                out[name] = mod.name
    return out


def test_the_tables_name_every_command_s_module_in_the_help_order():
    assert list(cli.COMMANDS.items()) == list(_modules_of("app").items())
    assert list(cli.REPRODUCE.items()) == list(_modules_of("reproduce").items())
    lazy = typer.main.get_command(cli.app)
    eager = typer.main.get_command(_eager_app())
    assert list(lazy.commands) == list(eager.commands)
    assert list(lazy.commands["reproduce"].commands) == list(eager.commands["reproduce"].commands)


def _pages(cmd, prefix=()):
    yield list(prefix)
    for name, sub in getattr(cmd, "commands", {}).items():
        yield from _pages(sub, (*prefix, name))


ERRORS = [["plan", "--bogus"], ["plan", "--order", "x"], ["plan", "--order", "2.5"],
          ["plan", "--saturation", "abc"], ["plan", "--saturation", "1e"], ["run"],
          ["nonsense"], ["plna"], ["reproduce", "tf"], ["reproduce"], [],
          ["cover", "--angle", "north"], ["plan", "--threads", "x"], ["check"],
          ["export", "--bogus"], ["routes", "--starts", "s.csv"]]


def test_every_help_page_and_usage_error_is_the_eager_app_s(monkeypatch):
    monkeypatch.setenv("COLUMNS", "100")
    runner = CliRunner()
    eager = _eager_app()
    pages = list(_pages(typer.main.get_command(eager)))
    assert len(pages) > 20
    for words in [[*p, "--help"] for p in pages] + ERRORS:
        ours, theirs = runner.invoke(cli.app, words), runner.invoke(eager, words)
        assert (ours.exit_code, ours.output) == (theirs.exit_code, theirs.output), words
        assert "Traceback" not in ours.output


# In a fresh interpreter: what one command's help, a bad flag and a missing mission file
# load (the other commands' modules are not imported, pydantic and numpy not at all).
PROBE = """
import json, sys
sys.argv = ["fm2uav", *{args!r}]
from fm2uav.__main__ import main
try:
    main()
except SystemExit as exc:
    code = exc.code
mods = sorted(m for m in sys.modules if m.startswith("fm2uav.cli.cmd_"))
print(json.dumps({{"code": code, "cmd": mods, "pydantic": "pydantic" in sys.modules,
                  "numpy": "numpy" in sys.modules}}), file=sys.stderr)
"""


def _probe(tmp_path, *args: str) -> dict:
    # a help cache of the test's own: a page kept by an earlier run would be copied without
    # building any command (fm2uav._help_cache)
    env = {**os.environ, "PYTHONPATH": str(ROOT / "src"), "NUMBA_DISABLE_JIT": "1",
           "FM2UAV_CACHE_DIR": str(tmp_path / "cache")}
    res = subprocess.run([sys.executable, "-c", PROBE.format(args=list(args))], cwd=tmp_path,
                         capture_output=True, text=True, timeout=120, env=env)
    return json.loads(res.stderr.strip().splitlines()[-1])


@pytest.mark.parametrize("args, code, modules", [
    (["plan", "--help"], 0, ["fm2uav.cli.cmd_plan"]),
    (["plan", "--bogus"], 2, ["fm2uav.cli.cmd_plan"]),
    (["reproduce", "tff", "--help"], 0, ["fm2uav.cli.cmd_tff"]),
    (["run", "missing.yaml"], 2, ["fm2uav.cli.cmd_run"]),
])
def test_one_command_builds_only_its_own_module_without_pydantic(tmp_path, args, code,
                                                                 modules):
    got = _probe(tmp_path, *args)
    assert got["code"] == code
    assert set(modules) <= set(got["cmd"]), got  # its own (and what it imports: cmd_plan
    assert len(got["cmd"]) <= 2, got  # shares cmd_run's helpers), not the fifteen of the app
    assert not got["pydantic"] and not got["numpy"], got


def test_the_command_list_is_read_without_building_any_command(tmp_path, monkeypatch, capsys):
    monkeypatch.setenv("COLUMNS", "200")
    group = typer.main.get_command(cli.app)
    text = group.get_help(group.make_context("fm2uav", [], resilient_parsing=True))
    text += capsys.readouterr().out  # rich prints the page itself
    assert group.commands._built == {}  # names and help only: no parameter made
    for name in cli.COMMANDS:
        first = (group.commands[name].help or "").split("\n")[0][:30]
        assert f"{name} " in text and first in text, name
    got = _probe(tmp_path, "--help")
    assert got["code"] == 0 and not got["pydantic"] and not got["numpy"]


def test_a_module_the_table_forgot_is_still_found():
    table = {k: v for k, v in cli.COMMANDS.items() if k != "plan"}
    group_cls = _lazy.lazy_group(table, package="fm2uav.cli", section="app")
    group = group_cls(name="fm2uav", commands={})
    assert "plan" in group.commands and "plan" in list(group.commands)
    assert group.commands["plan"].name == "plan"
    assert "--order" in {o for p in group.commands["plan"].params for o in p.opts}
    assert group.commands.get("nonsense") is None


# -- coercion ----------------------------------------------------------------------------------

def _param(annotation, default=None, **info):
    """A typer parameter of ``annotation`` (built the way typer builds the app's)."""
    def f(x=typer.Option(default, "--x", **info)):  # noqa: B008
        pass
    f.__annotations__ = {"x": annotation}  # the object, not a string (future annotations)
    cmd = typer.main.get_command_from_info(typer.models.CommandInfo(callback=f),
                                           pretty_exceptions_short=True,
                                           rich_markup_mode="rich")
    return cmd, cmd.params[0]


def _coerced(runtime, cmd, param, value):
    ctx = Context(cmd)
    try:
        return ("ok", runtime.coerce(value, param=param, ctx=ctx))
    except Exception as exc:  # noqa: BLE001 - the message is compared
        return ("error", type(exc).__name__, getattr(exc, "message", str(exc)))


VALUES = ["1", "+1", "-7", "007", " 1", "1 ", "1_000", "1.0", "1.5", ".5", "5.", "1e3",
          "1E-3", "-0", "inf", "nan", "1e400", "0x10", "", "abc", "٣", "9" * 40, "1.5e",
          "true", "no", "a/b", "a//b/", "./x", "~", "-", 3, 2.5, True, None, Path("p"),
          ("1", "2"), ["a", "b/"], ()]


@pytest.mark.skipif(_coerce.LightCoercion is None, reason="typer without pydantic coercion")
@pytest.mark.parametrize("annotation, default, info", [
    (int, None, {}), (float, None, {}), (str, None, {}), (bool, False, {}),
    (Path, None, {}), (Path, None, {"exists": True}), (Path, None, {"dir_okay": False}),
    (Path, None, {"file_okay": False}), (Path, None, {"resolve_path": True}),
    (Path, None, {"readable": False}), (Path, None, {"allow_dash": True}),
    (int, None, {"min": 0}), (list[str], None, {}), (list[Path], None, {}),
    (list[int], None, {}), (list[float], None, {}),
])
def test_light_coercion_gives_typer_s_values_and_errors(tmp_path, monkeypatch, annotation,
                                                      default, info):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "a").mkdir()
    (tmp_path / "p").write_text("x")
    from typer._coercion import build_runtime_param

    cmd, param = _param(annotation, default, **info)
    light, typer_own = _coerce.LightCoercion(param.type_descriptor), build_runtime_param(
        param.type_descriptor)
    for value in VALUES:
        ours = _coerced(light, cmd, param, value)
        theirs = _coerced(typer_own, cmd, param, value)
        assert repr(ours) == repr(theirs), (annotation, info, value)  # repr: nan == nan
        if ours[0] == "ok":  # same type too (1 is not 1.0, a str is not a Path)
            assert type(ours[1]) is type(theirs[1]), (annotation, value)


@pytest.mark.skipif(_coerce.LightCoercion is None, reason="typer without pydantic coercion")
def test_plain_values_need_no_adapter_and_the_rest_builds_typer_s():
    cmd, param = _param(float)
    light = _coerce.LightCoercion(param.type_descriptor)
    assert _coerced(light, cmd, param, "2.5") == ("ok", 2.5) and light._typer is None
    assert _coerced(light, cmd, param, "abc")[0] == "error" and light._typer is not None
