"""The command line stays light (issue 27): help, usage errors and the assembly of the app
import typer and rich only; every ``cli/*.py`` module keeps its heavy imports inside the
functions that need them (docs/architecture.md, "The command line stays light").

Import checks, not timings: the seconds are measured by ``make bench`` (benchmarks/bench_cli.py).
"""

from __future__ import annotations

import ast
import json
import os
import subprocess
import sys
from pathlib import Path

from fm2uav.cli.options import AIRFRAME_NAMES, SCENARIO_NAMES

ROOT = Path(__file__).resolve().parents[2]
CLI = ROOT / "src" / "fm2uav" / "cli"

#: What `fm2uav --help` must not load (the libraries of the issue, and fm2uav's own heavy
#: layers, which import them).
HEAVY = ("numpy", "numba", "llvmlite", "scipy", "matplotlib", "plotly", "rasterio", "shapely",
         "pyproj", "pyogrio", "dask", "distributed", "pyarrow", "yaml", "PIL", "ompl",
         "fm2uav.eikonal", "fm2uav.world", "fm2uav.planning", "fm2uav.missions",
         "fm2uav.vehicles", "fm2uav.analysis", "fm2uav.scenarios", "fm2uav.experiments",
         "fm2uav.io", "fm2uav.viz", "fm2uav.baselines", "fm2uav._validate",
         "fm2uav.autopilot", "fm2uav.pipeline.run", "fm2uav.pipeline.cover", "fm2uav.app",
         "fastapi", "starlette", "uvicorn", "rio_tiler")

#: Light modules inside a heavy package that help pages may load: the io package (lazy)
#: and its table of export file names, which the shared output module reads.
LIGHT = ("fm2uav.io", "fm2uav.io.formats")

#: Top-level imports a ``cli/*.py`` module may have: the standard library, typer, rich,
#: fm2uav.errors, the light modules of fm2uav.cli (the cmd_* modules among them) and the two
#: pipeline modules the commands share with the app, light by the same rule (numpy inside
#: their functions; the jobs, fm2uav.pipeline.run / .cover, are imported by the commands),
#: and fm2uav._lazy (names re-exported on first use: importlib and sys only).
ALLOWED_TOP = ("typer", "rich", "fm2uav.errors", "fm2uav.cli", "fm2uav.pipeline.outputs",
               "fm2uav.pipeline.rows", "fm2uav._lazy")

# In a fresh interpreter: import the app, render every help page and the usage errors,
# then list what got loaded.
PROBE = """
import json, sys
import typer
from typer.testing import CliRunner
from fm2uav.cli import app

heavy = {heavy!r}
light = {light!r}
loaded = lambda: sorted(m for m in heavy if any((k == m or k.startswith(m + "."))
                                                 and k not in light for k in sys.modules))
report = {{"import": loaded() + (["pydantic"] if "pydantic" in sys.modules else [])}}
runner = CliRunner()
cmd = typer.main.get_command(app)

def pages(c, prefix):
    yield prefix
    for name, sub in sorted(getattr(c, "commands", {{}}).items()):
        yield from pages(sub, prefix + [name])

codes = {{}}
for words in pages(cmd, []):
    res = runner.invoke(app, [*words, "--help"])
    codes[" ".join(words) + " --help"] = res.exit_code
for words in (["plan", "--bogus"], ["plan", "--order", "x"], ["run"], ["nonsense"],
              ["cover", "--angle", "north"], []):
    codes[" ".join(words)] = runner.invoke(app, words).exit_code
report["help"] = loaded()
report["codes"] = codes
print(json.dumps(report))
"""


def _probe() -> dict:
    res = subprocess.run([sys.executable, "-c", PROBE.format(heavy=HEAVY, light=LIGHT)], capture_output=True,
                         text=True, timeout=300)
    assert res.returncode == 0, res.stderr
    return json.loads(res.stdout.strip().splitlines()[-1])


