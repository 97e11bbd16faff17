"""The ``fm2uav`` command line.

The application is assembled from the modules ``fm2uav/cli/cmd_*.py``: each
defines ``register(app, reproduce_app)`` and adds its commands; :data:`COMMANDS`
and :data:`REPRODUCE` name the module of each command, which is imported and built
only when that command is run or asked for its help (:mod:`._lazy`). Commands are
thin: parse, call the library, print a summary (see :mod:`._common`).

The command line stays light: importing this package (and so ``fm2uav --help``,
``fm2uav <cmd> --help`` and every error typer reports while parsing) loads
typer, rich and the light modules of this package only (the ``cmd_*`` module of the
command asked for; typer's pydantic coercion and rich's markdown and traceback modules
only when used: :mod:`._coerce`, :mod:`._rich_light`). A ``cmd_*`` module imports at its
top only the standard library, typer, rich, :mod:`fm2uav.errors` and the
light modules of this package (``_common``, ``options``, ``_mission_options``,
other ``cmd_*``); numpy, numba, scipy, matplotlib, the geodata libraries and the
rest of fm2uav are imported inside the command's function, by the code path
that needs them (tests/cli/test_init.py checks every ``cli/*.py`` module).
"""

from __future__ import annotations

import typer

from . import _rich_light
from ._lazy import lazy_group

_rich_light.install()  # help pages and usage errors without rich.markdown / rich.traceback

__all__ = ["COMMANDS", "REPRODUCE", "app", "main"]

#: ``fm2uav <name>`` → the ``cmd_*`` module that registers it, in the order of the help page
#: (each command is built only when it is run or asked for its help: :mod:`._lazy`;
#: tests/cli/test_lazy.py holds this table to what the modules register).
COMMANDS = {
    "app": "cmd_app", "batch": "cmd_batch", "calibrate": "cmd_calibrate", "check": "cmd_check",
    "cover": "cmd_cover", "export": "cmd_export", "formation": "cmd_formation",
    "plan": "cmd_plan", "routes": "cmd_routes", "run": "cmd_run", "sweep": "cmd_sweep",
    "tune": "cmd_tff",
}
#: ``fm2uav reproduce <name>`` → its ``cmd_*`` module, likewise.
REPRODUCE = {
    "city": "cmd_city", "coverage": "cmd_cover", "formation": "cmd_formation",
    "curvature": "cmd_sweep", "tff": "cmd_tff", "tracking": "cmd_tracking", "urban": "cmd_urban",
}

app = typer.Typer(
    name="fm2uav",
    help=(
        "UAV mission planning with Fast Marching Square (FM²).\n\n"
        "Example:  fm2uav plan --scenario open-field --out out/plan"
    ),
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
    rich_markup_mode="rich",
    cls=lazy_group(COMMANDS, package=__name__, section="app"),
)
reproduce_app = typer.Typer(
    help="Reproduce the experiments of the source papers (tables and figures).\n\n"
    "Example:  fm2uav reproduce tff --out out/tff",
    no_args_is_help=True,
    cls=lazy_group(REPRODUCE, package=__name__, section="reproduce"),
)
app.add_typer(reproduce_app, name="reproduce")


def main() -> None:
    """Run the command line (the console script enters through :mod:`fm2uav.__main__`).

    Installs the compile notice: right before numba compiles the first kernel
    of this process (a cold cache), one line on stderr says so.
    """
    import sys

    from .. import _jit
    from . import _common

    _common.RERUN_ALLOWED = True  # a damaged numba cache: rebuilt by running this again
    if "--quiet" not in sys.argv:  # numba is not imported here: the listener waits for it
        _jit.on_first_compile(lambda: _common.err_console.print(
            _jit.NOTICE.format(seconds=_jit.cold_estimate_s()), style="yellow",
            highlight=False))
    app()
