"""Compiled code of the source text libraries write at import, kept between runs (issue 27:
an instant command line).

Python source that libraries build as text and compile while they are imported is parsed
and compiled again in every process: each ``@dataclass`` class compiles its ``__init__``,
``__repr__``, ``__eq__``... from generated text (:mod:`dataclasses`, ``exec``), each
``namedtuple`` its ``__new__`` (:mod:`collections`, ``eval``), and each string annotation
(``from __future__ import annotations`` in pydantic-core's schema types, pydantic's
models) becomes a :class:`typing.ForwardRef` that compiles its text (``compile``). On
``fm2uav run bad.yaml`` that is ~1,300 compilations, ~190 M instructions (~22 % of the
answer); on ``fm2uav plan --bogus`` ~100. Regular expressions are the same kind of work:
:mod:`re` parses a pattern and compiles it to the matcher's code in Python (~60 patterns
compiled at import on ``run bad.yaml``: textwrap, logging, yaml's resolver, rich, typer...).

:func:`install` (the entry point, :mod:`fm2uav.__main__`, once a help page is not served
from :mod:`fm2uav._help_cache`) gives those three modules an ``exec``, ``eval`` and
``compile`` of their own (a module global, which the module's code finds before the
built-in) that look the text up in a table of code objects kept from earlier runs and
compile it only when it is new, and :mod:`re` a compiler (``re._compiler.compile``) that
takes a pattern's matcher code (the arguments of ``_sre.compile``) from the same table.
:func:`save` (at exit) adds the new ones to the table.

The key of a code object is everything compiling reads: the exact text, the mode
(``exec`` / ``eval``), the ``__future__`` flags the built-in would inherit from its
caller, and the interpreter (the file's name holds its bytecode magic number and
:mod:`marshal`'s format; :data:`sys.version` is checked inside). Compiling is a function
of those alone, so a kept entry can never differ from a fresh compilation: there is
nothing to go stale. Anything else (bytes, a file name other than ``<string>``, explicit
flags, another ``optimize``) goes to the built-in unchanged, and so does a text the
built-in refuses (its own error, raised by the built-in itself). A pattern's key is its
text (``str`` or ``bytes``) and flags; a pattern the parser refuses raises the parser's
error, and one whose parsing warns (a possible nested set...) is not kept, so it warns
again in every run; ``re.DEBUG``, and a new pattern while other threads run (the warnings'
check is process-wide), go to :mod:`re` unchanged.

The tables live in ``$FM2UAV_CACHE_DIR/code``, else ``$XDG_CACHE_HOME/fm2uav/code``
(``~/.cache``), one :mod:`marshal` file per interpreter and command word (``plan``,
``run``, ...: a run reads only what its command compiles, ~8 M instructions for
``run``'s ~1,300 entries), written atomically; at most :data:`MAX_ENTRIES` entries
(beyond, only the run's own are kept). A table that cannot be
read or written is ignored (the text is compiled); ``FM2UAV_CODE_CACHE=0`` turns it off.
Only the entry point installs it: the library, and tests running commands in process,
compile as usual.

Bottom layer (the standard library only).
"""

from __future__ import annotations

import builtins
import marshal
import os
import sys
from typing import Any

__all__ = ["MAX_ENTRIES", "MODULES", "cache_file", "enabled", "install", "installed",
           "lookup", "save", "stats"]

#: Entries kept at most per table (each ~0.2 kB, read by every run of its command); a run
#: that would pass it keeps its own only.
MAX_ENTRIES = 5_000

#: The modules given a caching built-in, and which: those that compile generated text.
MODULES = {"dataclasses": ("exec",), "collections": ("eval",), "typing": ("compile",)}

_FILE_NAME = "<string>"  # the file name exec/eval give a text (and typing's compile)
_HEADER = "fm2uav code cache 1"


def _future_mask() -> int:
    """The compiler flags of every ``__future__`` feature: what exec/eval/compile inherit
    from the calling frame (``PyCF_MASK``)."""
    import __future__

    mask = 0
    for name in __future__.all_feature_names:
        mask |= getattr(__future__, name).compiler_flag
    return mask


