"""What a command shows of warnings (``cli._noise``): fm2uav's own, once, in its words;
library warnings and log records in our words or not at all."""

from __future__ import annotations

import ast
import logging
import warnings
from pathlib import Path

from fm2uav.cli._noise import captured, library_line
from fm2uav.world.dem import GeodataWarning

SRC = Path(__file__).resolve().parents[2] / "src" / "fm2uav"


def test_ours_once_each_libraries_dropped_and_kept_for_debug():
    said, raw = [], []
    with captured(said.append, debug=True, raw=raw.append):
        for _ in range(3):
            warnings.warn_explicit("below sea level", GeodataWarning, "x.py", 1)
        warnings.warn_explicit("lose projection information", UserWarning, "pyproj.py", 7)
        warnings.warn_explicit("invalid value encountered in log", RuntimeWarning, "y.py", 2)
        logging.getLogger("rasterio._env").warning("CPLE_AppDefined: bad block")
        logging.getLogger("fm2uav.test").info("not a warning")
        assert raw == []  # the library messages wait for the end of the command
    assert said == ["below sea level"]
    assert raw == ["(library) UserWarning: lose projection information",
                   "(library) RuntimeWarning: invalid value encountered in log",
                   "(library) rasterio._env: CPLE_AppDefined: bad block"]
    said.clear()
    with captured(said.append):  # without debug: nothing of the libraries, ever
        warnings.warn_explicit("lose projection information", UserWarning, "pyproj.py", 8)
        logging.getLogger("pyogrio").error("GDAL error")
    assert said == []
    assert logging.getLogger().handlers == [] or all(  # the capture is removed again
        type(h).__name__ != "_Records" for h in logging.getLogger().handlers)


def test_library_lines_drop_numerical_noise():
    assert library_line("RuntimeWarning", "divide by zero encountered in divide") is None
    assert library_line("NumbaPerformanceWarning", "parallel=True but no transformation") is None
    assert library_line("UserWarning", "anything else") is None


def _warning_classes() -> set[str]:
    names = set()
    for path in SRC.rglob("*.py"):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.ClassDef) and any(
                    "Warning" in ast.unparse(b) for b in node.bases):
                names.add(node.name)
    return names


def test_every_warning_fm2uav_issues_has_a_category_of_its_own():
    # only fm2uav's categories are shown (a UserWarning would be taken for a library's
    # and dropped): each warnings.warn in src/ names a Warning class defined in fm2uav
    ours = _warning_classes()
    assert "GeodataWarning" in ours
    wrong = []
    for path in SRC.rglob("*.py"):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if not (isinstance(node, ast.Call) and ast.unparse(node.func) == "warnings.warn"):
                continue
            cat = node.args[1] if len(node.args) > 1 else next(
                (k.value for k in node.keywords if k.arg == "category"), None)
            if cat is None and node.args and isinstance(node.args[0], ast.Call):
                cat = node.args[0].func  # warnings.warn(ZoneWarning("...")): its class
            name = ast.unparse(cat).split(".")[-1] if cat is not None else "UserWarning"
            if name not in ours:
                wrong.append(f"{path.relative_to(SRC)}:{node.lineno} warns with {name}")
    assert not wrong, ("give fm2uav's warnings a category of fm2uav (e.g. GeodataWarning), "
                       "or the command line drops them as a library's: " + "; ".join(wrong))
