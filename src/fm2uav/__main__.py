"""Entry point of the ``fm2uav`` command (console script and ``python -m fm2uav``).

It speaks before the heavy imports (numba, scipy, matplotlib: ~1-2 s): on a
cold numba cache ``fm2uav plan`` / ``fm2uav run`` print "compiling kernels,
first use only, ~N s" at once, and ``fm2uav plan`` compiles its kernels in two
processes (the Fast Marching kernels in a child, the rest here) before
planning, which halves the first run on a 2-core machine. The command line
proper is :mod:`fm2uav.cli`.
"""

from __future__ import annotations

import os
import subprocess
import sys

#: Commands whose first run compiles kernels (the notice is shown up front).
_COMPILING_COMMANDS = ("plan", "run")


def _option(argv: list[str], name: str) -> str | None:
    """Value of ``--name VALUE`` or ``--name=VALUE`` in ``argv`` (last wins)."""
    value = None
    for i, a in enumerate(argv):
        if a == name and i + 1 < len(argv):
            value = argv[i + 1]
        elif a.startswith(name + "="):
            value = a.split("=", 1)[1]
    return value


def _fmm_group(argv: list[str]) -> str:
    """The Fast Marching warm-up group a ``fm2uav plan`` command line will use."""
    order = "1" if _option(argv, "--order") == "1" else "2"
    ndim = "2" if _option(argv, "--scenario") == "city2d" else "3"
    return f"fmm{ndim}d_o{order}"


def _spawn(groups: list[str]) -> subprocess.Popen | None:
    """Start ``python -m fm2uav.planning.warmup GROUPS`` in the background (None if it cannot)."""
    try:
        return subprocess.Popen(
            [sys.executable, "-m", "fm2uav.planning.warmup", *groups],
            stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
            env=os.environ.copy(),
        )
    except OSError:  # no fork / exec: the command compiles everything itself
        return None


def main() -> None:
    """Run the ``fm2uav`` command line."""
    argv = sys.argv[1:]
    command = argv[0] if argv else ""
    child = None
    cold = False
    if command in _COMPILING_COMMANDS and not {"--help", "-h"} & set(argv):
        from . import _jit

        cold = _jit.likely_cold()
        if cold:
            _jit.mark_announced()  # the numba-event fallback stays silent
            if "--quiet" not in argv:
                from rich.console import Console

                Console(stderr=True).print(
                    f"compiling kernels, first use only, ~{_jit.cold_estimate_s()} s",
                    style="yellow", highlight=False)
            if command == "plan":
                child = _spawn([_fmm_group(argv)])
    if child is not None:
        from .planning.warmup import FIRST_PLAN_MAIN, warm

        try:
            warm(FIRST_PLAN_MAIN)
        except Exception:  # a warm-up failure only costs time: the plan compiles what it needs
            pass
    from .cli import main as cli_main  # matplotlib & co. while the child finishes

    if child is not None:
        try:
            child.wait(timeout=600)
        except subprocess.TimeoutExpired:  # stuck: plan anyway (numba compiles what is missing)
            pass
    cli_main()


if __name__ == "__main__":
    main()
