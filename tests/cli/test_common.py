"""The one place errors become exit codes (``cli._common.handle_errors``): the debug switch,
library warnings and log records never printed raw, a damaged numba cache rebuilt."""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest
from typer.testing import CliRunner

from fm2uav.cli import app
from fm2uav.cli._common import debug_enabled

ROOT = Path(__file__).resolve().parents[2]
runner = CliRunner()


@pytest.mark.parametrize("value, on", [
    (None, False), ("", False), ("0", False), ("false", False), ("no", False), ("off", False),
    ("2", False), ("1", True), ("true", True), ("TRUE", True), ("yes", True), (" Yes ", True),
])
def test_only_1_true_or_yes_turn_tracebacks_on(monkeypatch, value, on):
    if value is None:
        monkeypatch.delenv("FM2UAV_DEBUG", raising=False)
    else:
        monkeypatch.setenv("FM2UAV_DEBUG", value)
    assert debug_enabled() is on


def test_fm2uav_debug_0_keeps_the_one_line_error(tmp_path):
    missing = str(tmp_path / "missing.yaml")
    for off in ("0", "false", "no", ""):
        res = runner.invoke(app, ["run", missing], env={"FM2UAV_DEBUG": off})
        assert res.exit_code == 2 and "missing.yaml not found" in res.output
        assert res.exception is None or isinstance(res.exception, SystemExit)
    res = runner.invoke(app, ["run", missing], env={"FM2UAV_DEBUG": "1"})
    assert type(res.exception).__name__ == "InputError"  # raised through, with its traceback


def _env(**extra: str) -> dict[str, str]:
    src = str(ROOT / "src")
    path = os.environ.get("PYTHONPATH")
    env = {k: v for k, v in os.environ.items() if k != "FM2UAV_DEBUG"}
    return {**env, "PYTHONPATH": src if not path else f"{src}{os.pathsep}{path}", **extra}


# A command like every fm2uav command (handle_errors), whose libraries warn and log the way
# pyproj, rasterio, numpy and GDAL do, then fails on bad input (or not, with --ok).
NOISY = textwrap.dedent("""
    import logging, warnings
    import numpy as np, pyproj, typer
    from rasterio.io import MemoryFile
    from fm2uav.cli._common import handle_errors
    from fm2uav.errors import InputError
    from fm2uav.world.dem import GeodataWarning

    app = typer.Typer()

    @app.command()
    @handle_errors
    def main(ok: bool = False) -> None:
        pyproj.CRS.from_epsg(2056).to_proj4()             # pyproj UserWarning
        with MemoryFile() as mf:                          # rasterio NotGeoreferencedWarning
            with mf.open(driver="GTiff", width=2, height=2, count=1, dtype="float32") as ds:
                ds.write(np.zeros((1, 2, 2), "float32"))
            with mf.open() as ds:
                ds.read()
        np.log(np.array([-1.0]))                           # numpy RuntimeWarning
        logging.getLogger("rasterio._env").error("CPLE_AppDefined in TIFFReadDirectory")
        for _ in range(2):
            warnings.warn("the DEM lies below sea level", GeodataWarning, stacklevel=1)
        if not ok:
            raise InputError("world.sea_level is missing")
        print("done")

    app()
""")


@pytest.fixture(scope="module")
def noisy(tmp_path_factory) -> Path:
    p = tmp_path_factory.mktemp("noisy") / "noisy_cmd.py"
    p.write_text(NOISY)
    return p


def _run(script: Path, *args: str, **env: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, str(script), *args], capture_output=True, text=True,
                          timeout=300, env=_env(**env))


def test_library_warnings_and_log_records_are_never_printed_raw(noisy):
    res = _run(noisy)
    assert res.returncode == 2, res.stderr
    lines = res.stderr.strip().splitlines()
    # ours once, in our words, then the one-line error; nothing of the libraries
    assert lines == ["warning: the DEM lies below sea level",
                     "error: world.sea_level is missing"], res.stderr
    res = _run(noisy, "--ok")
    assert res.returncode == 0 and res.stdout.strip() == "done"
    assert res.stderr.strip().splitlines() == ["warning: the DEM lies below sea level"]


def test_fm2uav_debug_shows_the_library_messages_as_they_are(noisy):
    res = _run(noisy, "--ok", FM2UAV_DEBUG="1")
    assert res.returncode == 0, res.stderr
    err = res.stderr
    for text in ("UserWarning: You will likely lose important projection information",
                 "NotGeoreferencedWarning: Dataset has no geotransform",
                 "RuntimeWarning: invalid value encountered in log",
                 "rasterio._env: CPLE_AppDefined in TIFFReadDirectory"):
        assert err.count(text) == 1, err  # once each, after the command


# A command that runs one of fm2uav's compiled kernels (numba cache in NUMBA_CACHE_DIR);
# RERUN_ALLOWED as the real command line (fm2uav.cli.main) sets it.
KERNEL = textwrap.dedent("""
    import numpy as np, typer
    from fm2uav.cli import _common
    from fm2uav.cli._common import handle_errors

    app = typer.Typer()

    @app.command()
    @handle_errors
    def main() -> None:
        from fm2uav.eikonal import _kernels as k
        print("result", k.scan_speed(k._readonly(np.ones(3)), 1e-9))

    _common.RERUN_ALLOWED = True
    app()
""")


def _damage(cache: Path, pattern: str, data: bytes) -> list[Path]:
    files = sorted(cache.rglob(pattern))
    for f in files:
        f.write_bytes(data)
    return files


