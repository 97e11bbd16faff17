"""The ``fm2uav`` command line.

The application is assembled from the modules ``fm2uav/cli/cmd_*.py``: each
defines ``register(app, reproduce_app)`` and adds its commands. Commands are
thin: parse, call the library, print a summary (see :mod:`._common`).
"""

from __future__ import annotations

import importlib
import pkgutil

import typer

__all__ = ["app", "main"]

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
)
reproduce_app = typer.Typer(
    help="Reproduce the experiments of the source papers (tables and figures).\n\n"
    "Example:  fm2uav reproduce tff --out out/tff",
    no_args_is_help=True,
)
app.add_typer(reproduce_app, name="reproduce")


def _register_all() -> None:
    for mod in sorted(pkgutil.iter_modules(__path__), key=lambda m: m.name):
        if mod.name.startswith("cmd_"):
            module = importlib.import_module(f"{__name__}.{mod.name}")
            module.register(app, reproduce_app)


_register_all()


def main() -> None:
    """Run the command line (the console script enters through :mod:`fm2uav.__main__`).

    Installs the compile notice: right before numba compiles the first kernel
    of this process (a cold cache), one line on stderr says so.
    """
    import sys

    from .._jit import cold_estimate_s, on_first_compile
    from ._common import err_console

    if "--quiet" not in sys.argv:
        on_first_compile(lambda: err_console.print(
            f"compiling kernels, first use only, ~{cold_estimate_s()} s", style="yellow",
            highlight=False))
    app()
