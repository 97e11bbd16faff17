"""Argument checks shared by every layer: points, numbers, choices, flags.

Each check returns the value in its canonical type (``float``, ``int``, ``bool``,
a float array) or raises :class:`~fm2uav.errors.InputError` with a one-line
message that says *what* is wrong, *where* the value comes from and *how* to fix
it. ``where`` names the places a user sets the value, e.g.
``where=("planner.saturation", "--saturation")`` for the mission-file key and the
CLI flag; it is appended as ``(mission file: planner.saturation; CLI: --saturation)``.

Examples
--------
>>> positive(2.5, "agl", unit="m")
2.5
>>> positive(-1, "agl", unit="m", where=("planner.agl", "--agl"))
Traceback (most recent call last):
...
fm2uav.errors.InputError: agl must be a finite number > 0 m, got -1 (mission file: planner.agl; CLI: --agl)
"""

from __future__ import annotations

import math
import numbers
import sys
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

from ._yaml_light import import_yaml
from .errors import InputError

if TYPE_CHECKING:  # numpy is imported by the checks that need it: the file checks
    import numpy as np  # (input_file, read_text, ...) stay light for the command line

__all__ = [
    "Where",
    "where_text",
    "number",
    "positive",
    "non_negative",
    "in_range",
    "optional",
    "integer",
    "seed_value",
    "choice",
    "flag",
    "point",
    "grid",
    "input_file",
    "missing",
    "cwd_gone",
    "input_log",
    "note_input",
    "noted_inputs",
    "read_text",
    "load_yaml",
    "load_json",
]

#: Where a value is set: ``None``, one place (``"planner.agl"``) or
#: ``(mission-file key, CLI flag)``; either may be None.
Where = str | tuple[str | None, str | None] | None


def where_text(where: Where) -> str:
    """`` (mission file: KEY; CLI: FLAG)`` for ``where``, or ``""``."""
    if where is None:
        return ""
    if isinstance(where, str):
        return f" ({where})"
    key, flag_ = where
    parts = ([f"mission file: {key}"] if key else []) + ([f"CLI: {flag_}"] if flag_ else [])
    return f" ({'; '.join(parts)})" if parts else ""


def _fmt(v: float) -> str:
    return f"{v:g}"


def _is_bool(value: Any) -> bool:
    """A Python or numpy bool (numpy is not imported for it: without numpy loaded, no
    value can be a numpy one — the command line checks its flags before numpy loads)."""
    np = sys.modules.get("numpy")
    return isinstance(value, bool) or (np is not None and isinstance(value, np.bool_))


def number(value: Any, what: str, *, unit: str = "", where: Where = None) -> float:
    """``value`` as a finite float.

    Raises
    ------
    InputError
        Not a number (booleans are refused), NaN or inf.
    """
    u = f" {unit}" if unit else ""
    if _is_bool(value):
        raise InputError(f"{what} must be a number{u}, got {value!r}{where_text(where)}")
    try:
        v = float(value)
    except OverflowError:  # an int beyond float's range
        v = math.inf
    except (TypeError, ValueError):
        raise InputError(
            f"{what} must be a number{u}, got {value!r}{where_text(where)}"
        ) from None
    if not math.isfinite(v):
        raise InputError(f"{what} must be a finite number{u}, got {value!r}{where_text(where)}")
    return v


def positive(value: Any, what: str, *, unit: str = "", where: Where = None) -> float:
    """``value`` as a finite float > 0 (see :func:`number`)."""
    v = number(value, what, unit=unit, where=where)
    if not v > 0:
        u = f" {unit}" if unit else ""
        raise InputError(f"{what} must be a finite number > 0{u}, got {value!r}{where_text(where)}")
    return v


def non_negative(value: Any, what: str, *, unit: str = "", where: Where = None) -> float:
    """``value`` as a finite float >= 0 (see :func:`number`)."""
    v = number(value, what, unit=unit, where=where)
    if not v >= 0:
        u = f" {unit}" if unit else ""
        raise InputError(f"{what} must be a finite number >= 0{u}, got {value!r}{where_text(where)}")
    return v


