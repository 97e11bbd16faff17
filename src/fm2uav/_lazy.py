"""Names of a package imported on first access (PEP 562), written once for every package.

``import fm2uav``, ``import fm2uav.io.outdir`` or ``import fm2uav.planning.params`` must
not load numba, scipy and the kernels (~1 s): the command line checks its flags and
answers ``--help`` before any heavy import. A package that re-exports heavy names
declares where each lives and takes its module ``__getattr__``/``__dir__`` from
:func:`lazy_names`.

Examples
--------
In a package's ``__init__.py``::

    __getattr__, __dir__ = lazy_names(__name__, {"plan": ".planner"})
"""

from __future__ import annotations

import importlib
import sys
from collections.abc import Callable, Iterable, Mapping
from typing import Any

__all__ = ["lazy_names", "lazy_function"]


def lazy_names(package: str, names: Mapping[str, str], submodules: Iterable[str] = ()
               ) -> tuple[Callable[[str], Any], Callable[[], list[str]]]:
    """The module ``__getattr__`` and ``__dir__`` of a package with lazily imported names.

    Parameters
    ----------
    package : str
        The package's ``__name__``.
    names : mapping of str to str
        Each public name and the module it lives in, relative to ``package`` (``".planner"``,
        ``"..autopilot"``). Imported on first access, then kept in the package's namespace
        (later accesses skip ``__getattr__``).
    submodules : iterable of str
        Subpackages imported on first attribute access (``fm2uav.scenarios`` after a bare
        ``import fm2uav``).

    Returns
    -------
    (__getattr__, __dir__)
        To assign in the package's namespace.
    """
    subs = frozenset(submodules)

    def __getattr__(name: str) -> Any:
        if name in names:
            value = getattr(importlib.import_module(names[name], package), name)
            vars(sys.modules[package])[name] = value
            return value
        if name in subs:
            return importlib.import_module(f".{name}", package)
        raise AttributeError(f"module {package!r} has no attribute {name!r}")

    def __dir__() -> list[str]:
        return sorted(set(vars(sys.modules[package])) | set(names) | subs)

    return __getattr__, __dir__


def lazy_function(package: str, module: str, name: str) -> Callable[..., Any]:
    """A function that imports ``module`` (relative to ``package``) on its first call.

    For tables of callables (the builders of :class:`fm2uav.world.World`, the factories
    of the built-in scenarios) that must exist before their heavy modules load.

    Parameters
    ----------
    package : str
        The ``__name__`` of the package ``module`` is relative to.
    module : str
        The module defining the function, e.g. ``".dem"``.
    name : str
        The function's name in ``module``.

    Returns
    -------
    callable
        Calls ``module.name`` with the same arguments.
    """

    def call(*args: Any, **kwargs: Any) -> Any:
        return getattr(importlib.import_module(module, package), name)(*args, **kwargs)

    call.__name__ = call.__qualname__ = name
    call.__doc__ = f"``{module.lstrip('.')}.{name}`` of :mod:`{package}`, imported on first call."
    return call