@pytest.mark.slow  # three processes that import numba and compile a kernel
@pytest.mark.parametrize("pattern, data", [
    ("_kernels.scan_speed-*.nbi", b"\x80\x04\x95"),  # a truncated index (killed writer)
    ("_kernels.scan_speed-*.nbc", b""),               # an empty data file (full disk)
], ids=["truncated-index", "empty-data"])
def test_a_damaged_numba_cache_is_rebuilt_and_the_command_run_again(tmp_path, pattern, data):
    script = tmp_path / "kernel_cmd.py"
    script.write_text(KERNEL)
    cache = tmp_path / "numba"
    first = _run(script, NUMBA_CACHE_DIR=str(cache))
    assert first.returncode == 0, first.stderr
    assert _damage(cache, pattern, data)
    res = _run(script, NUMBA_CACHE_DIR=str(cache))
    assert res.returncode == 0, res.stderr
    assert res.stdout == first.stdout  # the command ran (once) to the end
    assert res.stderr.count("numba cache of fm2uav's compiled kernels is damaged") == 1
    assert "Traceback" not in res.stderr
    again = _run(script, NUMBA_CACHE_DIR=str(cache))  # the rebuilt cache loads
    assert again.returncode == 0 and again.stderr == ""


@pytest.mark.slow  # three processes that import numba, two compile a kernel
def test_a_damaged_cache_without_rerun_says_how(tmp_path):

    script = tmp_path / "kernel_cmd.py"
    script.write_text(KERNEL.replace("_common.RERUN_ALLOWED = True", ""))
    cache = tmp_path / "numba"
    assert _run(script, NUMBA_CACHE_DIR=str(cache)).returncode == 0
    _damage(cache, "_kernels.scan_speed-*.nbi", b"\x80")
    res = _run(script, NUMBA_CACHE_DIR=str(cache))
    assert res.returncode == 2 and "Traceback" not in res.stderr, res.stderr
    assert "deleted its" in res.stderr and "run the command again" in res.stderr
    assert _run(script, NUMBA_CACHE_DIR=str(cache)).returncode == 0  # it was deleted


def test_an_error_names_only_the_flags_of_the_command_that_raised_it():
    import typer

    from fm2uav.cli._common import handle_errors
    from fm2uav.errors import InputError

    mini = typer.Typer()

    @mini.command()
    @handle_errors
    def main(ceiling: float = typer.Option(0.0, "--ceiling")) -> None:
        import warnings

        from fm2uav.world.dem import GeodataWarning

        warnings.warn("the DEM is distorted; crop it with world.bbox (CLI --bbox) or raise "
                      "--ceiling", GeodataWarning, stacklevel=1)
        raise InputError("the flight level leaves the map; lower it or build a taller world "
                         "(mission file planner.agl / world.ceiling; CLI --agl / --ceiling); "
                         "crop with world.bbox (CLI --bbox W,S,E,N) or give --agl too")

    res = runner.invoke(mini, [])
    assert res.exit_code == 2
    assert res.output.strip() == (
        "warning: the DEM is distorted; crop it with world.bbox or raise --ceiling\n"
        "error: the flight level leaves the map; lower it or build a taller world (mission "
        "file planner.agl / world.ceiling; CLI --ceiling); crop with world.bbox or give "
        "planner.agl too")


def _writing_command(stop):
    """A one-command app (:func:`handle_errors`) that writes ``a.txt`` in an output set at
    ``--out``, then calls ``stop()`` (where a stop signal lands)."""
    import typer

    from fm2uav.cli._common import handle_errors
    from fm2uav.io import outdir

    mini = typer.Typer()

    @mini.command()
    @handle_errors
    def main(out: str = typer.Option(..., "--out")) -> None:
        od = outdir.OutputDir(out)
        od.check(["a.txt"])
        with od.open("a.txt") as fh:
            fh.write("new")
        stop()

    return mini


def test_a_stop_swallowed_inside_a_command_still_ends_it_with_130(tmp_path):
    import signal

    from fm2uav.io import outdir

    class Victim:
        def __del__(self):  # Python ignores what is raised here ("Exception ignored in")
            outdir._on_stop_signal(signal.SIGTERM, None)

    # the stop lands in its __del__ and is swallowed; the command runs on
    mini = _writing_command(lambda: Victim())
    out = tmp_path / "out"
    res = runner.invoke(mini, ["--out", str(out)])
    assert res.exit_code == 130, res.output
    assert "interrupted by SIGTERM" in res.output and "Traceback" not in res.output
    assert not out.exists()  # nothing put in place
    outdir.raise_if_stopped()  # reported: not raised again
    res = runner.invoke(mini, ["--out", str(out)])  # the next command is not affected
    assert res.exit_code == 130  # (its own Victim again)


@pytest.mark.parametrize("how", ["swallowed", "turned-into-error"])
def test_a_stop_a_library_swallows_or_turns_into_an_error_ends_the_command_with_130(
        tmp_path, how):
    import signal

    from fm2uav.io import outdir

    def stop():
        try:  # a library that catches everything (or numba's dispatcher, which answers a
            outdir._on_stop_signal(signal.SIGTERM, None)  # pending exception with an error)
        except BaseException as exc:
            if how == "turned-into-error":
                raise SystemError("CPUDispatcher(<function f>) returned a result with an "
                                  "exception set") from exc

    out = tmp_path / "out"
    res = runner.invoke(_writing_command(stop), ["--out", str(out)])
    assert res.exit_code == 130, res.output
    assert res.output.strip().splitlines() == [
        "error: interrupted by SIGTERM; no partial outputs were left (an earlier output set "
        "is as it was)"]
    assert not out.exists()  # nothing put in place
    assert outdir.unreported_stop() is None  # reported: not raised again
    outdir.raise_if_stopped()