def in_range(
    value: Any,
    what: str,
    low: float | None = None,
    high: float | None = None,
    *,
    low_open: bool = False,
    high_open: bool = False,
    unit: str = "",
    where: Where = None,
    hint: str = "",
) -> float:
    """``value`` as a finite float in the interval ``low .. high``.

    ``low_open`` / ``high_open`` exclude the bound (``(0, 1]`` is
    ``low=0, high=1, low_open=True``). ``hint`` is appended to the message.
    """
    v = number(value, what, unit=unit, where=where)
    bad = (low is not None and (v <= low if low_open else v < low)) or (
        high is not None and (v >= high if high_open else v > high)
    )
    if bad:
        left = "(" if low_open else "["
        right = ")" if high_open or high is None else "]"
        lo = "-inf" if low is None else _fmt(low)
        hi = "inf" if high is None else _fmt(high)
        u = f" {unit}" if unit else ""
        extra = f"; {hint}" if hint else ""
        raise InputError(
            f"{what} must be in {left}{lo}, {hi}{right}{u}, got {value!r}{extra}{where_text(where)}"
        )
    return v


def optional(check: Any, value: Any, *args: Any, **kwargs: Any) -> Any:
    """``None`` stays None; anything else goes through ``check(value, *args, **kwargs)``."""
    return None if value is None else check(value, *args, **kwargs)


def integer(
    value: Any, what: str, *, minimum: int | None = None, where: Where = None
) -> int:
    """``value`` as an int (an integral float such as ``2.0`` is accepted), ``>= minimum``."""
    ok = not _is_bool(value)
    if ok and isinstance(value, numbers.Integral):  # int and numpy's integers
        v = int(value)
    elif ok and isinstance(value, numbers.Real) and float(value).is_integer():
        v = int(value)
    else:
        raise InputError(f"{what} must be an integer, got {value!r}{where_text(where)}")
    if minimum is not None and v < minimum:
        raise InputError(f"{what} must be an integer >= {minimum}, got {value!r}{where_text(where)}")
    return v


#: Largest seed (numpy's generators take any integer >= 0; 2**63 - 1 keeps it one int64).
MAX_SEED = 2**63 - 1


def seed_value(value: Any, what: str = "seed", *, where: Where = None) -> int:
    """``value`` as a random seed: an integer in [0, 2**63 - 1].

    Examples
    --------
    >>> seed_value(7)
    7
    >>> seed_value(-1, where=("world.seed", "--seed"))
    Traceback (most recent call last):
    ...
    fm2uav.errors.InputError: seed must be an integer in [0, 9223372036854775807], got -1 (mission file: world.seed; CLI: --seed)
    """
    v = integer(value, what, where=where)
    if not 0 <= v <= MAX_SEED:
        raise InputError(f"{what} must be an integer in [0, {MAX_SEED}], got {value!r}"
                         f"{where_text(where)}")
    return v


def choice(value: Any, options: Sequence[Any], what: str, *, where: Where = None) -> Any:
    """``value`` if it is one of ``options`` (compared with ``==``), else InputError."""
    if value not in tuple(options):
        allowed = ", ".join(repr(o) for o in options)
        raise InputError(f"{what} must be one of {allowed}, got {value!r}{where_text(where)}")
    return value


def flag(value: Any, what: str, *, where: Where = None) -> bool:
    """``value`` as a bool; only ``True``/``False`` (and numpy bools) are accepted."""
    if not _is_bool(value):
        raise InputError(f"{what} must be true or false, got {value!r}{where_text(where)}")
    return bool(value)


def point(value: Any, ndim: int, what: str, *, where: Where = None) -> np.ndarray:
    """``value`` as a finite float array of ``ndim`` coordinates [m], shape ``(ndim,)``.

    Raises
    ------
    InputError
        Not numeric, wrong number of coordinates, NaN or inf.
    """
    import numpy as np

    try:
        arr = np.asarray(value, dtype=float).reshape(-1)
    except (TypeError, ValueError):
        raise InputError(
            f"{what} must be {ndim} coordinates in metres, got {value!r}{where_text(where)}"
        ) from None
    if arr.size != ndim:
        raise InputError(
            f"{what} must have {ndim} coordinates (metres) for this {ndim}D world, got "
            f"{arr.size}{where_text(where)}"
        )
    if not np.all(np.isfinite(arr)):
        raise InputError(f"{what} must be finite, got {arr.tolist()}{where_text(where)}")
    return arr