def test_help_and_usage_errors_load_no_heavy_library():
    report = _probe()
    assert report["import"] == [], f"`import fm2uav.cli` loads {report['import']}"
    assert report["help"] == [], f"help pages / usage errors load {report['help']}"
    codes = report["codes"]
    assert len(codes) > 20  # every command's help page was rendered
    assert all(code == 0 for k, code in codes.items() if k.endswith("--help")), codes
    assert [codes[k] for k in ("plan --bogus", "plan --order x", "run", "nonsense",
                               "cover --angle north")] == [2] * 5
    assert codes[""] in (0, 2)  # no arguments: the help (no_args_is_help)


def _top_level_imports(path: Path) -> list[tuple[int, str]]:
    """``(line, absolute module)`` of the imports a module runs when it is imported (not those
    inside functions or under ``if TYPE_CHECKING:``)."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    out = []

    def visit(body):
        for node in body:
            if isinstance(node, ast.Import):
                out.extend((node.lineno, a.name) for a in node.names)
            elif isinstance(node, ast.ImportFrom):
                if node.level:
                    base = ["fm2uav", "cli"][:3 - node.level] if node.level <= 2 else []
                    mod = ".".join(base + ([node.module] if node.module else []))
                else:
                    mod = node.module or ""
                out.append((node.lineno, mod))
            elif isinstance(node, ast.If):
                test = ast.unparse(node.test)
                if "TYPE_CHECKING" not in test:
                    visit(node.body)
                visit(node.orelse)
            elif isinstance(node, (ast.Try, ast.With)):
                visit(node.body)
    visit(tree.body)
    return out


def _allowed(module: str) -> bool:
    top = module.split(".")[0]
    return (top in sys.stdlib_module_names or top == "__future__"
            or any(module == a or module.startswith(a + ".") for a in ALLOWED_TOP))


def test_every_cli_module_imports_only_light_modules_at_its_top():
    modules = sorted(CLI.glob("*.py"))
    assert any(p.name.startswith("cmd_") for p in modules)
    bad = [f"{p.relative_to(ROOT)}:{line}: {mod}" for p in modules
           for line, mod in _top_level_imports(p) if not _allowed(mod)]
    assert not bad, ("heavy imports at the top of a cli module (move them into the command "
                     "function that needs them; docs/architecture.md): " + "; ".join(bad))


def test_the_import_rule_sees_relative_imports_and_type_checking_blocks(tmp_path):
    f = tmp_path / "cmd_x.py"
    f.write_text("from typing import TYPE_CHECKING\nimport typer\nfrom ..world import World\n"
                 "from ._common import Output\nif TYPE_CHECKING:\n    import numpy\n"
                 "def run():\n    import scipy\n")
    mods = [m for _, m in _top_level_imports(f)]
    assert mods == ["typing", "typer", "fm2uav.world", "fm2uav.cli._common"]
    assert [m for m in mods if not _allowed(m)] == ["fm2uav.world"]


def test_the_help_lists_the_library_s_scenarios_and_airframes():
    from fm2uav.scenarios import SCENARIOS
    from fm2uav.vehicles import AIRFRAMES

    assert SCENARIO_NAMES == tuple(SCENARIOS)
    assert AIRFRAME_NAMES == tuple(AIRFRAMES)


def test_the_scenarios_dimensions_are_the_library_s():
    from fm2uav.cli.options import SCENARIOS_2D, scenario_ndim
    from fm2uav.scenarios import SCENARIOS, get_scenario

    assert SCENARIOS_2D == tuple(n for n in SCENARIOS if get_scenario(n).world.ndim == 2)
    assert [scenario_ndim(n) for n in SCENARIOS] == [get_scenario(n).world.ndim
                                                      for n in SCENARIOS]
    assert scenario_ndim(None) == 3  # a --dem/--buildings world, or the default open field


#: One-line value errors of the planning commands (and a missing input file): each answered before the world, numpy or
#: the kernels load (issue 27: "any one-line input error in <= 0.3 s"). (argv, words the
#: message must hold.)
VALUE_ERRORS = [
    (["plan", "--threads", "0"], ["threads", "--threads", ">= 1"]),
    (["plan", "--order", "3"], ["--order", "1, 2"]),
    (["plan", "--saturation", "2"], ["--saturation", "(0, 1]"]),
    (["plan", "--storage", "bogus"], ["--storage", "'regional'"]),
    (["plan", "--p1", "-1"], ["--p1"]),
    (["plan", "--min-agl", "10"], ["--min-agl", "--agl"]),
    (["plan", "--export", "foo"], ["--export", "'foo'"]),
    (["plan", "--rally", "bogus"], ["--rally", "auto"]),
    (["plan", "--start", "1,2"], ["--start", "3 numbers", "'1,2'"]),
    (["plan", "--scenario", "city2d", "--goal", "1,2,3"], ["--goal", "2 numbers"]),
    (["plan", "--via", "1,x,3"], ["--via 1", "numbers"]),
    (["plan", "--lonlat", "--start", "200,40,50"], ["--start", "longitude"]),
    (["plan", "--lonlat", "--start", "10,40"], ["--start", "no height", "--agl"]),
    (["plan", "--lonlat", "--cells", "--start", "10,40,5"], ["--lonlat", "--cells"]),
    (["routes", "--goal", "1,2,30", "--starts", "s.csv", "--threads", "0"], ["--threads"]),
    (["routes", "--goal", "1,2,30", "--starts", "s.csv", "--speed", "0"], ["--speed"]),
    (["routes", "--goal", "1", "--starts", "s.csv"], ["--goal", "LON,LAT"]),
    (["routes", "--goal", "1,2,30", "--starts", "s.csv"], ["--starts s.csv", "no such file"]),
    (["routes", "--goal", "1,2,30", "--starts", "s.csv", "--exponent", "0"], ["--exponent"]),
    (["check", "missing.csv"], ["path file", "missing.csv", "not found"]),
    (["export", "missing.csv", "--scenario", "open-field"], ["path file", "not found"]),
    # the formation's settings read the shapes (numpy): numpy, but not the planner
    (["formation", "--followers", "0"], ["--followers", ">= 1"], {"numpy"}),
]

VALUE_PROBE = """
import json, sys
from typer.testing import CliRunner
from fm2uav.cli import app

