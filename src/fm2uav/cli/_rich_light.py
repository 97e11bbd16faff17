"""typer's help and error renderer without the two rich modules it never uses here
(issue 27: an instant command line).

``typer.rich_utils`` renders every help page and usage error. At its top it imports
``rich.markdown`` (markdown-it: help in ``rich_markup_mode="markdown"``, which fm2uav
does not use) and ``rich.traceback`` (pygments: pretty tracebacks, which fm2uav turns
off): ~60 ms of the ~70 ms its import costs, on every ``--help`` and bad flag.
:func:`install` lets typer import it with stand-ins for ``Markdown`` and ``Traceback``
that import the real class the first time one is used (called, an attribute read, an
``isinstance``): the renderer behaves as before, and pays for those modules only if it
ever needs them. The stand-in modules are removed from ``sys.modules`` as soon as
``typer.rich_utils`` is loaded, so any ``import rich.markdown`` elsewhere gets the real one.
A module already imported (a process that loaded rich.markdown before) is used as is.
"""

from __future__ import annotations

import importlib
import importlib.abc
import importlib.machinery
import sys
import types
from typing import Any

__all__ = ["install"]

TARGET = "typer.rich_utils"
#: module → the names ``typer.rich_utils`` imports from it, imported when first used.
DEFERRED = {"rich.markdown": ("Markdown",), "rich.traceback": ("Traceback",)}


class _Deferred(type):
    """The type of a stand-in class: calls, attributes and ``isinstance`` go to the real one."""

    def __call__(cls, *args: Any, **kwargs: Any) -> Any:
        return cls._real()(*args, **kwargs)

    def __getattr__(cls, name: str) -> Any:
        return getattr(cls._real(), name)

    def __instancecheck__(cls, obj: Any) -> bool:
        return isinstance(obj, cls._real())

    def __subclasscheck__(cls, sub: type) -> bool:
        return issubclass(sub, cls._real())


def stand_in(module: str, name: str) -> type:
    """A class that stands for ``module.name`` and imports it on first use."""
    def real() -> Any:
        return getattr(importlib.import_module(module), name)

    return _Deferred(name, (), {"_real": staticmethod(real), "__module__": module,
                                "__doc__": f"Stands for {module}.{name} (imported on use)."})


class _Finder(importlib.abc.MetaPathFinder):
    """Finds ``typer.rich_utils`` once and loads it with the stand-ins in place."""

    def find_spec(self, fullname: str, path: Any, target: Any = None) -> Any:
        if fullname != TARGET:
            return None
        uninstall()
        spec = importlib.machinery.PathFinder.find_spec(fullname, path)
        loader = getattr(spec, "loader", None)
        if loader is None or not hasattr(loader, "exec_module"):
            return spec
        real_exec = loader.exec_module

        def exec_module(module: types.ModuleType) -> None:
            placed = {}
            for mod, names in DEFERRED.items():
                if mod not in sys.modules:
                    stub = types.ModuleType(mod)
                    for name in names:
                        setattr(stub, name, stand_in(mod, name))
                    sys.modules[mod] = placed[mod] = stub
            try:
                real_exec(module)
            finally:
                for mod, stub in placed.items():
                    if sys.modules.get(mod) is stub:
                        del sys.modules[mod]

        loader.exec_module = exec_module  # this module's own loader object (one per file)
        return spec


_FINDER = _Finder()


def install() -> None:
    """Load ``typer.rich_utils`` with deferred ``Markdown``/``Traceback`` when it is first
    imported (nothing is imported now; a no-op when it already is)."""
    if TARGET not in sys.modules and _FINDER not in sys.meta_path:
        sys.meta_path.insert(0, _FINDER)


def uninstall() -> None:
    """Stop intercepting (after the one import, or for a test)."""
    while _FINDER in sys.meta_path:
        sys.meta_path.remove(_FINDER)