def grid(value: Any, what: str, *, holding: str = "") -> np.ndarray:
    """``value`` as a non-empty 2D or 3D float64 array of numbers (not bools).

    ``holding`` completes "must be a numeric array" in the message (e.g. ``" of
    arrival times"``).

    Raises
    ------
    InputError
        Not numeric, not 2D/3D, or empty.

    Examples
    --------
    >>> grid([[1, 2], [3, 4]], "speed").dtype
    dtype('float64')
    >>> grid([1, 2], "speed")
    Traceback (most recent call last):
    ...
    fm2uav.errors.InputError: speed must be a 2D or 3D array, got 1D with shape (2,)
    """
    import numpy as np

    arr = np.asarray(value)
    if arr.dtype == bool or arr.dtype.kind not in "iuf":
        raise InputError(f"{what} must be a numeric array{holding}, got dtype {arr.dtype}")
    if arr.ndim not in (2, 3):
        raise InputError(f"{what} must be a 2D or 3D array, got {arr.ndim}D with shape "
                         f"{arr.shape}")
    if min(arr.shape) < 1:
        raise InputError(f"{what} must not be empty, got shape {arr.shape}")
    return np.asarray(arr, dtype=np.float64)


# ---------------------------------------------------------------------------------------
# Files: every reader checks its input with these before opening it (issue 17)
# ---------------------------------------------------------------------------------------

def _named(what: str, path: Any) -> str:
    return f"{what} {path}" if what else str(path)


def cwd_gone(path: Any = None) -> str | None:
    """Why the relative ``path`` (any relative path when None) cannot be found because
    the current folder was deleted, or None.

    A shell can stay in a folder that another program removed; every relative path
    then fails with "not found", which names the wrong culprit.
    """
    import os
    from pathlib import Path

    if path is not None and Path(path).is_absolute():
        return None
    try:
        os.getcwd()
    except FileNotFoundError:
        what = f"the relative path {path}" if path is not None else "relative paths"
        return (f"the current folder no longer exists (it was deleted or moved after the shell "
                f"entered it), so {what} cannot be found; cd into an existing folder (e.g. "
                "cd ~) or give absolute paths")
    return None


def missing(path: Any) -> str:
    """Why ``path`` (which does not exist) is missing: ``"not found; check the path"``, or a
    symbolic link pointing nowhere (its target named)."""
    import os

    if os.path.islink(path):
        import errno

        try:
            target = os.readlink(path)
            os.stat(path)
        except OSError as exc:
            if exc.errno == errno.ELOOP:
                return ("is a symbolic link that leads back to itself (a loop of links); fix "
                        "the link or give the file itself")
        return (f"is a symbolic link to {target}, which does not exist; fix the link or give "
                "the file itself")
    return "not found; check the path"


class _Log:
    """The inputs of the running command (see :func:`input_log`); None = not recording."""

    entries: list[tuple[Any, str]] | None = None


def input_log() -> Any:
    """Record, for the duration, every input file and folder the process reads.

    A context manager yielding the live list of ``(path, what)`` entries:
    :func:`input_file` (which every reader calls before opening a file) and
    :func:`note_input` append to it. The command line opens one per command, and
    :class:`fm2uav.io.outdir.OutputDir` takes the list when it is made, so that
    ``--force`` never replaces a folder holding one of the command's inputs, even
    one that a new command reads without declaring it. Nested logs share the
    outermost list.

    Examples
    --------
    >>> with input_log() as log:
    ...     note_input("dem.tif", "the DEM (world.dem, --dem)")
    >>> [(str(p), w) for p, w in log]
    [('dem.tif', 'the DEM (world.dem, --dem)')]
    """
    from contextlib import contextmanager

    @contextmanager
    def scope() -> Any:
        outer = _Log.entries
        if outer is None:
            _Log.entries = []
        try:
            yield _Log.entries
        finally:
            _Log.entries = outer

    return scope()


