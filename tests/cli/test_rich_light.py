"""typer's renderer loaded with deferred rich.markdown / rich.traceback (cli/_rich_light.py):
the same pages and errors as with the real modules, which are loaded only when used."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]

# Renders help pages and errors of fm2uav and of a markdown-mode typer app (which does use
# rich.markdown), then reports what got loaded. {preload}: import the real modules first
# (the stand-ins are then not used: the reference output).
PROBE = """
import io, json, sys
{preload}
import typer
from typer.testing import CliRunner
from fm2uav.cli import app

before = {{m: m in sys.modules for m in ("rich.markdown", "rich.traceback", "markdown_it")}}
runner = CliRunner()
out = {{}}
for words in (["--help"], ["plan", "--help"], ["plan", "--bogus"], ["plan", "--order", "x"],
              ["reproduce", "--help"], ["nonsense"]):
    res = runner.invoke(app, words)
    out[" ".join(words)] = [res.exit_code, res.output]
light = {{m: m in sys.modules for m in ("rich.markdown", "rich.traceback", "markdown_it")}}

md = typer.Typer(rich_markup_mode="markdown", add_completion=False)

@md.command()
def go(x: int = typer.Option(1, help="**bold** and `code`")):
    "A *markdown* docstring.\\n\\n- one\\n- two"

out["markdown"] = [runner.invoke(md, ["--help"]).exit_code, runner.invoke(md, ["--help"]).output]
import typer.rich_utils as ru
import rich.markdown, rich.traceback
try:
    raise ValueError("boom")
except ValueError as exc:
    tb = ru.Traceback.from_exception(type(exc), exc, exc.__traceback__)
print(json.dumps({{"out": out, "before": before, "light": light,
                  "real": [type(ru.Markdown("x")) is rich.markdown.Markdown,
                           type(tb) is rich.traceback.Traceback,
                           isinstance(rich.markdown.Markdown("x"), ru.Markdown),
                           sys.modules["rich.markdown"].__file__ is not None]}}))
"""


def _probe(preload: str) -> dict:
    env = {**os.environ, "PYTHONPATH": str(ROOT / "src"), "COLUMNS": "100",
           "NUMBA_DISABLE_JIT": "1"}
    res = subprocess.run([sys.executable, "-c", PROBE.format(preload=preload)],
                         capture_output=True, text=True, timeout=120, env=env)
    assert res.returncode == 0, res.stderr[-3000:]
    return json.loads(res.stdout.strip().splitlines()[-1])


def test_pages_and_errors_are_those_of_the_real_modules_which_load_only_when_used():
    light = _probe("")
    real = _probe("import rich.markdown, rich.traceback")
    assert light["out"] == real["out"]
    assert "bold" in light["out"]["markdown"][1] and "Usage" in light["out"]["plan --bogus"][1]
    assert not any(light["before"].values()) and not any(light["light"].values()), light
    assert all(real["light"].values())  # the reference did have them
    assert light["real"] == [True, True, True, True]  # the stand-ins give the real objects
