"""``import yaml`` without compiling its slowest regular expression (issue 27: an instant
command line).

PyYAML's pure-Python reader checks every document for characters YAML does not allow
with one regular expression, compiled when ``yaml`` is imported
(``yaml.reader.Reader.NON_PRINTABLE``: "any character except TAB, LF, CR, the printable
ASCII range, NEL, and the printable ranges U+00A0-U+D7FF, U+E000-U+FFFD,
U+10000-U+10FFFF"). Written as the complement of those ranges, Python's regular
expression compiler walks a 65,536-entry table in Python code: ~30 ms (57 M
instructions), more than half of what importing yaml costs, on every mission file the
command line reads (``fm2uav run bad.yaml`` answers in ~0.3 s).

The same set written directly — the characters that are *not* allowed,
:data:`NOT_ALLOWED` — compiles in ~1 ms and matches exactly the same characters (every
code point, tests/test_yaml_light.py). :func:`import_yaml` puts that pattern in the
``re`` module's cache under yaml's pattern before yaml is first imported, so
``re.compile`` returns it to the reader instead of compiling the slow form; matches,
their ``group()`` and ``start()``, and so yaml's errors are unchanged. When yaml is
imported already, or the ``re`` module keeps its cache differently (another Python
version), nothing is seeded and yaml compiles its own pattern as before.

Bottom layer (the standard library's ``re`` and ``sys``; PyYAML on call).
"""

from __future__ import annotations

import re
import sys
from types import ModuleType

__all__ = ["NOT_ALLOWED", "YAML_NON_PRINTABLE", "import_yaml"]

#: ``yaml.reader.Reader.NON_PRINTABLE``'s pattern (PyYAML 5 and 6): the characters allowed
#: in a YAML stream, negated.
YAML_NON_PRINTABLE = ("[^\x09\x0A\x0D\x20-\x7E\x85\xA0-\uD7FF\uE000-\uFFFD"
                      "\U00010000-\U0010ffff]")
#: The same set of characters, listed: C0 controls but TAB, LF and CR; DEL and the C1
#: controls but NEL; the surrogates; U+FFFE and U+FFFF.
NOT_ALLOWED = "[\x00-\x08\x0B\x0C\x0E-\x1F\x7F-\x84\x86-\x9F\uD800-\uDFFF\uFFFE\uFFFF]"


def _seed() -> bool:
    """Put the fast pattern in ``re``'s cache under yaml's; whether it was put there."""
    cache = getattr(re, "_cache", None)
    if not isinstance(cache, dict):  # pragma: no cover - another re module
        return False
    key = (str, YAML_NON_PRINTABLE, 0)
    if key not in cache:
        cache[key] = re.compile(NOT_ALLOWED)
    return True


def import_yaml() -> ModuleType:
    """The ``yaml`` module, imported (the first time) with its reader's pattern of
    characters not allowed compiled fast (see the module's notes)."""
    if "yaml" not in sys.modules:
        _seed()
    import yaml

    return yaml