def note_input(path: Any, what: str) -> None:
    """Add ``path`` (a file or a folder the command reads) to the :func:`input_log`.

    ``what`` names it for a message (``"the mission file"``); nothing happens outside
    an :func:`input_log`.
    """
    import os
    from pathlib import Path

    if _Log.entries is None or not isinstance(path, (str, os.PathLike)) or str(path) == "":
        return
    p = Path(path)
    if all(p != q for q, _ in _Log.entries):
        _Log.entries.append((p, what))


def noted_inputs() -> list[tuple[Any, str]] | None:
    """The live list of the current :func:`input_log` (None outside one)."""
    return _Log.entries


def input_file(path: Any, what: str, *, where: Where = None) -> Any:
    """``path`` as a :class:`pathlib.Path` to an existing, readable, *regular* file.

    Refuses directories, named pipes (FIFOs), sockets and devices up front, so a
    reader never blocks on a pipe or fails with ``IsADirectoryError`` later. The
    path is noted as an input of the running command (:func:`input_log`).

    Raises
    ------
    InputError
        Missing, not a regular file, or not readable (one line naming ``what``
        and ``where``).
    """
    import os
    import stat
    from pathlib import Path

    if not isinstance(path, (str, os.PathLike)) or str(path) == "":
        raise InputError(f"{what} must be a file path, got {path!r}{where_text(where)}")
    p = Path(path)
    note_input(p, (what or "an input file") + where_text(where))
    try:
        st = p.stat()
    except FileNotFoundError:
        gone = cwd_gone(p)
        if gone:
            raise InputError(f"{_named(what, p)}: {gone}{where_text(where)}") from None
        raise InputError(f"{_named(what, p)} {missing(p)}{where_text(where)}") from None
    except OSError as exc:
        if os.path.islink(p):  # a loop of links
            raise InputError(f"{_named(what, p)} {missing(p)}{where_text(where)}") from None
        raise InputError(f"{_named(what, p)} cannot be read ({exc.strerror or exc}); check the path "
                         f"and its permissions{where_text(where)}") from None
    if stat.S_ISDIR(st.st_mode):
        raise InputError(f"{_named(what, p)} is a directory, not a file; give the file inside it"
                         f"{where_text(where)}")
    if not stat.S_ISREG(st.st_mode):
        kind = ("a named pipe (FIFO)" if stat.S_ISFIFO(st.st_mode) else
                "a socket" if stat.S_ISSOCK(st.st_mode) else "a device")
        raise InputError(f"{_named(what, p)} is {kind}, not a regular file; save the data to a file "
                         f"first{where_text(where)}")
    if not os.access(p, os.R_OK):
        raise InputError(f"{_named(what, p)} is not readable (permission denied); fix its "
                         f"permissions{where_text(where)}")
    return p


def read_text(path: Any, what: str, *, where: Where = None) -> str:
    """The UTF-8 text of the regular file ``path`` (see :func:`input_file`), without the
    byte-order mark that Excel and Notepad write at the start.

    Raises
    ------
    InputError
        Not a readable regular file, or not UTF-8 text (the byte offset is named).
    """
    p = input_file(path, what, where=where)
    try:  # utf-8-sig: a byte-order mark (Excel, Notepad) is not part of the text
        return p.read_text(encoding="utf-8-sig")
    except UnicodeDecodeError as exc:
        with open(p, "rb") as fh:
            head = fh.read(2)
        if head in (b"\xff\xfe", b"\xfe\xff"):
            raise InputError(f"{_named(what, p)} is UTF-16 text (as Excel's \"Unicode text\" or "
                             "Windows PowerShell write it), not UTF-8; save it as UTF-8 (Excel: "
                             f"\"CSV UTF-8\"){where_text(where)}") from None
        raise InputError(f"{_named(what, p)} is not a UTF-8 text file (byte {exc.start}: "
                         f"{exc.reason}); give a text file{where_text(where)}") from None
    except OSError as exc:
        raise InputError(f"{_named(what, p)} cannot be read ({exc.strerror or exc}){where_text(where)}"
                         ) from None


_YAML_LOADER: Any = None


#: Most values a YAML document may hold once its aliases are expanded (a mission file has
#: a few hundred; a "billion laughs" file nests aliases to blow up whoever walks it).
MAX_YAML_VALUES = 1_000_000


