"""fm2uav._gc: the collector paused while the command line starts, on again when the
command runs; a process that did not pause keeps its own setting."""

from __future__ import annotations

import gc
import json
import subprocess
import sys

import pytest

from fm2uav import _gc


@pytest.fixture
def fresh_state(monkeypatch):
    monkeypatch.setattr(_gc._State, "paused", False)
    monkeypatch.setattr(_gc._State, "owner", False)
    was = gc.isenabled()
    yield
    gc.unfreeze()
    (gc.enable if was else gc.disable)()


def test_pause_then_resume_turns_the_collector_off_then_on_and_freezes(fresh_state):
    gc.enable()
    _gc.pause()
    assert not gc.isenabled() and _gc.paused()
    _gc.resume()
    assert gc.isenabled() and not _gc.paused()
    assert gc.get_freeze_count() > 0  # what was alive at the start is out of the collections


def test_resume_and_at_exit_do_nothing_without_pause(fresh_state):
    gc.unfreeze()
    gc.disable()  # a program (or test) that turned it off itself
    _gc.pause()  # off already: not ours to turn on again
    _gc.resume()
    _gc.at_exit()
    assert not gc.isenabled() and gc.get_freeze_count() == 0
    gc.enable()
    _gc.resume()
    _gc.at_exit()
    assert gc.isenabled() and gc.get_freeze_count() == 0


PROBE = """
import gc, json, sys
states = []
import fm2uav.cli._common as common
real = common.debug_enabled
def spy():
    states.append(gc.isenabled())
    return real()
common.debug_enabled = spy  # called first thing inside a running command
import atexit
atexit.register(lambda: print(json.dumps({"in_command": states, "at_exit": gc.isenabled()})))
sys.argv = ["fm2uav", *ARGV]
from fm2uav.__main__ import main
main()
"""


@pytest.mark.parametrize("argv", [["plan", "--bogus"], ["run", "missing.yaml"]])
def test_the_command_line_pauses_and_the_command_runs_with_the_collector(tmp_path, argv):
    res = subprocess.run([sys.executable, "-c", PROBE.replace("ARGV", repr(argv))],
                         capture_output=True, text=True, timeout=300, cwd=tmp_path)
    assert res.returncode == 2, res.stderr
    report = json.loads(res.stdout.strip().splitlines()[-1])
    if argv[0] == "run":  # the command ran: with the collector on
        assert report["in_command"] and all(report["in_command"])
    else:  # a parse error: no command ran, the collector stayed paused to the end
        assert report == {"in_command": [], "at_exit": False}


def test_every_command_runs_through_handle_errors_so_the_collector_is_on():
    """The entry point pauses the collector; only ``handle_errors`` turns it on again. A
    command registered without it (a long ``fm2uav app`` server, a sweep) would run with the
    collector off and never free a reference cycle: every command of both groups must be
    wrapped by it."""
    from fm2uav.cli import COMMANDS, REPRODUCE
    from fm2uav.cli._lazy import registered

    def wrapped(fn):
        while fn is not None:
            if getattr(getattr(fn, "__code__", None), "co_qualname", "") == \
                    "handle_errors.<locals>.wrapper":  # wraps() copies __qualname__
                return True
            fn = getattr(fn, "__wrapped__", None)
        return False

    seen = 0
    for table, section in ((COMMANDS, "app"), (REPRODUCE, "reproduce")):
        for name, module in table.items():
            info = registered("fm2uav.cli", module, section)[name]
            assert wrapped(info.callback), f"{section} {name}: not wrapped by handle_errors"
            seen += 1
    assert seen >= 15
