"""Typer's value coercion without pydantic where the result is certain (issue 27: an
instant command line).

typer >= 0.2x coerces every parameter value through a pydantic ``TypeAdapter`` built
on first use: the help flag of a group (value ``None``) and the defaults of a command
(``--order 2``) import pydantic (~0.1 s) and build an adapter each, on every
``fm2uav <cmd> --help``, bad flag and one-line input error. :func:`install` gives each
parameter of a built command a :class:`LightCoercion` instead, which returns at once
what the adapter would return, for the cases where that is certain:

* ``None`` (an option not given): ``None`` (or ``()`` for a repeatable one), as typer;
* a value already of the annotated type (``str``, ``int``, ``float``, ``bool``):
  itself, as pydantic's lax mode returns it;
* a string for an ``int`` / ``float`` that Python and pydantic read alike (plain
  decimal digits, an optional sign, a decimal point and exponent for ``float``):
  ``int(s)`` / ``float(s)``;
* a path (``pathlib.Path``): ``Path(s)`` (what pydantic makes of a string), then
  typer's own checks (``exists``, ``dir_okay``, ...);
* a list of such values, item by item.

Anything else — a string that is not a plain number (``--order x``), a type of another
kind, a check that fails — goes to typer's own coercion, built on demand: its result
and its error messages are typer's, unchanged. On a typer without this machinery
(< 0.2x, click types) :func:`install` does nothing.
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any, get_args, get_origin

try:  # typer >= 0.2x: pydantic coercion per parameter
    from typer._coercion import RuntimeParam, build_runtime_param
    from typer._param_types import coerce_cli_path
except ImportError:  # pragma: no cover - an older typer coerces with click types
    RuntimeParam = None  # type: ignore[assignment,misc]

__all__ = ["LightCoercion", "install"]

#: Strings that ``int(s)`` and pydantic's ``int`` read to the same number.
_INT = re.compile(r"[+-]?[0-9]{1,400}")
#: Strings that ``float(s)`` and pydantic's ``float`` read to the same number.
_FLOAT = re.compile(r"[+-]?(?:[0-9]{1,400}\.?[0-9]{0,400}|\.[0-9]{1,400})(?:[eE][+-]?[0-9]{1,4})?")

_NO_RESULT = object()


def _plain(parameter_info: Any) -> bool:
    """No parser, click type, range or clamp: the adapter is the bare type's."""
    return all(getattr(parameter_info, k, None) is None
               for k in ("parser", "click_type", "min", "max")) and not getattr(
        parameter_info, "clamp", False)


def _leaf(value: Any, annotation: Any, parameter_info: Any, param: Any, ctx: Any) -> Any:
    """What typer's adapter returns for one value, or ``_NO_RESULT`` when not certain."""
    if annotation is str:
        return value if type(value) is str else _NO_RESULT
    if annotation is bool:
        return value if type(value) is bool else _NO_RESULT
    if annotation is int:
        if type(value) is int:
            return value
        if type(value) is str and _INT.fullmatch(value):
            return int(value)
        return _NO_RESULT
    if annotation is float:
        if type(value) is float:
            return value
        if type(value) is str and _FLOAT.fullmatch(value):
            return float(value)
        return _NO_RESULT
    if annotation is Path and getattr(parameter_info, "path_type", None) in (None, Path):
        if type(value) is str:
            value = Path(value)
        if not isinstance(value, Path) or getattr(parameter_info, "allow_dash", False):
            return _NO_RESULT
        try:  # typer's checks; a failure is reported by typer's own coercion (its message)
            return coerce_cli_path(value, parameter_info, path_type=Path, param=param, ctx=ctx)
        except Exception:  # noqa: BLE001 - typer reports it, below
            return _NO_RESULT
    return _NO_RESULT


if RuntimeParam is not None:

    class LightCoercion(RuntimeParam):  # type: ignore[misc,valid-type]
        """Typer's coercion of one parameter, pydantic only where the result is uncertain.

        Parameters
        ----------
        parameter_info, annotation
            As typer's ``RuntimeParam`` (the parameter's type descriptor).
        """

        def __init__(self, descriptor: Any) -> None:
            object.__setattr__(self, "parameter_info", descriptor.parameter_info)
            object.__setattr__(self, "annotation", descriptor.annotation)
            object.__setattr__(self, "_descriptor", descriptor)
            object.__setattr__(self, "_typer", None)

        def _fast(self, value: Any, param: Any, ctx: Any) -> Any:
            info = self.parameter_info
            if self._descriptor.is_file or not _plain(info):
                return _NO_RESULT
            annotation = self.annotation
            if get_origin(annotation) is list:
                (item_type,) = get_args(annotation) or (None,)
                if not isinstance(value, (list, tuple)):
                    return _NO_RESULT
                items = [_leaf(v, item_type, info, param, ctx) for v in value]
                return _NO_RESULT if any(i is _NO_RESULT for i in items) else items
            return _leaf(value, annotation, info, param, ctx)

        def _coerce_value(self, value: Any, param: Any, ctx: Any) -> Any:
            out = self._fast(value, param, ctx)
            if out is not _NO_RESULT:
                return out
            if self._typer is None:
                object.__setattr__(self, "_typer", build_runtime_param(self._descriptor))
            return self._typer._coerce_value(value, param=param, ctx=ctx)

else:  # pragma: no cover
    LightCoercion = None  # type: ignore[assignment,misc]


def install(command: Any) -> Any:
    """Give every typer parameter of ``command`` (and its help option) a
    :class:`LightCoercion`; returns ``command``. A no-op on a typer without it."""
    if LightCoercion is None:
        return command
    for param in [*getattr(command, "params", ()), getattr(command, "_help_option", None)]:
        if (param is not None and hasattr(param, "type_descriptor")
                and getattr(param, "_runtime_param", False) is None):
            param._runtime_param = LightCoercion(param.type_descriptor)
    return command