def _expanded_size(root: Any) -> float:
    """How many scalars and collections ``root`` (a composed YAML node) holds with every
    alias expanded, counted in linear time over the node graph (aliases are shared nodes)."""
    yaml = import_yaml()

    def kids(node: Any) -> list[Any]:
        if isinstance(node, yaml.SequenceNode):
            return list(node.value)
        if isinstance(node, yaml.MappingNode):
            return [v for kv in node.value for v in kv]
        return []

    memo: dict[int, float] = {}
    opened: set[int] = set()
    stack: list[tuple[Any, bool]] = [(root, False)]
    while stack:  # post-order without recursion (a deep file must not exhaust the stack)
        node, done = stack.pop()
        if id(node) in memo:
            continue
        if done:  # every child is counted by now
            memo[id(node)] = 1.0 + sum(memo[id(k)] for k in kids(node))
            continue
        if id(node) in opened:  # met again inside itself: an alias to its own anchor
            return float("inf")
        opened.add(id(node))
        stack.append((node, True))
        stack.extend((k, False) for k in kids(node) if id(k) not in memo)
    return memo[id(root)]


def _yaml_int(loader: Any, node: Any) -> int:
    text = loader.construct_scalar(node)
    return int(text, 0) if text.startswith(("0x", "0o")) else int(text, 10)


def _yaml_float(loader: Any, node: Any) -> float:
    text = str(loader.construct_scalar(node)).lower()
    if text.lstrip("+-") in (".inf", ".nan"):
        return float(text.replace(".", ""))
    return float(text)


def _unique_key_loader() -> Any:
    """A ``yaml.SafeLoader`` subclass: YAML 1.2 core schema for plain scalars, and
    duplicate mapping keys refused.

    PyYAML implements YAML 1.1, whose float pattern needs a dot (``5e-1`` and ``1e3``
    are *text* there), whose booleans include ``yes``/``no``/``on``/``off`` (``no``, the
    country code of Norway, is *false*), whose integers read ``010`` as octal 8 and
    ``1:30`` as 90, and which turns ``2024-01-01`` into a date. The YAML 1.2 core
    schema (what YAML 1.2 parsers and most other tools read) resolves only
    ``true``/``false``, ``null``/``~``, integers ``[-+]?[0-9]+``, ``0o17``, ``0x1F``
    and floats ``[-+]?(.[0-9]+|[0-9]+(.[0-9]*)?)([eE][-+]?[0-9]+)?``, ``.inf``, ``.nan``;
    everything else is text.
    """
    global _YAML_LOADER
    if _YAML_LOADER is not None:
        return _YAML_LOADER
    import re

    yaml = import_yaml()

    class Yaml12Loader(yaml.SafeLoader):
        pass

    tags = {f"tag:yaml.org,2002:{t}": t for t in ("bool", "int", "float", "timestamp")}
    Yaml12Loader.yaml_implicit_resolvers = {
        first: [(tag, rx) for tag, rx in rules if tag not in tags]
        for first, rules in yaml.SafeLoader.yaml_implicit_resolvers.items()}
    Yaml12Loader.add_implicit_resolver(
        "tag:yaml.org,2002:bool", re.compile(r"^(?:true|True|TRUE|false|False|FALSE)$"),
        list("tTfF"))
    Yaml12Loader.add_implicit_resolver(
        "tag:yaml.org,2002:int", re.compile(r"^(?:[-+]?[0-9]+|0o[0-7]+|0x[0-9a-fA-F]+)$"),
        list("-+0123456789"))
    Yaml12Loader.add_implicit_resolver(
        "tag:yaml.org,2002:float", re.compile(
            r"^(?:[-+]?(?:\.[0-9]+|[0-9]+(?:\.[0-9]*)?)(?:[eE][-+]?[0-9]+)?"
            r"|[-+]?\.(?:inf|Inf|INF)|\.(?:nan|NaN|NAN))$"),
        list("-+.0123456789"))
    Yaml12Loader.add_constructor("tag:yaml.org,2002:int", _yaml_int)
    Yaml12Loader.add_constructor("tag:yaml.org,2002:float", _yaml_float)

    def construct_mapping(loader: Any, node: Any, deep: bool = False) -> Any:
        loader.flatten_mapping(node)
        seen: dict[Any, int] = {}
        for key_node, _ in node.value:
            key = loader.construct_object(key_node, deep=True)
            try:
                first = seen.get(key)
            except TypeError:  # an unhashable key: let the normal constructor report it
                continue
            line = key_node.start_mark.line + 1
            if first is not None:
                raise yaml.constructor.ConstructorError(
                    None, None, f"duplicate key {key!r} (lines {first} and {line}): the second "
                    "would silently replace the first; keep one", key_node.start_mark)
            seen[key] = line
        return yaml.SafeLoader.construct_mapping(loader, node, deep=deep)

    Yaml12Loader.add_constructor(yaml.resolver.BaseResolver.DEFAULT_MAPPING_TAG,
                                 construct_mapping)
    _YAML_LOADER = Yaml12Loader
    return Yaml12Loader