heavy = {heavy!r}
res = CliRunner().invoke(app, {argv!r})
print(json.dumps({{"code": res.exit_code, "out": res.output,
                  "loaded": sorted(m for m in heavy if m in sys.modules)}}))
"""


def test_value_errors_are_answered_before_the_heavy_libraries_load(tmp_path):
    # the libraries (and fm2uav's modules that import them); the packages themselves
    # (fm2uav.planning, .missions, .autopilot: lazy), fm2uav.planning.params,
    # fm2uav.missions.formation.config and fm2uav._validate are light and may load: they
    # make the checks
    heavy = ("numpy", "numba", "llvmlite", "scipy", "matplotlib", "plotly", "rasterio",
             "shapely", "pyproj", "pyogrio", "yaml", "fm2uav.eikonal", "fm2uav.world",
             "fm2uav.planning.planner", "fm2uav.missions.route", "fm2uav.missions.coverage",
             "fm2uav.missions.formation.mission", "fm2uav.scenarios", "fm2uav.autopilot.build",
             "fm2uav.pipeline.routes", "fm2uav.experiments", "fm2uav.viz")
    for argv, words, *allowed in VALUE_ERRORS:
        argv = [*argv, "--out", str(tmp_path / "out")]
        res = subprocess.run([sys.executable, "-c", VALUE_PROBE.format(heavy=heavy, argv=argv)],
                             capture_output=True, text=True, timeout=300)
        assert res.returncode == 0, res.stderr
        report = json.loads(res.stdout.strip().splitlines()[-1])
        assert report["code"] == 2, (argv, report)
        message = " ".join(report["out"].split())
        assert all(w in message for w in words), (argv, message)
        assert "Traceback" not in report["out"]
        assert set(report["loaded"]) <= (allowed[0] if allowed else set()), (argv, report)
    assert not (tmp_path / "out").exists()  # refused before any output


#: Mission files with one bad line, each refused by the schema (exit 2, one line naming the
#: key) before numpy, the world, its builders, the kernels or any geodata library load: the
#: schema needs pydantic and yaml only. (file text, words the message must hold.)
W = "world: {scenario: open-field}\n"
MISSION_ERRORS = [
    ("world: {bogus: 1}\n", ["world.bogus", "allowed fields"]),
    (W + "planner: {saturation: 1.5}\n", ["planner.saturation", "1.5"]),
    (W + "airframe: {firmware: betaflight}\n", ["airframe.firmware", "betaflight"]),
    (W + "outputs: {formats: [csv, docx]}\n", ["outputs.formats", "docx"]),
    ("start: [1, 2\n", ["not valid YAML", "line"]),
    (W + "planner: {order: true}\n", ["planner.order"]),
]

MISSION_HEAVY = ("numpy", "numba", "llvmlite", "scipy", "matplotlib", "plotly", "rasterio", "shapely",
                 "pyproj", "pyogrio", "dask", "PIL", "fm2uav.eikonal", "fm2uav.planning.planner",
                 "fm2uav.world.clearance", "fm2uav.world.dem", "fm2uav.world.buildings",
                 "fm2uav.autopilot.build", "fm2uav.io.exports",
                 "fm2uav.autopilot.firmware.profile", "fm2uav.autopilot.firmware.registry",
                 "fm2uav.world.world", "fm2uav.world.geo", "fm2uav.scenarios.field",
                 "fm2uav.scenarios.city", "fm2uav.scenarios.coverage",
                 "fm2uav.viz", "fm2uav.experiments", "fm2uav.missions.coverage")


def test_mission_file_errors_are_answered_before_the_heavy_libraries_load(tmp_path):
    for k, (text, words) in enumerate(MISSION_ERRORS):
        mission = tmp_path / f"m{k}.yaml"
        mission.write_text(text, encoding="utf-8")
        argv = ["run", str(mission), "--out", str(tmp_path / "out")]
        res = subprocess.run(
            [sys.executable, "-c", VALUE_PROBE.format(heavy=MISSION_HEAVY, argv=argv)],
            capture_output=True, text=True, timeout=300)
        assert res.returncode == 0, res.stderr
        report = json.loads(res.stdout.strip().splitlines()[-1])
        message = " ".join(report["out"].split())
        assert report["code"] == 2, (text, report)
        assert all(w in message for w in words), (text, message)
        assert "Traceback" not in report["out"]
        assert report["loaded"] == [], (text, report["loaded"])
    assert not (tmp_path / "out").exists()


#: What the command line's own answer to a mission file's error must not load beyond
#: MISSION_HEAVY: importlib.metadata (pydantic's plugin loader, cli/_pydantic_plugins.py;
#: with email, zipfile, socket), the run's modules (imported once the file is valid) and the
#: rally reader (only with --rally). Through fm2uav.__main__, whose PYDANTIC_DISABLE_PLUGINS
#: default the stand-in needs.
MISSION_RUN_LATER = ("importlib.metadata", "email", "zipfile", "socket", "fm2uav.pipeline.run",
                     "fm2uav.io.rally", "fm2uav.autopilot.items", "fm2uav.cli._first_use")

MAIN_PROBE = """
import atexit, json, sys
heavy = {heavy!r}
atexit.register(lambda: print(json.dumps(sorted(m for m in heavy if m in sys.modules))))
sys.argv = ["fm2uav", *{argv!r}]
from fm2uav.__main__ import main
main()
"""


def test_a_mission_file_error_through_the_command_line_loads_no_plugin_machinery(tmp_path):
    env = {k: v for k, v in os.environ.items() if k != "PYDANTIC_DISABLE_PLUGINS"}
    for k, (text, words) in enumerate(MISSION_ERRORS):
        mission = tmp_path / f"m{k}.yaml"
        mission.write_text(text, encoding="utf-8")
        argv = ["run", str(mission), "--out", str(tmp_path / "out")]
        res = subprocess.run(
            [sys.executable, "-c", MAIN_PROBE.format(heavy=MISSION_HEAVY + MISSION_RUN_LATER,
                                                     argv=argv)],
            capture_output=True, text=True, timeout=300, env=env)
        assert res.returncode == 2, (text, res.stderr)
        message = " ".join(res.stderr.split())
        assert all(w in message for w in words), (text, message)
        assert "Traceback" not in res.stderr
        assert json.loads(res.stdout.strip().splitlines()[-1]) == [], text
    assert not (tmp_path / "out").exists()


#: What the command line does not load to answer a bad flag or value, a missing or a bad
#: mission file (issue 27, deliverable 4: every one-line error <= 0.3 s): the output sets'
#: machinery (the stop signals are fm2uav.io._stops), the shared output writers with the
#: progress events and json (imported by the commands that write), glob's regular
#: expressions (the cold-cache check lists the folder) and ``run``'s module for ``plan``.
ERROR_PATH_LATER = ("fm2uav.io.outdir", "fm2uav.pipeline.outputs", "fm2uav.progress", "json",
                    "glob")

ERROR_PROBE = """
import atexit, sys
heavy = {heavy!r}
def report():
    yaml = sys.modules.get("yaml")
    loaded = sorted(m for m in heavy if m in sys.modules)
    import json
    print(json.dumps({{"loaded": loaded,
                      "gc_frozen": __import__("gc").get_freeze_count() > 0,
                      "yaml_pattern": yaml and yaml.reader.Reader.NON_PRINTABLE.pattern}}))
