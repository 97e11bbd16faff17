"""The first use of the compiled kernels: say so at once, compile in two processes.

A command that plans calls :func:`announce_compile` first thing in its body,
once its arguments are parsed (a bad flag is refused before anything is
compiled). On a cold numba cache (:func:`fm2uav._jit.likely_cold`, a few ms,
numba not imported) it prints "compiling kernels, first use only, ~N s" on
stderr at once (unless ``--quiet``) and, given a Fast Marching warm-up group,
compiles a first plan in two processes: ``python -m fm2uav.planning.warmup
GROUP`` in a child while this process compiles
:data:`~fm2uav.planning.warmup.FIRST_PLAN_MAIN` and imports the modules the
command needs, which halves the first run on a 2-core machine. Every other
compilation prints the same line right before it starts
(:func:`fm2uav._jit.on_first_compile`, installed by :func:`fm2uav.cli.main`).
"""

from __future__ import annotations

import importlib
import os
import subprocess
import sys
from collections.abc import Sequence

__all__ = ["announce_compile", "fmm_group"]


def fmm_group(*, order: int | str, ndim: int) -> str:
    """The Fast Marching warm-up group of a plan (``fmm3d_o2``, ...): order 1, else 2."""
    return f"fmm{ndim}d_o{'1' if str(order) == '1' else '2'}"


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


def announce_compile(*, quiet: bool = False, child_group: str | None = None,
                     preload: Sequence[str] = (), also: Sequence[str] = (),
                     kernels: Sequence[tuple[str, str]] | None = None) -> bool:
    """On a cold cache: the compile notice, and the two-process warm-up with ``child_group``.

    Parameters
    ----------
    quiet : bool
        ``--quiet``: compile, but print nothing.
    child_group : str, optional
        A :data:`fm2uav.planning.warmup.GROUPS` name compiled in a child process
        (:func:`fmm_group`) while this one compiles ``FIRST_PLAN_MAIN``; None: only
        the notice.
    preload : sequence of str
        Modules the command imports next, imported while the child finishes.
    also : sequence of str
        More warm-up groups the child compiles after ``child_group`` (e.g. ``many``).
    kernels : sequence of (str, str), optional
        The kernels whose cache decides "cold" (default
        :data:`fm2uav._jit.FIRST_PLAN_KERNELS`; ``fm2uav routes``: ``ROUTES_KERNELS``).

    Returns
    -------
    bool
        Whether the cache was cold.
    """
    from .. import _jit

    if not _jit.likely_cold(_jit.FIRST_PLAN_KERNELS if kernels is None else kernels):
        return False
    if not quiet and not _jit.announced():  # (fm2uav.__main__ may have said it already)
        from ._common import err_console

        err_console.print(_jit.NOTICE.format(seconds=_jit.cold_estimate_s()), style="yellow",
                          highlight=False)
    _jit.mark_announced()  # the numba-event fallback stays silent
    child = _spawn([child_group, *also]) if child_group else None
    if child is None:
        return True
    try:
        from ..planning.warmup import FIRST_PLAN_MAIN, warm

        try:
            warm(FIRST_PLAN_MAIN)
        except Exception:  # noqa: BLE001 - a warm-up failure only costs time: the plan
            pass  # compiles what it needs (and reports what cannot be compiled)
        for name in preload:
            importlib.import_module(name)
        try:
            child.wait(timeout=600)
        except subprocess.TimeoutExpired:  # stuck: plan anyway (numba compiles what is missing)
            pass
    finally:
        if child.poll() is None:  # interrupted (or stuck): never leave it compiling behind us
            child.terminate()
    return True