def load_yaml(text_or_path: Any, what: str, *, where: Where = None, source: str | None = None
              ) -> Any:
    """Parse YAML (a path to a file, or the text itself with ``source`` naming it).

    Plain scalars follow the YAML 1.2 core schema (``5e-1`` is a number, ``no`` is
    text; see :func:`_unique_key_loader`). Duplicate keys are an error (with both
    line numbers), as are syntax errors (line and column), nesting so deep it
    exhausts the recursion limit, and files that are not UTF-8 text. A byte-order
    mark (as Windows editors write) is ignored.

    Examples
    --------
    >>> load_yaml("a: 1\\nb: [1, 2]", "config", source="<text>")
    {'a': 1, 'b': [1, 2]}
    >>> load_yaml("x: 5e-1\\ny: 1e3\\nz: no\\nw: 010", "config", source="<text>")
    {'x': 0.5, 'y': 1000.0, 'z': 'no', 'w': 10}
    >>> load_yaml("a: 1\\na: 2", "config", source="<text>")
    Traceback (most recent call last):
    ...
    fm2uav.errors.InputError: config <text>: duplicate key 'a' (lines 1 and 2): the second would silently replace the first; keep one, at line 2, column 1
    """
    yaml = import_yaml()  # its reader's slowest pattern compiled fast (fm2uav._yaml_light)

    if source is None:
        text = read_text(text_or_path, what, where=where)
        source = str(text_or_path)
    else:
        text = str(text_or_path)
    try:
        loader = _unique_key_loader()(text)
        try:
            node = loader.get_single_node()
            if node is None:
                return None
            n = _expanded_size(node)
            if n > MAX_YAML_VALUES:
                raise InputError(
                    f"{_named(what, source)}: the document refers to itself through an alias "
                    f"(*name inside its own &name); write the values out{where_text(where)}"
                    if n == float("inf") else
                    f"{_named(what, source)}: the document expands to {n:.3g} values through "
                    f"its aliases (*name), more than {MAX_YAML_VALUES:,} (a \"billion laughs\" "
                    f"file); write the values out or use fewer aliases{where_text(where)}")
            return loader.construct_document(node)
        finally:
            loader.dispose()
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        at = f", at line {mark.line + 1}, column {mark.column + 1}" if mark else ""
        problem = getattr(exc, "problem", None) or str(exc).splitlines()[0]
        if not str(problem).startswith("duplicate key"):
            problem = f"not valid YAML: {problem}"
        raise InputError(f"{_named(what, source)}: {problem}{at}{where_text(where)}") from None
    except RecursionError:
        raise InputError(f"{_named(what, source)}: nested too deeply to read (more than a few hundred "
                         f"levels of lists/mappings); flatten it{where_text(where)}") from None


def load_json(path: Any, what: str, *, where: Where = None) -> Any:
    """Parse the JSON file ``path``; syntax errors name the line and column.

    Raises
    ------
    InputError
        Not a readable regular UTF-8 file, invalid JSON, or nested too deeply.
    """
    import json

    text = read_text(path, what, where=where)
    try:
        return json.loads(text)
    except json.JSONDecodeError as exc:
        raise InputError(f"{_named(what, path)}: not valid JSON ({exc.msg} at line {exc.lineno}, "
                         f"column {exc.colno}){where_text(where)}") from None
    except RecursionError:
        raise InputError(f"{_named(what, path)}: nested too deeply to read{where_text(where)}"
                         ) from None