atexit.register(report)
sys.argv = ["fm2uav", *{argv!r}]
from fm2uav.__main__ import main
main()
"""


def test_one_line_errors_through_the_command_line_load_no_output_machinery(tmp_path):
    from fm2uav._yaml_light import NOT_ALLOWED

    bad = tmp_path / "bad.yaml"
    bad.write_text(W + "planner: {saturation: 1.5}\n", encoding="utf-8")
    out = str(tmp_path / "out")
    cases = [(["plan", "--bogus"], ("cmd_run",)), (["plan", "--threads", "0", "--out", out], ()),
             (["plan", "--start", "1,2", "--out", out], ("cmd_run",)),
             (["run", str(tmp_path / "missing.yaml")], ()), (["run", str(bad), "--out", out], ())]
    for argv, also in cases:
        heavy = ERROR_PATH_LATER + tuple(f"fm2uav.cli.{m}" for m in also)
        res = subprocess.run([sys.executable, "-c", ERROR_PROBE.format(heavy=heavy, argv=argv)],
                             capture_output=True, text=True, timeout=300, cwd=tmp_path)
        assert res.returncode == 2, (argv, res.stderr)
        assert "Traceback" not in res.stderr
        report = json.loads(res.stdout.strip().splitlines()[-1])
        assert report["loaded"] == [], (argv, report)
        assert report["gc_frozen"], argv  # fm2uav._gc froze the start-up's objects (at exit)
        if argv[1] == str(bad):  # yaml's reader compiled the fast form of its pattern
            assert report["yaml_pattern"] == NOT_ALLOWED
            assert "planner.saturation" in res.stderr
    assert not (tmp_path / "out").exists()


CODE_PROBE = """
import atexit, json, sys
from fm2uav import _code_cache
heavy = {heavy!r}
atexit.register(lambda: print(json.dumps({{**_code_cache.stats(),
                                          "loaded": sorted(m for m in heavy if m in sys.modules)}})))