class _State:
    table: dict[tuple[str, int, Any], Any] | None = None  # None: not installed (key: mode, flags, text)
    used: dict[tuple[str, int, Any], Any] = {}  # the entries this run looked up or added
    new = 0  # entries compiled in this run
    hits = 0
    path = ""
    mask = 0


def enabled() -> bool:
    """Whether the table is used (``FM2UAV_CODE_CACHE`` is not 0/false/no/off)."""
    return os.environ.get("FM2UAV_CODE_CACHE", "1").strip().lower() not in (
        "0", "false", "no", "off")


def cache_file(command: str = "") -> str:
    """The table of this interpreter (its bytecode magic number and marshal's format) for
    ``command`` (a command word: lower-case letters, digits and ``-``; anything else
    shares one table)."""
    from ._help_cache import cache_dir

    if not (command[:1].isalpha() and command.islower()
            and all(c.isalnum() or c == "-" for c in command)):
        command = "_"
    magic = sys.modules["_frozen_importlib_external"].MAGIC_NUMBER.hex()
    name = f"{sys.implementation.cache_tag}-{magic}-m{marshal.version}-{command}.marshal"
    return os.path.join(os.path.dirname(cache_dir()), "code", name)


def _load(path: str) -> dict:
    """The table kept in ``path`` ({} when absent, unreadable or of another interpreter)."""
    try:
        with open(path, "rb") as fh:
            data = marshal.loads(fh.read())
    except (OSError, ValueError, EOFError, TypeError):
        return {}
    if (not isinstance(data, tuple) or len(data) != 3 or data[0] != _HEADER
            or data[1] != sys.version or not isinstance(data[2], dict)):
        return {}
    return data[2]


def lookup(source: str, mode: str, flags: int) -> Any:
    """The code object of ``source`` compiled as ``compile(source, "<string>", mode,
    flags, dont_inherit=True)`` — from the table, else compiled and added.

    Raises what :func:`compile` raises for a text it refuses (nothing is added).
    """
    key = (mode, flags, source)
    table = _State.table
    code = table.get(key) if table is not None else None
    if code is None:
        code = builtins.compile(source, _FILE_NAME, mode, flags, True)
        if table is not None:
            table[key] = code
            _State.new += 1
    else:
        _State.hits += 1
    _State.used[key] = code
    return code


def _caller_flags(depth: int = 2) -> int:
    """The ``__future__`` flags of the frame calling the built-in's stand-in."""
    return sys._getframe(depth).f_code.co_flags & _State.mask


def _prepared(source: Any, mode: str, globals: Any, locals: Any) -> tuple[Any, Any, Any]:
    """What the stand-in of ``exec`` / ``eval`` (``mode``) hands the built-in: the text's
    code from the table (a text the built-in refuses, or not a text, unchanged) and the
    namespaces the built-in would default to (the stand-in's caller's)."""
    frame = sys._getframe(2)
    if globals is None:  # the built-ins' defaults: the caller's namespaces
        globals = frame.f_globals
        if locals is None:
            locals = frame.f_locals
    elif locals is None:
        locals = globals
    if type(source) is str:
        text = source if mode == "exec" else source.lstrip(" \t")  # eval strips them too
        try:
            source = lookup(text, mode, frame.f_code.co_flags & _State.mask)
        except (SyntaxError, ValueError):  # the built-in raises its own error
            pass
    return source, globals, locals


def _exec(source: Any, globals: Any = None, locals: Any = None, /, **kw: Any) -> Any:
    """``exec`` for :mod:`dataclasses`: a text's code from the table, run as exec runs it."""
    return builtins.exec(*_prepared(source, "exec", globals, locals), **kw)


def _eval(source: Any, globals: Any = None, locals: Any = None, /) -> Any:
    """``eval`` for :mod:`collections`: a text's code from the table, run as eval runs it."""
    return builtins.eval(*_prepared(source, "eval", globals, locals))


