"""The progress display of long commands (fm2uav.cli._progress): the library's
fm2uav.progress stages, counts and time left drawn by rich on a terminal — and nothing on a
pipe, with --quiet or with --json.

The end-to-end checks run ``fm2uav plan`` three times at once: under a pseudo-terminal
(stderr a tty: the display is drawn), through pipes, and under a pseudo-terminal with
``--quiet`` (nothing drawn).
"""

from __future__ import annotations

import io
import json
import os
import pty
import re
import select
import subprocess
import sys
import time
from types import SimpleNamespace

import pytest
from rich.console import Console

from fm2uav import progress
from fm2uav.cli._progress import _eta_column, progress_display

#: ANSI control sequences (colours, cursor moves, line erases)
ANSI = re.compile(r"\x1b\[[0-9;?]*[A-Za-z]")


def _terminal(width: int = 120) -> tuple[Console, io.StringIO]:
    buf = io.StringIO()
    return Console(file=buf, force_terminal=True, width=width, color_system=None), buf


def _frames(text: str) -> list[str]:
    """The lines a terminal showed, control sequences removed."""
    return [s for s in (ANSI.sub("", x).strip() for x in re.split(r"[\r\n]", text)) if s]


def test_stages_counts_and_units_are_drawn_on_a_terminal():
    console, buf = _terminal()
    with progress_display(True, console) as say:
        say("reading the mission")
        progress.step("planning (FM²)", 0.5)
        with progress.span("bands", 1.0):
            for k in range(3):
                progress.count(k + 1, 40, "bands")
        time.sleep(0.3)                         # the bar redraws at 8 Hz
        progress.step("writing the files", 0.5)
        time.sleep(0.3)
    frames = _frames(buf.getvalue())
    assert any("bands — planning (FM²)" in f and "3/40 bands" in f for f in frames), frames
    assert any("writing the files" in f and "50%" in f for f in frames), frames


def test_a_narrow_terminal_keeps_the_count_and_the_innermost_stage():
    console, buf = _terminal(width=80)
    with progress_display(True, console):
        progress.step("the formation flight with three UAVs over the fissure", 0.8)
        with progress.span("flying the 3 UAVs (FM² re-planning every cycle)", 1.0):
            progress.count(40, 95, "cycles")
            time.sleep(0.3)
    frames = _frames(buf.getvalue())
    last = [f for f in frames if "cycles" in f]
    assert last and all(len(f) <= 80 for f in last), frames
    assert "40/95 cycles" in last[-1] and "%" in last[-1], last[-1]
    # what is done now comes first; what it is part of is cut with "…"
    assert last[-1][2:].startswith("flying the 3 UAVs") and "…" in last[-1], last[-1]
    assert "formation" not in last[-1]


def test_nothing_is_drawn_or_listened_to_off_a_terminal_or_when_disabled():
    for console, enabled in ((Console(file=io.StringIO(), width=120), True),   # a pipe
                             (_terminal()[0], False)):                       # --quiet/--json
        with progress_display(enabled, console) as say:
            say("planning")
            assert progress._LISTENER.get() is None   # the library's events cost nothing
            progress.step("planning", 1.0)
        assert console.file.getvalue() == ""


def test_the_time_left_is_shown_once_the_rate_says_something():
    col = _eta_column()
    task = SimpleNamespace(elapsed=10.0, completed=250, total=1000)
    assert col.render(task).plain == "ETA 0:30"                 # 10 s for a quarter
    assert col.render(SimpleNamespace(elapsed=1.0, completed=500, total=1000)).plain == ""
    assert col.render(SimpleNamespace(elapsed=10.0, completed=10, total=1000)).plain == ""
    assert col.render(SimpleNamespace(elapsed=90.0, completed=1000, total=1000)).plain == ""


def _env() -> dict[str, str]:
    env = {k: v for k, v in os.environ.items()
           if k not in ("NO_COLOR", "FORCE_COLOR", "TTY_COMPATIBLE", "TTY_INTERACTIVE",
                        "COLUMNS", "LINES", "TERM")}
    return {**env, "TERM": "xterm-256color", "COLUMNS": "120"}


def _start_on_a_pty(args: list[str]):
    """``fm2uav <args>`` with stdin/stdout/stderr on a pseudo-terminal: (process, master fd)."""
    master, slave = pty.openpty()
    proc = subprocess.Popen([sys.executable, "-m", "fm2uav", *args], stdin=slave,
                            stdout=slave, stderr=slave, env=_env(), close_fds=True)
    os.close(slave)
    return proc, master


def _read_pty(proc, master: int, timeout: float = 240.0) -> str:
    chunks, deadline = [], time.monotonic() + timeout
    try:
        while time.monotonic() < deadline:
            ready, _, _ = select.select([master], [], [], 0.5)
            if ready:
                try:
                    data = os.read(master, 65536)
                except OSError:        # EIO: the child closed the terminal
                    break
                if not data:
                    break
                chunks.append(data)
            elif proc.poll() is not None:
                break
    finally:
        os.close(master)
        if proc.poll() is None:
            proc.kill()
        proc.wait(timeout=30)
    return b"".join(chunks).decode("utf-8", "replace")


@pytest.fixture(scope="module")
def plan_runs(tmp_path_factory):
    """``fm2uav plan --scenario city2d`` on a terminal, through pipes and on a terminal with
    --quiet, run side by side: {name: (exit code, terminal text or (stdout, stderr))}."""
    root = tmp_path_factory.mktemp("progress")
    args = ["plan", "--scenario", "city2d"]
    tty, tty_fd = _start_on_a_pty([*args, "--out", str(root / "tty")])
    quiet, quiet_fd = _start_on_a_pty([*args, "--quiet", "--out", str(root / "quiet")])
    piped = subprocess.Popen([sys.executable, "-m", "fm2uav", *args, "--json", "--out",
                              str(root / "pipe")], stdin=subprocess.DEVNULL,
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE, env=_env())
    out, err = piped.communicate(timeout=240)
    runs = {"pipe": (piped.returncode, (out.decode(), err.decode()))}
    runs["tty"] = (None, _read_pty(tty, tty_fd))
    runs["tty"] = (tty.returncode, runs["tty"][1])
    runs["quiet"] = (None, _read_pty(quiet, quiet_fd))
    runs["quiet"] = (quiet.returncode, runs["quiet"][1])
    return runs


@pytest.mark.slow
def test_a_terminal_shows_the_stages_of_fm2uav_plan(plan_runs):
    code, text = plan_runs["tty"]
    assert code == 0, text[-2000:]
    frames = _frames(text)
    # the stages the library and the command report, with the share done
    assert any(f.startswith(("⠋", "⠙", "⠹", "⠸", "⠼", "⠴", "⠦", "⠧", "⠇", "⠏"))
               and "%" in f for f in frames), frames[:20]
    assert any("planning (FM²)" in f for f in frames), frames[:40]
    # transient: the summary that follows starts on a clean line, the bar is gone
    assert "FM² plan" in ANSI.sub("", text)
    assert "\x1b[?25l" in text                   # rich hid the cursor while drawing


@pytest.mark.slow
def test_a_pipe_or_quiet_gets_no_progress_display(plan_runs):
    code, (out, err) = plan_runs["pipe"]
    assert code == 0, err
    json.loads(out)                               # --json: stdout is the summary alone
    assert "planning (FM²)" not in err and "\x1b[" not in err and "%" not in err, err
    code, text = plan_runs["quiet"]
    assert code == 0, text
    assert "planning" not in text and "building the world" not in text, text
    assert "\x1b[?25l" not in text