sys.argv = ["fm2uav", *{argv!r}]
from fm2uav.__main__ import main
main()
"""


def test_one_line_errors_compile_no_generated_source_once_kept(tmp_path):
    # fm2uav._code_cache: the dataclasses' methods, namedtuples and forward references the
    # imports compile are kept by the first run of a command and taken by the next; the
    # numba cache check's hashlib (OpenSSL) waits for a cache to read (fm2uav._jit)
    bad = tmp_path / "bad.yaml"
    bad.write_text(W + "planner: {saturation: 1.5}\n", encoding="utf-8")
    env = {**os.environ, "FM2UAV_CACHE_DIR": str(tmp_path / "cache")}
    out = str(tmp_path / "out")
    cases = [(["plan", "--bogus"], ()), (["run", str(bad), "--out", out], ()),
             (["run", str(tmp_path / "missing.yaml")], ("hashlib", "_hashlib"))]
    for argv, later in cases:
        probe = CODE_PROBE.format(heavy=later, argv=argv)
        runs = [subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True,
                               timeout=300, env=env) for _ in range(2)]
        assert [r.returncode for r in runs] == [2, 2] and runs[0].stderr == runs[1].stderr
        first, second = (json.loads(r.stdout.strip().splitlines()[-1]) for r in runs)
        assert second["new"] == 0 and second["hits"] > 50, (argv, first, second)
        assert first["loaded"] == second["loaded"] == [], (argv, first)