def _compile(source: Any, filename: Any, mode: str, flags: int = 0, dont_inherit: bool = False,
             optimize: int = -1, **kw: Any) -> Any:
    """``compile`` for :mod:`typing` (forward references): a plain call's code from the
    table; any other call as the built-in makes it for the caller."""
    inherited = 0 if dont_inherit else _caller_flags()
    if (type(source) is str and filename == _FILE_NAME and mode in ("exec", "eval")
            and flags == 0 and optimize == -1 and not kw):
        try:
            return lookup(source, mode, inherited)
        except (SyntaxError, ValueError):
            pass
    return builtins.compile(source, filename, mode, flags | inherited, True, optimize, **kw)


_STAND_INS = {"exec": _exec, "eval": _eval, "compile": _compile}


def installed() -> bool:
    """Whether :func:`install` put the stand-ins in place in this process."""
    return _State.table is not None


def install(command: str = "") -> bool:
    """Give :data:`MODULES` their caching built-ins, the table of ``command`` read from
    :func:`cache_file` (see the module's notes); True when installed. Imports
    :mod:`dataclasses` (and :mod:`typing`, :mod:`collections`) so their first use finds the
    stand-ins."""
    if _State.table is not None or not enabled():
        return _State.table is not None
    import collections  # noqa: F401
    import dataclasses  # noqa: F401
    import typing  # noqa: F401

    _State.mask = _future_mask()
    _State.path = cache_file(command)
    _State.table = _load(_State.path)
    for module, names in MODULES.items():
        namespace = vars(sys.modules[module])
        for name in names:
            if name not in namespace:  # a module of its own name: left as it is
                namespace[name] = _STAND_INS[name]
    import re._compiler

    if not _RE_COMPILE:
        _RE_COMPILE.append(re._compiler.compile)
        re._compiler.compile = _re_compile
    return True


def save() -> bool:
    """Write the table back when this run compiled new entries (atomically; errors
    ignored); True when written."""
    table = _State.table
    if table is None or not _State.new:
        return False
    keep = table if len(table) <= MAX_ENTRIES else dict(_State.used)
    path = _State.path
    tmp = f"{path}.{os.getpid()}.tmp"
    try:
        os.makedirs(os.path.dirname(path), exist_ok=True)
        with open(tmp, "wb") as fh:
            fh.write(marshal.dumps((_HEADER, sys.version, keep)))
        os.replace(tmp, path)
    except (OSError, ValueError):
        try:  # a write cut short (a full disk...) leaves no partial file behind
            os.unlink(tmp)
        except OSError:
            pass
        return False
    _State.new = 0
    return True


def _re_compile(p: Any, flags: int = 0) -> Any:
    """``re._compiler.compile`` with the matcher's code of a pattern text from the table
    (see the module's notes): the same ``_sre.compile`` call, its arguments kept."""
    compiler = sys.modules["re._compiler"]
    if not (type(p) in (str, bytes) and type(flags) is int) or flags & compiler.SRE_FLAG_DEBUG:
        return (_RE_COMPILE or [compiler.compile])[0](p, flags)
    key = ("re", flags, p)
    table = _State.table
    args = table.get(key) if table is not None else None
    if args is None:
        import threading
        import warnings

        if threading.active_count() > 1:  # catch_warnings is process-wide: left to re
            return (_RE_COMPILE or [compiler.compile])[0](p, flags)
        with warnings.catch_warnings(record=True) as said:
            warnings.simplefilter("always")
            parsed = compiler._parser.parse(p, flags)
        for w in said:  # said again where the parser said it; such a pattern is not kept
            warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
        state = parsed.state
        index = [None] * state.groups
        for name, i in state.groupdict.items():
            index[i] = name
        code = list(map(int, compiler._code(parsed, flags)))  # marshal takes plain ints
        args = (flags | state.flags, code, state.groups - 1, dict(state.groupdict),
                tuple(index))
        if table is not None and not said:
            table[key] = args
            _State.new += 1
    else:
        _State.hits += 1
    _State.used[key] = args
    return compiler._sre.compile(p, *args)


#: ``re._compiler.compile`` as :mod:`re` has it (set by :func:`install`).
_RE_COMPILE: list[Any] = []


def stats() -> dict[str, int]:
    """Entries in the table, looked up in the table (hits) and compiled (new) in this run."""
    return {"entries": len(_State.table or {}), "hits": _State.hits, "new": _State.new}
