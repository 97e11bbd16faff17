"""Help pages kept between runs: ``fm2uav [command ...] --help`` answered without typer or rich.

A help page costs the import of typer and rich (~0.25 CPU-s) and, for a command with
many options, rich's tables (``fm2uav plan --help``: ~0.15 CPU-s more). The page depends
only on the package's source, the libraries that render it and where it is written, so
the first ``--help`` of a page is rendered as usual and its exact text kept; the next ones
copy it (~0.05 s, the interpreter's start included).

The key of a page is everything its rendering reads: the program's name and the command
words; the package's source files (path, size, modification time of every ``.py`` of
``fm2uav``) and the renderers' (typer, rich: their own files likewise), the interpreter;
the standard streams as rich reads them (the size of the first terminal among stdin,
stdout, stderr; whether stdout is a terminal; its encoding); the environment variables
that steer the rendering (colour, width, terminal, locale: :data:`_ENV_PARTS`). A page is
kept only when the command exited 0 having written nothing to stderr. Pages live in
``$FM2UAV_CACHE_DIR/help``, else ``$XDG_CACHE_HOME/fm2uav/help`` (``~/.cache``), one file
per key, written atomically; at most :data:`MAX_PAGES` (the oldest go).
``FM2UAV_HELP_CACHE=0`` turns it off; a cache that cannot be read or written is ignored
(the page is rendered). ``make install`` renders every page once for scripts and pipes.

This module imports nothing of fm2uav and no third-party library.
"""

from __future__ import annotations

import os
import sys
from collections.abc import Sequence
from typing import Any

__all__ = ["MAX_PAGES", "help_words", "cache_dir", "page_key", "serve", "Recorder", "keep"]

#: Pages kept at most (each ~2–8 kB); the least recently written go first.
MAX_PAGES = 200

#: Environment variables whose name contains one of these steer rich/typer's rendering.
_ENV_PARTS = ("COLOR", "TERM", "COLUMNS", "LINES", "TTY", "TYPER", "RICH", "JUPYTER",
              "GITHUB_ACTIONS", "LANG", "LC_", "PYTHONIOENCODING", "PYTHONUTF8")

_HELP = "--help"


def help_words(argv: Sequence[str]) -> tuple[str, ...] | None:
    """The command words of a plain help request (``[cmd ...] --help``), else None.

    Only command words (lower-case letters, digits, ``-``) before one final ``--help``;
    anything else (options, values, ``-h``) is left to typer.
    """
    if not argv or argv[-1] != _HELP:
        return None
    words = tuple(argv[:-1])
    for w in words:
        if not w or not (w[0].isalpha() and w.islower()) or not all(
                c.isalnum() or c == "-" for c in w):
            return None
    return words


def cache_dir() -> str:
    """Where the pages live (``$FM2UAV_CACHE_DIR/help``, else the user's cache directory)."""
    root = os.environ.get("FM2UAV_CACHE_DIR")
    if not root:
        xdg = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"),
                                                               ".cache")
        root = os.path.join(xdg, "fm2uav")
    return os.path.join(root, "help")


def _tree(root: str, out: list[str]) -> None:
    """Every ``.py`` file under ``root`` as ``path size mtime_ns`` (``__pycache__`` skipped)."""
    try:
        entries = sorted(os.scandir(root), key=lambda e: e.name)
    except OSError:
        out.append(f"{root} unreadable")
        return
    for e in entries:
        try:
            if e.is_dir(follow_symlinks=False):
                if e.name != "__pycache__":
                    _tree(e.path, out)
            elif e.name.endswith(".py"):
                st = e.stat()
                out.append(f"{e.path} {st.st_size} {st.st_mtime_ns}")
        except OSError:
            out.append(f"{e.path} unreadable")


def _package_dir(name: str) -> str | None:
    """The folder of an installed top-level package, without importing it."""
    for entry in sys.path:
        d = os.path.join(entry or os.getcwd(), name)
        if os.path.isfile(os.path.join(d, "__init__.py")):
            return d
    return None


