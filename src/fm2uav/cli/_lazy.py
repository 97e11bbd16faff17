"""Sub-commands built on demand (issue 27: an instant command line).

``fm2uav plan --help`` needs the click command of ``plan`` only: building all twenty
(typer reads every signature and makes ~450 parameters) and importing every
``cmd_*`` module costs more than rendering the page. A :func:`lazy_group` knows its
commands by name (``fm2uav.cli.COMMANDS``: name → ``cmd_*`` module) and builds one
the first time it is asked for (:class:`LazyCommands`): it imports that module, lets
its ``register(app, reproduce_app)`` add its commands to a scratch typer app, and
makes the click command of the one asked for, as typer would have
(``typer.main.get_command_from_info``), its parameters coerced by
:mod:`._coerce`. The list of ``fm2uav --help`` reads each command's name and help
(:meth:`LazyCommands.summary`) without building its parameters.

A ``cmd_*`` module missing from the table is still found (the group imports the
modules not in it, in order, when asked for a name it does not know, or for the list),
only slower; tests/cli/test_lazy.py holds the table to what the modules register.
"""

from __future__ import annotations

import importlib
import inspect
import pkgutil
from collections.abc import Iterator, Mapping, MutableMapping
from typing import Any

import typer
import typer.core
import typer.main

from . import _coerce

__all__ = ["FastCommand", "LazyCommands", "lazy_group", "registered"]

#: Which scratch app of ``register(app, reproduce_app)`` a group reads.
SECTIONS = ("app", "reproduce")


class FastCommand(typer.core.TyperCommand):
    """A typer command whose help option is coerced without pydantic (:mod:`._coerce`)."""

    def get_help_option(self, ctx: Any) -> Any:
        option = super().get_help_option(ctx)
        _coerce.install(self)
        return option


def registered(package: str, module: str, section: str) -> dict[str, typer.models.CommandInfo]:
    """The commands ``package.module``'s ``register`` adds to ``section`` (name → info)."""
    mod = importlib.import_module(f"{package}.{module}")
    scratch = {name: typer.Typer() for name in SECTIONS}
    mod.register(scratch["app"], scratch["reproduce"])
    out = {}
    for info in scratch[section].registered_commands:
        name = info.name or typer.main.get_command_name(info.callback.__name__)
        out[name] = info
    return out


class LazyCommands(MutableMapping):
    """A group's commands, name → click command, each built the first time it is read.

    Parameters
    ----------
    table
        Name → ``cmd_*`` module that registers it, in the order of the help page.
    package, section
        Where the modules are (``"fm2uav.cli"``) and which part of their ``register`` the
        group is (``"app"`` or ``"reproduce"``).
    built
        Commands already made (a sub-group), after those of ``table``.
    make
        ``CommandInfo → click command`` (typer's ``get_command_from_info`` with the app's
        settings).
    """

    def __init__(self, table: Mapping[str, str], package: str, section: str,
                 built: Mapping[str, Any], make: Any) -> None:
        self._table = dict(table)
        self._package, self._section, self._make = package, section, make
        self._built: dict[str, Any] = {}
        self._infos: dict[str, typer.models.CommandInfo] = {}
        self._extra: list[str] | None = None  # names of modules outside the table
        self._tail = dict(built)

    # -- what the table does not say ---------------------------------------------------------
    def _discover(self) -> None:
        """Register the ``cmd_*`` modules the table does not name (normally none)."""
        if self._extra is not None:
            return
        self._extra = []
        package = importlib.import_module(self._package)
        known = set(self._table.values())
        for mod in sorted(pkgutil.iter_modules(package.__path__), key=lambda m: m.name):
            if mod.name.startswith("cmd_") and mod.name not in known:
                for name, info in registered(self._package, mod.name, self._section).items():
                    if name not in self._table and name not in self._tail:
                        self._infos[name] = info
                        self._extra.append(name)

    def _info(self, name: str) -> typer.models.CommandInfo | None:
        if name not in self._infos:
            if name in self._table:
                self._infos.update(registered(self._package, self._table[name], self._section))
            else:
                self._discover()
        return self._infos.get(name)

    # -- the mapping -------------------------------------------------------------------------
    def __getitem__(self, name: str) -> Any:
        if name in self._tail:
            return self._tail[name]
        if name not in self._built:
            info = self._info(name)
            if info is None:
                raise KeyError(name)
            if info.cls in (None, typer.core.TyperCommand):  # typer's default class
                info.cls = FastCommand
            self._built[name] = _coerce.install(self._make(info))
        return self._built[name]

    def __iter__(self) -> Iterator[str]:
        self._discover()
        yield from self._table
        yield from self._extra or ()
        yield from self._tail

    def __len__(self) -> int:
        return sum(1 for _ in self)

    def __contains__(self, name: object) -> bool:
        return name in self._table or name in self._tail or (
            isinstance(name, str) and self._info(name) is not None)

    def __setitem__(self, name: str, command: Any) -> None:  # click's add_command
        self._table.pop(name, None)
        self._tail[name] = command

    def __delitem__(self, name: str) -> None:
        if name not in self:
            raise KeyError(name)
        self._table.pop(name, None)
        self._tail.pop(name, None)
        self._built.pop(name, None)
        if self._extra and name in self._extra:
            self._extra.remove(name)

    def summary(self, name: str, markup_mode: Any) -> Any:
        """``name``'s line of the group's help (name, help, panel), its parameters not built."""
        if name in self._tail or name in self._built:
            return self[name]
        info = self._info(name)
        if info is None:
            return None
        text = (inspect.cleandoc(info.help) if info.help is not None
                else inspect.getdoc(info.callback))
        return typer.core.TyperCommand(
            name=name, callback=None, params=[], help=text, short_help=info.short_help,
            hidden=info.hidden, deprecated=info.deprecated,
            rich_help_panel=info.rich_help_panel, rich_markup_mode=markup_mode)


def lazy_group(table: Mapping[str, str], *, package: str, section: str,
               pretty_exceptions_short: bool = True) -> type[typer.core.TyperGroup]:
    """A ``TyperGroup`` class (``typer.Typer(cls=...)``) whose commands are ``table``'s,
    built on demand (:class:`LazyCommands`)."""

    class LazyGroup(typer.core.TyperGroup):
        def __init__(self, *args: Any, commands: Any = None, **kwargs: Any) -> None:
            super().__init__(*args, commands=commands, **kwargs)
            mode = self.rich_markup_mode

            def make(info: typer.models.CommandInfo) -> Any:
                return typer.main.get_command_from_info(
                    info, pretty_exceptions_short=pretty_exceptions_short,
                    rich_markup_mode=mode)

            self.commands = LazyCommands(table, package, section, self.commands, make)
            self._listing = False

        def get_help_option(self, ctx: Any) -> Any:
            option = super().get_help_option(ctx)
            _coerce.install(self)
            return option

        def list_commands(self, ctx: Any) -> list[str]:
            return list(self.commands)  # typer's reads the items: it would build them all

        def get_command(self, ctx: Any, cmd_name: str) -> Any:
            if self._listing:  # the help page's list: names and help only
                return self.commands.summary(cmd_name, self.rich_markup_mode)
            return self.commands.get(cmd_name)

        def format_help(self, ctx: Any, formatter: Any) -> None:
            self._listing = True
            try:
                super().format_help(ctx, formatter)
            finally:
                self._listing = False

    return LazyGroup