def _streams() -> list[str]:
    """What rich reads of the standard streams: the size of the first terminal among stdin,
    stdout, stderr (its width), whether stdout is a terminal (colours), stdout's encoding."""
    size = None
    for fd in (0, 1, 2):
        try:
            size = tuple(os.get_terminal_size(fd))
        except (OSError, ValueError):
            continue
        break
    try:
        tty = sys.stdout.isatty()
    except (AttributeError, OSError, ValueError):
        tty = False
    return [f"terminal {size}", f"stdout tty {tty}",
            f"stdout {getattr(sys.stdout, 'encoding', None)} "
            f"{getattr(sys.stdout, 'errors', None)} {type(sys.stdout).__name__}"]


def page_key(words: Sequence[str]) -> str:
    """The key (hex SHA-256) of the help page of ``fm2uav <words> --help`` here and now."""
    # the program's name is on the page ("Usage: fm2uav ..." / "python -m fm2uav ...")
    name = os.path.basename(sys.argv[0]) if sys.argv and sys.argv[0] else ""
    parts = ["fm2uav help page 1", sys.executable, sys.version, name, " ".join(words)]
    parts += _streams()
    parts += sorted(f"{k}={v}" for k, v in os.environ.items()
                    if any(p in k.upper() for p in _ENV_PARTS))
    _tree(os.path.dirname(os.path.abspath(__file__)), parts)
    for lib in ("typer", "rich", "click"):
        d = _package_dir(lib)
        if d is not None:
            _tree(d, parts)
    import hashlib  # (OpenSSL's: only for a help request)

    return hashlib.sha256("\n".join(parts).encode("utf-8", "backslashreplace")).hexdigest()


def _enabled() -> bool:
    return os.environ.get("FM2UAV_HELP_CACHE", "1").strip() not in ("0", "false", "no", "off")


def serve(argv: Sequence[str]) -> tuple[bool, str | None]:
    """Write the kept page of a help request to stdout.

    Returns
    -------
    (bool, str or None)
        Whether the page was written (the command is answered: exit 0), and the key to
        keep the page under once rendered (None: not a cacheable request).
    """
    words = help_words(argv)
    if words is None or not _enabled():
        return False, None
    key = page_key(words)
    try:
        with open(os.path.join(cache_dir(), key + ".txt"), encoding="utf-8") as fh:
            text = fh.read()
    except (OSError, UnicodeDecodeError):
        return False, key
    sys.stdout.write(text)
    sys.stdout.flush()
    return True, key


class Recorder:
    """Stands in for a standard stream: writes through and keeps what was written."""

    def __init__(self, stream: Any) -> None:
        self._stream = stream
        self.parts: list[str] = []

    def write(self, text: Any) -> int:
        # click writes an empty ``b""`` once (its flush): kept as text in the stream's encoding
        self.parts.append(text.decode(getattr(self._stream, "encoding", None) or "utf-8")
                          if isinstance(text, (bytes, bytearray)) else text)
        return self._stream.write(text)

    def writelines(self, lines: Any) -> None:
        for line in lines:
            self.write(line)

    def __getattr__(self, name: str) -> Any:
        return getattr(self._stream, name)


def keep(key: str, text: str) -> None:
    """Keep a rendered page under ``key`` (atomically; errors ignored), at most MAX_PAGES."""
    d = cache_dir()
    try:
        os.makedirs(d, exist_ok=True)
        tmp = os.path.join(d, f".{key}.{os.getpid()}.tmp")
        with open(tmp, "w", encoding="utf-8") as fh:
            fh.write(text)
        os.replace(tmp, os.path.join(d, key + ".txt"))
        pages = [e for e in os.scandir(d) if e.name.endswith(".txt")]
        if len(pages) > MAX_PAGES:
            pages.sort(key=lambda e: e.stat().st_mtime_ns)
            for e in pages[:len(pages) - MAX_PAGES]:
                os.unlink(e.path)
    except OSError:
        pass
